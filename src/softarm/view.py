"""Interactive 3D views of equilibria in a browser: ``softarm view RESULT -o view.html``,
:meth:`softarm.Equilibrium.show` and the figures of the live app (``softarm app``); and of
motions (:func:`trajectory_figure`, :func:`write_trajectory_html`, ``softarm view
TRAJECTORY.npz`` of a ``softarm simulate`` output): the moving arm with a time slider, a
player at real time or a chosen rate, the tip's path and the energy plot (see "trajectories"
below).

The figures are built here as plain dicts in plotly's figure schema (``data``, ``layout``,
``frames``; a sweep's tip plot as a second figure under ``"tips"``) from
:mod:`softarm.geometry`, with numpy only, and written as HTML by :func:`to_html` with a small
script of ours (a sweep's frames are shown by it, see ``_DRAW``); plotly (``pip install
"softarm[view]"``) is needed only for the plotly.js it ships, which a page embeds to open
without a network (a notebook's displays embed it once per kernel session:
:data:`NOTEBOOK_PLOTLYJS`). Speed matters here: a figure is redrawn on every slider move, in
browsers that may draw WebGL in software; the notes at ``_SIDES``, ``_cube_anchor`` and
``_DRAW`` say what each choice saves.

Drawn: the arm as a tube of its real radius (its centreline when the sections are not known),
the arm and its centreline with hover read-outs (s, position, strains and stresses in the
material frame), the tip's material frame (e1 red, e2 green, e3 blue: no other legend entry
shares their colours), arrows for the loads (forces solid, moments dashed; each load's arrows
are scaled to its own largest value, the hover gives the value), the clamped base, and the
obstacles of a :class:`softarm.Contact` (grey translucent meshes: a plane as a square about the
drawing) with the contact forces per length (magenta arrows where they act). A sweep
gets a slider over its parameter, a play button and a plot of the tip coordinates against
the parameter.
"""

from __future__ import annotations

import base64
import json
import math
import os
from pathlib import Path

import numpy as np

from ._files import write_atomic
from .geometry import (
    actuator_paths,
    contact_arrows,
    contact_scale,
    contacts,
    cube_limits,
    grid_mesh,
    load_arrows,
    obstacle_surface,
    station_radii,
    sweep_axis,
    tip_frame,
    tube_mesh,
    tube_rings,
    tube_surface,
)

__all__ = ["NOTEBOOK_PLOTLYJS", "PLAYBACK_RATES", "PLOTLY_MISSING", "TRAJECTORY_FRAMES",
           "axis_ticks", "figure", "frame_indices", "notebook_html", "plotly_js_path",
           "scene_traces", "to_html", "to_json", "trajectory_figure", "view_result_file",
           "view_trajectory_file", "write_html", "write_trajectory_html"]

#: The message when plotly is not installed.
PLOTLY_MISSING = "the browser views need plotly: pip install 'softarm[view]'"

# Every entry of the legend has a colour of its own (tests/test_view.py measures how far
# apart they are): e1 e2 e3 are red, green and blue, so the centreline is dark brown, the
# tendons black, the forces mid grey and the chambers cyan.
_TUBE = "rgb(255,127,14)"
_LINE = "rgb(110,55,0)"
_AXES = ("rgb(220,40,40)", "rgb(40,160,40)", "rgb(40,80,220)")
_FORCE = "rgb(100,100,100)"
_MOMENT = "rgb(148,103,189)"
_TENDON = "rgb(30,30,30)"
_CHAMBER = "rgb(23,190,207)"
_OBSTACLE = "rgb(160,160,175)"
_CONTACT = "rgb(214,0,154)"
#: The key of the contact forces' arrow scale (m per N/m) in a figure's ``scales``.
CONTACT_KEY = ("contact", "force")
# The tube's mesh: software WebGL (headless or GPU-less browsers) spends its time per vertex,
# so the tube has at most about _RINGS rings of _SIDES vertices whatever the number of
# stations (1616 vertices at 101 stations before; the look is the same, see tube_rings).
_SIDES = 16
_RINGS = 50


def _plotly():
    try:
        import plotly.io
    except ImportError as error:
        raise ImportError(PLOTLY_MISSING) from error
    return plotly.io


def plotly_js_path() -> Path:
    """The plotly.min.js file shipped with the installed plotly package (ImportError if none)."""
    _plotly()
    import plotly

    path = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not path.is_file():  # pragma: no cover - a broken plotly installation
        raise ImportError(f"plotly.js not found at {path}; reinstall plotly")
    return path


def _vec(v) -> str:
    return "(" + ", ".join(f"{c:.4g}" for c in np.asarray(v, dtype=float)) + ")"


_HOVER = ("s = %{customdata[0]:.4g} m<br>p = (%{x:.4g}, %{y:.4g}, %{z:.4g}) m"
          "<br>γ = (%{customdata[1]:.3g}, %{customdata[2]:.3g}, %{customdata[3]:.3g})"
          "<br>κ = (%{customdata[4]:.3g}, %{customdata[5]:.3g}, %{customdata[6]:.3g}) 1/m"
          "<br>n = (%{customdata[7]:.3g}, %{customdata[8]:.3g}, %{customdata[9]:.3g}) N"
          "<br>m = (%{customdata[10]:.3g}, %{customdata[11]:.3g}, %{customdata[12]:.3g}) N m"
          "<br><i>strains, stresses: material frame</i><extra>centreline</extra>")


def _arrow_traces(arrows, scales, length: float) -> list[dict]:
    """Shafts (lines) and heads (cones) of the force arrows, then of the moment arrows."""
    traces = []
    for moment in (False, True):
        xs: list = [[], [], []]
        text: list = []
        tips, dirs = [], []
        for arrow in arrows:
            if arrow.moment is not moment:
                continue
            scale = scales.get(arrow.key, 0.0)
            for origin, vector in zip(arrow.origins, arrow.vectors, strict=True):
                norm = float(np.linalg.norm(vector))
                if norm == 0.0:
                    continue
                end = origin + vector * scale
                for k in range(3):
                    xs[k] += [float(origin[k]), float(end[k]), None]
                text += [f"{arrow.label}<br>{_vec(vector)} {arrow.unit}"] * 2 + [None]
                tips.append(end)
                dirs.append(vector / norm * 0.06 * length)
        color = _MOMENT if moment else _FORCE
        name = "moments" if moment else "forces"
        traces.append({"type": "scatter3d", "mode": "lines", "x": xs[0], "y": xs[1],
                       "z": xs[2], "text": text, "hovertemplate": "%{text}<extra></extra>",
                       "line": {"color": color, "width": 5, "dash": "dash" if moment else
                                "solid"}, "name": name, "legendgroup": name,
                       "showlegend": True})
        tips_a = np.array(tips).reshape(-1, 3)
        dirs_a = np.array(dirs).reshape(-1, 3)
        traces.append({"type": "cone", "x": tips_a[:, 0], "y": tips_a[:, 1], "z": tips_a[:, 2],
                       "u": dirs_a[:, 0], "v": dirs_a[:, 1], "w": dirs_a[:, 2],
                       "anchor": "tip", "sizemode": "raw", "sizeref": 1.0,
                       "colorscale": [[0, color], [1, color]], "showscale": False,
                       "hoverinfo": "skip", "legendgroup": name, "name": name})
    return traces


