"""Pictures of equilibria: a 3D view with equal axis scaling and the two side projections.

Needs matplotlib (``pip install "softarm[plot]"``); it is imported only when a function here is
called, never by ``import softarm``. Figures are created as plain
:class:`matplotlib.figure.Figure` objects (not through pyplot), so saving a picture needs no
display and no GUI backend (it renders with Agg), and no figure is left open behind the caller's
back. Pass ``fig`` to draw into a figure of your own (e.g. ``plt.figure()`` in a notebook).

The arm is drawn as a translucent tube of its real radius (built from the material frames) when
the cross-section is known, else as its centreline. The obstacles of a :class:`softarm.Contact`
are drawn as grey translucent surfaces (a plane as a square about the drawing, spheres,
capsules) and, in the side views, as outlines (a plane only where it is seen edge-on); the
contact forces per length as magenta arrows at the stations where they act.
"""

from __future__ import annotations

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
    obstacle_outline,
    obstacle_surface,
    silhouette,
    station_radii,
    sweep_axis,
    tube_surface,
)

__all__ = ["describe_loads", "plot_equilibrium", "plot_result_file", "plot_sweep",
           "plot_trajectory"]

#: Figure size in inches and resolution of saved pictures (pixels = size × dpi).
FIGSIZE = (11.0, 5.5)
DPI = 100

_TUBE_COLOR = "tab:orange"
_LINE_COLOR = "tab:blue"
#: How actuator paths are drawn: tendons as thin dark lines, chambers as wide blue bands.
_PATH_STYLE = {"tendon": dict(color="0.15", linewidth=1.0),
               "chamber": dict(color="tab:blue", linewidth=3.0, alpha=0.6)}
_PLANES = (("x", 0), ("z", 2)), (("x", 0), ("y", 1))  # side views: x–z and x–y
_OBSTACLE_COLOR = "0.55"
_CONTACT_COLOR = "#d6009a"  # magenta: no other drawn thing shares it


def _matplotlib():
    try:
        import matplotlib
    except ImportError as error:  # pragma: no cover - depends on the environment
        raise ImportError(
            "softarm.plot needs matplotlib: pip install 'softarm[plot]'"
        ) from error
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the 3d projection)

    return matplotlib, Figure


def _fmt(vector, unit: str) -> str:
    v = np.asarray(vector, dtype=float)
    return "(" + ", ".join(f"{c:.4g}" for c in v) + f") {unit}"


def describe_loads(loads, sweep=None) -> str:
    """One line describing the loads, e.g. ``"tip force (0, 0, -1) N + gravity"``.

    A swept field is described by its range (``sweep`` as a :class:`softarm.case.Sweep`).
    """
    from .loads import as_loads

    parts = []
    for i, load in enumerate(as_loads(loads)):
        swept = None
        if sweep is not None and sweep.load == i:
            swept = (sweep.field, f"{sweep.component} {_range(sweep)}")
        parts.append(load.describe(swept))
    return " + ".join(parts) if parts else "no load"


def _range(sweep) -> str:
    values = sweep.values
    return f"{min(values):.4g} … {max(values):.4g} {sweep.unit} ({len(values)} steps)"


def _wrapped(text: str, width: int = 130, lines: int = 3) -> str:
    """A title on at most ``lines`` lines of ``width`` characters (the last one cut with …)."""
    import textwrap

    out = textwrap.wrap(text, width)
    if len(out) > lines:
        out = out[:lines]
        out[-1] = out[-1][:width - 1] + "…"
    return "\n".join(out)


def _layout(fig):
    grid = fig.add_gridspec(2, 2, width_ratios=(1.25, 1.0), left=0.02, right=0.97,
                            bottom=0.13, top=0.88, wspace=0.18, hspace=0.38)
    ax3 = fig.add_subplot(grid[:, 0], projection="3d")
    side = [fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1])]
    return ax3, side


def _equal_3d(ax, points: np.ndarray) -> None:
    """Cube limits around ``points`` (..., 3): equal scaling on x, y and z."""
    centre, half = cube_limits(points)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1.0, 1.0, 1.0))
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    ax.tick_params(labelsize=8)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.view_init(elev=22.0, azim=-60.0)


