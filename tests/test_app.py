"""The live app over HTTP (no browser): answers against a published elastica, bad requests,
a taken port, Ctrl-C, clients that reset their connection and a burst of 200 requests."""

from __future__ import annotations

import http.client
import json
import os
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import softarm

pytest.importorskip("plotly", reason="the app needs plotly: pip install 'softarm[view]'")

from softarm import app, cli
from softarm.case import CaseError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def server():
    live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
    httpd = app.make_server(live, port=0)
    thread = threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.05},
                              daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}", live
    httpd.shutdown()
    httpd.server_close()


def get(url):
    try:
        with urllib.request.urlopen(url, timeout=60) as reply:
            return reply.status, reply.read()
    except urllib.error.HTTPError as error:
        return error.code, error.read()


def test_inputs_of_the_case():
    live = app.LiveCase(softarm.load_case(EXAMPLES / "demo.toml"))
    names = [i.name for i in live.inputs]
    assert names == ["l1.on", "l1.acceleration.x", "l1.acceleration.y", "l1.acceleration.z",
                     "l2.on", "l2.force.x", "l2.force.y", "l2.force.z", "l2.moment.x",
                     "l2.moment.y", "l2.moment.z"]
    by = live.by_name
    # tip force |(0, 0.15, -0.4)| = 0.427 N: sliders over ±2 × that, rounded up to ±1 N
    assert (by["l2.force.y"].low, by["l2.force.y"].high, by["l2.force.y"].value) == \
        (-1.0, 1.0, 0.15)
    # a zero moment: ± EI/L rounded up; EI of the tip tube = E π (R⁴ - r⁴)/4
    EI = 2.0e6 * np.pi * (0.011**4 - 0.005**4) / 4  # demo.toml, tip segment (the softer)
    assert by["l2.moment.z"].high >= EI / 0.4 > by["l2.moment.z"].high / 5
    assert by["l1.acceleration.z"].high == 20.0  # |g| = 9.81 m/s²: ±2 × 9.81 rounded up


def test_solve_matches_the_published_elastica(server):
    url, _ = server
    status, body = get(f"{url}/reset?l1.force.z=-5")
    assert status == 200
    reply = json.loads(body)
    # Mattiasson (1981) Table 1, k = PL²/EI = 5: w/L = 0.71379, u/L = 0.38763
    np.testing.assert_allclose(reply["tip"], [1 - 0.38763, 0.0, -0.71379], atol=2e-5)
    assert reply["solve_ms"] > 0 and reply["method"].startswith("numeric")
    # k = 1: w/L = 0.30172 (same table), reached from k = 5 quasi-statically
    status, body = get(f"{url}/solve?l1.force.z=-1")
    np.testing.assert_allclose(json.loads(body)["tip"][2], -0.30172, atol=2e-5)


def test_tip_moment_slider_against_a_circular_arc(server):
    url, _ = server
    # pure bending: a tip moment τ bends the arm into an arc of curvature τ/EI (EI = 1 N m²)
    status, body = get(f"{url}/solve?l1.force.z=0&l1.moment.y=-0.8")
    assert status == 200, body
    tau = 0.8
    np.testing.assert_allclose(json.loads(body)["tip"], [np.sin(tau) / tau, 0.0,
                                                         (1 - np.cos(tau)) / tau], atol=1e-5)


@pytest.mark.parametrize(("query", "message"), [
    ("l1.force.z=abc", "must be a number"),
    ("l1.force.z=nan", "finite"),
    ("l1.force.z=1e9", "must be in"),
    ("nosuch=1", "unknown input"),
    ("l1.on=0.5", "0 (off) or 1 (on)"),
    ("l1.force.z=1&l1.force.z=2", "twice"),
    ("%%%", "malformed"),
])
def test_bad_request_gets_400_and_the_server_keeps_serving(server, query, message):
    url, live = server
    before = dict(live.values)
    status, body = get(f"{url}/solve?{query}")
    assert status == 400
    assert message in json.loads(body)["error"]
    assert live.values == before
    status, _ = get(f"{url}/solve?l1.force.z=-2")
    assert status == 200


def test_unknown_page_and_the_page_itself(server):
    url, _ = server
    assert get(f"{url}/nothing")[0] == 404
    status, body = get(url + "/")
    assert status == 200 and b'<script src="/plotly.min.js">' in body
    status, body = get(url + "/plotly.min.js")
    assert status == 200 and b"plotly.js v" in body[:300]


