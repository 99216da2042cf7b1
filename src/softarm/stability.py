"""Critical loads, continuation and the stable branch (issue 15; docs/stability.md).

Every numerical equilibrium carries its verdict (``Equilibrium.stability``, the Morse index by
the backward sweep); this module follows equilibria as a load grows:

- :func:`critical_load`: the smallest load factor at which the equilibrium followed from
  λ = 0 loses stability, its mode, kind and nullity;
- :func:`continuation`: a :class:`Branch` of equilibria in (x, λ), with the index at each
  point and the critical points met; :meth:`Branch.switch` follows a bifurcating branch;
- :func:`solve_stable` (:mod:`softarm.dispatch`, re-exported here): what
  ``softarm.solve(..., branch="stable")`` returns.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ._validate import real
from .dispatch import solve_stable
from .errors import ConvergenceError
from .loads import as_loads
from .statics import Solver
from .statics.continuation import (
    STEPS,
    Branch,
    CriticalPoint,
    Mode,
    Path,
    branch,
    follow,
    follow_to,
)

__all__ = ["Branch", "CriticalPoint", "Mode", "continuation", "critical_load", "plot_branch",
           "solve_stable"]


def _split(loads, vary):
    loads = as_loads(loads)
    if vary is None:
        return (), loads
    chosen = as_loads(vary)
    for load in chosen:
        if not any(load is other for other in loads):
            raise ValueError(f"vary must be loads given in loads (the same objects), got "
                             f"{load!r}")
    return tuple(x for x in loads if not any(x is c for c in chosen)), chosen


def _refuse_nonconservative(path: Path, what: str) -> None:
    if not path.conservative:
        raise ValueError(
            f"{what}: these loads include a follower load or a dead couple, which are not "
            "conservative; the static (adjacent-equilibrium) test proves nothing about their "
            "stability (Beck's column under a follower force loses it by flutter, a dynamic "
            "instability at 20.05 EI/L², with no static critical load)")


def critical_load(arm, loads, vary=None, *, max_factor=10.0, steps=STEPS, tol=1e-9,
                  base=None) -> CriticalPoint | None:
    """The smallest load factor λ_c > 0 at which the equilibrium, followed from λ = 0 with the
    loads in ``vary`` (default: all) scaled by λ and the others at their full value, loses
    stability; None if it stays stable up to ``max_factor``.

    Parameters
    ----------
    arm : Arm or SegmentedArm
    loads : load or sequence of loads (a single case)
    vary : load or sequence of loads, optional
        The loads scaled by λ (the same objects as in ``loads``); the others are held.
    max_factor : float
        The largest load factor searched.
    steps : int
        RK4 steps over the arm of the first grid; the grid is doubled until two grids agree
        on λ_c within ``tol`` (relative).
    tol : float
        Relative accuracy of λ_c.
    base : array_like (4, 4), optional
        The base pose.

    Returns
    -------
    CriticalPoint or None
        ``factor`` (λ_c), ``kind`` ("fold" or "bifurcation"), ``nullity`` (2 for a round
        section's symmetric buckling) and ``mode`` (the null vector of ∂r/∂x,
        ``mode.base_reaction``, and the buckled shape direction, ``mode.displacement``).

    Raises
    ------
    ValueError
        Follower loads or dead couples (nonconservative: no static critical load is claimed).
    InadmissibleStateError
        The equilibrium at the critical point, or at ``max_factor`` if none is met, is
        outside the model (an axial stretch v₁ <= 0: the arm would be inside out).
    """
    max_factor = real(max_factor, "max_factor")
    if not max_factor > 0:
        raise ValueError(f"max_factor must be > 0, got {max_factor!r}")
    tol = real(tol, "tol")
    if not 1e-13 <= tol <= 1e-2:
        raise ValueError(f"tol must be a relative accuracy in [1e-13, 1e-2], got {tol!r}")
    fixed, varied = _split(loads, vary)
    if any(load.kind == "contact" for load in fixed + varied):
        return _critical_in_contact(arm, fixed, varied, max_factor, tol, base)
    solver = Solver(arm, base=base, stability=False)
    previous = None
    n = int(steps)
    while True:
        path = Path(solver, fixed, varied, n)
        _refuse_nonconservative(path, "critical_load")
        z0 = path.correct(path.z(np.zeros(6), 0.0)) if not fixed else _start(path)
        start_index = path.index(z0)[0]
        if start_index != 0:
            raise ValueError(f"the equilibrium at λ = 0 (the held loads alone) is already "
                             f"unstable (Morse index {start_index})")
        points, _, critical = follow(path, z0, max_factor, stop_at_critical=True)
        point = critical[0] if critical else None
        # (the last point followed, or the critical one, inside the model: Path.record
        # refuses an axial stretch v₁ <= 0, an arm that would be inside out before it
        # buckles, or before max_factor)
        path.record(points[-1:] if point is None else path.z(point.x, point.factor)[None])
        if point is None:
            return previous
        if previous is not None and abs(point.factor - previous.factor) <= \
                tol * abs(point.factor):
            return point
        previous = point
        n *= 2
        if n > 1 << 15:
            warnings.warn(f"critical_load: λ_c = {point.factor:.12g} did not settle to "
                          f"tol = {tol:g} up to {n // 2} RK4 steps", RuntimeWarning,
                          stacklevel=2)
            return point


def _critical_in_contact(arm, fixed, varied, max_factor, tol, base) -> CriticalPoint | None:
    """:func:`critical_load` with a Contact among the loads: the Morse index of the
    multiple-shooting solve (the route that resolves a contact, docs/contact.md) at
    ``max_factor``: None if the equilibrium there is stable; else bisected on [0,
    max_factor] to ``tol``, each point solved from the unloaded arm (a continuation in λ on
    a fixed grid does not resolve a contact's band). Each point is a whole solve (1-3 s on
    the table of docs/contact.md), so the index is taken to stay lost once lost (what it
    does along a path from the unloaded arm, where stability is lost at bifurcations
    crossed, not regained): a window of instability that closes again below
    ``max_factor`` is not looked for (sixteen samples before bisection missed those
    narrower than max_factor/16, and took 28 s of CPU to return None on the table). The
    point's ``mode`` is None and ``x`` the base reaction at the last stable factor; ``kind``
    is "fold" where the solve fails beyond it (no equilibrium connected to the unloaded
    arm), else "bifurcation"."""
    solver = Solver(arm, base=base, stability=True)

    def index(lam):
        """(Morse index, base reaction) at λ, or (None, None) where no solve succeeds."""
        case = (*fixed, *(load.scaled(lam) for load in varied))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # (an unstable answer is what is looked for)
                eq = solver.solve_from_unloaded(case)
        except ConvergenceError:
            return None, None
        return int(eq.stability.index), np.asarray(eq.base_wrench)

    start, x = index(0.0)
    if start is None or start != 0:
        raise ValueError(f"the equilibrium at λ = 0 (the held loads alone) is "
                         f"{'not found' if start is None else 'already unstable'} "
                         f"(Morse index {start})")
    low, high = 0.0, max_factor
    after, _ = index(high)
    if after == 0:
        return None
    while high - low > tol * high:
        middle = 0.5 * (low + high)
        found, y = index(middle)
        if found == 0:
            low, x = middle, y
        else:
            high, after = middle, found
    fold = after is None
    return CriticalPoint(factor=0.5 * (low + high), kind="fold" if fold else "bifurcation",
                         nullity=1 if fold else after, mode=None, x=x, index_before=0,
                         index_after=-1 if fold else after)


def _start(path: Path):
    """The equilibrium under the held loads alone (λ = 0): the solver's, then corrected on
    the path's grid."""
    eq = path.solver.solve_from_unloaded(path.fixed)
    z = path.correct(path.z(np.asarray(eq.base_wrench), 0.0))
    if z is None:
        raise ConvergenceError("the equilibrium under the held loads could not be corrected "
                               "on the continuation grid", math.nan)
    return z