def _side_axes(side) -> None:
    for ax, ((a, _), (b, _)) in zip(side, _PLANES, strict=True):
        ax.set_xlabel(f"{a} (m)")
        ax.set_ylabel(f"{b} (m)")
        ax.set_title(f"side view {a}–{b}", fontsize=10)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.4, alpha=0.5)
        ax.plot([0.0], [0.0], marker="s", color="0.3", markersize=5, zorder=5)
        ax.margins(0.06)


def _finish(fig, path):
    if path is not None:

        path = Path(path)
        fmt = path.suffix.lstrip(".").lower() or "png"
        with write_atomic(path, "wb") as stream:
            fig.savefig(stream, format=fmt, dpi=DPI)
    return fig


def plot_equilibrium(result, *, fig=None, path: str | os.PathLike | None = None,
                     name: str | None = None, title: str | None = None, tube: bool = True):
    """Draw one equilibrium: 3D view (equal axes) and side views x–z and x–y.

    Parameters
    ----------
    result : Equilibrium
        With batch shape (); for a batch use :func:`plot_sweep`.
    fig : matplotlib.figure.Figure, optional
        Drawn into (cleared first); a new Figure of size :data:`FIGSIZE` otherwise.
    path : path-like, optional
        Save the picture there (format from the suffix, :data:`DPI` dots per inch), written
        atomically.
    name : str, optional
        Case name for the title.
    title : str, optional
        Replaces the whole title.
    tube : bool
        Draw the arm as a translucent tube of its real radius when its sections are known.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if result.batch_shape:
        raise ValueError(f"result has batch shape {result.batch_shape}: use plot_sweep for a "
                         "batch of equilibria")
    _, Figure = _matplotlib()
    fig = Figure(figsize=FIGSIZE) if fig is None else fig
    fig.clear()
    ax3, side = _layout(fig)
    poses = np.asarray(result.poses)
    p = poses[:, :3, 3]
    radii = station_radii(result.arm, result.s) if tube else None
    extent = p
    if radii is not None:
        surface = tube_surface(poses, radii)
        step = max(1, len(poses) // 120)
        rows = np.r_[0:len(poses):step, len(poses) - 1]
        # rstride = cstride = 1: every face is a quad. With coarser strides matplotlib pads
        # ragged faces with uninitialised memory, whose garbage makes its projection warn
        # ("overflow encountered in dot") at random.
        ax3.plot_surface(*surface[:, rows], rstride=1, cstride=1, color=_TUBE_COLOR, alpha=0.35,
                         linewidth=0, antialiased=True, shade=True)
        extent = np.concatenate([p, surface.reshape(3, -1).T])
    ax3.plot(*p.T, color=_LINE_COLOR if radii is None else "tab:red", linewidth=1.5)
    arrows = contact_arrows(result)
    scale = contact_scale([arrows], float(result.arm.length))
    if arrows is not None:
        extent = np.concatenate([extent, arrows.origins + scale * arrows.vectors])
    extent = _with_obstacles(extent, result.loads)
    routes = actuator_paths(result.loads, poses, result.s)
    for route in routes:
        ax3.plot(*route.points.T, **_PATH_STYLE[route.kind])
    ax3.scatter(*p[-1], color="k", s=12, depthshade=False)
    ax3.scatter([0.0], [0.0], [0.0], color="0.3", marker="s", s=20, depthshade=False)
    _equal_3d(ax3, extent)
    note = _draw_contact(ax3, side, result.loads, extent, arrows, scale)
    for ax, ((_, i), (_, j)) in zip(side, _PLANES, strict=True):
        if radii is not None:
            outline = silhouette(p[:, [i, j]], radii)
            ax.fill(outline[:, 0], outline[:, 1], color=_TUBE_COLOR, alpha=0.35, linewidth=0)
        ax.plot(p[:, i], p[:, j], color=_LINE_COLOR if radii is None else "tab:red",
                linewidth=1.2)
        for route in routes:
            ax.plot(route.points[:, i], route.points[:, j], **_PATH_STYLE[route.kind])
        ax.plot(p[-1, i], p[-1, j], "k.", markersize=6)
    _side_axes(side)
    tip = p[-1]
    fig.suptitle(title if title is not None else
                 _wrapped(f"{name or 'softarm'}: {describe_loads(result.loads)}"), fontsize=11)
    verdict = "" if result.stability is None else f"; {result.stability.describe()}"
    fig.text(0.02, 0.02, f"tip at {_fmt(tip, 'm')}; method {result.method}"
             f"{'' if result.exact else ' (approximate)'}{verdict}{note}", fontsize=8,
             color="0.1" if "UNSTABLE" in verdict else "0.3")
    return _finish(fig, path)


def _with_obstacles(extent: np.ndarray, loads) -> np.ndarray:
    """``extent`` (k, 3) and the points of the loads' spheres and capsules that lie within
    the cube of twice the half side about ``extent``'s (the drawing shows the obstacles
    near the arm, not a whole large one; planes are drawn to fit)."""
    centre, half = cube_limits(extent, margin=1.0)
    points = [extent]
    for contact in contacts(loads):
        for obstacle in contact.obstacles:
            if obstacle.kind == "plane":
                continue
            surface = obstacle_surface(obstacle, centre, half).reshape(3, -1).T
            points.append(np.clip(surface, centre - 2.0 * half, centre + 2.0 * half))
    return np.concatenate(points)


def _draw_contact(ax3, side, loads, extent, arrows=None, scale: float = 0.0) -> str:
    """The obstacles of the loads' Contact and its force arrows (:func:`contact_arrows`,
    m per N/m ``scale``) in the 3D view and the side views; returns a note on the arrows'
    scale for the caption ("" without). Every artist has a ``gid``: "obstacle K kind" (K
    from 1, in the Contact's order) or "contact forces"."""
    centre, half = cube_limits(extent)
    for contact in contacts(loads):
        for k, obstacle in enumerate(contact.obstacles):
            gid = f"obstacle {k + 1} {obstacle.kind}"
            surface = obstacle_surface(obstacle, centre, half / 1.1)
            artist = ax3.plot_surface(*surface, rstride=1, cstride=1, color=_OBSTACLE_COLOR,
                                      alpha=0.25 if obstacle.kind == "plane" else 0.3,
                                      linewidth=0, shade=obstacle.kind != "plane")
            artist.set_gid(gid)
            for ax, ((_, i), (_, j)) in zip(side, _PLANES, strict=True):
                _draw_outline(ax, obstacle, (i, j), centre, half / 1.1, gid)
    if arrows is None or not len(arrows.origins):
        return ""
    tips = arrows.vectors * scale
    artist = ax3.quiver(*arrows.origins.T, *tips.T, color=_CONTACT_COLOR, linewidth=1.0,
                        arrow_length_ratio=0.25)
    artist.set_gid("contact forces")
    for ax, ((_, i), (_, j)) in zip(side, _PLANES, strict=True):
        artist = ax.quiver(arrows.origins[:, i], arrows.origins[:, j], tips[:, i], tips[:, j],
                           color=_CONTACT_COLOR, angles="xy", scale_units="xy", scale=1.0,
                           width=0.004, zorder=4)
        artist.set_gid("contact forces")
        ax.update_datalim(arrows.origins[:, [i, j]] + tips[:, [i, j]])  # (quiver does not)
    largest = float(np.max(np.linalg.norm(arrows.vectors, axis=-1)))
    return (f"; {arrows.label} (magenta) {'' if arrows.unit == 'N' else 'up to '}"
            f"{largest:.3g} {arrows.unit}, drawn {largest * scale:.3g} m long")


def plot_sweep(result, values=None, *, label: str | None = None, fig=None,
               path: str | os.PathLike | None = None, name: str | None = None,
               title: str | None = None, sweep=None, cmap: str = "viridis"):
    """Overlay the shapes of a batch of equilibria coloured by a parameter, with a colour bar.

    Parameters
    ----------
    result : Equilibrium
        With batch shape (steps,).
    values : array_like, shape (steps,), optional
        The parameter per step (default: ``sweep.values``, else 0, 1, 2, …).
    label : str, optional
        Colour-bar label with unit (default: ``sweep.label``).
    sweep : softarm.case.Sweep, optional
        The case's sweep, for defaults and the title.
    fig, path, name, title
        As in :func:`plot_equilibrium`.
    cmap : str
        Matplotlib colormap name.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if len(result.batch_shape) != 1:
        raise ValueError(f"plot_sweep needs a result with one batch axis, got batch shape "
                         f"{result.batch_shape}")
    matplotlib, Figure = _matplotlib()
    steps = result.batch_shape[0]
    values, label = sweep_axis(steps, sweep, values, label)
    fig = Figure(figsize=FIGSIZE) if fig is None else fig
    fig.clear()
    ax3, side = _layout(fig)
    low, high = float(values.min()), float(values.max())
    norm = matplotlib.colors.Normalize(low, high if high > low else low + 1.0)
    colormap = matplotlib.colormaps[cmap]
    p = np.asarray(result.positions)
    for k in range(steps):
        color = colormap(norm(values[k]))
        ax3.plot(*p[k].T, color=color, linewidth=1.4)
        for ax, ((_, i), (_, j)) in zip(side, _PLANES, strict=True):
            ax.plot(p[k, :, i], p[k, :, j], color=color, linewidth=1.2)
    ax3.scatter([0.0], [0.0], [0.0], color="0.3", marker="s", s=20, depthshade=False)
    extent = _with_obstacles(p.reshape(-1, 3), result.loads)
    _equal_3d(ax3, extent)
    _draw_contact(ax3, side, result.loads, extent)  # the obstacles (the forces per step: view)
    _side_axes(side)
    mappable = matplotlib.cm.ScalarMappable(norm=norm, cmap=colormap)
    bar = fig.colorbar(mappable, ax=[ax3, *side], fraction=0.03, pad=0.02, aspect=30)
    bar.set_label(label)
    fig.suptitle(title if title is not None else
                 _wrapped(f"{name or 'softarm'}: {describe_loads(result.loads, sweep)}"),
                 fontsize=11)
    return _finish(fig, path)


def plot_result_file(source, path: str | os.PathLike | None = None, *, fig=None):
    """Re-plot a result file written by :func:`softarm.io.save_result` (CSV, JSON or NPZ).

    ``source`` is a path or a :class:`softarm.io.SavedResult`.
    """
    from .io import SavedResult, load_saved

    saved = source if isinstance(source, SavedResult) else load_saved(source)
    name = saved.case.name  # every saved result carries its case
    result = saved.result
    if result.batch_shape:
        if len(result.batch_shape) > 1:
            raise ValueError(f"{saved.path}: cannot plot a batch of shape {result.batch_shape}")
        return plot_sweep(result, saved.sweep_values, label=saved.sweep_label,
                          sweep=saved.case.sweep, fig=fig, path=path, name=name)
    return plot_equilibrium(result, fig=fig, path=path, name=name)


def _draw_outline(ax, obstacle, axes: tuple[int, int], centre, half: float, gid: str):
    """An obstacle in a side view of the spatial ``axes`` (i, j): a plane seen edge-on as
    its line, a ball or capsule as its filled outline (nothing where the view shows no edge:
    :func:`softarm.geometry.obstacle_outline`)."""
    outline = obstacle_outline(obstacle, axes, centre, half)
    if outline is None:
        return
    if obstacle.kind == "plane":
        line, = ax.plot(*outline.T, color=_OBSTACLE_COLOR, linewidth=2.5)
    else:
        line, = ax.fill(*outline.T, color=_OBSTACLE_COLOR, alpha=0.35, linewidth=0.8,
                        edgecolor="0.35")
    line.set_gid(gid)


def _draw_trajectory_contact(ax, axes: tuple[int, int], trajectory, positions) -> None:
    """The obstacles of a trajectory's contact law in its side view of the spatial ``axes``
    (:func:`softarm.geometry.obstacle_outline`) and the contact forces per length at its
    last time as arrows (0.15 L for the largest); ``positions`` (T, S, 3). Artists have the
    equilibrium picture's ``gid``s: "obstacle K kind", "contact forces"."""
    contact = getattr(trajectory, "contact", None)
    if contact is None:
        return
    i, j = axes
    centre, half = cube_limits(positions)
    for k, obstacle in enumerate(contact.obstacles):
        _draw_outline(ax, obstacle, (i, j), centre, half, f"obstacle {k + 1} {obstacle.kind}")
    forces = np.asarray(trajectory.contact_forces).reshape(-1, *positions.shape)
    last = forces[0, -1]
    on = np.linalg.norm(last, axis=-1) > 0.0
    if not on.any():
        return
    length = float(np.sum(np.linalg.norm(np.diff(positions[0], axis=0), axis=-1)))
    tips = last[on] * (0.15 * length / float(np.max(np.linalg.norm(last[on], axis=-1))))
    artist = ax.quiver(positions[-1, on, i], positions[-1, on, j], tips[:, i], tips[:, j],
                       color=_CONTACT_COLOR, angles="xy", scale_units="xy", scale=1.0,
                       width=0.004, zorder=4, label="contact forces at the end")
    artist.set_gid("contact forces")


def _motion_plane(points: np.ndarray) -> tuple[int, int]:
    """The two spatial axes (indices) along which ``points`` (..., 3) spread the most, in
    increasing order: the plane a side view of a motion shows best."""
    spread = np.ptp(points.reshape(-1, 3), axis=0)
    first, second = sorted(int(i) for i in np.argsort(spread)[-2:])
    return first, second


def plot_trajectory(trajectory, *, name: str = "", sweep=None, snapshots: int = 9, fig=None,
                    path: str | os.PathLike | None = None):
    """A picture of a motion (a :class:`softarm.Trajectory` or a trajectory file read back
    with :func:`softarm.io.read_trajectory`): snapshots of the arm at ``snapshots`` evenly
    spaced times coloured by time, with the tip's path, in the side view of the two spatial
    axes it moves along most; the tip's coordinates over time; and the change of each
    energy since t = 0 (kinetic, elastic, gravity, dissipated and their total, which the
    base's and actuators' work changes). With contact, the side view shows the obstacles
    and the contact forces at the last time, and the energies the penalty's stored energy
    (``Trajectory.contact_energy``), which the total drawn then holds.

    A batch (a sweep) shows the tip paths and final shapes of every case, coloured by case
    (``sweep``: the case's :class:`softarm.sweep.Sweep`, for the colour bar's label), the
    distance of each tip from its start and each case's total energy change.
    """
    matplotlib, Figure = _matplotlib()
    fig = Figure(figsize=FIGSIZE) if fig is None else fig
    grid = fig.add_gridspec(2, 2, width_ratios=(1.2, 1.0), left=0.08, right=0.97,
                            bottom=0.1, top=0.88, wspace=0.25, hspace=0.4)
    ax = fig.add_subplot(grid[:, 0])
    ax_tip, ax_energy = fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1])
    times = np.asarray(trajectory.times)
    positions = np.asarray(trajectory.positions)
    batch = positions.shape[:-3]
    positions = positions.reshape(-1, *positions.shape[-3:])  # (cases, T, S, 3)
    a, b = _motion_plane(positions)
    names = "xyz"
    cmap = matplotlib.colormaps["viridis"]
    energy = trajectory.energy
    change = {key: np.asarray(getattr(energy, key)).reshape(-1, times.size)
              for key in ("kinetic", "elastic", "gravity", "dissipated", "total")}
    change = {key: value - value[:, :1] for key, value in change.items()}
    if not batch:
        picks = np.unique(np.linspace(0, times.size - 1, max(2, snapshots)).round().astype(int))
        duration = times[-1] - times[0]
        for k in picks:
            colour = cmap((times[k] - times[0]) / duration if duration > 0 else 0.0)
            ax.plot(positions[0, k, :, a], positions[0, k, :, b], color=colour, linewidth=2.0)
        ax.plot(positions[0, :, -1, a], positions[0, :, -1, b], color="0.4", linewidth=0.8,
                linestyle="--", label="tip path")
        ax.plot(positions[0, :, 0, a], positions[0, :, 0, b], color="k", linewidth=2.5,
                marker="s", markersize=4, label="base")
        _draw_trajectory_contact(ax, (a, b), trajectory, positions[0])
        mappable = matplotlib.cm.ScalarMappable(
            norm=matplotlib.colors.Normalize(times[0], times[-1]), cmap=cmap)
        fig.colorbar(mappable, ax=ax, label=f"t (s) of the {picks.size} snapshots",
                     shrink=0.8)
        tip = positions[0, :, -1] - positions[0, :1, -1]
        for i, colour in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
            ax_tip.plot(times, tip[:, i], color=colour, label=names[i])
        ax_tip.set_ylabel("tip displacement (m)")
        styles = {"kinetic": "tab:orange", "elastic": "tab:blue", "gravity": "tab:green",
                  "dissipated": "tab:purple", "total": "k"}
        labels = dict(zip(styles, styles, strict=True))
        if getattr(trajectory, "contact", None) is not None:
            # the penalty's stored energy, which Energy.total leaves out: the total drawn
            # holds it, so that an impact's exchange shows as one conserved sum
            stored = np.asarray(trajectory.contact_energy).reshape(-1, times.size)[0]
            styles = {**styles, "contact": _CONTACT_COLOR}
            change["contact"] = (stored - stored[0])[None]
            change["total"] = change["total"] + change["contact"]
            labels.update(contact="contact (penalty)", total="total with contact")
            styles["total"] = styles.pop("total")  # (drawn last, on top)
        for key, colour in styles.items():
            ax_energy.plot(times, change[key][0], color=colour, label=labels[key],
                           linewidth=2.0 if key == "total" else 1.2, gid=f"energy {key}")
        ax.legend(fontsize=8, loc="best")
    else:
        cases = positions.shape[0]
        values = np.asarray(sweep.values, dtype=float) if sweep is not None else \
            np.arange(cases, dtype=float)
        span = (values.min(), values.max()) if values.max() > values.min() else (0.0, 1.0)
        for c in range(cases):
            colour = cmap((values[c] - span[0]) / (span[1] - span[0]))
            ax.plot(positions[c, :, -1, a], positions[c, :, -1, b], color=colour,
                    linewidth=0.8, linestyle="--")
            ax.plot(positions[c, -1, :, a], positions[c, -1, :, b], color=colour, linewidth=2.0)
            ax_tip.plot(times, np.linalg.norm(positions[c, :, -1] - positions[c, :1, -1],
                                              axis=-1), color=colour)
            ax_energy.plot(times, change["total"][c], color=colour)
        mappable = matplotlib.cm.ScalarMappable(
            norm=matplotlib.colors.Normalize(*span), cmap=cmap)
        fig.colorbar(mappable, ax=ax, label=sweep.label if sweep is not None else "case",
                     shrink=0.8)
        ax_tip.set_ylabel("tip distance from start (m)")
        ax.set_title("tip paths (dashed) and shapes at the end", fontsize=10)
    ax.set_xlabel(f"{names[a]} (m)")
    ax.set_ylabel(f"{names[b]} (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    if not batch:
        ax.set_title(f"snapshots, side view {names[a]}–{names[b]}", fontsize=10)
    for axis in (ax_tip, ax_energy):
        axis.grid(True, linewidth=0.4, alpha=0.5)
        axis.set_xlabel("t (s)")
    ax_energy.set_ylabel("energy change since t = 0 (J)")
    if not batch:
        ax_tip.legend(fontsize=7, loc="best")
        ax_energy.legend(fontsize=7, loc="best", ncol=3)
    fig.suptitle(_wrapped(f"{name or 'trajectory'}: {times.size - 1} steps to "
                          f"t = {times[-1]:.4g} s"), fontsize=11)
    return _finish(fig, path)