def test_port_taken(capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
        with pytest.raises(CaseError, match=f"port {port} on 127.0.0.1 is already in use"):
            app.make_server(live, port)
        code = cli.main(["app", str(EXAMPLES / "mattiasson_cantilever.toml"), "--port",
                         str(port), "--no-browser"])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and "already in use" in err


def start_app():
    """`softarm app` on the Mattiasson case, on a free port, as a child process; (the child,
    its address)."""
    launcher = Path(sys.executable).with_name("softarm")
    command = [str(launcher)] if launcher.exists() else [sys.executable, "-m", "softarm"]
    child = subprocess.Popen([*command, "app", str(EXAMPLES / "mattiasson_cantilever.toml"),
                              "--port", "0", "--no-browser"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    line = child.stdout.readline()
    # the first line is the address: no claim of a compile (a kernel compiled for the first
    # time says so itself, on stderr, with this machine's time: tests/test_compile.py)
    assert line.startswith("softarm app for ") and "at http://127.0.0.1:" in line, line
    return child, line.split(" at ")[1].split()[0]


def stop_app(child) -> str:
    """Ctrl-C to the app; its stderr (the app must exit with 130)."""
    try:
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=30)
    finally:
        if child.poll() is None:
            os.kill(child.pid, signal.SIGKILL)
    assert child.returncode == 130
    return err


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
@pytest.mark.slow
def test_ctrl_c_stops_the_app_cleanly():
    child, address = start_app()
    assert get(address)[0] == 200
    assert stop_app(child).strip() == "softarm: interrupted"


def reset(sock: socket.socket) -> None:
    """Close with SO_LINGER 0: the connection ends with a TCP reset, as a client that crashes
    or is killed leaves it."""
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    sock.close()


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
@pytest.mark.slow
def test_a_client_that_resets_its_connection_is_no_error():
    # It used to print a ConnectionResetError traceback on the app's stderr.
    child, address = start_app()
    host, port = "127.0.0.1", int(address.rstrip("/").rsplit(":", 1)[1])
    try:
        # reset in the middle of the request's headers (the server is reading them) ...
        sock = socket.create_connection((host, port), timeout=30)
        sock.sendall(b"GET /solve?l1.force.z=-1 HTTP/1.1\r\nHost: softarm\r\n")
        time.sleep(0.3)
        reset(sock)
        # ... and after a whole request for plotly.js, 4.8 MB (the server is writing it)
        sock = socket.create_connection((host, port), timeout=30)
        sock.sendall(b"GET /plotly.min.js HTTP/1.1\r\nHost: softarm\r\n\r\n")
        sock.recv(1000)
        reset(sock)
        time.sleep(0.3)
        # the app serves on: the Mattiasson elastica at k = 5 (w/L = 0.71379, u/L = 0.38763)
        status, body = get(f"{address}reset?l1.force.z=-5")
        assert status == 200
        np.testing.assert_allclose(json.loads(body)["tip"], [1 - 0.38763, 0.0, -0.71379],
                                   atol=2e-5)
    finally:
        err = stop_app(child)
    assert err.strip() == "softarm: interrupted"


def test_static_files_are_served_while_a_solve_runs():
    # a solve holds the app's lock (its one Solver): plotly.js, the inputs and unknown pages
    # are answered meanwhile, and another solve waits for the lock
    live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
    httpd = app.make_server(live, port=0)
    threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.05},
                     daemon=True).start()
    url = f"http://127.0.0.1:{httpd.server_address[1]}"
    done = threading.Event()
    try:
        with httpd.RequestHandlerClass.lock:
            solving = threading.Thread(target=lambda: (get(f"{url}/solve?l1.force.z=-1"),
                                                       done.set()), daemon=True)
            solving.start()
            assert get(f"{url}/plotly.min.js")[0] == 200
            assert get(f"{url}/inputs")[0] == 200
            assert get(f"{url}/nothing")[0] == 404
            assert not done.is_set()
        assert done.wait(timeout=60)
    finally:
        httpd.shutdown()
        httpd.server_close()


