"""The live app's dynamic mode over HTTP (no browser): the states it serves against
softarm.Simulator.step replayed with the same inputs, its bad requests and its settings."""

from __future__ import annotations

import json
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import softarm

pytest.importorskip("plotly", reason="the app needs plotly: pip install 'softarm[view]'")

from softarm import app

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
DYNAMICS = app.Dynamics(dt=2e-3, stations=21, damping=0.01)


def get(url):
    try:
        with urllib.request.urlopen(url, timeout=60) as reply:
            return reply.status, json.loads(reply.read())
    except urllib.error.HTTPError as error:
        return error.code, json.loads(error.read())


def states(url, after, query=""):
    """The states after step ``after`` (asking again while the server has none: a first step
    compiles the dynamics kernel, which may take longer than a request waits)."""
    end = time.monotonic() + 300
    while True:
        status, reply = get(url + f"/state?after={after}{query}")
        assert status == 200, reply
        if reply["states"] or time.monotonic() > end:
            return reply["states"]
        query = ""


@pytest.fixture(scope="module")
def motion():
    live = app.LiveMotion(softarm.load_case(EXAMPLES / "tendon_robot.toml"), DYNAMICS)
    httpd = app.make_server(live, port=0)
    thread = threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.05},
                              daemon=True)
    thread.start()
    live.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}", live
    live.stop()
    httpd.shutdown()
    httpd.server_close()


@pytest.mark.slow  # two dynamics variants no other default test compiles
def test_served_states_are_the_simulators(motion):
    url, live = motion
    first = states(url, -1)[0]
    # change a tension and switch another tendon off, then take a state 40 steps later
    index = start = states(url, first["index"], "&l2.tension=5.5&l3.on=0")[-1]["index"]
    while index < start + 40:
        reply = states(url, index)
        later = reply[-1]
        # the states after the index asked for, in order
        assert [s["index"] for s in reply] == sorted({s["index"] for s in reply})
        assert reply[0]["index"] > index
        index = later["index"]
    status, history = get(url + "/history")
    assert status == 200
    assert history["replayable"] and history["history"][0] == [0, [3.0, 1.0, 0.0]]
    assert history["history"][-1][1] == [5.5, 0.0, 0.0]  # (tendon 2 switched off: 0 N)
    # the second method: a Simulator of the same case stepped one step at a time
    case = live.case
    simulator = softarm.Simulator(case.arm, case.loads[1:], case.loads[:1], dt=DYNAMICS.dt,
                                  stations=DYNAMICS.stations,
                                  damping=softarm.Damping(retardation=DYNAMICS.damping),
                                  initial=softarm.solve(case.arm, case.loads))
    changes = dict((k, q) for k, q in history["history"])
    q = None
    for step in range(index):
        q = changes.get(step, q)
        state = simulator.step(q)
    assert simulator.time == pytest.approx(later["time"], abs=1e-12)
    # to the step's tolerance (1e-6 L): the server runs the steps in chunks (Simulator.run)
    np.testing.assert_allclose(later["positions"], state.positions, rtol=0, atol=1e-6 * 0.25)
    np.testing.assert_allclose(later["rotations"], state.rotations[-1], rtol=0, atol=1e-5)
    # and the arm has moved: the new tension curls it
    assert np.linalg.norm(np.subtract(later["positions"][-1], first["positions"][-1])) > 1e-3


def test_bad_requests(motion):
    url, _ = motion
    status, body = get(url + "/state?after=x")
    assert (status, body) == (400, {"error": "after must be a state index, got 'x'"})
    status, body = get(url + "/state?after=0&l2.tension=99")
    assert (status, body) == (400, {"error": "l2.tension must be in [0.0, 10.0] N, got 99.0"})
    status, body = get(url + "/state?after=0&nothing=1")
    assert status == 400 and body["error"].startswith("unknown input 'nothing'")


def test_a_state_waits_for_a_newer_one(motion):
    url, _ = motion
    a = states(url, -1)[-1]
    states(url, a["index"])  # (the first steps compiled)
    a = states(url, -1)[-1]
    start = time.perf_counter()
    _, b = get(url + f"/state?after={a['index']}")
    b = b["states"][0]
    assert b["index"] > a["index"] and b["time"] > a["time"]
    assert time.perf_counter() - start < 1.0


def test_passive_load_change_continues_from_the_state():
    live = app.LiveMotion(softarm.load_case(EXAMPLES / "demo.toml"),
                          app.Dynamics(dt=2e-3, stations=21))
    with live._lock:
        before = live._state
        live.update({"l2.force.z": "0.5"})
        assert live.simulator is not None and not live.replayable
        # the new Simulator starts from the state it had (positions and time)
        np.testing.assert_array_equal(live.simulator.state.positions, before.positions)
        assert live.simulator.time == before.time
        assert any(load.kind == "tip" and load.force[2] == 0.5 for load in live.simulator.loads
                   if hasattr(load, "kind"))


def test_dynamics_settings_are_checked():
    with pytest.raises(ValueError, match=r"Dynamics\.dt must be a positive number, got 0"):
        app.Dynamics(dt=0)
    with pytest.raises(ValueError, match=r"Dynamics\.damping must be a retardation time"):
        app.Dynamics(damping=-1.0)


@pytest.mark.parametrize(("argv", "message"), [
    (["--dt", "0"], "softarm: error: --dt must be a positive time step in s, got 0\n"),
    (["--dt", "x"], "argument --dt: must be a time in s, got 'x'"),
    (["--damping", "-1"], "argument --damping: must be a time >= 0 s, got '-1'"),
])
def test_cli_dynamic_options(argv, message, capsys):
    from softarm import cli

    assert cli.main(["app", str(EXAMPLES / "demo.toml"), "--no-browser", *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and message in err and err.strip().count("\n") <= 1


def test_settings_from_the_simulate_table():
    case = softarm.load_case(EXAMPLES / "whip.toml")  # dt 1 ms, 41 stations, τ = 2 ms
    settings = app.Dynamics.of(case)
    assert (settings.dt, settings.stations, settings.initial) == (0.001, 41, "equilibrium")
    assert settings.damping_law().retardation == 0.002
    settings = app.Dynamics.of(case, dt=0.004, damping=0.01)
    assert (settings.dt, settings.damping_law().retardation) == (0.004, 0.01)
    plain = app.Dynamics.of(softarm.load_case(EXAMPLES / "demo.toml"))
    assert (plain.dt, plain.stations, plain.damping) == (2e-3, 41, None)


def test_cli_static_and_dynamic_exclude_each_other(capsys):
    from softarm import cli

    assert cli.main(["app", str(EXAMPLES / "whip.toml"), "--static", "--dt", "0.001"]) == 2
    _, err = capsys.readouterr()
    assert err == "softarm: error: --static cannot go with --dynamic, --dt or --damping\n"