def _contact_traces(arrow, scales, length: float) -> list[dict]:
    """The contact forces (:func:`softarm.geometry.contact_arrows`: per length, or a held
    tip's) as magenta shafts and cones, scaled by ``scales[CONTACT_KEY]`` (m per N/m, or
    per N; absent: this equilibrium's own, :func:`softarm.geometry.contact_scale`). Two
    traces, empty where no force acts, so that a sweep's frames and the app's updates keep
    their number."""
    scale = scales.get(CONTACT_KEY) or contact_scale([arrow], length)
    origins, vectors = arrow.origins, arrow.vectors
    ends = origins + scale * vectors
    xs = [np.stack([origins[:, k], ends[:, k], np.full(len(origins), np.nan)], -1).ravel()
          for k in range(3)]
    norms = np.linalg.norm(vectors, axis=-1)
    unit = arrow.unit
    text = [f"{arrow.label}<br>{_vec(v)} {unit} (|f| = {n:.3g} {unit})"
            for v, n in zip(vectors, norms, strict=True)]
    heads = vectors / np.where(norms > 0, norms, 1.0)[:, None] * 0.03 * length
    return [{"type": "scatter3d", "mode": "lines", "x": xs[0], "y": xs[1], "z": xs[2],
             "text": [t for t in text for _ in range(3)],
             "hovertemplate": "%{text}<extra></extra>",
             "line": {"color": _CONTACT, "width": 4}, "name": "contact forces",
             "legendgroup": "contact forces", "showlegend": True},
            {"type": "cone", "x": ends[:, 0], "y": ends[:, 1], "z": ends[:, 2],
             "u": heads[:, 0], "v": heads[:, 1], "w": heads[:, 2], "anchor": "tip",
             "sizemode": "raw", "sizeref": 1.0, "colorscale": [[0, _CONTACT], [1, _CONTACT]],
             "showscale": False, "hoverinfo": "skip", "legendgroup": "contact forces",
             "name": "contact forces"}]


def _obstacle_traces(loads, centre, half: float) -> list[dict]:
    """The obstacles of the loads' Contact as grey translucent meshes (a plane: the square
    of the axis cube's side about ``centre``), one trace each, named "obstacle K: kind"."""
    traces = []
    for contact in contacts(loads):
        for k, obstacle in enumerate(contact.obstacles):
            vertices, triangles = grid_mesh(obstacle_surface(obstacle, centre, half / 1.1))
            traces.append({"type": "mesh3d", "x": vertices[:, 0], "y": vertices[:, 1],
                           "z": vertices[:, 2], "i": triangles[:, 0], "j": triangles[:, 1],
                           "k": triangles[:, 2], "color": _OBSTACLE,
                           "opacity": 0.35 if obstacle.kind == "plane" else 0.5,
                           "flatshading": False, "name": f"obstacle {k + 1}: {obstacle.kind}",
                           "legendgroup": "obstacles", "showlegend": True,
                           "hovertemplate": f"obstacle {k + 1}: {obstacle.kind}"
                                            "<extra></extra>"})
    return traces


def _arrow_scales(arrows_per_frame, length: float) -> dict[str, float]:
    """m per load unit for each load: its largest arrow over all frames is 0.25 L long (tip
    and point loads) or 0.12 L (distributed loads and gravity, drawn as several arrows)."""
    largest: dict[str, float] = {}
    several: dict[str, bool] = {}
    for arrows in arrows_per_frame:
        for arrow in arrows:
            norm = float(np.max(np.linalg.norm(arrow.vectors, axis=-1), initial=0.0))
            largest[arrow.key] = max(largest.get(arrow.key, 0.0), norm)
            several[arrow.key] = len(arrow.origins) > 1
    return {key: (0.12 if several[key] else 0.25) * length / value
            for key, value in largest.items() if value > 0}


def _tube_trace(poses, radii, **extra) -> dict:
    """The arm as an opaque tube (a plotly mesh3d) through ``poses`` (..., 4, 4) of the
    given ``radii``; ``extra`` trace keys (hover, legend)."""
    vertices, triangles = tube_mesh(poses, radii, sides=_SIDES)
    return {"type": "mesh3d", "x": vertices[:, 0], "y": vertices[:, 1], "z": vertices[:, 2],
            "i": triangles[:, 0], "j": triangles[:, 1], "k": triangles[:, 2], "color": _TUBE,
            "opacity": 1.0, "name": "arm", **extra}


def _scene_traces(result, arrows, scales, rings) -> list[dict]:
    """The traces of one (unbatched) equilibrium, always the same number and order (``rings``:
    :func:`softarm.geometry.tube_rings` of the arm, or None to draw no tube)."""
    poses = np.asarray(result.poses)
    p = poses[:, :3, 3]
    length = float(result.arm.length)
    traces = []
    custom = np.concatenate([np.asarray(result.s)[:, None], result.strains, result.stresses],
                            axis=-1)
    if rings is not None:
        index, radii = rings
        traces.append(_tube_trace(poses[index], radii,
                                  customdata=np.repeat(custom[index], _SIDES, axis=0),
                                  hovertemplate=_HOVER.replace("centreline", "arm"),
                                  showlegend=True))
    # inside the opaque tube the stations' markers cannot be seen: drawn without a tube only
    traces.append({"type": "scatter3d", "mode": "lines" if rings is not None else
                   "lines+markers", "x": p[:, 0], "y": p[:, 1],
                   "z": p[:, 2], "customdata": custom, "hovertemplate": _HOVER,
                   "line": {"color": _LINE, "width": 4}, "marker": {"size": 2, "color": _LINE},
                   "name": "centreline"})
    for path in actuator_paths(result.loads, poses, result.s):
        tendon = path.kind == "tendon"
        traces.append({"type": "scatter3d", "mode": "lines", "x": path.points[:, 0],
                       "y": path.points[:, 1], "z": path.points[:, 2],
                       "line": {"color": _TENDON if tendon else _CHAMBER,
                                "width": 3 if tendon else 8},
                       "name": path.label, "hovertemplate": f"{path.label}<extra></extra>"})
    frame = tip_frame(poses, 0.15 * length)
    for k, axis in enumerate(("e1", "e2", "e3")):  # one legend entry each, in its colour
        traces.append({"type": "scatter3d", "mode": "lines", "x": frame[k, :, 0],
                       "y": frame[k, :, 1], "z": frame[k, :, 2],
                       "line": {"color": _AXES[k], "width": 6}, "name": axis,
                       "legendgroup": "tip frame", "legendgrouptitle": {"text": "tip frame"},
                       "showlegend": True, "hovertemplate": f"tip frame {axis}<extra></extra>"})
    traces += _arrow_traces(arrows, scales, length)
    if contacts(result.loads):
        traces += _contact_traces(contact_arrows(result), scales, length)
    traces.append({"type": "scatter3d", "mode": "markers", "x": p[:1, 0], "y": p[:1, 1],
                   "z": p[:1, 2],
                   "marker": {"symbol": "square", "size": 5, "color": "rgb(80,80,80)"},
                   "name": "base", "hovertemplate": "clamped base<extra></extra>",
                   "showlegend": False})
    return traces