def continuation(arm, loads, lam=(0.0, 1.0), *, steps=STEPS, base=None, s=None,
                 max_points=2000, max_step=0.25) -> Branch:
    """Follow the equilibria of λ·loads from λ = lam[0] to lam[1] by pseudo-arclength
    continuation in (x, λ) (x the base reaction), through folds and bifurcations, with the
    Morse index at every point.

    The start at lam[0] is the equilibrium connected to the unloaded arm
    (:func:`softarm.solve`). Returns a :class:`Branch`: ``lam``, ``x``, ``index``,
    ``critical`` (folds and bifurcations, located to about 1e-12 in arclength) and
    ``equilibria`` (one batched Equilibrium); ``branch.switch(point)`` follows a bifurcating
    branch. A branch that stops before lam[1] (``max_points`` points followed, or a point
    beyond which it cannot be followed: under a tension of kL beyond about 20, or a grid too
    coarse) is returned with ``complete`` False and ``reason`` saying why, after a
    RuntimeWarning. ``max_step`` bounds the steps (nondimensional arclength in (x, λ): base reaction
    in units of the bending scale times the load size, and λ); ``steps``: RK4 steps over
    the arm.
    """
    lam0, lam1 = (real(v, "lam") for v in lam)
    solver = Solver(arm, base=base, s=s, stability=False)
    path = Path(solver, (), loads, steps)
    if lam0 == 0.0:
        z0 = path.correct(path.z(np.zeros(6), 0.0))
    else:
        eq = solver.solve_from_unloaded(tuple(x.scaled(lam0) for x in path.varied))
        z0 = path.correct(path.z(np.asarray(eq.base_wrench), lam0))
    if z0 is None:
        raise ConvergenceError(f"no equilibrium to start from at λ = {lam0}", math.nan)
    return branch(path, *follow_to(path, z0, lam1, max_points=max_points,
                                   locate=path.conservative, max_step=max_step))


