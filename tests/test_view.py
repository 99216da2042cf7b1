"""The HTML viewer without a browser: the figure's numbers against the equilibrium drawn, the
self-contained page, `softarm view` on the command line and the notebook display."""

from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import cli

pytest.importorskip("plotly", reason="the viewer needs plotly: pip install 'softarm[view]'")

from softarm import view

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def decode(value):
    """A plotly.js typed array {"dtype": "f4", "bdata", "shape"} as numpy (plotly.js's own
    format: little-endian float32 in base64, shape "N, M"), or the value as an array."""
    if isinstance(value, dict):
        array = np.frombuffer(base64.b64decode(value["bdata"]), dtype="<" + value["dtype"])
        shape = value.get("shape")
        return array.reshape([int(n) for n in shape.split(",")]) if shape else array
    return np.asarray(value, dtype=float)


@pytest.fixture(scope="module")
def demo():
    case = softarm.load_case(EXAMPLES / "demo.toml")
    return case, softarm.solve(case.arm, case.loads)


@pytest.fixture(scope="module")
def sweep():
    case = softarm.load_case(EXAMPLES / "fig2_sweep.toml")
    return case, softarm.case.solve_case(case)


def traces(fig, name, kind=("scatter3d", "surface", "scatter")):
    return [t for t in fig["data"] if t.get("name") == name and t["type"] in kind]


def test_figure_draws_the_equilibrium(demo):
    case, result = demo
    fig = json.loads(view.to_json(view.figure(result, name=case.name)))
    (line,) = traces(fig, "centreline")
    p = np.asarray(result.positions)
    for k, axis in enumerate("xyz"):
        np.testing.assert_allclose(decode(line[axis]), p[:, k], rtol=1e-6, atol=1e-7)
    # hover read-outs: s, strains (γ; κ), stresses (n; m), material frame
    custom = decode(line["customdata"])
    expected = np.concatenate([result.s[:, None], result.strains, result.stresses], -1)
    np.testing.assert_allclose(custom, expected, rtol=1e-6, atol=1e-9)
    # the tube: rings of 16 vertices at stations spread along the whole arm (at most about
    # 50 rings, so no more than a 3.2 % of L gap between two); every vertex at the segment's
    # radius (16 mm, then 11 mm) from the axis, in the plane normal to e1 there, with the
    # read-outs of its station
    (tube,) = traces(fig, "arm", ("mesh3d",))
    vertices = np.stack([decode(tube[a]) for a in "xyz"], -1).reshape(-1, 16, 3)
    ring_custom = decode(tube["customdata"]).reshape(-1, 16, 13)
    np.testing.assert_array_equal(ring_custom, ring_custom[:, :1].repeat(16, axis=1))
    station = np.argmin(np.abs(ring_custom[:, :1, 0] - result.s), axis=1)  # by its s
    np.testing.assert_allclose(ring_custom[:, 0], expected[station], rtol=1e-6, atol=1e-9)
    assert station[0] == 0 and station[-1] == result.s.size - 1
    assert np.max(np.diff(result.s[station])) <= 0.4 / 50 * 1.6 and len(station) <= 60
    offset = vertices - p[station][:, None, :]
    distance = np.linalg.norm(offset, axis=-1)
    radius = np.where(result.s[station] < 0.25, 0.016, 0.011)  # demo.toml: segment radii
    np.testing.assert_allclose(distance, np.broadcast_to(radius[:, None], distance.shape),
                               rtol=1e-5)
    np.testing.assert_allclose(np.einsum("nkx,nx->nk", offset, result.poses[station, :3, 0]),
                               0.0, atol=1e-7)
    triangles = np.stack([decode(tube[a]) for a in "ijk"], -1)
    assert tube["i"]["dtype"] == "u2" and triangles.min() == 0
    assert triangles.max() == vertices.shape[0] * 16 - 1
    surface = vertices
    # the tip frame: 0.15 L along each column of R(L)
    (e1,) = traces(fig, "e1")
    tip = np.stack([decode(e1[a]) for a in "xyz"], -1)
    np.testing.assert_allclose(tip[1] - tip[0], 0.15 * 0.4 * result.tip[:3, 0], atol=1e-6)
    # equal axis scaling: a cube holding every point drawn
    scene = fig["layout"]["scene"]
    assert scene["aspectmode"] == "cube"
    ranges = np.array([scene[f"{a}axis"]["range"] for a in "xyz"])
    np.testing.assert_allclose(ranges[:, 1] - ranges[:, 0], ranges[0, 1] - ranges[0, 0])
    assert np.all(ranges[:, 0] <= surface.min(axis=(0, 1)))
    assert np.all(ranges[:, 1] >= surface.max(axis=(0, 1)))


