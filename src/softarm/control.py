"""Inverse statics: the actuation inputs that put the tip where it should be.

:func:`inverse` finds tendon tensions, chamber pressures and field components that bring the
tip of an arm to a target position (or pose), under the other loads (gravity, a payload),
within bounds; :class:`InverseSolver` tracks a sequence of targets, each warm-started from the
last (the call a control loop makes).

The method (``docs/control.md``): bounded Levenberg–Marquardt on the task error with the
*exact* actuation Jacobian of the equilibrium (``softarm.solve(..., jacobians=True)``, the
implicit function theorem on the shooting problem), each step a small box-constrained
least-squares problem solved by an active-set method, the forward solves following the arm
quasi-statically from its last equilibrium. With more inputs than task dimensions the
minimum-effort solution is returned: the one with the least Σ (q_i / s_i)² (s_i the input
scales, default 1 in SI units) among those that reach the target, reached by a small
effort term in every step of a redundant task (its bias on the task error grows as the
square of the condition of J diag(s): keep the scaled Jacobian's condition well below 1e6).
A target missed from the first guess is tried from other starts (the answer without the
bounds given, projected onto them; Halton points in the bounds) before it is called
unreachable: then the closest point found, with ``reached=False``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from . import kernels
from ._validate import count, format_value, real
from .dispatch import warn_unstable, warn_verdict
from .equilibrium import Equilibrium, Stability
from .errors import ConvergenceError
from .loads import InputRules, as_actuators, as_loads
from .statics import Solver
from .statics._bounded import regularised_step
from .statics.displacement import displaced_columns, displacement_jacobians
from .statics.solver import Snapshot

__all__ = ["ForwardResult", "ForwardSolver", "InverseResult", "InverseSolver", "inverse"]

_EYE3 = np.eye(3)


class _Warm(NamedTuple):
    """The fast route's last answer, where the next target's warm step starts (with the
    actuation Jacobian A (6, n) and J_x⁻¹ [r | J_q] (6, 1 + n) of the last integration,
    left in the fast route's arrays, ``_FastArrays``)."""

    q: np.ndarray  # the inputs
    x: np.ndarray  # the base reaction (N, N m, spatial)
    tip: np.ndarray  # the tip state (12,): p, then R row-major
    miss: tuple | None  # what the linear warm step missed: (in q, in x, its task step)
    redundant: bool  # whether the task is redundant there


class _FastArrays(NamedTuple):
    """The arrays of the kernel's ``inverse_newton`` for n inputs and a task of size t,
    allocated once (a tracked target's Python is its cost, not its arithmetic)."""

    target: np.ndarray  # (3,)
    weights: np.ndarray  # (t,)
    settings: np.ndarray  # (4,)
    on: np.ndarray  # [1.0]
    off: np.ndarray  # [0.0]
    zeros: tuple  # a warm tip (12,), miss q (n,), miss x (6,), miss task step (t,)
    A: np.ndarray  # (6, n), read by the next warm step
    G: np.ndarray  # (6, 1 + n), likewise
    J: np.ndarray  # (t, n)
    linear: tuple  # x (6,), q (n,), its linear prediction (n,), G (6, 1 + n), e (t,)
    singular: np.ndarray  # (min(t, n),)
    info: np.ndarray  # (4,)

    @classmethod
    def of(cls, n, t, weights, A, G):
        """The arrays for a task of size t, sharing A and G with the other task size's (the
        warm step may follow an answer of either)."""
        return cls(np.empty(3), weights, np.empty(4), np.ones(1), np.zeros(1),
                   (np.zeros(12), np.zeros(n), np.zeros(6), np.zeros(t)),
                   A, G, np.empty((t, n)),
                   (np.empty(6), np.empty(n), np.empty(n), np.empty((6, 1 + n)),
                    np.empty(t)), np.empty(min(t, n)), np.zeros(4))


@dataclass(frozen=True)
class InverseResult:
    """The answer of :func:`inverse` (or, batched over targets, of
    :meth:`InverseSolver.track`).

    Attributes
    ----------
    inputs : ndarray, shape (B..., n)
        The actuation inputs, in the order of the actuators' input fields (each tendon's
        tension in N, or its displacement in m if it is displacement-controlled, each
        chamber's pressure in Pa, each field's B0 components in T).
    equilibrium : Equilibrium
        The equilibrium they produce (batched like ``inputs``).
    reached : bool or ndarray (B...)
        Whether the task error is within tolerance (position within tol·L, orientation
        within tol rad).
    error : float or ndarray (B...)
        The remaining task error: the distance to the target / L, or with an orientation the
        larger of that and the rotation angle to the target orientation in rad.
    iterations : int or ndarray (B...)
        Of the start that gave the answer: forward solves with Jacobians used after the
        first (the full route), or integrations with the input columns (the fast route from
        a prepared solver's last equilibrium; docs/control.md).
    at_bound : ndarray of bool, shape (B..., n)
        Which inputs sit at a bound (a slack tendon: tension 0).
    condition : float or ndarray (B...)
        The condition number of the weighted task Jacobian at the answer.
    starts : int or ndarray (B...)
        How many starting points were tried: 1 when the first guess reached the target;
        after a miss, up to ``InverseSolver``'s ``starts`` (an answer with ``reached=False``
        tried them all).
    """

    inputs: np.ndarray
    equilibrium: object
    reached: bool | np.ndarray
    error: float | np.ndarray
    iterations: int | np.ndarray
    at_bound: np.ndarray
    condition: float | np.ndarray
    starts: int | np.ndarray


class ForwardResult(NamedTuple):
    """One answer of :meth:`ForwardSolver.solve`: what a controller reads, as arrays of its
    own (not views of the solver's buffers). A named tuple: immutable, and built in half a
    microsecond (a frozen dataclass costs several, in a call of a quarter millisecond).

    Attributes
    ----------
    inputs : ndarray, shape (n,)
        The actuation inputs solved at (the actuators' input fields in order: each tendon's
        tension in N, each chamber's pressure in Pa, each field's B0 components in T).
    tip : ndarray, shape (4, 4)
        The tip pose (spatial).
    actuation_jacobian : ndarray, shape (6, n) or None
        The tip's (δp; δθ), spatial components, per unit change of each input (the
        implicit function theorem, as ``Equilibrium.actuation_jacobian``); None without
        ``jacobians``.
    tip_compliance : ndarray, shape (6, 6) or None
        The tip's (δp; δθ) per dead tip wrench (δn; δm), all spatial
        (``Equilibrium.tip_compliance``); None without ``jacobians``.
    tendon_lengths : ndarray, shape (T,)
        Each actuator tendon's length (m), in the order of the actuators.
    tendon_length_jacobian : ndarray, shape (T, n) or None
        ∂(tendon lengths)/∂(inputs) (m per input unit); None without ``jacobians``.
    base_wrench : ndarray, shape (6,)
        The total wrench at the clamp (N, N m, spatial).
    error_estimate : float
        The tip position error estimate (m), ≤ tol · L.
    stability : Stability or None
        The verdict (``Equilibrium.stability``); None if the solver was made with
        ``stability=False``.
    """

    inputs: np.ndarray
    tip: np.ndarray
    actuation_jacobian: np.ndarray | None
    tip_compliance: np.ndarray | None
    tendon_lengths: np.ndarray
    tendon_length_jacobian: np.ndarray | None
    base_wrench: np.ndarray
    error_estimate: float
    stability: Stability | None

    @property
    def tip_position(self) -> np.ndarray:
        """The tip position (m, spatial), shape (3,)."""
        return self.tip[:3, 3]


class ForwardSolver:
    """The forward model of an actuated arm for a control loop: the equilibrium, tip
    compliance and actuation Jacobian at given actuation inputs, solved quasi-statically
    from the last call's equilibrium, in a fraction of a millisecond.

    A prepared :meth:`Solver.solve <softarm.statics.Solver.solve>`: the same kernels and
    guarantees (tol, error estimate, stability verdict and its warning), with the loads
    prepared once and only the inputs changing between calls (``Solver.prepared``), and
    two more savings where only the inputs changed: the last answer's exact tangent
    -J_x⁻¹ J_q Δq predicts the new base reaction, so the loading path takes one correction
    instead of an integration at its start and a correction at its end, and the fine
    solution is predicted too, its output pass accepted within 1 % of tol of the converged
    answer (docs/control.md).

    Parameters
    ----------
    arm : Arm or SegmentedArm
    actuators : sequence of loads with actuation inputs (``Tendon``, ``Chamber``,
        ``MagneticField``), unbatched, tension-controlled; their current values are where
        the first call starts from (the arm is at rest before it).
    loads : sequence of loads, optional
        The other loads (gravity, a payload), held fixed.
    tol : float
        Tip position tolerance relative to L.
    s : stations (default: the tip only, ``[L]``; None for 101 uniform stations), read from
        :meth:`equilibrium`.
    jacobians : bool
        Return the actuation Jacobian, the tip compliance and the tendon length Jacobian
        (default True).
    stability : bool
        Compute each answer's stability verdict (default True), with a
        :class:`~softarm.StabilityWarning` for an unstable one.

    Examples
    --------
    >>> import softarm
    >>> from softarm.routing import Straight
    >>> arm = softarm.Arm.from_stiffness(0.2, EA=1e4, GAy=1e4, GAz=1e4, GJ=0.01, EIy=0.01,
    ...                                  EIz=0.01)
    >>> model = softarm.ForwardSolver(arm, [softarm.Tendon(0.0, Straight(0.0, 0.01))])
    >>> state = model.solve([0.5])
    >>> # a straight tendon bends the arm into a circular arc of curvature r τ / EI and
    >>> # shortens it by τ / EA (the closed form of docs/actuation.md)
    >>> kappa, stretch = 0.01 * 0.5 / 0.01, 1.0 - 0.5 / 1e4
    >>> bool(abs(state.tip_position[0] - stretch * np.sin(kappa * 0.2) / kappa) < 1e-6 * 0.2)
    True
    """

    def __init__(self, arm, actuators, loads=(), *, tol=1e-6, s="tip", jacobians=True,
                 stability=True):
        self.arm = arm
        self.actuators = as_actuators(actuators)
        if any(load.displacement_controlled for load in self.actuators):
            raise ValueError("ForwardSolver takes tension-controlled tendons (a "
                             "displacement-controlled Tendon's tension is an unknown of the "
                             "problem, solved by softarm.solve or Solver.solve)")
        self.loads = as_loads(loads)
        if isinstance(s, str) and s == "tip":
            s = [float(arm.length)]
        self.solver = Solver(arm, s=s, tol=tol, stability=stability)
        self._prepared = self.solver.prepared([*self.loads, *self.actuators],
                                              jacobians=jacobians)
        every = self._prepared.inputs
        first = sum(_input_count(load) for load in self.loads)
        self.n_inputs = every.size - first
        self._every = every.copy()  # the fixed loads' inputs, then the actuators' slots
        self._slots = slice(first, first + self.n_inputs)
        self._columns = slice(6 + first, 6 + first + self.n_inputs)  # of the Jacobians
        self._rules = InputRules(arm, self.actuators)
        # the least value of each input: 0 for a tension, else -inf excluded (finite)
        self._lowest = np.array([0.0 if name == "tension" else -np.finfo(float).max
                                 for load in self.actuators for name in load.inputs
                                 for _ in range(int(np.size(getattr(load, name))))])
        # the actuator tendons' columns among the Solver's actuators (one column per
        # tendon or chamber, in load order; the fixed loads' come first): of `lengths`
        # and, after 6, of the Jacobian's rows
        columns = [(i, load.kind) for i, load in enumerate([*self.loads, *self.actuators])
                   if load.kind in ("tendon", "chamber")]
        self._lengths = np.array([a for a, (i, kind) in enumerate(columns)
                                  if kind == "tendon" and i >= len(self.loads)],
                                 dtype=np.int64)
        self._length_rows = 6 + self._lengths
        self.jacobians = bool(jacobians)
        self._stability = bool(stability)

    @property
    def inputs(self) -> np.ndarray:
        """The actuators' inputs of the last call (at first their given values), (n,)."""
        return self._every[self._slots].copy()

    def solve(self, inputs) -> ForwardResult:
        """The equilibrium at ``inputs`` (shape (n,): the actuators' input fields in order),
        reached quasi-statically from the last call's. ValueError for inputs of another
        shape, non-finite ones or a negative tension; ConvergenceError if the solver fails
        (the next call then starts from the unloaded arm)."""
        q = np.asarray(inputs, dtype=np.float64)
        # (one comparison: NaN fails it; beyond the bounds of InputRules' screen, the exact
        # rules: a tension >= 0, finite, and the loads' size limit, as the statics')
        if q.shape != (self.n_inputs,) or not self._rules.admits(q):
            if q.shape != (self.n_inputs,) or not (
                    ((q >= self._lowest) & (q < np.inf)).all()):
                raise ValueError(
                    f"inputs must be {self.n_inputs} finite numbers (the actuators' inputs in "
                    f"order), tensions >= 0, got {inputs!r}")
            self._rules.check(q)
        every = self._every
        every[self._slots] = q
        prepared = self._prepared
        prepared.solve(every)
        stability = None
        if self._stability:
            index, conservative = prepared.index, prepared.conservative
            stability = Stability(index, conservative, index == 0 and conservative)
            if index > 0 and (conservative or index % 2):  # Stability.unstable
                warn_verdict(stability, 3)
        if self.jacobians:
            motion = prepared.motion[-1]
            actuation, compliance = motion[:, self._columns].copy(), motion[:, :6].copy()
            length_jacobian = prepared.jacobian[self._length_rows, self._columns]
        else:
            actuation = compliance = length_jacobian = None
        return ForwardResult(q.copy(), prepared.poses[-1].copy(), actuation, compliance,
                             prepared.lengths[self._lengths], length_jacobian,
                             prepared.base_wrench.copy(), float(prepared.info[1]), stability)

    def equilibrium(self) -> Equilibrium:
        """The full :class:`~softarm.Equilibrium` of the last call (every station of ``s``,
        strains, stresses, tendon fields, Jacobians)."""
        if not self._prepared.solved:
            raise ValueError("ForwardSolver.equilibrium: no solution yet (call solve first, "
                             "or the last call failed)")
        return self._prepared.equilibrium()

    def reset(self) -> None:
        """Return to the unloaded arm (the next call's path starts there)."""
        self._prepared.reset()


class InverseSolver:
    """A prepared inverse-statics problem: an arm, its actuators, the other loads, bounds.

    Parameters
    ----------
    arm : Arm or SegmentedArm
    actuators : sequence of loads with actuation inputs (``Tendon``, ``Chamber``,
        ``MagneticField``), unbatched; their current values are the first guess. A
        displacement-controlled ``Tendon`` (``Tendon(displacement=...)``) has its
        displacement (m) as input: the problem is solved in its tension (>= 0, its least
        effort Σ τ² like any tendon's) and the answer reports the tendon's length change
        there, the displacement that gives that equilibrium (for a slack tendon, at
        tension 0, the one that just makes it taut: any larger one gives the same
        equilibrium). Bounds on a displacement input are not supported.
    loads : sequence of loads, optional
        The other loads (gravity, a payload), held fixed.
    bounds : (lower, upper), optional
        Per input (arrays of shape (n,), ±inf allowed). Tensions are always >= 0;
        displacement inputs take no bound (±inf).
    scales : float or array_like, shape (n,), optional
        Input scales s_i (in [1e-100, 1e100]) of the effort Σ (q_i/s_i)² minimised when the
        task is redundant, and of the Levenberg–Marquardt damping (default: 1 in SI units
        for every input).
    tol : float
        Position tolerance relative to L (orientation: rad).
    max_iterations : int
        Forward solves with Jacobians per start.
    starts : int
        The most starting points tried for a target before it is called unreachable
        (default 6): the first guess; after a miss, the answer without the bounds given
        (tensions stay >= 0) projected onto them, then points of a Halton sequence in the
        bounds (docs/control.md, "Local minima"). 1: the first guess only.
    s, solver_tol : stations and the forward solver's tolerance (relative to L; default
        tol / 10).
    progress : callable, optional
        ``progress(start, iteration, error)`` after every forward solve of a target: the
        start (1 for the first guess, up to ``starts``), the Gauss–Newton iterations done
        from it, and the task error (relative to L) at the last accepted point. A slow
        target can be followed with it (in contact, a forward solve from the unloaded arm
        takes a second or more, one from the last solution a tenth; a target that pushes
        the arm into an obstacle raises the contact's penalty on the way, and with it the
        cost of every solve); ``softarm inverse`` shows it on stderr.

    After a target that is not reached, the next one starts from the last answer that
    reached its target (or the first guess), from the unloaded arm: the closest point to an
    unreachable target can be far from everything else.
    """

    def __init__(self, arm, actuators, loads=(), *, bounds=None, scales=None, tol=1e-6,
                 max_iterations=10, starts=6, s=None, solver_tol=None, progress=None):
        self.arm = arm
        if progress is not None and not callable(progress):
            raise TypeError(f"progress must be a callable (start, iteration, error) or None, "
                            f"got {type(progress).__name__}")
        self.progress = progress
        self._start = 1  # the start being tried (reported to progress)
        self.actuators = as_actuators(actuators)
        self.loads = as_loads(loads)
        self.tol = real(tol, "tol")
        if not self.tol > 0.0:
            raise ValueError(f"tol must be > 0, got {self.tol!r}")
        self.max_iterations = count(max_iterations, "max_iterations", 1)
        self.starts = count(starts, "starts", 1)
        self.length = float(arm.length)
        solver_tol = 0.1 * self.tol if solver_tol is None else solver_tol
        # displacement-controlled tendons are solved in their tensions (self._actuators)
        self._actuators, self._displaced = self._in_tensions(arm, s, solver_tol)
        self._shooter = None  # the fast route's prepared shooting (Solver.shooter)
        self._confirm = None  # and its prepared confirming solve (Solver.prepared)
        self._first = sum(_input_count(load) for load in self.loads)  # the actuators' slot
        # the task's weights, 1/L on positions and 1 on rotations (never written; writable:
        # a read-only array is another type to numba)
        self._weights = {t: np.array([1.0 / self.length] * 3 + [1.0] * (t - 3))
                         for t in (3, 6)}
        self._warm = None  # the fast route's last answer (_Warm)
        self._fast_arrays = {}  # per task size t: _FastArrays
        self._slots = []  # (actuator index, field, component, is tension)
        self._fields = []  # (actuator index, field, its shape, its slots): the inputs' home
        values = []
        for i, load in enumerate(self._actuators):
            for name in load.inputs:
                value = np.atleast_1d(np.asarray(getattr(load, name), dtype=float))
                self._fields.append((i, name, np.shape(getattr(load, name)),
                                     np.arange(len(self._slots), len(self._slots) + value.size)))
                for c in range(value.size):
                    self._slots.append((i, name, c, name == "tension"))
                    values.append(value[c])
        n = len(values)
        self.q = np.array(values, dtype=float)
        lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
        if bounds is not None:
            try:
                lo, hi = (np.broadcast_to(np.asarray(b, dtype=float), (n,)) for b in bounds)
            except (TypeError, ValueError):
                raise ValueError(f"bounds must be (lower, upper), each a number or {n} "
                                 f"numbers (one per input), got {bounds!r}") from None
            lower, upper = lo.copy(), hi.copy()
        tension = np.array([slot[3] for slot in self._slots], dtype=bool)
        by_length = np.array([slot[0] in self._displaced for slot in self._slots], dtype=bool)
        if np.any(np.isfinite(lower[by_length]) | np.isfinite(upper[by_length])):
            raise ValueError(
                f"bounds on a displacement input are not supported (the inverse problem is "
                f"solved in the tendon's tension, >= 0): give -inf, inf for inputs "
                f"{np.flatnonzero(by_length).tolist()}, got lower {lower.tolist()}, upper "
                f"{upper.tolist()}")
        self._by_length = by_length
        lower[tension] = np.maximum(lower[tension], 0.0)
        if np.any(lower > upper) or np.any(np.isnan(lower)) or np.any(np.isnan(upper)):
            raise ValueError(f"bounds must satisfy lower <= upper (tensions >= 0), got "
                             f"lower {lower.tolist()}, upper {upper.tolist()}")
        self.lower, self.upper = lower, upper
        # the bounds of the model alone (tensions >= 0): a start after a miss drops the others
        self._model_bounds = (np.where(tension, 0.0, -np.inf), np.full(n, np.inf))
        self.scales = np.ones(n) if scales is None else _scales(scales, n)
        self.q = np.clip(self.q, lower, upper)
        # (its trial steps catch failures themselves: no diagnosis of a failed path)
        self.solver = Solver(arm, s=s, tol=solver_tol, diagnose=False)
        # where a target after a miss starts (_solve): the last answer that reached its
        # target, at first the first target's first guess (None until then)
        self._sane = None
        self._missed = None  # self.q after a miss (its closest point), until the next target

    def _in_tensions(self, arm, s, solver_tol):
        """The actuators with each displacement-controlled tendon under tension control,
        pulled with the tension its displacement needs (the first guess; 0 N if that solve
        fails), and the indices of those tendons."""
        displaced = [i for i, load in enumerate(self.actuators) if load.displacement_controlled]
        if not displaced:
            return self.actuators, displaced
        try:
            eq = Solver(arm, s=2, tol=solver_tol, diagnose=False).solve_from_unloaded(
                [*self.loads, *self.actuators])
            tensions = eq.tendon_tensions
        except ConvergenceError:
            tensions = None
        tendons = [i for i, load in enumerate([*self.loads, *self.actuators])
                   if load.kind == "tendon"]
        out = list(self.actuators)
        for i in displaced:
            row = tendons.index(len(self.loads) + i)
            out[i] = out[i].with_tension(0.0 if tensions is None else float(tensions[row]))
        return tuple(out), displaced

    @property
    def n_inputs(self) -> int:
        return self.q.size

    def _actuators_at(self, q, actuators=None) -> list:
        """The actuators (default: in tensions) at the inputs q."""
        given = actuators is not None  # the slots of a displaced tendon are its tension's
        actuators = actuators if given else self._actuators
        fields: dict[tuple[int, str], np.ndarray] = {}
        for value, (i, name, c, _) in zip(q, self._slots, strict=True):
            name = "displacement" if given and i in self._displaced else name
            current = fields.setdefault((i, name), np.atleast_1d(np.array(
                getattr(actuators[i], name), dtype=float)))
            current[c] = value
        out = list(actuators)
        # the inner loop's own inputs (finite, clipped to the bounds: tensions >= 0) need no
        # validation; the public actuators_at validates
        trusted = not given and bool(np.isfinite(q).all()) and bool(
            np.all((q >= self.lower) & (q <= self.upper)))
        for (i, name), value in fields.items():
            shape = np.shape(getattr(actuators[i], name))
            value = value.reshape(shape)
            out[i] = (out[i]._with_checked(**{name: value}) if trusted
                      else out[i].replace(**{name: value}))
        return out

    def _stacked_actuators(self, inputs) -> list:
        """The actuators (as given) with one case per row of ``inputs`` (N, n): loads of
        batch shape (N,), the loads of :meth:`track`'s batched equilibrium."""
        out = list(self.actuators)
        for i, name, _, slots in self._fields:
            name = "displacement" if i in self._displaced else name
            shape = np.shape(getattr(self.actuators[i], name))
            out[i] = out[i].replace(**{name: inputs[:, slots].reshape(len(inputs), *shape)})
        return out

    def actuators_at(self, inputs) -> list:
        """The actuators (as given: tension- or displacement-controlled) with these inputs
        (``InverseResult.inputs``)."""
        return self._actuators_at(inputs, self.actuators)

    def _displacement_answer(self, q, eq):
        """The inputs and the equilibrium of the tensions q with the displacement-controlled
        tendons' inputs as displacements (their length changes at q; the Jacobians' columns
        per metre of displacement)."""
        if not self._displaced:
            return q.copy(), eq
        inputs = q.copy()
        # the given loads: the displacement-controlled tendons' rows and input columns
        _, rows, cols = displaced_columns([*self.loads, *self.actuators])
        inputs[self._by_length] = eq.tendon_length_changes[rows]
        actuators = self.actuators_at(inputs)
        changes = displacement_jacobians(eq, rows, cols, ())
        return inputs, dataclasses.replace(eq, loads=(*self.loads, *actuators), **changes)

    def _forward(self, q):
        """The equilibrium at inputs q (followed quasi-statically from the last one) and the
        actuation Jacobian of the tip, (6, n), columns in the order of the inputs."""
        eq = self.solver.solve([*self.loads, *self._actuators_at(q)], jacobians=True)
        first = sum(_input_count(load) for load in self.loads)  # fixed loads' inputs first
        return eq, eq.actuation_jacobian[:, first:first + self.n_inputs]

    def _task(self, eq, target, orientation):
        return self._pose_task(eq.tip, target, orientation)

    def _pose_task(self, tip, target, orientation):
        """The weighted task error e and its weights w at the tip pose ``tip`` (4 × 4): the
        kernel's ``task_error``, which the fast route computes in its iteration."""
        t = 3 if orientation is None else 6
        e = np.empty(t)
        kernels.task_error(np.concatenate([tip[:3, 3], tip[:3, :3].ravel()]),
                              np.array(target, dtype=np.float64),
                              _EYE3 if orientation is None else np.array(orientation,
                                                                         dtype=np.float64),
                              self.length, e)
        return e, self._weights[t]

    def _singular(self, J) -> np.ndarray:
        """The singular values of the weighted task Jacobian J (task × inputs) in scaled
        inputs (J diag(s)), largest first."""
        try:
            return np.linalg.svd(J * self.scales, compute_uv=False)
        except np.linalg.LinAlgError as error:  # not finite (overflow) or no convergence
            raise ConvergenceError(
                f"inverse statics: no singular values of the task Jacobian in scaled inputs "
                f"({error}; largest entry {np.max(np.abs(J)):.3g}, scales "
                f"{self.scales.tolist()})", np.nan, "the singular value decomposition "
                "of the Jacobian at the current inputs") from None

    def _redundant(self, J) -> bool:
        """More inputs than the rank of the weighted task Jacobian J in scaled inputs (the
        kernel's ``redundant_task``, the fast route's rule)."""
        return bool(kernels.redundant_task(self._singular(J), self.n_inputs))

    def _step(self, J, b, q, mu, redundant):
        """The bounded Gauss–Newton step δq for the weighted task Jacobian J and right-hand
        side b: in scaled inputs u = q/s, min |J δu - b|² + μ σ² |δu|² + ε σ² |u + δu|²
        (σ = |J s|_F) within the bounds; ε (1e-12) picks the least effort along the task's
        null space when the task is ``redundant``, and is 0 when it is not.

        (Not redundant, the effort term has nothing to pick, and it would bias the answer:
        along the weakest direction of J s, of singular value σ / c, it weighs ε c² against
        the task. The nitinol robot has c ≈ 8e3 with unit scales; scales 100 apart make
        c ≈ 1e6, ε c² ≈ 1, and every target was missed by 3e-5 L, ``tests/test_control.py``.
        A redundant task keeps the term, and that limit: c² well below 1/ε.)"""
        return regularised_step(J, b, q, self.scales, mu, self.lower, self.upper,
                                redundant=redundant)

    def _shooting_newton(self, q, target, orientation, snapshot=False):
        """The fast route: Newton on the base reaction x and the inputs q together, one
        integration per iteration (the shooting primitive with the input columns, prepared
        once by ``Solver.shooter``, on the grid of the last solution), from the Solver's last
        equilibrium, compiled whole (the kernel's ``inverse_newton``); then one solve at the
        answer (``Solver.prepared`` from the iteration's base reaction, as
        ``Solver.solve_near``: refined to tol, with its stability verdict) that must
        confirm the task error. None (the caller takes the full-solve route) when there is
        no last equilibrium, displacement-controlled tendons are among the actuators, or the
        iteration does not converge or the confirmation fails.

        Linearised, r + J_x δx + J_q δq = 0 gives δx = -J_x⁻¹ (r + J_q δq), and the task
        error e = w (target - p(L)) changes by -w (E_x δx + E_q δq): the step solves
        (w A) δq ≈ e + w E_x J_x⁻¹ r with A = E_q - E_x J_x⁻¹ J_q, the actuation Jacobian
        (exact when r = 0), under the same bounds and effort term as the full route.

        Tracking: when the last answer came from this route, the first step needs no
        integration. The last equilibrium has r = 0 and a known tip, and A and J_x⁻¹ J_q
        from the last integration before it (one small step away) give the step. Along a
        smooth path the answer moves as q(Δ) = q + A⁺ Δ + ½ q''[Δ, Δ] + O(|Δ|³) (likewise
        x); the linear step leaves out the middle term. For the last target's task step Δ₀
        it was measured (``miss``: the answer minus the linear prediction, in q and in x
        beyond what the change of q explains); for Δ = α Δ₀ + Δ⊥ the term is α² times that
        one plus terms in Δ⊥, so the prediction adds α² times the last miss (for α² <= 4).
        What it gets wrong (a turn of the path, a slack tendon) the next integration
        corrects, as it corrects the linear step. Tracking a circle of 1000 targets, this
        takes the task error at the first integration from 2.3e-6 to 4e-8 L: one
        integration a target instead of two.
        """
        last = self.solver.last_solution()
        if last is None or self._displaced:  # (displacement answers need the full route's
            return None                     # Jacobians, per metre of displacement)
        x, N = last
        first = self._first
        if self._shooter is None:  # prepared once; each iteration sets the inputs only
            try:
                loads = [*self.loads, *self._actuators_at(q)]
                self._shooter = self.solver.shooter(loads)
                # the confirming solve, prepared too (no Jacobians: the iteration has them)
                self._confirm = self.solver.prepared(loads, jacobians=False)
            except ValueError:
                return None
        shooter, confirm = self._shooter, self._confirm
        n, t = self.n_inputs, 3 if orientation is None else 6
        warm, self._warm = self._warm, None
        # (bytes: exact equality of a few numbers at a fifth of the cost; -0.0 against 0.0
        # only costs the warm step)
        if warm is not None and not (warm.q.tobytes() == q.tobytes()
                                     and warm.x.tobytes() == x.tobytes()):
            warm = None  # the Solver or the inputs moved since
        k = kernels
        steps, base, arm, units = shooter.kernel_arrays(("solution", N))
        every = shooter.inputs.copy()  # every input of the loads, the actuators' at slots
        x, q = x.copy(), q.copy()
        # the kernel's arrays, allocated once per task size (every one is written before it
        # is read; the warm step reads A and G as given, the buffers the last call wrote)
        work = self._fast_arrays.get(t)
        if work is None:  # (A and G shared with the other task size's arrays, if made)
            other = next(iter(self._fast_arrays.values()), None)
            A, G = (np.zeros((6, n)), np.zeros((6, 1 + n))) if other is None \
                else (other.A, other.G)
            work = self._fast_arrays[t] = _FastArrays.of(n, t, self._weights[t], A, G)
        # (copies: a read-only array is another type to numba, one more compiled version)
        np.copyto(work.target, target)
        goal = (work.target, _EYE3 if orientation is None else
                np.array(orientation, dtype=np.float64), work.weights)
        work.settings[:] = (self.tol, self.max_iterations, self.length,
                            -1.0 if warm is None else float(warm.redundant))
        miss = None if warm is None else warm.miss
        if miss is not None and miss[2].size != t:
            miss = None
        zeros = work.zeros
        warm_in = (work.on if warm is not None else work.off,
                   zeros[0] if warm is None else warm.tip, work.A, work.G,
                   work.off if miss is None else work.on,
                   zeros[1] if miss is None else miss[0],
                   zeros[2] if miss is None else miss[1],
                   zeros[3] if miss is None else miss[2])
        info = work.info
        try:
            k.inverse_newton(x, q, every, first, steps, base, *arm, units, goal,
                             (self.lower, self.upper, self.scales), work.settings, warm_in,
                             (work.A, work.G, work.J, work.linear, work.singular), info)
        except np.linalg.LinAlgError:  # (its SVD of a Jacobian that overflowed): the full
            return None               # route, whose forward solves check their own values
        if info[0] != k.NEWTON_DONE:
            return None  # diverging, or the cap: the full-solve route, damped, from q
        try:
            every[first:first + n] = q
            confirm.solve(every, near=(x, 2 * N))
        except ConvergenceError:
            self.solver.reset()
            return None
        tip_pose = confirm.poses[-1]
        if orientation is None:  # the kernel's task_error, for a position
            e = (target - tip_pose[:3, 3]) / self.length
            size = math.sqrt(float(e @ e))
        else:
            size = _size(self._pose_task(tip_pose, target, orientation)[0])
        if size > self.tol:
            return None
        self.q = q
        last = self.solver.last_solution()
        if last is not None:
            miss = None
            if info[3]:  # what the linear warm step missed (the kernel adds it next time)
                x0, q0, q_linear, G0, e0 = work.linear
                miss = (q - q_linear, last[0] - (x0 - G0[:, 1:] @ (q - q0)), e0.copy())
            tip = np.empty(12)
            tip[:3], tip[3:] = tip_pose[:3, 3], tip_pose[:3, :3].ravel()
            self._warm = _Warm(q.copy(), last[0], tip, miss, bool(info[2]))
        singular = work.singular
        condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else np.inf
        at_bound = (q <= self.lower) | (q >= self.upper)
        # (track builds one batched Equilibrium from its targets' snapshots at the end)
        eq = confirm.snapshot() if snapshot else confirm.equilibrium()
        return InverseResult(q.copy(), eq, True, size, int(info[1]), at_bound, condition, 1)

    def solve(self, target, orientation=None) -> InverseResult:
        """The inputs that bring the tip to ``target`` (m, spatial, shape (3,)) or, with
        ``orientation`` (3 × 3 rotation), to that pose, starting from the current inputs and
        the last equilibrium (quasi-static), or after a missed target from the last answer
        that reached its target, from the unloaded arm. A :class:`~softarm.StabilityWarning`
        if the equilibrium reached is unstable."""
        result = self._solve(target, orientation)
        warn_unstable(result.equilibrium, 3)
        return result

    def _solve(self, target, orientation, snapshot=False) -> InverseResult:
        """:meth:`solve` without the warning (:meth:`track` warns once for its path);
        ``snapshot``: a fast-route answer's ``equilibrium`` is its confirming solve's
        :class:`~softarm.statics.solver.Snapshot` (track's), not an Equilibrium."""
        target = np.asarray(target, dtype=float)
        if target.shape != (3,) or not np.all(np.isfinite(target)):
            raise ValueError(f"target must be a position (3 finite numbers, m), got {target!r}")
        if orientation is not None:
            orientation = np.asarray(orientation, dtype=float)
            if orientation.shape != (3, 3) or not np.allclose(
                    orientation @ orientation.T, np.eye(3), atol=1e-9):
                raise ValueError("orientation must be a 3 × 3 rotation matrix")
        if self._missed is not None and self.q is self._missed:
            # the last target was missed: its closest point can be anywhere (tensions of
            # 1e4 N pulling towards a target off the workspace), and a path followed from
            # there misses every later target too. Start from the last answer that reached
            # its target instead, from the unloaded arm
            self.q = self._sane.copy()
            self._from_unloaded()
        self._missed = None
        q = np.minimum(np.maximum(self.q, self.lower), self.upper)  # (np.clip: 3× the cost)
        if self._sane is None:
            self._sane = q.copy()  # the first guess, until a target is reached
        self._start = 1
        result = self._attempt(q, target, orientation, snapshot)
        if not result.reached and self.starts > 1:
            result = self._more_starts(q, target, orientation, snapshot, result)
        if result.reached:
            self._sane = self.q.copy()
        else:
            self._missed = self.q
        return result

    def _report(self, iterations: int, error: float) -> None:
        if self.progress is not None:
            self.progress(self._start, iterations, float(error))

    def _from_unloaded(self) -> None:
        """Forget the last equilibrium: the next solve starts from the unloaded arm."""
        self.solver.reset()
        self._warm = None

    def _more_starts(self, first_guess, target, orientation, snapshot, missed):
        """After a miss from ``first_guess``: the same target from other starting points,
        each from the unloaded arm (docs/control.md, "Local minima"), until one reaches it
        or ``starts`` were tried; the answer that reached it, else the closest one found. A
        start whose forward solve fails is counted and left.

        The starts, in order: if bounds narrower than the model's (tensions >= 0) were
        given, the answer without them from the first guess, taken if it lies within them,
        else projected onto them as the next start; then the Halton points
        (:func:`_halton`) in the box of the bounds, each infinite side of the box at the
        largest magnitude of that input among the first guess, the last answer that reached
        its target and the input's scale (not the answers of this target: a miss can run
        far out, e.g. to tensions of 1e4 N compressing the arm)."""
        best, best_q, tried = missed, self.q, 1
        lower, upper = self.lower, self.upper

        def attempt(start, bounds=(lower, upper)):
            """The answer from ``start`` within ``bounds``, or None if a forward solve
            failed."""
            nonlocal tried
            tried += 1
            self._start = tried
            self._from_unloaded()
            self.lower, self.upper = bounds
            try:
                return self._attempt(start, target, orientation, snapshot)
            except (ConvergenceError, ValueError):  # (ValueError: the solver's check of
                return None                         # the loads' magnitude)
            finally:
                self.lower, self.upper = lower, upper

        def better(result):
            nonlocal best, best_q
            if result is not None and (result.reached or result.error < best.error):
                best, best_q = result, self.q
            return best.reached

        model = self._model_bounds
        if np.any(lower > model[0]) or np.any(upper < model[1]):
            free = attempt(first_guess, model)
            if free is not None:
                q = self.q
                if np.all((q >= lower) & (q <= upper)):  # an answer of the bounded problem
                    better(dataclasses.replace(free, at_bound=(q <= lower) | (q >= upper)))
                elif tried < self.starts:
                    better(attempt(np.minimum(np.maximum(q, lower), upper)))
        if not best.reached and tried < self.starts:
            largest = np.maximum(np.max(np.abs([first_guess, self._sane]), axis=0),
                                 self.scales)
            low = np.where(np.isfinite(lower), lower, -largest)
            high = np.where(np.isfinite(upper), upper, largest)
            for point in _halton(self.starts - tried, self.n_inputs):
                if better(attempt(low + point * (high - low))):
                    break
        self.q = best_q
        return dataclasses.replace(best, starts=tried)

    def _attempt(self, q, target, orientation, snapshot) -> InverseResult:
        """The answer from the first guess q (within the bounds), from the Solver's last
        equilibrium (or one solve at q when it has none): the fast route, else the full
        route. Sets ``self.q`` to the answer's inputs (in tensions)."""
        if self.solver.last_solution() is None and not self._displaced:
            # cold: one solve at the current inputs (its memory only: tip station, no
            # verdict) puts the fast route in reach (a cold inverse of the nitinol robot:
            # 13 ms median by the full route's solves with Jacobians, 7 ms so); a
            # ConvergenceError there leaves the full route to try
            try:
                self.solver._settle([*self.loads, *self._actuators_at(q)])
            except ConvergenceError:
                self.solver.reset()
        fast = self._shooting_newton(q, target, orientation, snapshot)
        if fast is not None:
            self._report(fast.iterations, fast.error)
            return fast
        eq, A = self._forward(q)
        e, w = self._task(eq, target, orientation)
        size = _size(e)
        self._report(0, size)
        redundant = self._redundant(w[:, None] * A[:e.size])
        mu = 0.0  # Gauss–Newton with the exact Jacobian; damped only after a failed step
        iterations = 0
        while iterations < self.max_iterations and not (size <= self.tol and not redundant):
            iterations += 1
            # in scaled inputs u = q/s: min |J δu - e|² + μ σ² |δu|² + ε σ² |u + δu|²,
            # within the bounds; ε (1e-12) picks the least effort along the task's null
            # space and moves the task solution by ~1e-12 relative
            step = self._step(w[:, None] * A[:e.size], e, q, mu, redundant)
            trial = np.clip(q + step, self.lower, self.upper)
            try:
                eq_t, A_t = self._forward(trial)
            except ConvergenceError:
                eq_t = None
            if eq_t is not None:
                e_t, _ = self._task(eq_t, target, orientation)
                size_t = _size(e_t)
            if eq_t is not None and (size_t <= max(size, self.tol)):
                small = np.max(np.abs(step) / self.scales) <= 1e-7 * (
                    1.0 + np.max(np.abs(q) / self.scales))
                q, eq, A, e, size = trial, eq_t, A_t, e_t, size_t
                mu = 0.0 if mu <= 1e-6 else mu / 10.0
                if size <= self.tol and small:
                    break  # reached, and the least effort too
            else:
                mu = 1e-3 if mu == 0.0 else 10.0 * mu
                self.solver.reset()
                eq, A = self._forward(q)  # back to the accepted point (the solver moved)
            self._report(iterations, size)
        self.q = q
        singular = self._singular(w[:, None] * A[:e.size])
        condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else np.inf
        at_bound = (q <= self.lower) | (q >= self.upper)
        inputs, eq = self._displacement_answer(q, eq)
        return InverseResult(inputs, eq, bool(size <= self.tol), float(size), iterations,
                             at_bound, condition, 1)

    def track(self, targets, orientations=None) -> InverseResult:
        """Solve a sequence of targets, (N, 3) positions or (N, 4, 4) poses, each from the
        last answer (after a missed target, from the last answer that reached its target, as
        :meth:`solve`): batched fields (``inputs`` (N, n), ``reached`` (N,), ...) and the
        equilibria batched along N (their loads: the actuators with inputs of batch shape
        (N,)). One :class:`~softarm.StabilityWarning` if any equilibrium reached is
        unstable, naming the first."""
        targets = np.asarray(targets, dtype=float)
        if targets.ndim == 3 and targets.shape[1:] == (4, 4):
            orientations, targets = targets[:, :3, :3], targets[:, :3, 3]
        if targets.ndim != 2 or targets.shape[1] != 3:
            raise ValueError(f"targets must have shape (N, 3) or (N, 4, 4), got "
                             f"{targets.shape}")
        results = [self._solve(t, None if orientations is None else orientations[k], True)
                   for k, t in enumerate(targets)]
        inputs = np.array([r.inputs for r in results])
        answers = [r.equilibrium for r in results]
        if all(isinstance(a, Snapshot) for a in answers):  # every target by the fast route
            equilibrium = self._confirm.equilibrium(
                answers, (*self.loads, *self._stacked_actuators(inputs)))
        else:
            equilibrium = self._stacked([
                self._confirm.equilibrium(a) if isinstance(a, Snapshot) else a
                for a in answers], inputs)
        warn_unstable(equilibrium, 3)
        return InverseResult(
            inputs, equilibrium,
            np.array([r.reached for r in results]), np.array([r.error for r in results]),
            np.array([r.iterations for r in results]),
            np.array([r.at_bound for r in results]), np.array([r.condition for r in results]),
            np.array([r.starts for r in results]))

    def _stacked(self, equilibria, inputs) -> Equilibrium:
        """The equilibria of a tracked path, one per target, batched along it (the
        Jacobian fields only if every one has them: targets the full route answered)."""
        first = equilibria[0]

        def stack(name):
            values = [getattr(eq, name) for eq in equilibria]
            # (the Jacobian fields come only from targets the full-solve route answered)
            if any(v is None for v in values):
                return None
            stacked = np.stack(values)
            stacked.setflags(write=False)  # fresh: Equilibrium takes it without a copy
            return stacked

        fields = {f.name: stack(f.name) for f in dataclasses.fields(Equilibrium)
                  if f.name not in ("s", "arm", "loads", "method", "exact", "residual",
                                    "error_estimate", "stability")}
        verdicts = [eq.stability for eq in equilibria]
        stability = None if any(v is None for v in verdicts) else Stability.of(
            np.array([v.index for v in verdicts]), np.array([v.conservative for v in verdicts]),
            (len(equilibria),))
        return dataclasses.replace(
            first, **fields, loads=(*self.loads, *self._stacked_actuators(inputs)),
            stability=stability, residual=np.array([eq.residual for eq in equilibria]),
            error_estimate=np.array([eq.error_estimate for eq in equilibria]))


def _size(e) -> float:
    """The task error: |δp|/L, or with an orientation the larger of that and |δθ| (rad)."""
    return math.sqrt(max(float(e[:3] @ e[:3]), float(e[3:] @ e[3:]) if e.size > 3 else 0.0))


def _scales(scales, n) -> np.ndarray:
    """The input scales: a number in [1e-100, 1e100], or n of them, as an array (n,). (The
    iteration squares them, and their products with the Jacobian's entries: far outside
    that range the squares underflow or overflow.)"""
    try:
        values = np.asarray(scales, dtype=np.float64)
    except (TypeError, ValueError):
        values = None
    if values is None or values.shape not in ((), (n,)) or not (
            np.all(values >= 1e-100) and np.all(values <= 1e100)):
        raise ValueError(f"scales must be a positive number in [1e-100, 1e100] (each input's "
                         f"unit of effort, in its SI unit) or {n} of them (one per input), got "
                         f"{format_value(scales)}")
    return np.broadcast_to(values, (n,)).copy()


def _halton(count, dimension) -> np.ndarray:
    """The Halton points 1 .. count in [0, 1)^dimension, (count, dimension): coordinate j of
    point k is the radical inverse of k in the j-th prime base (the digits of k mirrored
    about the radix point), unscrambled: deterministic, and spread evenly from the first
    points on (point 0, the corner at the origin, left out)."""
    primes = []
    candidate = 2
    while len(primes) < dimension:
        if all(candidate % p for p in primes):
            primes.append(candidate)
        candidate += 1
    points = np.zeros((count, dimension))
    for j, base in enumerate(primes):
        for k in range(1, count + 1):
            rest, unit = k, 1.0 / base
            while rest:
                rest, digit = divmod(rest, base)
                points[k - 1, j] += digit * unit
                unit /= base
    return points


def _input_count(load) -> int:
    return sum(int(np.prod(np.shape(getattr(load, name))[len(load.batch_shape):]) or 1)
               for name in load.inputs)


def inverse(arm, actuators, target, *, loads=(), bounds=None, orientation=None, scales=None,
            x0=None, tol=1e-6, max_iterations=10, starts=6, progress=None) -> InverseResult:
    """The actuation inputs that bring the tip of ``arm`` to ``target`` (m, spatial), or to
    the pose (``target``, ``orientation``), under the other ``loads``.

    ``actuators`` are the actuation loads (e.g. three :class:`~softarm.Tendon`); their
    current values (or ``x0``, shape (n,)) are the first guess. Tensions stay >= 0; other
    inputs within ``bounds`` = (lower, upper) if given. After a miss from the first guess,
    other starts are tried, ``starts`` in all (``InverseResult.starts`` says how many were).
    See :class:`InverseSolver` and :class:`InverseResult`. An unreachable target returns the
    closest reachable point found with ``reached=False``; a ConvergenceError only if the
    forward solver fails from the first guess. ``progress``: as InverseSolver's.

    Examples
    --------
    >>> import softarm
    >>> from softarm.routing import Straight
    >>> arm = softarm.Arm.from_stiffness(0.2, EA=1e4, GAy=1e4, GAz=1e4, GJ=0.01, EIy=0.01,
    ...                                  EIz=0.01)
    >>> hidden = [softarm.Tendon(1.2, Straight(0.0, 0.01)),
    ...           softarm.Tendon(0.4, Straight(0.01, 0.0))]
    >>> target = softarm.solve(arm, hidden).tip_position     # reachable by construction
    >>> answer = inverse(arm, [t.replace(tension=0.0) for t in hidden], target)
    >>> bool(answer.reached), answer.inputs.round(6).tolist()
    (True, [1.2, 0.4])
    """
    solver = InverseSolver(arm, actuators, loads, bounds=bounds, scales=scales, tol=tol,
                           max_iterations=max_iterations, starts=starts, progress=progress)
    if x0 is not None:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape != (solver.n_inputs,) or not np.all(np.isfinite(x0)):
            raise ValueError(f"x0 must be {solver.n_inputs} finite numbers (one per input), "
                             f"got {x0!r}")
        if solver._displaced:  # a displacement first guess: its tensions, solved again
            solver = InverseSolver(arm, solver.actuators_at(x0), loads, bounds=bounds,
                                   scales=scales, tol=tol, max_iterations=max_iterations,
                                   starts=starts, progress=progress)
        else:
            solver.q = np.clip(x0, solver.lower, solver.upper)
    result = solver._solve(target, orientation)
    warn_unstable(result.equilibrium, 3)
    return result