def plot_branch(*branches, coordinate=2, ax=None, labels=None, path=None):
    """Draw branches as load factor λ against a tip coordinate: stable points joined by a
    solid line, unstable (or undecided) ones by a dashed line, critical points marked.

    Parameters
    ----------
    *branches : Branch
    coordinate : int
        The tip position component on the horizontal axis (0, 1, 2: x, y, z; default 2).
    ax : matplotlib Axes, optional
    labels : sequence of str, optional
    path : str or Path, optional
        Write the figure there.

    Returns
    -------
    matplotlib.axes.Axes
    """
    import matplotlib.pyplot as plt

    if coordinate not in (0, 1, 2):
        raise ValueError(f"coordinate must be 0, 1 or 2 (x, y, z), got {coordinate!r}")
    component = int(coordinate)
    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 4.2), layout="constrained")
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for b, item in enumerate(branches):
        colour = colours[b % len(colours)]
        tip = np.asarray(item.equilibria.tip_position)[:, component]
        stable = np.asarray(item.stable)
        index = np.asarray(item.index)
        label = labels[b] if labels is not None else f"branch {b + 1}"
        for k in range(len(tip) - 1):
            # a critical point (index -1) takes the style of the other end
            a = stable[k] if index[k] >= 0 else stable[k + 1]
            b = stable[k + 1] if index[k + 1] >= 0 else stable[k]
            style = "-" if a and b else "--"
            ax.plot(tip[k:k + 2], item.lam[k:k + 2], style, color=colour,
                    label=label if k == 0 else None)
        for point in item.critical:
            z = item.path.z(point.x, point.factor)
            eq = item.path.record(z[None])
            ax.plot(eq.tip_position[0, component], point.factor, "o", color=colour,
                    markerfacecolor="white")
            ax.annotate(f"{point.kind}, λ = {point.factor:.4g}",
                        (eq.tip_position[0, component], point.factor),
                        textcoords="offset points", xytext=(6, -10), fontsize=8)
    ax.set_xlabel(f"tip {'xyz'[component]} (m)")
    ax.set_ylabel("load factor λ")
    ax.grid(alpha=0.3)
    ax.legend(title="solid: stable, dashed: unstable", fontsize=8, title_fontsize=8)
    if path is not None:
        ax.figure.savefig(path, dpi=120)
    return ax
