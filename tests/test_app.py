"""The live app over HTTP (no browser): answers against a published elastica, bad requests,
a taken port and Ctrl-C."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
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


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
def test_ctrl_c_stops_the_app_cleanly():
    launcher = Path(sys.executable).with_name("softarm")
    command = [str(launcher)] if launcher.exists() else [sys.executable, "-m", "softarm"]
    child = subprocess.Popen([*command, "app", str(EXAMPLES / "mattiasson_cantilever.toml"),
                              "--port", "0", "--no-browser"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    try:
        lines = [child.stdout.readline() for _ in range(2)]
        assert "at http://127.0.0.1:" in lines[1], lines
        address = lines[1].split(" at ")[1].split()[0]
        assert get(address)[0] == 200
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=30)
    finally:
        if child.poll() is None:
            os.kill(child.pid, signal.SIGKILL)
    assert child.returncode == 130
    assert err.strip() == "softarm: interrupted"


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