def scene_traces(result, scales, *, changing: bool = False) -> list[dict]:
    """The 3D traces of one (unbatched) equilibrium, as in :func:`figure` with ``scales``;
    ``changing``: only what changes with the equilibrium (coordinates, hover data), the
    same for each trace as a sweep's frame holds, to update a drawn figure with."""
    arrows = load_arrows(result.loads, result.poses, result.s, result.arm)
    traces = _scene_traces(result, arrows, scales, tube_rings(result.arm, result.s, _RINGS))
    return [_changing(trace) for trace in traces] if changing else traces


def _extent(result, radii, arrows, scales) -> np.ndarray:
    poses = np.asarray(result.poses)
    points = [poses[..., :3, 3].reshape(-1, 3)]
    if radii is not None:
        for pose in poses.reshape(-1, *poses.shape[-3:]):
            points.append(tube_surface(pose, radii, sides=8).reshape(3, -1).T)
    for frame_arrows in arrows:
        for arrow in frame_arrows:
            points.append(arrow.origins + arrow.vectors * scales.get(arrow.key, 0.0))
    return _with_obstacles(np.concatenate(points), result.loads)


def _with_obstacles(extent, loads) -> np.ndarray:
    """``extent`` (k, 3) and the points of the spheres and capsules of the loads' Contact
    within the cube of twice the half side about it (a large obstacle is shown near the
    arm; planes are drawn to fit the cube)."""
    centre, half = cube_limits(extent, margin=1.0)
    points = [extent]
    for contact in contacts(loads):
        for obstacle in contact.obstacles:
            if obstacle.kind != "plane":
                surface = obstacle_surface(obstacle, centre, half, sides=12)
                points.append(np.clip(surface.reshape(3, -1).T, centre - 2.0 * half,
                                      centre + 2.0 * half))
    return np.concatenate(points)


def _take(result, k: int):
    """Case k of a batched equilibrium, as an unbatched one (for drawing)."""
    import dataclasses

    loads = tuple(load.take(k) if load.batch_shape else load for load in result.loads)
    return dataclasses.replace(result, poses=result.poses[k], strains=result.strains[k],
                               stresses=result.stresses[k], loads=loads, residual=0.0,
                               error_estimate=0.0, tip_compliance=None, compliance=None)


def _describe(loads) -> str:
    return " + ".join(load.describe() for load in loads) or "no load"


def figure(result, *, name: str | None = None, values=None, label: str | None = None,
           sweep=None, title: str | None = None, height: int | None = 650, scales=None,
           limits=None) -> dict:
    """The plotly figure (a dict: ``data``, ``layout`` and, for a sweep, ``frames``).

    Parameters
    ----------
    result : Equilibrium
        Batch shape () or (steps,) (a sweep).
    name : str, optional
        Case name for the title.
    values : array_like, shape (steps,), optional
        A sweep's parameter per step (default ``sweep.values``, else 0, 1, 2, …).
    label : str, optional
        The parameter's label with unit (default ``sweep.label``, else "step").
    sweep : softarm.case.Sweep, optional
    title : str, optional
        Replaces the whole title.
    height : int or None
        In pixels; None: as high as the element it is drawn in (:func:`to_html`'s page: the
        browser window).
    scales : dict, optional
        Arrow length in m per unit of each load's field, keyed by (load index, field name)
        (default: each field's largest arrow is 0.25 L, or 0.12 L for distributed loads).
    limits : (centre (3,), half side), optional
        The axis cube (default: around everything drawn).
    """
    batch = result.batch_shape
    if len(batch) > 1:
        raise ValueError(f"result must have batch shape () or (steps,), got {batch}")
    cases = [result] if not batch else [_take(result, k) for k in range(batch[0])]
    length = float(result.arm.length)
    radii = station_radii(result.arm, result.s)
    arrows = [load_arrows(case.loads, case.poses, case.s, case.arm) for case in cases]
    scales = _arrow_scales(arrows, length) if scales is None else dict(scales)
    drawn = arrows
    if contacts(result.loads):
        forces = [contact_arrows(case) for case in cases]
        if CONTACT_KEY not in scales:  # one scale for every frame
            scales[CONTACT_KEY] = contact_scale(forces, length)
        drawn = [[*frame, force] for frame, force in zip(arrows, forces, strict=True)]
    centre, half = cube_limits(_extent(result, radii, drawn, scales)) if limits is None \
        else limits
    scene = _cube_scene(centre, half, 0.66 if batch else 1.0)
    head = name or "softarm"
    layout = {"scene": scene, "margin": {"l": 10, "r": 10, "t": 60, "b": 10},
              "legend": {"x": 0.0, "y": 1.0}, "hovermode": "closest",
              "uirevision": "keep the camera"}
    if height is not None:
        layout["height"] = height
    rings = tube_rings(result.arm, result.s, _RINGS)
    data = _scene_traces(cases[0], arrows[0], scales, rings)

    def caption(case) -> str:
        tip = np.asarray(case.tip_position)
        text = title if title is not None else f"{head}: {_describe(case.loads)}"
        return f"{text}<br><sub>tip at {_vec(tip)} m; method {result.method}</sub>"

    layout["title"] = {"text": caption(cases[0]), "x": 0.02, "font": {"size": 14}}
    fig = {"data": data, "layout": layout}
    n_scene = len(data)  # the traces that change with the equilibrium; the obstacles stay
    data += _obstacle_traces(result.loads, centre, half)
    if not batch:
        data.append(_cube_anchor(centre, half))
        return fig

    steps = batch[0]
    values, label = sweep_axis(steps, sweep, values, label)
    tips = np.asarray(result.tip_position)
    data.append(_cube_anchor(centre, half))
    # The tip against the parameter is a figure of its own (fig["tips"]), drawn in a second
    # <div> laid over the right-hand part of the 3D figure's (where its own axes used to be):
    # a 3D figure redraws all of itself on every frame, 2D axes included, so a separate 2D
    # plot saves a third of the redraw; the page moves its "shown" marker on each frame.
    tip_data = []
    for k, axis in enumerate("xyz"):
        tip_data.append({"type": "scatter", "mode": "lines+markers", "x": values,
                         "y": tips[:, k], "name": f"tip {axis}",
                         "line": {"color": _AXES[k]}, "marker": {"size": 5},
                         "hovertemplate": f"{label} = %{{x:.4g}}<br>tip {axis} = %{{y:.4g}} m"
                         "<extra></extra>"})
    tip_data.append({"type": "scatter", "mode": "markers", "x": [values[0]] * 3,
                     "y": tips[0].tolist(), "name": "shown",
                     "marker": {"size": 12, "color": "rgba(0,0,0,0)",
                                "line": {"color": "black", "width": 2}},
                     "hoverinfo": "skip", "showlegend": False})
    fig["tips"] = {"data": tip_data, "layout": {
        "xaxis": {"title": {"text": label}}, "yaxis": {"title": {"text": "tip (m)"}},
        "margin": {"l": 60, "r": 10, "t": 30, "b": 50},
        "legend": {"orientation": "h", "x": 0.0, "y": 1.0, "yanchor": "bottom"},
        "paper_bgcolor": "rgba(0,0,0,0)", "plot_bgcolor": "rgba(0,0,0,0)",
        "hovermode": "closest"},
        # the "shown" marker at each frame (plain lists for the page's script)
        "shown": [{"x": [float(v)] * 3, "y": tip.tolist()} for v, tip in zip(values, tips,
                                                                              strict=True)]}
    names = [f"{v:.6g}" for v in values]
    frames = []
    for k, case in enumerate(cases):
        traces = [_changing(trace) for trace in _scene_traces(case, arrows[k], scales, rings)]
        frames.append({"name": names[k], "data": traces, "traces": list(range(n_scene)),
                       "layout": {"title": {"text": caption(case), "x": 0.02,
                                            "font": {"size": 14}}}})
    # The frames are shown by the page's script (to_html; "skip": plotly.js only draws the
    # slider and the buttons): one Plotly.react per frame, see _DRAW.
    fig["frames"] = frames
    # The slider and the play and pause buttons share one row below the plotting area (they
    # hang from its bottom edge, y = 0, yanchor "top"), the buttons left of the slider's rail
    # (its pad "l"): nothing of them lies over the 3D scene, where they hid part of the arm.
    layout["sliders"] = [{
        "active": 0, "x": 0.0, "len": 1.0, "y": 0.0, "yanchor": "top",
        "pad": {"t": 10, "l": _BUTTONS_WIDTH + 20, "r": 20},
        "currentvalue": {"prefix": f"{label} = ", "font": {"size": 13}},
        "steps": [{"label": n, "method": "skip", "args": [[n]]} for n in names]}]
    layout["updatemenus"] = [{
        "type": "buttons", "direction": "left", "x": 0.0, "xanchor": "left", "y": 0.0,
        "yanchor": "top", "pad": {"t": 36, "l": 10}, "showactive": False,
        "buttons": [{"label": "▶", "method": "skip", "args": [None]},
                    {"label": "❚❚", "method": "skip", "args": [None]}]}]
    layout["margin"]["b"] = 40
    return fig


