"""``softarm.solve``: one entry point that picks an exact closed form or the numerical solver.

The two routes, :mod:`softarm.analytic` and :mod:`softarm.statics`, never import each other;
this module is the only place that knows both.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from ._validate import format_value
from .analytic.exact import closed_form
from .equilibrium import Equilibrium
from .errors import ConvergenceError, StabilityWarning
from .statics import Solver
from .statics.continuation import STEPS, Path, follow
from .statics.continuation import _switch as switch_at
from .statics.solver import _IDENTITY
from .statics.stability import closed_form_verdict

__all__ = ["METHODS", "solve", "solve_prepared", "solve_stable"]

#: Accepted values of ``method``.
METHODS = ("auto", "numeric", "analytic")


def _in_base_frame(loads, R: np.ndarray) -> tuple:
    """The loads with dead (spatial) components in the base frame (follower ones unchanged)."""
    return tuple(load.in_base_frame(R) for load in loads)


def _closed_form(arm, loads, shape, s, H0) -> Equilibrium | None:
    """An exact closed form for these checked loads (batch shape ``shape``) on the arm
    clamped at H0, at the checked stations s, or None."""
    identity = H0 is _IDENTITY or bool((H0 == _IDENTITY).all())  # (is: the default, cheaply)
    result = closed_form(arm, loads if identity else _in_base_frame(loads, H0[:3, :3]), s,
                         shape)
    if result is None or identity:
        return result
    # the same arm clamped at H0: rigidly move the solution; material strains are unchanged
    poses = H0 @ result.poses
    poses.setflags(write=False)  # fresh: Equilibrium takes it without a copy
    return dataclasses.replace(result, poses=poses, loads=loads)


def solve(arm, loads, *, method="auto", s=None, tol=1e-8, base=None, jacobians=False,
          branch=None, imperfection=None, **options) -> Equilibrium:
    """Static equilibrium of a clamped arm under any combination of loads.

    The answer is defined: the equilibrium connected to the unloaded arm along the
    proportional loading path λ·loads, λ from 0 to 1, followed continuously. Every case of a
    batch is solved on its own path, so it does not depend on the batch order, on its
    neighbours or on ``tol`` (beyond tol itself). If the path meets a fold before λ = 1 (the
    arm would snap), a ConvergenceError names the load factor of the fold.

    Parameters
    ----------
    arm : Arm or SegmentedArm
    loads : load or sequence of loads
        :class:`~softarm.TipLoad`, :class:`~softarm.Gravity`,
        :class:`~softarm.DistributedForce`, :class:`~softarm.PointLoad`; their force arrays
        may carry leading batch axes B, which every output array then carries too.
    method : {"auto", "numeric", "analytic"}
        "auto" uses an exact closed form (:func:`softarm.analytic.exact_closed_form`) where one
        applies and the numerical solver otherwise; "numeric" forces the solver (shooting on
        the base wrench, :mod:`softarm.statics`); "analytic" requires an exact closed form.
    s : None, int or array_like
        Output stations in m: default 101 uniform on [0, L]; an int gives that many; or an
        increasing array in [0, L].
    tol : float
        Tolerance of the numerical solver on the tip position, relative to L (the step count
        is raised until the step-doubling error estimate is ≤ tol·L).
    base : array_like, shape (4, 4), optional
        Pose of the clamped base in the spatial frame (default identity). A nearly rigid pose
        (RᵀR = I to 1e-5, e.g. printed to a few digits or stored in float32) is
        re-orthonormalised to the nearest rotation, the same on every route; a pose further
        from a rigid transform is rejected.
    jacobians : bool
        If True, also return the exact tip compliance ``tip_compliance`` (B..., 6, 6) and the
        station compliances ``compliance`` (B..., N, 6, 6): (δp; δθ), spatial, per unit extra
        dead tip wrench (δF; δM), spatial (δR = δθ~ R), from the variational equations and
        the implicit function theorem. Forces the numerical route.
    branch : None or "stable"
        None: the equilibrium connected to the unloaded arm, with a
        :class:`~softarm.StabilityWarning` if it is unstable. "stable": a stable
        equilibrium instead (single load case, numerical route): the loading path's first
        critical point is located, the branch switched along the null vector of ∂r/∂x
        there and followed to the full load (docs/stability.md).
    imperfection : array_like (3,), optional
        With ``branch="stable"``: a spatial direction for the tip's displacement that picks
        one of two mirror branches (default: the mode's own sign).
    **options
        Passed to :class:`softarm.statics.Solver` (``max_iterations``, ``max_load_step``,
        ``steps``, ``max_steps``, ``max_shootings``, ``stability``, ``threads``: a batch's
        cases are solved in threads, by default over every core, at most
        ``$SOFTARM_NUM_THREADS``, the same answer to the bit); checked on every route.

    Returns
    -------
    Equilibrium
        ``method`` says which route was taken (e.g. ``"numeric.shooting"``).

    Raises
    ------
    TypeError
        A string, bool, None or complex number where a number is expected (numpy scalars of
        any width are accepted).
    ValueError
        Bad method, stations, base, tolerance, or loads that do not fit the arm; a batch of
        load cases and stations whose result would not fit in memory (checked before
        allocating anything).
    ConvergenceError
        The numerical solver failed (never a silently wrong answer).

    Examples
    --------
    >>> import softarm
    >>> arm = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0,
    ...                                  EIz=1.0)
    >>> eq = softarm.solve(arm, softarm.TipLoad(force=[0.0, 0.0, 5.0]), method="numeric")
    >>> eq.method, round(float(eq.tip_position[2]), 6)  # Mattiasson (1981): w/L = 0.71379
    ('numeric.shooting', 0.713792)
    """
    _check_method(method)
    solver = Solver(arm, s=s, tol=tol, base=base, **options)
    if not isinstance(jacobians, (bool, np.bool_)):
        raise TypeError(f"jacobians must be True or False, got {format_value(jacobians)}")
    if branch not in (None, "stable"):
        raise ValueError(f"branch must be None or 'stable', got {format_value(branch)}")
    if imperfection is not None and branch != "stable":
        raise ValueError("imperfection chooses a buckled branch: it needs branch='stable'")
    if branch == "stable":
        if jacobians or method == "analytic" or not solver.stability:
            raise ValueError("branch='stable' needs the numerical route with its stability "
                             "verdict (method 'auto' or 'numeric', no jacobians, "
                             "stability=True)")
        return warn_unstable(solve_stable(solver, loads, imperfection))
    if jacobians:
        if method == "analytic":
            raise ValueError("jacobians=True needs the numerical route; use method='auto' or "
                             "'numeric'")
        return warn_unstable(solver.solve_from_unloaded(loads, jacobians=True))
    return solve_prepared(solver, loads, method)


def solve_stable(solver: Solver, loads, imperfection=None, *, max_switches=4):
    """A stable equilibrium under ``loads`` (a single case): the one connected to the
    unloaded arm if it is stable, else the branch reached by switching, at the first
    critical point of the loading path, along the null vector of ∂r/∂x, followed to the
    full load (repeated at later critical points of that branch)."""
    _, shape = solver.check_loads(loads)
    if shape != ():
        raise ValueError("branch='stable' takes a single load case (batch shape ()), got "
                         f"batch shape {shape}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StabilityWarning)
        eq = solver.solve_from_unloaded(loads)
    verdict = eq.stability
    if verdict is None or verdict.index == 0 or not verdict.conservative:
        return eq
    path = Path(Solver(solver.arm, base=solver.base, s=solver.s, stability=False), (),
                loads, STEPS)
    z0 = path.correct(path.z(np.zeros(6), 0.0))
    points, indices, critical = follow(path, z0, 1.0)
    for _ in range(max_switches):
        if indices[-1] == 0:
            break
        bifurcations = [c for c in critical if c.kind == "bifurcation"]
        if not bifurcations:
            break
        new = switch_at(path, bifurcations[0], imperfection, 1.0)
        indices, critical = new.index, new.critical
        points = np.column_stack([np.asarray(new.x) / path.xscale, new.lam])
    if indices[-1] != 0 or abs(points[-1, 6] - 1.0) > 1e-12:
        # (the residual of the branch's last point, in N and N m: an equilibrium, unstable)
        residual = float(np.max(np.abs(path.residual(points[-1])[0] * path.xscale)))
        raise ConvergenceError(
            f"no stable equilibrium was reached under the full load (the branch followed has "
            f"Morse index {int(indices[-1])} at λ = {points[-1, 6]:.6g})", residual)
    return solver.solve_near(loads, path.x(points[-1]), path.n)


def warn_unstable(eq: Equilibrium, stacklevel: int = 3) -> Equilibrium:
    """``eq``, after a :class:`~softarm.StabilityWarning` if any of its cases is unstable."""
    if eq.stability is not None:
        warn_verdict(eq.stability, stacklevel + 1)
    return eq


def warn_verdict(verdict, stacklevel: int = 3) -> None:
    """A :class:`~softarm.StabilityWarning` if any case of the verdict is unstable."""
    unstable = verdict.unstable
    if unstable is False or not np.any(unstable):
        return
    unstable = np.asarray(unstable)
    index = np.asarray(verdict.index)
    first = tuple(int(i) for i in np.unravel_index(
        int(np.flatnonzero(unstable.ravel())[0]), index.shape)) if index.shape else ()
    where = f" (load case {first}, and {int(unstable.sum()) - 1} more)" if index.shape else ""
    warnings.warn(
        f"softarm: the equilibrium returned is unstable{where}: Morse index "
        f"{int(index[first])}, {int(index[first])} independent direction(s) in which a real "
        "arm would move away from it. Use solve(..., branch='stable') for a stable "
        "equilibrium under the same loads, or softarm.critical_load to find where stability "
        "is lost.", StabilityWarning, stacklevel=stacklevel)


#: The solver options that are numbers: real (float) or integer ones.


def _check_method(method) -> None:
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {format_value(method)}")


def solve_prepared(solver: Solver, loads, method="auto") -> Equilibrium:
    """:func:`solve` with a prepared :class:`softarm.statics.Solver` (arm, stations, tol, base).

    The same routes and the same answers as :func:`solve` (every case from the unloaded arm);
    the numerical one reuses ``solver``'s preparation of the arm.
    """
    _check_method(method)
    checked = method != "numeric"  # else the solver validates the loads itself
    if checked:
        loads, shape = solver.check_loads(loads)
        result = _closed_form(solver.arm, loads, shape, solver.s, solver.base)
        if result is not None:
            if solver.stability:
                result = result._with_stability(closed_form_verdict(
                    solver, loads, result,
                    lambda s: _closed_form(solver.arm, loads, shape, s, solver.base)))
            return warn_unstable(result, 4)
        if method == "analytic":
            raise ValueError(
                "method='analytic' but no exact closed form applies to this arm and these "
                "loads; use method='auto' or 'numeric'"
            )
    # (Solver.solve_from_unloaded, without checking the loads a second time)
    return warn_unstable(solver._solve(loads, chained=False, jacobians=False, checked=checked),
                         4)
