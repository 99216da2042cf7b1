"""Displacement-controlled tendons: the tensions that give prescribed tendon length changes.

A :class:`~softarm.Tendon` given by ``displacement`` prescribes its length change d from the
unloaded arm (what a motor encoder sets); its tension τ is an unknown. The solver finds, per
load case, the tensions of those tendons with

    τ >= 0,   c(τ) = d - Δℓ(τ) >= 0,   τ c(τ) = 0

(Δℓ(τ) the length changes of the tension-controlled solve): a taut tendon has exactly its
prescribed length change; a tendon given more length than its path needs is *slack*, τ = 0.

Method: a bounded Newton method on the tensions, every iterate a tension-controlled solve
with its exact tendon length Jacobian H = ∂Δℓ/∂τ (``Equilibrium.tendon_length_jacobian``).
For a conservative system H is the Hessian of a concave function of τ (the complementary
energy: Δℓ is its gradient), symmetric and negative definite at a stable equilibrium, and the
conditions above are the optimality conditions of maximising it less τ·d over τ >= 0. Each
Newton step is that problem's quadratic model, min ½ δᵀ M δ - gᵀ δ over τ + δ >= 0 with
M = -H and g = Δℓ - d, a box-constrained least-squares problem |R δ - R⁻ᵀ g|² (M = RᵀR),
solved by :func:`softarm.statics._bounded.box_least_squares`. Where H is not symmetric (follower
loads) M is its symmetric part: the fixed points are the same exact solutions, the
convergence is then linear instead of quadratic.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import ConvergenceError
from ..loads import Tendon
from ._bounded import box_least_squares

__all__ = ["displaced_columns", "displacement_jacobians", "solve_displaced"]

#: Newton iterations per load case before a ConvergenceError.
MAX_ITERATIONS = 30


def _input_count(load) -> int:
    return sum(int(np.prod(np.shape(getattr(load, name))[len(load.batch_shape):]) or 1)
               for name in load.inputs)


def displaced_columns(loads):
    """Where the displacement-controlled tendons of ``loads`` are: (their indices in
    ``loads``, their rows among the tendons (``Equilibrium.tendon_lengths``), their columns
    among the actuation inputs (``Equilibrium.actuation_jacobian``))."""
    displaced = [i for i, load in enumerate(loads) if load.displacement_controlled]
    tendons = [i for i, load in enumerate(loads) if isinstance(load, Tendon)]
    rows = np.array([tendons.index(i) for i in displaced], dtype=np.int64)
    first = np.cumsum([0] + [_input_count(load) for load in loads])
    return displaced, rows, first[displaced].astype(np.int64)


def _flat(load, shape, count):
    """The load with every batchable field broadcast to ``shape`` and flattened to
    (count,): a batch of ``count`` cases (an unbatched load as it is)."""
    if not load.batch_shape:
        return load
    return load.replace(**{
        name: np.broadcast_to(getattr(load, name), (*shape, *object_shape)).reshape(
            count, *object_shape)
        for name, _, object_shape in load.arrays if getattr(load, name) is not None})


def _with_tensions(loads, displaced, tau):
    """``loads`` with displacement-controlled tendon k (at ``displaced[k]``) replaced by a
    tension-controlled one pulled with ``tau[..., k]``."""
    out = list(loads)
    for k, i in enumerate(displaced):
        out[i] = loads[i].with_tension(tau[..., k])
    return out


def _newton_step(H, g, tau):
    """The bounded Newton step δ (τ + δ >= 0) of one case: min ½ δᵀ M δ - gᵀ δ, M the
    symmetric part of -H (eigenvalues floored at 1e-12 of the largest: a tendon whose length
    no tension changes)."""
    M = -0.5 * (H + H.T)
    values, vectors = np.linalg.eigh(M)
    top = max(float(np.max(np.abs(values), initial=0.0)), 1e-300)
    values = np.maximum(values, 1e-12 * top)
    R = np.sqrt(values)[:, None] * vectors.T  # M = Rᵀ R
    b = (vectors.T @ g) / np.sqrt(values)  # R⁻ᵀ g
    return box_least_squares(R, b, -tau, np.full(tau.size, np.inf))


def _residual(change, target, tau):
    """Per case, the largest violation of the complementarity conditions, m: |Δℓ - d| of a
    taut tendon, and Δℓ - d > 0 of a slack one (a slack tendon too short)."""
    gap = change - target
    return np.max(np.where(tau > 0.0, np.abs(gap), np.maximum(gap, 0.0)), axis=-1)


def solve_displaced(solver, loads, *, jacobians: bool):
    """The equilibrium with displacement-controlled tendons among ``loads`` (see the module
    docstring): every case from the unloaded arm, as :meth:`Solver.solve_from_unloaded`.

    The result's ``tendon_tensions`` are the solved tensions, ``tendon_slack`` says which
    are 0; with ``jacobians``, the columns of a displacement-controlled tendon are per metre
    of its displacement (the tensions of the others re-solved: a taut displacement-
    controlled tendon keeps its length), those of the other inputs at fixed displacements.
    """
    loads, shape = solver.check_loads(loads)
    count = math.prod(shape)
    displaced, rows, cols = displaced_columns(loads)
    target = np.stack([np.broadcast_to(loads[i].displacement, shape).reshape(count)
                       for i in displaced], axis=-1)
    flat = [_flat(load, shape, count) for load in loads]
    tol_length = max(1e-3 * solver.tol, 1e-14) * solver.length
    tau = np.zeros((count, len(displaced)))
    active = np.arange(count)
    stability = solver.stability
    last = None
    iterations = 0
    residual = np.zeros(1)
    previous = np.full(count, np.nan)  # each case's residual at its last iterate
    final = False  # whether this iterate is predicted to be the last one
    try:
        while active.size:
            if iterations == MAX_ITERATIONS:
                worst = float(np.max(residual))
                where = f" for load case {np.unravel_index(int(active[0]), shape)}" \
                    if shape else ""
                raise ConvergenceError(
                    f"the tensions of the displacement-controlled tendons did not give their "
                    f"prescribed length changes{where}: largest length error {worst:.3e} m "
                    f"(tolerance {tol_length:.3e} m)", worst,
                    f"{MAX_ITERATIONS} bounded Newton steps on the tensions")
            iterations += 1
            # the stability verdict only where the result is likely to be returned
            solver.stability = stability and final
            case = [load.take(active) if load.batch_shape else load for load in flat]
            eq = solver.solve_from_unloaded(_with_tensions(case, displaced, tau[active]),
                                            jacobians=True)
            change = np.asarray(eq.tendon_length_changes).reshape(active.size, -1)[:, rows]
            H = np.asarray(eq.tendon_length_jacobian).reshape(
                active.size, -1, eq.tendon_length_jacobian.shape[-1])[:, rows][:, :, cols]
            residual = _residual(change, target[active], tau[active])
            done = residual <= tol_length
            last = eq if done.all() and active.size == count and \
                solver.stability == stability else None
            keep, predicted = [], []
            for k, b in enumerate(active):
                if done[k]:
                    continue
                step = _newton_step(H[k], change[k] - target[b], tau[b])
                tau[b] = np.maximum(tau[b] + step, 0.0)
                keep.append(b)
                # quadratic convergence, r' ≈ C r² with C ≈ r / r_prev²: done after this?
                predicted.append(residual[k] ** 3 <= 0.1 * tol_length * previous[b] ** 2)
                previous[b] = residual[k]
            active = np.array(keep, dtype=np.int64)
            final = bool(predicted) and all(predicted)
    finally:
        solver.stability = stability
    if last is None:
        # the converged tensions, solved once more as one batch (with the verdict if asked)
        last = solver.solve_from_unloaded(
            _with_tensions(loads, displaced, tau.reshape(*shape, len(displaced))),
            jacobians=jacobians)
    else:
        last = _reshaped(last, shape, jacobians)
    changes = {"loads": loads}
    if jacobians:
        changes.update(displacement_jacobians(last, rows, cols, shape))
    return dataclasses.replace(last, **changes)


#: The fields of a solve with jacobians=True that a solve without has as None.
_JACOBIANS = ("tip_compliance", "compliance", "actuation_jacobian",
              "station_actuation_jacobian", "tendon_length_jacobian")


def _reshaped(eq, shape, jacobians):
    """The equilibrium of the flattened batch (count,) of the iterations with the batch
    shape ``shape`` (and without its Jacobians unless ``jacobians``)."""
    fields = {}
    for field in dataclasses.fields(eq):
        value = getattr(eq, field.name)
        if field.name in _JACOBIANS and not jacobians:
            fields[field.name] = None
        elif field.name == "stability" and value is not None:
            fields[field.name] = type(value).of(value.index, value.conservative, shape)
        elif field.name in ("residual", "error_estimate"):
            value = np.asarray(value).reshape(shape)
            fields[field.name] = float(value) if not shape else value
        elif field.name != "s" and isinstance(value, np.ndarray):
            fields[field.name] = value.reshape(*shape, *value.shape[1:])
    return dataclasses.replace(eq, **fields)


def displacement_jacobians(eq, rows, cols, shape) -> dict:
    """The Jacobian fields of ``eq`` (solved with tension-controlled tendons, jacobians=True)
    in the inputs where the tendons at ``rows`` (tendon rows) and ``cols`` (input columns)
    have their displacement as input instead of their tension: with S the taut ones (G_SS
    their lengths per their tensions), dτ_S = G_SS⁻¹ (dd_S - G_SO dq_O) (O the other
    inputs), a slack one's dτ = 0."""
    G = np.asarray(eq.tendon_length_jacobian)
    n = G.shape[-1]
    count = math.prod(shape)
    tension = np.asarray(eq.tendon_tensions).reshape(count, -1)[:, rows]
    names = ("actuation_jacobian", "station_actuation_jacobian", "tendon_length_jacobian")
    flat = [np.asarray(getattr(eq, name)).reshape(count, -1, n) for name in names]
    out = [np.empty_like(array) for array in flat]
    G = G.reshape(count, -1, n)
    others = np.setdiff1d(np.arange(n), cols)
    for b in range(count):
        taut = tension[b] > 0.0
        S, Z = cols[taut], cols[~taut]
        # the map from the new inputs to the old: q_O = q'_O, τ_S = Φ (q'_O; d_S)
        Phi = np.zeros((S.size, n))
        if S.size:
            inverse = np.linalg.inv(G[b][np.ix_(rows[taut], S)])
            Phi[:, S] = inverse
            Phi[:, others] = -inverse @ G[b][np.ix_(rows[taut], others)]
        for array, result in zip(flat, out, strict=True):
            Y = array[b]
            result[b] = 0.0
            result[b][:, others] = Y[:, others]
            result[b] += Y[:, S] @ Phi
            result[b][:, Z] = 0.0
    fields = {}
    for name, result in zip(names, out, strict=True):
        result = result.reshape(np.shape(getattr(eq, name)))
        result.setflags(write=False)
        fields[name] = result
    return fields