#: The play and pause buttons' width in pixels (two buttons of about 35 px).
_BUTTONS_WIDTH = 75
#: The smallest height of a figure that fills the window, pixels.
_MIN_HEIGHT = 480


def _cube_scene(centre, half: float, width: float) -> dict:
    """A 3D scene: the cube of half-side ``half`` about ``centre`` (m) with ticks, over the
    page's left ``width`` fraction."""
    # the camera far enough out that the whole box and its labels are in the picture
    scene = {"aspectmode": "cube", "domain": {"x": [0.0, width], "y": [0.0, 1.0]},
             "camera": {"eye": {"x": 1.27, "y": -1.84, "z": 0.86}}}
    for k, axis in enumerate("xyz"):
        low, high = centre[k] - half, centre[k] + half
        scene[f"{axis}axis"] = {"range": [low, high], "tickmode": "array",
                                "tickvals": axis_ticks(low, high),
                                "title": {"text": f"{axis} (m)"}}
    return scene


def axis_ticks(low: float, high: float) -> list[float]:
    """Tick values for a 3D axis over [low, high]: multiples of 1, 2 or 5 × 10^k, at least
    three, none within 10 % of the axis length from either end.

    A 3D scene draws each axis's tick labels along an edge of its box, and three edges meet
    at each corner: a label at an axis's end sat on the labels of the other axes there, which
    overlapped (plotly.js's own ticks run to the ends of the range)."""
    span = high - low
    inner = (low + 0.1 * span, high - 0.1 * span)
    exponent = math.floor(math.log10((inner[1] - inner[0]) / 3))
    step = max(m * 10.0**exponent for m in (1.0, 2.0, 5.0)
               if m * 10.0**exponent <= (inner[1] - inner[0]) / 3)
    first, last = math.ceil(inner[0] / step), math.floor(inner[1] / step)
    digits = max(0, 1 - math.floor(math.log10(step)))
    return [round(k * step, digits) + 0.0 for k in range(first, last + 1)]


def _cube_anchor(centre, half) -> dict:
    """An undrawn trace (mode "none") at two corners of the axis cube.

    plotly.js scales a 3D scene's data by the extent of the data, not of the axes: when the
    arm moves (a sweep's frame, an app's slider), that scale changes, and with it the axes'
    tick positions, and the scene rebuilds its grid lines and compiles their shader again on
    every redraw, which costs software WebGL tens of milliseconds. These two points make the
    data's extent that of the fixed axis cube, so the scale stays put."""
    corners = np.array([centre - half, centre + half])
    return {"type": "scatter3d", "mode": "none", "x": corners[:, 0], "y": corners[:, 1],
            "z": corners[:, 2], "hoverinfo": "skip", "showlegend": False,
            "name": "axis cube"}


_CHANGING = ("x", "y", "z", "u", "v", "w", "customdata", "text")


def _changing(trace: dict) -> dict:
    """The part of a trace that changes from frame to frame (a frame updates the figure's
    traces; the mesh's triangles, colours and hover templates stay)."""
    return {"type": trace["type"], **{k: trace[k] for k in _CHANGING if k in trace}}


def _plain(value):
    if isinstance(value, np.ndarray):
        return np.where(np.isfinite(value), value, np.nan).tolist() if value.dtype.kind == "f" \
            else value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def to_json(fig: dict) -> str:
    """The figure as JSON text (numpy arrays as lists), for plotly.js without plotly.py."""
    return json.dumps(_compact(fig), default=_plain, separators=(",", ":"), allow_nan=False)