def test_load_arrows_in_the_figure(demo):
    _, result = demo
    fig = json.loads(view.to_json(view.figure(result)))
    (forces,) = traces(fig, "forces")
    x = np.array([np.nan if v is None else v for v in forces["x"]])
    ends = np.stack([np.array([np.nan if v is None else v for v in forces[a]])
                     for a in "xyz"], -1).reshape(-1, 3, 3)[:, :2]
    assert len(ends) == 6 + 1 and np.isfinite(x).sum() == 14  # 6 gravity arrows, 1 tip
    tip_arrow = ends[-1]
    np.testing.assert_allclose(tip_arrow[0], result.tip_position, atol=1e-12)
    direction = (tip_arrow[1] - tip_arrow[0]) / np.linalg.norm(tip_arrow[1] - tip_arrow[0])
    force = np.array([0.0, 0.15, -0.4])  # demo.toml, the tip load (dead: spatial)
    np.testing.assert_allclose(direction, force / np.linalg.norm(force), atol=1e-12)
    assert "0.15" in forces["text"][-2] and "N" in forces["text"][-2]


def rgb(color: str) -> np.ndarray:
    """"rgb(r,g,b)" as a vector."""
    match = re.fullmatch(r"rgb\((\d+),\s*(\d+),\s*(\d+)\)", color)
    assert match, color
    return np.array([float(v) for v in match.groups()])


@pytest.mark.parametrize("name", ["demo", "tendon_robot", "pneumatic_actuator"])
def test_legend_entries_have_colours_of_their_own(name):
    # The centreline was drawn in the red of the tip frame's e1, and the tip frame had one
    # legend entry drawn in e1's red: now e1, e2 and e3 are entries of their own, and no two
    # kinds of things in the legend are closer in colour than 60 (of 255, RGB distance).
    # Actuators of one kind (three tendons) share their colour.
    case = softarm.load_case(EXAMPLES / f"{name}.toml")
    fig = json.loads(view.to_json(view.figure(softarm.case.solve_case(case), name=name)))
    actuators = {load.describe(): load.kind for load in case.loads
                 if load.kind in ("tendon", "chamber")}
    colours: dict[str, np.ndarray] = {}
    for trace in fig["data"]:
        if not trace.get("showlegend", trace["type"] == "scatter3d"):
            continue
        kind = actuators.get(trace["name"], trace["name"])
        colour = rgb(trace["color"] if trace["type"] == "mesh3d" else trace["line"]["color"])
        assert np.array_equal(colours.setdefault(kind, colour), colour), kind
    kinds = sorted(colours)
    for i, a in enumerate(kinds):
        for b in kinds[i + 1:]:
            assert np.linalg.norm(colours[a] - colours[b]) > 60, (a, b)
    assert {"arm", "centreline", "e1", "e2", "e3", "forces"} <= set(colours)
    assert set(actuators.values()) <= set(colours)
    # the tip frame's three entries, one group: a click on one hides or shows the frame
    frame = [trace for trace in fig["data"] if trace.get("legendgroup") == "tip frame"]
    assert [trace["name"] for trace in frame] == ["e1", "e2", "e3"]
    assert frame[0]["legendgrouptitle"]["text"] == "tip frame"


