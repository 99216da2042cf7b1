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


def write_npz(trajectory, path, **extra):
    """The trajectory's arrays under the names of softarm.io.TRAJECTORY_ARRAYS."""
    arrays = {name: getattr(trajectory, name) for name in ("times", "s", "positions",
                                                           "rotations")}
    arrays |= {f"energy_{k}": getattr(trajectory.energy, k)
               for k in ("kinetic", "elastic", "gravity", "dissipated")}
    np.savez(path, **arrays, **extra)
    return path


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
    assert moving == ["arm", "centreline", "e1", "e2", "e3"]
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


def test_trajectory_file_round_trip(swing, tmp_path):
    path = write_npz(swing, tmp_path / "swing.npz", radii=np.full(21, 0.02), name="swing",
                     velocities=swing.velocities)
    assert io.is_trajectory_file(path)
    saved = io.load_trajectory(path)
    np.testing.assert_array_equal(saved.positions, swing.positions)
    np.testing.assert_array_equal(saved.energy.total, swing.energy.total)
    assert saved.name == "swing" and saved.arm is None
    np.testing.assert_array_equal(saved.radii, 0.02)


def test_cli_view_trajectory(swing, tmp_path, capsys):
    source = write_npz(swing, tmp_path / "swing.npz", radii=np.full(21, 0.02), name="swing")
    assert cli.main(["view", str(source)]) == 0
    out, err = capsys.readouterr()
    page = tmp_path / "swing.html"
    assert out.strip() == f"wrote {page}" and err == ""
    text = page.read_text(encoding="utf-8")
    fig = json.loads(re.search(r"var id = \"softarm-view\", fig = (\{.*?\}), config", text,
                               re.S).group(1)
                     .replace("<\\/", "</"))
    shown = view.frame_indices(swing.times)
    line = fig["frames"][-1]["data"][1]
    np.testing.assert_allclose(np.stack([decode(line[a]) for a in "xyz"], -1),
                               swing.positions[shown[-1]], rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize(("change", "message"), [
    ("garbage", "not a softarm trajectory file (not an NPZ archive, or truncated)"),
    ("no energy", "not a softarm trajectory file (no energy_gravity array)"),
    ("short", "positions must have shape (151, 21, 3) (T = 151 times, S = 21 stations), "
              "got (151, 5, 3)"),
    ("nan", "rotations holds values that are not finite"),
])
def test_cli_view_bad_trajectory(swing, tmp_path, capsys, change, message):
    source = tmp_path / "bad.npz"
    if change == "garbage":
        source.write_bytes(b"PK\x03\x04 not really")
        source = tmp_path / "bad.npz"
    else:
        arrays = dict(np.load(write_npz(swing, tmp_path / "good.npz")))
        if change == "no energy":
            del arrays["energy_gravity"]
        elif change == "short":
            arrays["positions"] = arrays["positions"][:, :5]
        else:
            arrays["rotations"][3, 2, 0, 0] = np.nan
        np.savez(source, **arrays)
    page = tmp_path / "bad.html"
    # (garbage is no NPZ archive: read as a result file, which says the same)
    assert cli.main(["view", str(source), "-o", str(page)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    if change == "garbage":
        assert err.startswith(f"softarm: error: {source}: not a softarm result file")
    else:
        assert err == f"softarm: error: {source}: {message}\n"
    assert not page.exists()
