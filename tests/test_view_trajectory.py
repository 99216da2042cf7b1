"""A motion's page without a browser: the frames against the simulated trajectory (the
drawn numbers against the Trajectory's arrays), the slider's times, the energy plot, the
self-contained page, the trajectory file and `softarm view TRAJECTORY.npz`."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import softarm
from softarm import cli, io

pytest.importorskip("plotly", reason="the viewer needs plotly: pip install 'softarm[view]'")

from test_view import decode

from softarm import view

ARM = softarm.Arm(0.5, softarm.Circle(0.02),
                  softarm.Material(1e6, poisson_ratio=0.5, density=1100.0))


@pytest.fixture(scope="module")
def swing():
    """A horizontal arm released under gravity: 0.3 s in steps of 2 ms (151 times)."""
    return softarm.simulate(ARM, [softarm.Gravity()], duration=0.3, dt=2e-3, stations=21,
                            damping=softarm.Damping(retardation=0.005))


CASE = """
name = "swing"
[arm]
length = 0.5
section = { kind = "circle", radius = 0.02 }
material = { E = 1.0e6, nu = 0.5, density = 1100.0 }
[[load]]
kind = "gravity"
[simulate]
duration = 0.3
dt = 0.002
stations = 21
damping = { retardation = 0.005 }
"""


def saved_case(tmp_path, text=CASE):
    path = tmp_path / "swing.toml"
    path.write_text(text, encoding="utf-8")
    return softarm.load_case(path)


def test_frame_indices_spread_evenly_in_time():
    times = np.concatenate([np.linspace(0.0, 1.0, 11), np.linspace(1.001, 2.0, 1000)])
    shown = view.frame_indices(times, 21)
    # instants 0, 0.1, ..., 2.0 s: the nearest stored time to each, first and last included
    np.testing.assert_allclose(times[shown], np.linspace(0.0, 2.0, 21), atol=5e-4)
    assert shown[0] == 0 and shown[-1] == times.size - 1
    assert view.frame_indices(times[:5], 21).tolist() == [0, 1, 2, 3, 4]
    with pytest.raises(ValueError, match="frames must be an integer >= 2, got 1"):
        view.frame_indices(times, 1)


def test_frames_hold_the_trajectory_at_the_shown_times(swing):
    fig = json.loads(view.to_json(view.trajectory_figure(swing, arm=ARM, frames=40)))
    shown = view.frame_indices(swing.times, 40)
    assert len(fig["frames"]) == shown.size == 40
    names = [t["name"] for t in fig["data"]]
    moving = [names[i] for i in fig["frames"][0]["traces"]]
    assert moving == ["arm", "centreline", "e1", "e2", "e3", "base"]
    for frame, k in zip(fig["frames"], shown, strict=True):
        line = frame["data"][1]
        drawn = np.stack([decode(line[a]) for a in "xyz"], -1)
        np.testing.assert_allclose(drawn, swing.positions[k], rtol=1e-6, atol=1e-7)
        # the tube's rings: 16 vertices at the radius, 20 mm, around the centreline, in the
        # plane normal to e1 (second method: the rotations' first column)
        tube = np.stack([decode(frame["data"][0][a]) for a in "xyz"], -1).reshape(-1, 16, 3)
        station = np.argmin(np.linalg.norm(tube.mean(1)[:, None] - swing.positions[k],
                                           axis=-1), axis=1)
        offset = tube - swing.positions[k][station][:, None]
        np.testing.assert_allclose(np.linalg.norm(offset, axis=-1), 0.02, rtol=1e-5)
        np.testing.assert_allclose(np.einsum("nvx,nx->nv", offset,
                                             swing.rotations[k][station, :, 0]), 0.0,
                                   atol=1e-7)
        e1 = frame["data"][2]
        np.testing.assert_allclose([decode(e1[a])[1] - decode(e1[a])[0] for a in "xyz"],
                                   0.15 * 0.5 * swing.rotations[k, -1, :, 0], atol=1e-6)
    # the slider's labels are the shown times; the player's times are those times in s
    steps = fig["layout"]["sliders"][0]["steps"]
    np.testing.assert_allclose([float(s["label"]) for s in steps], swing.times[shown],
                               rtol=1e-6)
    assert [f["name"] for f in fig["frames"]] == [s["label"] for s in steps]
    np.testing.assert_allclose(fig["player"]["times"], swing.times[shown])
    assert fig["player"]["rates"]["real time"] == 1.0
    assert fig["player"]["rates"]["1/10 ×"] == 0.1
    # the tip's path: every time (151 <= 4000)
    (path,) = [t for t in fig["data"] if t["name"] == "tip path"]
    np.testing.assert_allclose(np.stack([decode(path[a]) for a in "xyz"], -1),
                               swing.tip_position, rtol=1e-6, atol=1e-7)


def test_energy_plot_and_its_cursor(swing):
    fig = json.loads(view.to_json(view.trajectory_figure(swing, frames=30)))
    energy = {t["name"]: t for t in fig["energy"]["data"]}
    for name in ("kinetic", "elastic", "gravity", "dissipated"):
        np.testing.assert_allclose(decode(energy[name]["y"]), getattr(swing.energy, name),
                                   rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(decode(energy[name]["x"]), swing.times, rtol=1e-6)
    np.testing.assert_allclose(decode(energy["total"]["y"]), swing.energy.total, rtol=1e-6,
                               atol=1e-9)
    # the cursor (last trace) at each frame's time
    assert fig["energy"]["data"][-1]["name"] == "shown"
    shown = view.frame_indices(swing.times, 30)
    np.testing.assert_allclose([c["x"][0] for c in fig["energy"]["shown"]], swing.times[shown])
    # without an arm or radii: the centreline alone, with markers
    assert [t["name"] for t in fig["data"][:2]] == ["centreline", "e1"]


def test_trajectory_page_is_self_contained(swing, tmp_path):
    page = view.write_trajectory_html(swing, tmp_path / "swing.html", arm=ARM, name="swing")
    text = page.read_text(encoding="utf-8")
    assert "plotly.js v" in text  # the library inline
    assert not re.search(r"<script[^>]+src=", text)
    # nothing fetched from elsewhere outside the library's own code
    outside = text.replace(view.plotly_js_path().read_text(encoding="utf-8"), "")
    assert len(outside) < len(text) - 1_000_000
    assert not re.search(r"(src|href)=\"?https?://|<link", outside)
    assert "<title>swing: motion, t = 0 s</title>" in text


def test_batched_trajectory_is_refused(swing):
    class Batched:
        times, s, energy = swing.times, swing.s, swing.energy
        positions = np.stack([swing.positions] * 2)
        rotations = np.stack([swing.rotations] * 2)

    with pytest.raises(ValueError, match=r"trajectory must be unbatched \(positions of "
                       r"shape \(T, S, 3\)\), got positions of shape \(2, 151, 21, 3\)"):
        view.trajectory_figure(Batched())


def test_cli_view_trajectory(swing, tmp_path, capsys):
    # the file of softarm simulate (softarm.io.save_trajectory) of the same motion
    source = io.save_trajectory(swing, tmp_path / "swing.npz", saved_case(tmp_path))
    assert cli.main(["view", str(source)]) == 0
    out, err = capsys.readouterr()
    page = tmp_path / "swing.html"
    assert out.strip() == f"wrote {page}" and err == ""
    fig = page_figure(page)
    shown = view.frame_indices(swing.times)
    line = fig["frames"][-1]["data"][1]
    np.testing.assert_allclose(np.stack([decode(line[a]) for a in "xyz"], -1),
                               swing.positions[shown[-1]], rtol=1e-6, atol=1e-7)
    assert fig["layout"]["title"]["text"].startswith("swing: motion, t = 0 s")
    # the tube of the case's arm: 20 mm from the axis
    tube = np.stack([decode(fig["data"][0][a]) for a in "xyz"], -1).reshape(-1, 16, 3)
    np.testing.assert_allclose(np.linalg.norm(tube[0] - swing.positions[0, 0], axis=-1), 0.02,
                               rtol=1e-5)


def page_figure(page):
    text = page.read_text(encoding="utf-8")
    return json.loads(re.search(r"var id = \"softarm-view\", fig = (\{.*?\}), config", text,
                                re.S).group(1).replace("<\\/", "</"))


def test_cli_view_a_sweep_of_simulations(tmp_path, capsys):
    text = CASE.replace("duration = 0.3", "duration = 0.02") + (
        '[[load]]\nkind = "tip"\nforce = [0.0, 0.0, 0.0]\n'
        '[sweep]\nload = 2\nfield = "force"\ncomponent = "z"\nstart = 0.0\nstop = 0.2\n'
        'steps = 3\n')
    case = saved_case(tmp_path, text)
    assert cli.main(["simulate", str(case.source), "-o", str(tmp_path / "s.npz")]) == 0
    saved = io.read_trajectory(tmp_path / "s.npz")
    assert saved.batch_shape == (3,)
    capsys.readouterr()
    assert cli.main(["view", str(tmp_path / "s.npz"), "--case", "3"]) == 0
    fig = page_figure(tmp_path / "s.html")
    line = fig["frames"][-1]["data"][1]
    np.testing.assert_allclose(np.stack([decode(line[a]) for a in "xyz"], -1),
                               saved.positions[2, -1], rtol=1e-6, atol=1e-7)
    assert saved.sweep_values[2] == 0.2
    assert fig["layout"]["title"]["text"].startswith(
        f"swing ({saved.sweep_label} = 0.2): motion, t = 0 s")
    assert cli.main(["view", str(tmp_path / "s.npz"), "--case", "4", "-o",
                     str(tmp_path / "x.html")]) == 2
    _, err = capsys.readouterr()
    assert err == (f"softarm: error: {tmp_path / 's.npz'}: case must be 1 ... 3 (the file "
                   "holds 3 simulations), got 4\n")
    assert not (tmp_path / "x.html").exists()


@pytest.mark.parametrize("change", ["garbage", "short"])
def test_cli_view_bad_trajectory(swing, tmp_path, capsys, change):
    source = tmp_path / "bad.npz"
    if change == "garbage":
        source.write_bytes(b"PK\x03\x04 not really")
    else:
        good = io.save_trajectory(swing, tmp_path / "good.npz", saved_case(tmp_path))
        arrays = dict(np.load(good))
        arrays["positions"] = arrays["positions"][:, :5]
        np.savez(source, **arrays)
    page = tmp_path / "bad.html"
    assert cli.main(["view", str(source), "-o", str(page)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    if change == "garbage":  # (no trajectory: read as a result file, which says so)
        assert err.startswith(f"softarm: error: {source}: not a softarm result file")
    else:
        assert err == (f"softarm: error: {source}: not a valid softarm trajectory: "
                       "'positions' has shape (151, 5, 3), expected (151, 21, 3)\n")
    assert not page.exists()


def test_trajectory_show_writes_the_motions_page(tmp_path):
    import softarm as _softarm

    arm = _softarm.Arm(0.3, _softarm.Circle(0.01),
                       _softarm.Material(1e6, poisson_ratio=0.5, density=1100.0))
    path = _softarm.simulate(arm, [_softarm.Gravity()], duration=0.01, dt=1e-3, stations=11)
    page = path.show(tmp_path / "motion.html", arm=arm, browser=False)
    text = page.read_text(encoding="utf-8")
    assert page == tmp_path / "motion.html" and "softarm-view" in text
    assert f"{path.times[-1]:g}" in text  # the slider's last time


def test_a_saved_trajectory_in_contact_shows_its_cases_obstacles(tmp_path):
    """Issue 39: a trajectory file read back had no contact law (a live Trajectory's
    ``contact``): its page drew no obstacle and its total energy dipped at each impact by
    the penalty's stored energy, which it could not compute. The file keeps the law now:
    the gaps, forces and stored energy read back are the live trajectory's, and the page
    draws the obstacles and the same energy curves as the live trajectory's page."""
    from softarm.case import join_trajectories, simulation_parts

    case = saved_case(tmp_path, CASE.replace("duration = 0.3", "duration = 0.1") + """
[[obstacle]]
kind = "plane"
point = [0.0, 0.0, -0.025]
normal = [0.0, 0.0, 1.0]
""")
    live = join_trajectories(list(simulation_parts(case)))
    assert live.contact_energy.max() > 0.0  # (the premise: it lands)
    for name in ("drop.npz", "drop.zarr", "drop.csv"):
        # the file keeps the law the steps used: the contact's gaps, forces and stored
        # energy read back are the live trajectory's, to the bit
        io.save_trajectory(live, tmp_path / name, case)
        back = io.read_trajectory(tmp_path / name)
        assert back.contact.stiffness == live.contact.stiffness
        assert back.contact.distance == live.contact.distance
        assert np.array_equal(back.contact_energy, live.contact_energy), name
        assert np.array_equal(back.contact_wrench, live.contact_wrench), name
    page = view.view_trajectory_file(back, tmp_path / "drop.html")
    fig = json.loads(view.to_json(view.trajectory_figure(live, arm=case.arm)))
    obstacles = [t for t in fig["data"] if t["name"].startswith("obstacle")]
    assert [t["name"] for t in obstacles] == ["obstacle 1: plane"]
    html = page.read_text(encoding="utf-8")
    assert html.count('"name":"obstacle 1: plane"') == 1
    # and its energy plot holds the penalty's stored energy, as the live page's does
    energy = [t["name"] for t in fig["energy"]["data"]]
    assert any("contact" in name for name in energy)
    for name in energy:
        assert f'"name":"{name}"' in html, name