def test_sweep_figure_has_frames_slider_and_tip_plot(sweep):
    case, result = sweep
    fig = json.loads(view.to_json(view.figure(result, sweep=case.sweep, name=case.name)))
    values = np.asarray(case.sweep.values)
    assert [f["name"] for f in fig["frames"]] == [f"{v:.6g}" for v in values]
    slider = fig["layout"]["sliders"][0]
    assert [s["args"][0] for s in slider["steps"]] == [[f["name"]] for f in fig["frames"]]
    assert fig["layout"]["updatemenus"][0]["buttons"][0]["label"] == "▶"
    # the tip against the parameter, a 2D figure of its own: pure bending, tip =
    # (sin(τL)/τ, 0, (1 - cos τL)/τ) for EI = 1 N m², L = 1 m (circular arc of curvature
    # τ/EI, paper Fig. 2); its "shown" marker at each step's tip
    tips = fig["tips"]
    tip_x, tip_z = traces(tips, "tip x")[0], traces(tips, "tip z")[0]
    tau = values
    for k, shown in enumerate(tips["shown"]):
        np.testing.assert_allclose(shown["x"], [tau[k]] * 3)
        np.testing.assert_allclose(shown["y"], result.tip_position[k], atol=1e-12)
    np.testing.assert_allclose(decode(tip_x["x"]), values)
    np.testing.assert_allclose(decode(tip_x["y"]), np.sin(tau) / tau, atol=1e-6)
    np.testing.assert_allclose(np.abs(decode(tip_z["y"])), (1 - np.cos(tau)) / tau, atol=1e-6)
    # each frame redraws the centreline of its own step
    index = next(i for i, t in enumerate(fig["data"]) if t.get("name") == "centreline")
    for k, frame in enumerate(fig["frames"]):
        assert index in frame["traces"]
        line = frame["data"][frame["traces"].index(index)]
        np.testing.assert_allclose(decode(line["x"])[-1], np.sin(tau[k]) / tau[k], atol=1e-6)


def test_a_page_fills_the_window_and_a_notebook_output_has_a_height(demo, sweep, tmp_path):
    # A 650 px figure left a third of a 1200 x 900 window blank below it: a page's figure
    # (softarm view, Equilibrium.show) now has no height of its own and its <div> is as high
    # as the window; a notebook output keeps a fixed height (a notebook has no window height).
    _, result = demo
    page = view.write_html(result, tmp_path / "demo.html").read_text(encoding="utf-8")
    assert re.search(r'<div id="softarm-view" class="plotly-graph-div" '
                     r'style="height:100vh; min-height:\d+px; width:100%;">', page)
    assert '"height":' not in page.split("var id =")[1].split("function draw")[0]
    case, swept = sweep
    path = view.view_result_file(io_saved(swept, case, tmp_path), tmp_path / "sweep.html")
    page = path.read_text(encoding="utf-8")
    # the sweep's 3D figure and its tip plot in a container as high as the window, the tip
    # plot placed in percentages of it
    assert re.search(r'<div style="position:relative; height:100vh; min-height:\d+px; '
                     r'width:100%;"><div id="softarm-view" class="plotly-graph-div" '
                     r'style="height:100%; width:100%;">', page)
    assert re.search(r'id="softarm-view-tips" class="plotly-graph-div" style="position:'
                     r'absolute; top:calc\([^;]*%[^;]*\); bottom:calc\([^;]*%[^;]*\);', page)
    notebook = view.notebook_html(result)
    assert re.search(r'class="plotly-graph-div" style="height:650px; width:100%;"', notebook)


def io_saved(result, case, folder):
    """``result`` written and read back by softarm.io, as `softarm view` gets it."""
    softarm.io.save_result(result, folder / "saved.npz", case)
    return softarm.io.load_saved(folder / "saved.npz")


@pytest.mark.parametrize(("low", "high"), [(-0.1, 0.52), (-0.31, 0.31), (0.0, 1.0),
                                           (-1e-3, 2e-3), (5.0, 5.4), (-0.2222, 0.4444),
                                           (-100.0, 300.0), (0.123, 0.124)])
def test_axis_ticks_keep_away_from_the_corners(low, high):
    # plotly.js's own ticks run to the ends of an axis, where three axes' labels meet at a
    # corner of the box and overlapped: at least three ticks of a 1, 2 or 5 x 10^k step,
    # none within 10 % of the axis's length from either end
    ticks = np.array(view.axis_ticks(low, high))
    span = high - low
    assert len(ticks) >= 3
    assert np.all(ticks >= low + 0.1 * span - 1e-12 * span)
    assert np.all(ticks <= high - 0.1 * span + 1e-12 * span)
    steps = np.diff(ticks)
    np.testing.assert_allclose(steps, steps[0], rtol=1e-9)
    mantissa = steps[0] / 10.0 ** np.floor(np.log10(steps[0]))
    assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-9
    np.testing.assert_allclose(ticks / steps[0], np.round(ticks / steps[0]), atol=1e-9)