def _compact(value):
    """``value`` with numeric arrays as plotly.js typed arrays (``{"dtype": "f4", "bdata":
    base64, "shape": "N, M"}``): float32 keeps 7 significant digits, more than a drawing or
    its read-outs show, in a fifth of the characters of decimal text (fewer digits would
    not help: plotly.js takes no smaller float type)."""
    if isinstance(value, dict):
        return {k: _compact(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_compact(v) for v in value]
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu" and value.size:
        if value.dtype.kind == "f":
            dtype = "<f4"
        else:  # indices (a mesh's triangles): two bytes each while they fit
            dtype = "<u2" if value.min() >= 0 and value.max() < 2**16 else "<i4"
        data = np.ascontiguousarray(value, dtype=dtype)
        typed = {"dtype": dtype[1:], "bdata": base64.b64encode(data.tobytes()).decode("ascii")}
        if data.ndim > 1:
            typed["shape"] = ", ".join(str(n) for n in data.shape)
        return typed
    return value


# The page's script for one figure. WebGL draws at the screen's own resolution: plotly.js's
# default (plotGlPixelRatio 2) draws a 3D scene at twice the resolution on every screen, four
# times the pixels, which software WebGL (a browser without a GPU, a headless one) pays on
# every redraw; on a high-density screen (devicePixelRatio 2) nothing changes. Without
# window.Plotly (a notebook output that relies on an earlier output to have loaded it), the
# figure waits for the "softarm-plotly-ready" event that an embedding output sends.
_DRAW = """(function () {
  var id = %(id)s, fig = %(fig)s, config = {displaylogo: false, responsive: true,
    plotGlPixelRatio: Math.min(2, Math.max(1, Math.round(window.devicePixelRatio || 1)))};
  function draw() {
    var gd = document.getElementById(id);
    if (!gd || gd.getAttribute("data-drawn")) return;
    gd.setAttribute("data-drawn", "1");
    gd.textContent = "";
    // a sweep's tip plot or a motion's energy plot, in a <div> of its own (see to_html)
    var side = fig.tips || fig.energy, tips = side && document.getElementById(id + "-tips");
    Plotly.newPlot(gd, fig.data, fig.layout, config).then(function () {
      if (fig.player) motion(gd, tips); else if (fig.frames) sweep(gd, tips);
    });
    if (tips) Plotly.newPlot(tips, side.data, side.layout,
                             {displaylogo: false, responsive: true, displayModeBar: false});
  }
  // a frame: its data merged into the figure and one Plotly.react (see sweep below)
  function showFrame(gd, tips, k) {
    var frame = fig.frames[k], side = fig.tips || fig.energy;
    frame.traces.forEach(function (t, i) { Object.assign(gd.data[t], frame.data[i]); });
    gd.layout.title = frame.layout.title;
    gd.layout.sliders[0].active = k;
    gd.layout.datarevision = (gd.layout.datarevision || 0) + 1;
    // a 2D animation step without redraw moves the side plot's marker alone (a restyle
    // would redraw that whole plot, as costly again as the 3D frame); it is the last trace
    if (tips) Plotly.animate(tips, {data: [side.shown[k]], traces: [side.data.length - 1]},
      {mode: "immediate", frame: {duration: 0, redraw: false}, transition: {duration: 0}});
    return Plotly.react(gd, gd.data, gd.layout);
  }
  // A sweep's slider and play button (method "skip": plotly.js only draws them) show a
  // frame by merging its data into the figure and one Plotly.react. Plotly.animate would
  // do the work twice: its transition step computes the figure's defaults and data before
  // the redraw (for a 3D scene, a full one) computes them again.
  function sweep(gd, tips) {
    var frames = fig.frames, playing = null;
    var names = frames.map(function (frame) { return frame.name; });
    function show(k) { return showFrame(gd, tips, k); }
    function play() {
      var token = {}, k = gd.layout.sliders[0].active;
      playing = token;
      if (k >= frames.length - 1) k = -1;
      (function next() {
        if (playing !== token) return;
        k += 1;
        show(k).then(function () {
          if (k < frames.length - 1) setTimeout(next, 400); else playing = null;
        });
      })();
    }
    gd.on("plotly_sliderchange", function (event) {
      playing = null;
      var k = names.indexOf(event.step.label);
      if (k >= 0) show(k);
    });
    gd.on("plotly_buttonclicked", function (event) {
      if (event.button.label === "\u25b6") play(); else playing = null;
    });
  }
  // A motion's player: the last frame whose time has come at the chosen rate (real time:
  // the trajectory's own seconds), redrawn as soon as the previous redraw is done; frames
  // that come faster than the browser redraws are skipped, the motion keeps its pace.
  // gd.softarmPlayed lists [frame, the playback's clock (s of the trajectory), the wall
  // clock (ms)] when each frame drawn while playing was chosen.
  function motion(gd, tips) {
    var times = fig.player.times, rates = fig.player.rates, n = times.length;
    var names = fig.frames.map(function (frame) { return frame.name; });
    var rate = 1, playing = null, k = 0, t0 = 0, wall0 = 0;
    gd.softarmPlayed = [];
    function anchor() { t0 = times[k]; wall0 = performance.now(); }
    function show(j) { k = j; return showFrame(gd, tips, j); }
    function play() {
      var token = {};
      playing = token;
      k = gd.layout.sliders[0].active;
      var start = k >= n - 1 ? show(0) : Promise.resolve();
      start.then(function () {
        anchor();
        (function tick() {
          if (playing !== token) return;
          var t = t0 + (performance.now() - wall0) / 1000 * rate, j = k;
          while (j + 1 < n && times[j + 1] <= t) j++;
          if (j === k) {  // the next frame's time has not come yet
            setTimeout(tick, Math.max(0, (times[k + 1] - t) / rate * 1000));
            return;
          }
          var chosen = performance.now();
          show(j).then(function () {
            gd.softarmPlayed.push([j, t, chosen]);
            if (j >= n - 1) playing = null; else requestAnimationFrame(tick);
          });
        })();
      });
    }
    gd.on("plotly_sliderchange", function (event) {
      playing = null;
      var j = names.indexOf(event.step.label);
      if (j >= 0) show(j);
    });
    gd.on("plotly_buttonclicked", function (event) {
      var label = event.button.label;
      if (label in rates) { rate = rates[label]; anchor(); }
      else if (label === "\u25b6") play(); else playing = null;
    });
  }
  if (window.Plotly) { draw(); return; }
  document.getElementById(id).textContent = %(waiting)s;
  window.addEventListener("softarm-plotly-ready", draw);
})();"""

_WAITING = ("softarm: waiting for plotly.js, which the first softarm view shown in this "
            "notebook's kernel session carries; it is not on this page (its output was "
            "cleared, or the page reloaded). Run softarm.view.NOTEBOOK_PLOTLYJS = 'always' "
            "and this cell again, or restart the kernel and run the notebook from the top.")


def _library() -> str:
    """plotly.js as an inline script that announces itself ("softarm-plotly-ready")."""
    code = plotly_js_path().read_text(encoding="utf-8")
    if "</script" in code.lower():  # pragma: no cover - would end the script element early
        raise ValueError("plotly.min.js contains '</script'; cannot inline it")
    return ('<script type="text/javascript">window.PlotlyConfig = {MathJaxConfig: "local"};'
            '</script>\n<script type="text/javascript">' + code +
            '\nwindow.dispatchEvent(new Event("softarm-plotly-ready"));</script>\n')


def to_html(fig: dict, *, full_html: bool = True, div_id: str | None = None,
            include_plotlyjs: bool = True) -> str:
    """An HTML page (or, ``full_html=False``, a ``<div>`` with its scripts) drawing ``fig``.

    ``include_plotlyjs``: embed plotly.js (about 4.8 MB; the page opens offline on its own),
    or not (the figure uses the ``window.Plotly`` of the page it is put in, waiting for it
    if an embedding figure comes later on the page). ``div_id``: the id of the figure's
    ``<div>`` (default: a fresh unique one)."""
    import html
    import uuid

    if include_plotlyjs:
        _plotly()
    div_id = div_id or f"softarm-{uuid.uuid4().hex[:12]}"
    height = fig.get("layout", {}).get("height")
    # a figure without a height fills the window (min-height: a usable figure in a small one)
    size = f"height:{int(height)}px;" if height else f"height:100vh; min-height:{_MIN_HEIGHT}px;"
    script = _DRAW % {"id": json.dumps(div_id), "fig": to_json(fig).replace("</", "<\\/"),
                      "waiting": json.dumps(_WAITING)}
    side = "tips" in fig or "energy" in fig  # a sweep's tip plot, a motion's energy plot
    own = "height:100%;" if side else size  # then: that of its container
    main = (f'<div id="{html.escape(div_id)}" class="plotly-graph-div" '
            f'style="{own} width:100%;"></div>')
    if side:  # a sweep's tip plot over the right of the 3D figure, see figure()
        # its axes from 0.1 to 0.7 of the plotting area's height (that of the page less the
        # 3D figure's margins), whatever the page's height: CSS percentages of the container
        margin = fig["layout"]["margin"]
        inner = f"(100% - {margin['t'] + margin['b']}px)"
        top = f"calc({margin['t'] - 30}px + 0.1 * {inner})"
        bottom = f"calc({margin['b'] - 50}px + 0.3 * {inner})"
        main = (f'<div style="position:relative; {size} width:100%;">{main}'
                f'<div id="{html.escape(div_id)}-tips" class="plotly-graph-div" '
                f'style="position:absolute; top:{top}; bottom:{bottom}; '
                f'left:calc(0.72 * (100% - 20px) - 50px); right:0px;"></div></div>')
    body = ((_library() if include_plotlyjs else "") + main + "\n" +
            f'<script type="text/javascript">{script}</script>\n')
    if not full_html:
        return f"<div>{body}</div>"
    title = html.escape(_plain_title(fig))
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head><meta charset="utf-8">'
            f'<title>{title}</title></head>\n<body style="margin:0">\n{body}</body>\n</html>\n')