def test_a_burst_of_200_requests_is_all_answered():
    """200 clients connect at once, before the server takes any of them (a burst that
    arrives faster than it accepts): every connection is queued (the listen backlog was 5:
    six got in, the others waited for seconds, were reset or never answered), then each
    sends its request and gets the right answer: 150 solves, serialised on the app's one
    Solver, each the equilibrium of its own input, mixed with requests for plotly.js and the
    inputs. The timeouts are generous: they fail only if a request hangs."""
    live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
    httpd = app.make_server(live, port=0)  # listening, not yet accepting
    port = httpd.server_address[1]
    socks, serving = [], None
    try:
        for _ in range(200):
            sock = socket.socket()
            sock.setblocking(False)
            sock.connect_ex(("127.0.0.1", port))
            socks.append(sock)
        pending, deadline = set(socks), time.monotonic() + 30
        while pending and time.monotonic() < deadline:
            _, writable, _ = select.select([], list(pending), [], 0.1)
            pending -= set(writable)
        connected = [s for s in socks
                     if s not in pending and s.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR) == 0]
        assert len(connected) == 200, f"{len(connected)} of 200 connections were queued"
        serving = threading.Thread(target=httpd.serve_forever,
                                   kwargs={"poll_interval": 0.05}, daemon=True)
        serving.start()
        forces = -0.5 * np.arange(1, 11)  # k = P L²/EI = 0.5 ... 5
        others = "&".join(f"l1.{field}.{axis}=0" for field in ("force", "moment")
                          for axis in "xyz" if (field, axis) != ("force", "z"))
        plotly_js = softarm.view.plotly_js_path().read_bytes()
        replies: list = [None] * 200

        def ask(k):
            sock = socks[k]
            sock.setblocking(True)
            sock.settimeout(120)
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
            connection.sock = sock
            path = ("/plotly.min.js" if k % 8 == 0 else "/inputs" if k % 8 == 1 else
                    f"/solve?{others}&l1.force.z={forces[k % 10]}")
            connection.request("GET", path)
            answer = connection.getresponse()
            replies[k] = (answer.status, answer.read())
            connection.close()

        askers = [threading.Thread(target=ask, args=(k,), daemon=True) for k in range(200)]
        for asker in askers:
            asker.start()
        for asker in askers:
            asker.join(timeout=180)
    finally:
        if serving is not None:
            httpd.shutdown()
        httpd.server_close()
        for sock in socks:
            sock.close()
    assert all(reply is not None for reply in replies), \
        f"{sum(reply is None for reply in replies)} of 200 requests got no answer"
    assert all(status == 200 for status, _ in replies)
    # each solve is the equilibrium of its own input: the same tip as a solve from unloaded
    expected = {k: softarm.solve(live.case.arm, softarm.TipLoad(force=[0.0, 0.0, force]),
                                 method="numeric").tip_position
                for k, force in enumerate(forces)}
    names = [item.name for item in live.inputs]
    for k, (_, body) in enumerate(replies):
        if k % 8 == 0:
            assert body == plotly_js
        elif k % 8 == 1:
            assert [item["name"] for item in json.loads(body)] == names
        else:
            np.testing.assert_allclose(json.loads(body)["tip"], expected[k % 10],
                                       atol=1e-6, err_msg=f"request {k}")



def test_axis_cube_holds_the_arm_and_only_grows():
    live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
    live.update({"l1.force.z": "0"})
    first = live.solve()
    ranges = np.array(first["ranges"])
    sides = ranges[:, 1] - ranges[:, 0]
    np.testing.assert_allclose(sides, sides[0])  # equal scaling on x, y and z
    # straight arm: from the base (0, 0, 0) to the tip (1, 0, 0) m, inside the cube
    assert np.all(ranges[:, 0] <= 0.0) and ranges[0, 1] >= 1.0
    live.update({"l1.force.z": "-10"})  # k = 10: the arm hangs far below
    hanging = np.array(live.solve()["ranges"])
    assert np.all(hanging[:, 0] <= ranges[:, 0]) and np.all(hanging[:, 1] >= ranges[:, 1])
    assert hanging[2, 0] <= live.result.tip_position[2]
    live.update({"l1.force.z": "0"})  # back: the view keeps its size, it does not jump
    np.testing.assert_allclose(live.solve()["ranges"], hanging)


def test_the_page_figure_fills_the_page_and_its_ticks_follow_the_cube():
    # the app's figure was 700 px high, whatever the window: now it has no height of its own
    # (it is as high as its element, the page); each reply carries the tick values for the
    # axis cube as it grows (none near a corner of the box, see softarm.view.axis_ticks)
    live = app.LiveCase(softarm.load_case(EXAMPLES / "mattiasson_cantilever.toml"))
    assert "height" not in live.figure()["layout"]
    for force in ("0", "-10"):
        live.update({"l1.force.z": force})
        reply = live.solve()
        assert reply["ticks"] == [softarm.view.axis_ticks(*bounds)
                                  for bounds in reply["ranges"]]


def test_without_plotly_one_line(monkeypatch, capsys):
    def missing():
        raise ImportError(softarm.view.PLOTLY_MISSING)

    monkeypatch.setattr(app, "plotly_js_path", missing)
    code = cli.main(["app", str(EXAMPLES / "mattiasson_cantilever.toml"), "--no-browser"])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and "pip install 'softarm[view]'" in err


def test_load_headings_follow_the_sliders(server):
    """Each load's heading on the page is redescribed with the current values (it used to keep
    the case file's): here the tip force set by the request, the other components the case's."""
    url, live = server
    status, body = get(f"{url}/solve?l1.force.z=-2.5")
    assert status == 200, body
    heading = json.loads(body)["headings"]["l1.on"]
    v = live.values  # (earlier tests in this module moved other sliders)
    expected = live.case.loads[0].replace(
        force=np.array([v["l1.force.x"], v["l1.force.y"], -2.5]),
        moment=np.array([v["l1.moment.x"], v["l1.moment.y"], v["l1.moment.z"]]))
    assert heading == "1: " + expected.describe()
    assert "-2.5" in heading