def test_figure_ticks_and_the_sweep_controls_stay_off_the_scene(demo, sweep):
    _, result = demo
    scene = view.figure(result)["layout"]["scene"]
    for axis in "xyz":
        low, high = scene[f"{axis}axis"]["range"]
        assert scene[f"{axis}axis"]["tickvals"] == view.axis_ticks(low, high)
    case, swept = sweep
    layout = view.figure(swept, sweep=case.sweep)["layout"]
    bottom = layout["scene"]["domain"]["y"][0]
    # the play and pause buttons overlapped the 3D scene: the buttons and the slider hang
    # below the plotting area now (their top at its bottom edge, y = 0, or lower), the
    # buttons to the left of the slider's rail
    for control in (layout["updatemenus"][0], layout["sliders"][0]):
        assert control["yanchor"] == "top" and control["y"] <= bottom
    buttons, slider = layout["updatemenus"][0], layout["sliders"][0]
    assert buttons["xanchor"] == "left" and buttons["x"] == slider["x"] == 0.0
    assert slider["pad"]["l"] >= buttons["pad"]["l"] + 70  # two buttons of about 35 px


def test_page_is_self_contained(demo, tmp_path):
    _, result = demo
    path = view.write_html(result, tmp_path / "demo.html")
    text = path.read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]+src=", text), "the page must not load scripts"
    assert "plotly.js v" in text[:200000]  # the library itself is embedded
    assert 'Plotly.newPlot(' in text and '"softarm-view"' in text


def test_cli_view(tmp_path, capsys, sweep):
    result_file = tmp_path / "fig2.npz"
    assert cli.main(["solve", str(EXAMPLES / "fig2_sweep.toml"), "-o", str(result_file)]) == 0
    assert cli.main(["view", str(result_file)]) == 0
    assert (tmp_path / "fig2.html").stat().st_size > 1_000_000
    assert cli.main(["view", str(result_file), "-o", str(tmp_path / "v.html")]) == 0
    out, _ = capsys.readouterr()
    assert f"wrote {tmp_path / 'v.html'}" in out
    for argv, message in [
        (["view", str(tmp_path / "missing.npz")], "no such file"),
        (["view", str(result_file), "-o", str(tmp_path / "v.png")], "unknown page format"),
        (["view", str(result_file), "-o", str(tmp_path / "nofolder" / "v.html")],
         "does not exist"),
    ]:
        assert cli.main(argv) == 2
        _, err = capsys.readouterr()
        assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_notebook_display(demo, monkeypatch):
    _, result = demo
    monkeypatch.setitem(view._notebook, "embedded", False)  # a fresh kernel session
    first, second = result._repr_html_(), result._repr_html_()
    library = view.plotly_js_path().stat().st_size
    # the first display of a session carries plotly.js, the next ones use it from the page
    assert first.startswith("<div") and "Plotly.newPlot(" in first
    assert "plotly.js v" in first[:2000] and len(first) > library
    assert "plotly.js v" not in second and "Plotly.newPlot(" in second
    assert len(second) < 120_000 and "softarm-plotly-ready" in second
    monkeypatch.setattr(view, "NOTEBOOK_PLOTLYJS", "always")
    assert "plotly.js v" in result._repr_html_()[:2000]
    monkeypatch.setattr(view, "NOTEBOOK_PLOTLYJS", "sometimes")
    with pytest.raises(ValueError, match="NOTEBOOK_PLOTLYJS must be 'once' or 'always'"):
        result._repr_html_()
    monkeypatch.setattr(view, "NOTEBOOK_PLOTLYJS", "once")
    poses = np.broadcast_to(result.poses, (2, 2, *result.poses.shape))
    batch = softarm.Equilibrium(result.s, poses,
                                np.zeros((2, 2, result.s.size, 6)),
                                np.zeros((2, 2, result.s.size, 6)), result.arm, (), "x", True)
    assert batch._repr_html_() is None


def test_show_writes_the_page(demo, tmp_path):
    _, result = demo
    path = result.show(tmp_path / "shown.html", browser=False)
    text = path.read_text(encoding="utf-8")
    assert text.count('class="plotly-graph-div"') == 1 and "plotly.js v" in text[:2000]


def test_view_command_does_not_load_the_solver(tmp_path, demo):
    # `softarm view` only reads and draws: the compiled solver (numba) stays unloaded
    case, result = demo
    softarm.io.save_result(result, tmp_path / "demo.npz", case)
    code = ("import sys, softarm.cli; code = softarm.cli.main(['view', sys.argv[1]]); "
            "print(code, 'numba' in sys.modules, 'matplotlib' in sys.modules)")
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "demo.npz")],
                         capture_output=True, text=True, check=True)
    assert out.stdout.split()[-3:] == ["0", "False", "False"]