def _plain_title(fig: dict) -> str:
    text = fig.get("layout", {}).get("title", {}).get("text", "softarm")
    import re

    return re.sub(r"<[^>]+>", " ", text.split("<br>")[0]).strip() or "softarm"


#: How a notebook's rich display of an :class:`~softarm.Equilibrium` carries plotly.js:
#: ``"once"`` (default): the first display of the kernel session embeds it (about 4.8 MB)
#: and later ones use it from the page (tens of kB each); a reopened notebook works offline
#: as long as that first output is still in it (its script loads plotly.js for the views
#: below, and a view drawn before it waits for it). ``"always"``: every display embeds it
#: (each output stands alone: for a notebook whose outputs are cleared or moved around, or a
#: front end that isolates outputs, which Google Colab does and is detected).
NOTEBOOK_PLOTLYJS = "once"
_notebook = {"embedded": False}


def notebook_html(result, **options) -> str:
    """The notebook display of ``result`` (:func:`figure`, ``options`` as there), carrying
    plotly.js as :data:`NOTEBOOK_PLOTLYJS` says."""
    import sys

    if NOTEBOOK_PLOTLYJS not in ("once", "always"):
        raise ValueError(f"softarm.view.NOTEBOOK_PLOTLYJS must be 'once' or 'always', got "
                         f"{NOTEBOOK_PLOTLYJS!r}")
    fig = figure(result, **options)
    embed = (NOTEBOOK_PLOTLYJS == "always" or not _notebook["embedded"]
             or "google.colab" in sys.modules)
    text = to_html(fig, full_html=False, include_plotlyjs=embed)
    _notebook["embedded"] = _notebook["embedded"] or embed
    return text


def write_html(result, path: str | os.PathLike, **options) -> Path:
    """Write :func:`figure` (``options`` as there; ``height`` default None: the figure fills
    the browser's window) as a self-contained HTML file, atomically."""
    options.setdefault("height", None)
    text = to_html(figure(result, **options), div_id="softarm-view")
    path = Path(path)
    with write_atomic(path, "wb") as stream:
        stream.write(text.encode("utf-8"))
    return path


def view_result_file(saved, path: str | os.PathLike) -> Path:
    """:func:`write_html` for a result file read by :func:`softarm.io.load_saved` (CSV, JSON or
    NPZ written by :func:`softarm.io.save_result`): ``saved``, a :class:`softarm.io.SavedResult`.

    (This module reads no file itself: it imports nothing above :mod:`softarm.geometry`, so
    that :meth:`softarm.Equilibrium.show` may use it, see ``tests/test_layering.py``.)
    """
    if isinstance(saved, (str, os.PathLike)):
        raise TypeError(f"saved must be a softarm.io.SavedResult (softarm.io.load_saved(path)), "
                        f"got the path {str(saved)!r}")
    result = saved.result
    if len(result.batch_shape) > 1:
        raise ValueError(f"{saved.path}: cannot view a batch of shape {result.batch_shape}")
    case = saved.case
    return write_html(result, path, name=case.name if case is not None else None,
                      values=saved.sweep_values, label=saved.sweep_label,
                      sweep=case.sweep if case is not None else None)


# ---------------------------------------------------------------------------- trajectories
#
# A trajectory's page: the 3D scene of view.figure's kind (the tube, the centreline, the tip's
# frame, the base, the fixed axis cube) with one frame per shown time, the tip's path over the
# whole motion, and the energy budget against time in a 2D figure of its own (fig["energy"],
# laid over the right of the 3D figure like a sweep's tip plot, see to_html) with a cursor at
# the shown time. The page's script (_DRAW, "trajectory") plays it at real time times the
# chosen rate: each redraw shows the last frame whose time has come, so a browser that redraws
# slower than the frames come drops frames instead of slowing the motion down.

#: Frames of a trajectory's page, at most (a frame holds the tube: about 10 kB in the page).
TRAJECTORY_FRAMES = 240
#: Points of the tip's path and of the energy curves, at most (every k-th time).
_CURVE_POINTS = 4000
#: The playback rates' drop-down menu's width in pixels.
_RATES_WIDTH = 90
#: The playback rates offered (label, rate); "real time" (1) first, the default.
PLAYBACK_RATES = (("real time", 1.0), ("1/2 ×", 0.5), ("1/4 ×", 0.25), ("1/10 ×", 0.1),
                  ("1/100 ×", 0.01), ("2 ×", 2.0), ("5 ×", 5.0))
_ENERGIES = (("kinetic", "rgb(31,119,180)"), ("elastic", "rgb(44,160,44)"),
             ("gravity", "rgb(140,86,75)"), ("dissipated", "rgb(214,39,40)"),
             ("total", "rgb(0,0,0)"))
#: each energy curve's colour; "contact": the penalty's stored energy (with a Contact)
_ENERGY_COLORS = {**dict(_ENERGIES), "contact": "rgb(214,0,154)"}


def frame_indices(times, frames: int = TRAJECTORY_FRAMES) -> np.ndarray:
    """The indices of the times shown as frames: all of them up to ``frames``, else
    ``frames`` times evenly spread in time (the nearest stored time to each of
    ``frames`` equally spaced instants from the first to the last, without repeats),
    always the first and the last.

    >>> frame_indices(np.linspace(0.0, 1.0, 1001), 5).tolist()
    [0, 250, 500, 750, 1000]
    """
    times = np.asarray(times, dtype=float)
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 2:
        raise ValueError(f"frames must be an integer >= 2, got {frames!r}")
    if times.size <= frames:
        return np.arange(times.size)
    wanted = np.linspace(times[0], times[-1], frames)
    index = np.clip(np.searchsorted(times, wanted), 1, times.size - 1)
    nearer = np.where(wanted - times[index - 1] <= times[index] - wanted, index - 1, index)
    return np.unique(np.concatenate([[0], nearer, [times.size - 1]]))


def _every(count: int, most: int) -> np.ndarray:
    """Every k-th of ``count`` indices (k the smallest that keeps at most ``most``) and the
    last."""
    step = max(1, math.ceil(count / most))
    return np.unique(np.append(np.arange(0, count, step), count - 1))


def _trajectory_arrays(trajectory):
    """(times (T,), s (S,), poses (T, S, 4, 4), energies {name: (T,)}) of an unbatched
    trajectory (anything with :class:`softarm.Trajectory`'s ``times``, ``s``,
    ``positions``, ``rotations`` and ``energy``), checked."""
    times = np.asarray(trajectory.times, dtype=float)
    s = np.asarray(trajectory.s, dtype=float)
    positions = np.asarray(trajectory.positions, dtype=float)
    rotations = np.asarray(trajectory.rotations, dtype=float)
    if positions.ndim != 3:
        raise ValueError("trajectory must be unbatched (positions of shape (T, S, 3)), got "
                         f"positions of shape {positions.shape}; view one case: pass the "
                         "arrays of that case")
    T, S = times.size, s.size
    if positions.shape != (T, S, 3) or rotations.shape != (T, S, 3, 3):
        raise ValueError(f"trajectory: positions {positions.shape} and rotations "
                         f"{rotations.shape} do not match {T} times and {S} stations")
    if T < 1 or np.any(np.diff(times) <= 0) or not np.all(np.isfinite(times)):
        raise ValueError("trajectory.times must be finite and increasing")
    poses = np.zeros((T, S, 4, 4))
    poses[..., :3, :3] = rotations
    poses[..., :3, 3] = positions
    poses[..., 3, 3] = 1.0
    energy = trajectory.energy
    energies = {name: np.asarray(getattr(energy, name), dtype=float)
                for name, _ in _ENERGIES[:4]}
    if getattr(trajectory, "contact", None) is not None:
        # the penalty's stored energy, which Energy.total leaves out: the total holds it
        energies["contact"] = np.asarray(trajectory.contact_energy, dtype=float)
    energies["total"] = sum(energies.values())
    for name, values in energies.items():
        if values.shape != (T,):
            raise ValueError(f"trajectory.energy.{name} must have shape ({T},), got "
                             f"{values.shape}")
    return times, s, poses, energies


def _ring_stations(s, radii, arm):
    """The rings of the tube (index, radii) or None (no radius known)."""
    if arm is not None:
        return tube_rings(arm, s, _RINGS)
    if radii is None:
        return None
    radii = np.broadcast_to(np.asarray(radii, dtype=float), s.shape)
    if not np.all(np.isfinite(radii) & (radii > 0)):
        raise ValueError("radii must be positive finite tube radii in m, one per station")
    index = _every(s.size, _RINGS)
    return index, radii[index]


def _pose_traces(poses, s, rings, length: float) -> list[dict]:
    """The traces that move: tube, centreline, tip frame e1 e2 e3, base (this order)."""
    p = poses[:, :3, 3]
    traces = []
    if rings is not None:
        index, radii = rings
        traces.append(_tube_trace(poses[index], radii, hoverinfo="skip", showlegend=True))
    traces.append({"type": "scatter3d", "mode": "lines" if rings is not None else
                   "lines+markers", "x": p[:, 0], "y": p[:, 1], "z": p[:, 2],
                   "customdata": s, "line": {"color": _LINE, "width": 4},
                   "marker": {"size": 2, "color": _LINE}, "name": "centreline",
                   "hovertemplate": "s = %{customdata:.4g} m<br>p = (%{x:.4g}, %{y:.4g}, "
                                    "%{z:.4g}) m<extra>centreline</extra>"})
    frame = tip_frame(poses, 0.15 * length)
    for k, axis in enumerate(("e1", "e2", "e3")):
        traces.append({"type": "scatter3d", "mode": "lines", "x": frame[k, :, 0],
                       "y": frame[k, :, 1], "z": frame[k, :, 2],
                       "line": {"color": _AXES[k], "width": 6}, "name": axis,
                       "legendgroup": "tip frame", "legendgrouptitle": {"text": "tip frame"},
                       "showlegend": True, "hovertemplate": f"tip frame {axis}<extra></extra>"})
    # the base moves too where the simulation moved it
    traces.append({"type": "scatter3d", "mode": "markers", "x": p[:1, 0], "y": p[:1, 1],
                   "z": p[:1, 2], "marker": {"symbol": "square", "size": 5,
                                             "color": "rgb(80,80,80)"},
                   "name": "base", "hovertemplate": "base<extra></extra>",
                   "showlegend": False})
    return traces


def trajectory_figure(trajectory, *, arm=None, radii=None, name: str | None = None,
                      frames: int = TRAJECTORY_FRAMES, height: int | None = 650,
                      contact=None) -> dict:
    """The plotly figure of a motion: a dict with ``data``, ``layout``, ``frames`` (the
    moving traces at the shown times) and ``energy`` (the energy plot, a figure of its own),
    drawn by :func:`to_html`'s page with a time slider, play and pause and a choice of
    playback rates (real time: the trajectory's own times).

    Parameters
    ----------
    trajectory : softarm.Trajectory
        Unbatched (or anything with its ``times``, ``s``, ``positions``, ``rotations`` and
        ``energy``, such as :func:`softarm.io.read_trajectory`'s answer).
    arm : Arm, optional
        Draws the tube of its real radius (with a step at a joint).
    radii : array_like, shape (S,), optional
        Else the tube's radius at each station (m); neither: the centreline alone.
    name : str, optional
        For the title.
    frames : int
        The most frames (default :data:`TRAJECTORY_FRAMES`); a longer trajectory shows
        that many times evenly spread over its duration (:func:`frame_indices`: the slider
        steps through them, the playback shows the last one whose time has come), and its
        tip path and energy curves keep every k-th time, at most 4000.
    height : int or None
        As :func:`figure`'s.
    contact : Contact, optional
        Its obstacles are drawn; default the trajectory's own (``Trajectory.contact``; a
        file read back keeps its case's instead: :func:`view_trajectory_file`).
    """
    times, s, poses, energies = _trajectory_arrays(trajectory)
    shown = frame_indices(times, frames)
    curve = _every(times.size, _CURVE_POINTS)
    length = float(s[-1] - s[0])
    rings = _ring_stations(s, radii, arm)
    # the axis cube holds the whole motion (the tube's surface at the shown frames)
    points = [poses[..., :3, 3].reshape(-1, 3)]
    if rings is not None:
        index, ring_radii = rings
        points += [tube_surface(poses[k][index], ring_radii, sides=8).reshape(3, -1).T
                   for k in shown]
    centre, half = cube_limits(np.concatenate(points))
    scene = _cube_scene(centre, half, 0.66)
    tip = poses[curve, -1, :3, 3]
    data = _pose_traces(poses[0], s, rings, length)
    moving = len(data)
    data.append({"type": "scatter3d", "mode": "lines", "x": tip[:, 0], "y": tip[:, 1],
                 "z": tip[:, 2], "customdata": times[curve], "name": "tip path",
                 "line": {"color": "rgb(120,120,120)", "width": 3, "dash": "solid"},
                 "hovertemplate": "tip at t = %{customdata:.4g} s<br>(%{x:.4g}, %{y:.4g}, "
                                  "%{z:.4g}) m<extra></extra>"})
    data.append(_cube_anchor(centre, half))
    if contact is None:
        contact = getattr(trajectory, "contact", None)
    # (the obstacles stay: not in the frames)
    data += _obstacle_traces([] if contact is None else [contact], centre, half)
    head = name or "softarm"
    duration = times[-1] - times[0]
    subtitle = (f"{times.size} times over {duration:.4g} s"
                + (f"; {shown.size} frames shown (every {duration / (shown.size - 1):.3g} s)"
                   if shown.size < times.size else ""))

    def caption(k: int) -> str:
        return (f"{head}: motion, t = {times[k]:.4g} s<br><sub>tip at "
                f"{_vec(poses[k, -1, :3, 3])} m; {subtitle}</sub>")

    layout = {"scene": scene, "margin": {"l": 10, "r": 10, "t": 60, "b": 40},
              "legend": {"x": 0.0, "y": 1.0}, "hovermode": "closest",
              "uirevision": "keep the camera",
              "title": {"text": caption(0), "x": 0.02, "font": {"size": 14}}}
    if height is not None:
        layout["height"] = height
    names = [f"{t:.6g}" for t in times[shown]]
    fig = {"data": data, "layout": layout}
    fig["frames"] = [{"name": names[n], "traces": list(range(moving)),
                      "data": [_changing(t) for t in _pose_traces(poses[k], s, rings, length)],
                      "layout": {"title": {"text": caption(k), "x": 0.02,
                                           "font": {"size": 14}}}}
                     for n, k in enumerate(shown)]
    # what the page's player needs: the frames' times (s) and the playback rates
    fig["player"] = {"times": times[shown].tolist(), "rates": dict(PLAYBACK_RATES)}
    layout["sliders"] = [{
        "active": 0, "x": 0.0, "len": 1.0, "y": 0.0, "yanchor": "top",
        "pad": {"t": 10, "l": _BUTTONS_WIDTH + _RATES_WIDTH + 30, "r": 20},
        "currentvalue": {"prefix": "t = ", "suffix": " s", "font": {"size": 13}},
        "steps": [{"label": n, "method": "skip", "args": [[n]]} for n in names]}]
    layout["updatemenus"] = [
        {"type": "buttons", "direction": "left", "x": 0.0, "xanchor": "left", "y": 0.0,
         "yanchor": "top", "pad": {"t": 36, "l": 10}, "showactive": False,
         "buttons": [{"label": "▶", "method": "skip", "args": [None]},
                     {"label": "❚❚", "method": "skip", "args": [None]}]},
        # the playback rate, in the same row right of the buttons (opening upwards)
        {"type": "dropdown", "direction": "up", "x": 0.0, "xanchor": "left", "y": 0.0,
         "yanchor": "top", "pad": {"t": 36, "l": _BUTTONS_WIDTH + 15}, "showactive": True,
         "active": 0,
         "buttons": [{"label": label, "method": "skip", "args": [None]}
                     for label, _ in PLAYBACK_RATES]}]
    # the energy budget, with a cursor (a vertical line) at the shown time
    energy = [{"type": "scatter", "mode": "lines", "x": times[curve], "y": values[curve],
               "name": label, "line": {"color": _ENERGY_COLORS[label],
                                       "width": 2.5 if label == "total"
                                       else 1.5, "dash": "dash" if label == "total"
                                       else "solid"},
               "hovertemplate": f"t = %{{x:.4g}} s<br>{label} = %{{y:.4g}} J<extra></extra>"}
              for label, values in energies.items()]
    every = np.concatenate(list(energies.values()))
    low, high = float(np.min(every)), float(np.max(every))
    pad = 0.05 * max(high - low, 1e-12 * max(abs(low), abs(high)), 1e-300)
    bounds = [low - pad, high + pad]
    energy.append({"type": "scatter", "mode": "lines", "x": [times[0]] * 2, "y": bounds,
                   "name": "shown", "line": {"color": "rgb(90,90,90)", "width": 1},
                   "hoverinfo": "skip", "showlegend": False})
    fig["energy"] = {"data": energy, "layout": {
        "xaxis": {"title": {"text": "t (s)"}, "range": [times[0], times[-1]]},
        "yaxis": {"title": {"text": "energy (J)"}, "range": bounds},
        "margin": {"l": 60, "r": 10, "t": 30, "b": 50},
        "legend": {"orientation": "h", "x": 0.0, "y": 1.0, "yanchor": "bottom"},
        "paper_bgcolor": "rgba(0,0,0,0)", "plot_bgcolor": "rgba(0,0,0,0)",
        "hovermode": "closest"},
        "shown": [{"x": [float(t)] * 2, "y": bounds} for t in times[shown]]}
    return fig


def show_page(write, path=None, browser: bool = True) -> Path:
    """``write(path)`` a page to ``path`` or a new temporary file, open it in the web browser
    unless ``browser`` is False, and return its path (``Equilibrium.show``,
    ``Trajectory.show``)."""
    import tempfile
    import webbrowser

    if path is None:
        handle, path = tempfile.mkstemp(prefix="softarm-", suffix=".html")
        os.close(handle)
    path = write(path)
    if browser:
        webbrowser.open(Path(path).resolve().as_uri())
    return path


def write_trajectory_html(trajectory, path: str | os.PathLike, **options) -> Path:
    """Write :func:`trajectory_figure` (``options`` as there; ``height`` default None: the
    figure fills the browser's window) as a self-contained HTML file, atomically; returns
    its path."""
    options.setdefault("height", None)
    text = to_html(trajectory_figure(trajectory, **options), div_id="softarm-view")
    path = Path(path)
    with write_atomic(path, "wb") as stream:
        stream.write(text.encode("utf-8"))
    return path


def view_trajectory_file(saved, path: str | os.PathLike, *, case: int | None = None) -> Path:
    """:func:`write_trajectory_html` for a trajectory file read by
    :func:`softarm.io.read_trajectory` (``saved``, a :class:`softarm.io.SavedTrajectory`):
    the tube of its case's arm and its case's obstacles, titled with the case's name; of a
    sweep of simulations, case number ``case`` (counted from 1; default 1), with its
    parameter in the title."""
    import dataclasses

    if isinstance(saved, (str, os.PathLike)):
        raise TypeError(f"saved must be a softarm.io.SavedTrajectory (softarm.io."
                        f"read_trajectory(path)), got the path {str(saved)!r}")
    batch = tuple(saved.batch_shape)
    name = saved.case.name
    if len(batch) > 1:
        raise ValueError(f"{saved.path}: cannot view a batch of shape {batch}")
    if batch:
        k = 1 if case is None else case
        if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= batch[0]:
            raise ValueError(f"{saved.path}: case must be 1 ... {batch[0]} (the file holds "
                             f"{batch[0]} simulations), got {case!r}")
        energy = saved.energy
        law = saved.contact
        if law is not None and np.ndim(law.stiffness):  # (each case's own penalty)
            law = law.replace(stiffness=float(np.ravel(law.stiffness)[k - 1]))
        saved = dataclasses.replace(
            saved, positions=saved.positions[k - 1], rotations=saved.rotations[k - 1],
            energy=type(energy)(*(getattr(energy, n)[k - 1] for n, _ in _ENERGIES[:4])),
            contact=law)
        label = saved.sweep_label or "case"
        value = saved.sweep_values[k - 1] if saved.sweep_values is not None else k
        name = f"{name} ({label} = {value:.6g})"
    elif case not in (None, 1):
        raise ValueError(f"{saved.path}: case must be 1 (the file holds one simulation), got "
                         f"{case!r}")
    # (a file written before its contact law was kept: its case's obstacles, no stored
    # energy)
    contacts = [load for load in saved.case.loads if load.kind == "contact"]
    return write_trajectory_html(saved, path, arm=saved.case.arm, name=name,
                                 contact=saved.contact or (contacts[0] if contacts else None))
