"""Simulation: the time loop around the compiled implicit step (softarm/kernels/dynamics.py,
section "dynamics"). The equations, the scheme and its accuracy: docs/dynamics.md."""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .. import kernels
from .._admissible import load_case
from .._threads import in_threads, threads_for
from .._validate import (
    as_matrices,
    check_allocation,
    count,
    format_value,
    positive,
    real,
    rigid_transform,
)
from ..equilibrium import Equilibrium, _frozen
from ..errors import ApproximationWarning, ConvergenceError
from ..loads import Gravity, InputRules, as_actuators, as_loads
from ..statics import Solver
from ..statics.solver import _check_outside, check_tol
from ._results import Energy, State, Trajectory

__all__ = ["Damping", "Simulator", "simulate"]

#: Newton iterations of one step before it is declared failed.
MAX_ITERATIONS = 25
#: The relative step of the central difference that gives a moving base's velocity, in Δt.
_BASE_DIFFERENCE = 1e-3


@dataclass(frozen=True)
class Damping:
    """Kelvin–Voigt damping of the sections: stresses K (ε - ε⁰) + B ε̇.

    Give one of:

    retardation : float
        τ in s: B = τ K (every mode's damping ratio ζ = τ ω / 2).
    matrix : array_like, shape (6, 6)
        B itself, symmetric positive semi-definite (N s, N m² s; linear part first).

    Examples
    --------
    >>> Damping(retardation=0.01).matrix_for(np.diag([2.0, 1, 1, 1, 1, 1]))[0, 0]
    np.float64(0.02)
    """

    retardation: float | None = None
    matrix: np.ndarray | None = None

    def __post_init__(self):
        if (self.retardation is None) == (self.matrix is None):
            raise ValueError("Damping takes exactly one of retardation= (τ in s) or matrix= "
                             f"(6 × 6 B), got retardation={format_value(self.retardation)}, "
                             f"matrix={format_value(self.matrix)}")
        if self.retardation is not None:
            tau = real(self.retardation, "Damping.retardation", "s")
            if not tau >= 0.0:
                raise ValueError(f"Damping.retardation must be >= 0 s, got {format_value(tau)}")
            object.__setattr__(self, "retardation", tau)
        else:
            B = as_matrices(self.matrix, "Damping.matrix", 6, 6)
            if B.shape != (6, 6):
                raise ValueError(f"Damping.matrix must have shape (6, 6), got shape {B.shape}")
            scale = max(float(np.max(np.abs(B))), 1e-300)
            if not np.allclose(B, B.T, rtol=0.0, atol=1e-12 * scale):
                raise ValueError("Damping.matrix must be symmetric, got "
                                 f"{format_value(B)}")
            if np.min(np.linalg.eigvalsh(B)) < -1e-12 * scale:
                raise ValueError("Damping.matrix must be positive semi-definite (a damper "
                                 f"cannot give energy), got eigenvalues "
                                 f"{np.linalg.eigvalsh(B).tolist()}")
            B = B.copy()
            B.setflags(write=False)
            object.__setattr__(self, "matrix", B)

    def matrix_for(self, K: np.ndarray) -> np.ndarray:
        """B for a section of stiffness K."""
        return self.retardation * K if self.retardation is not None else np.array(self.matrix)


def _bdf_alpha(dt: float, alpha: float) -> np.ndarray:
    """BDF-α (Till, Aloi & Rucker 2019): ẋ(t) ≈ c0 x(t) + c1 x(t-Δt) + c2 x(t-2Δt) +
    d1 ẋ(t-Δt); α = -1/2 is the trapezoidal rule, α = 0 BDF2."""
    c0 = (1.5 + alpha) / (dt * (1.0 + alpha))
    c1 = -2.0 / dt
    c2 = (0.5 + alpha) / (dt * (1.0 + alpha))
    d1 = alpha / (1.0 + alpha)
    return np.array([c0, c1, c2, d1, dt, alpha])


def _actuator_loads(actuators) -> tuple:
    """The actuators (:func:`~softarm.loads.as_actuators`), tendons under tension control."""
    actuators = as_actuators(actuators)
    if any(getattr(load, "displacement_controlled", False) for load in actuators):
        raise ValueError("actuators: a tendon under displacement control is not modelled in "
                         "dynamics yet (give its tension)")
    return actuators


def _node_bytes() -> tuple[int, int]:
    """(the state of one case, the step's factorisation) per node, bytes: the node's state
    Z, its two past states and its history H, float64, held up to nine times over a step
    (the initial state, the current one, a step's working copy, the last and the new
    State's, their stacks and temporaries) with the outputs at the stations (30 numbers,
    twice); the banded Jacobian's rows (DUNK a node: 3 KL + 1 columns of the band, KL of
    the multipliers, a pivot), the nodes' Jacobians G and Hermite's G² (2 DUNK², kept with
    the factorisation) and the slopes (DUNK + 7). Measured (tracemalloc and the peak
    resident memory): 24.5 kB a node over the steps of one case, 1.8 kB after construction
    (tests/test_memory.py; before Hermite's rule, issue 40)."""
    k = kernels
    state = 8 * (9 * (3 * k.DYN + k.DHIST) + 2 * 30)
    storage = 8 * (k.DUNK * ((3 * k._DKL + 1) + k._DKL + 1) + 2 * k.DUNK * k.DUNK + k.DUNK
                   + 7)
    return state, storage


def _shared(arrays) -> tuple:
    """The simulator's state arrays made read-only, for a State to hold without a copy: the
    simulator never writes into them again (a step or a run advances copies of them)."""
    for array in arrays:
        array.setflags(write=False)
    return arrays


def _check_base(base):
    """(callable t -> (4, 4) pose or None, the fixed pose)."""
    if base is None:
        return None, np.eye(4)
    if callable(base):
        return base, None
    return None, rigid_transform(base, "base")


def _grid(length: float, starts: np.ndarray, count_: int):
    """The nodes of the step's equations: the uniform stations (``count_``) and the piece
    boundaries, a boundary inside the arm twice (a joint: the end of one piece and the
    start of the next). Returns (s of the nodes, interval lengths (0 at a joint), the piece
    of each node, the node of each station)."""
    s_out = np.linspace(0.0, length, count_)
    ends = np.append(starts[1:], length)
    nodes, piece = [], []
    for j, (a, b) in enumerate(zip(starts, ends, strict=True)):
        # the stations strictly inside (a, b): s_out is sorted (a search, not a scan per piece)
        inside = s_out[np.searchsorted(s_out, a, "right"):np.searchsorted(s_out, b, "left")]
        here = np.concatenate([[a], inside, [b]])
        nodes.append(here)
        piece.append(np.full(here.size, j))
    s = np.concatenate(nodes)  # (non-decreasing: a joint's node twice)
    node_piece = np.concatenate(piece).astype(np.int64)
    h = np.diff(s)
    h[h < 1e-12 * length] = 0.0
    # each station's node: the first within 1e-12 L of it, found by bisection in O(S log G)
    # (a scan of every node per station was quadratic: 17 s at 1e5 stations)
    tol = 1e-12 * length
    at = np.searchsorted(s, s_out - tol, "left")
    earlier = (at > 0) & (np.abs(s[np.maximum(at - 1, 0)] - s_out) <= tol)  # (rounding)
    at = np.where(earlier, at - 1, at)
    if not np.all(np.abs(s[np.minimum(at, s.size - 1)] - s_out) <= tol):
        raise AssertionError("a station without its node")  # pragma: no cover
    return s, h, node_piece, at.astype(np.int64), s_out


class Simulator:
    """An arm in motion, stepped in time by one implicit step per call: the real-time
    loop of a controller or an estimator.

    Each step of Δt discretises the rod's equations of motion in time by BDF-α and solves
    the resulting boundary value problem in s (Hermite's rule on the stations, fourth
    order, all nodes' states solved together by Newton on a banded system), warm-started
    from the last step (docs/dynamics.md).

    Parameters
    ----------
    arm : Arm or SegmentedArm
        Its mass (density or ``mass_per_length``) and rotary inertia
        (``inertia_per_length`` for an arm given by its stiffnesses) are required.
    actuators : sequence of loads with inputs
        Tendons (under tension control), chambers, magnetic fields, unbatched: their inputs
        (``inputs`` of :meth:`step` and :meth:`run`, in :class:`~softarm.ForwardSolver`'s
        order) may change in time; their own values are the inputs at first.
    loads : load or sequence of loads
        Gravity, tip loads, distributed and point loads (dead or follower), any load of the
        statics, constant in time; batch axes give one trajectory per case.
    dt : float
        Δt in s.
    damping : Damping, optional
        Kelvin–Voigt damping of the sections (default: none).
    initial : None, Equilibrium or State
        None: the unloaded arm at rest; an Equilibrium: that shape, at rest (the loads act
        from t = 0); a State: continue from it.
    base : None, (4, 4) array or callable
        The base pose, fixed, or a function of time t -> (4, 4) pose (a moving base; its
        velocity is taken by central differences).
    stations : int
        Uniform stations on [0, L] (≥ 3): the grid of the step's equations (its error is of
        fourth order in L/stations; second in a step that touches an obstacle) and the
        outputs.
    tol : float
        Newton tolerance of each step, relative (positions in L).
    alpha : float
        BDF-α parameter in [-1/2, 0]: -1/2 (default) the trapezoidal rule, which keeps the
        energy of an undamped arm (0.4 % over 20 periods at Δt = T/200, where α = -0.2
        loses 2.5 %); towards 0 (BDF2) it damps the high frequencies the step does not
        resolve (Till et al. use -0.2).

    Examples
    --------
    >>> from softarm import Arm, Circle, Gravity, Material
    >>> arm = Arm(0.5, Circle(0.02), Material(1e6, poisson_ratio=0.5, density=1100.0))
    >>> sim = Simulator(arm, loads=[Gravity()], dt=1e-3, stations=21)
    >>> state = sim.step()
    >>> round(float(state.tip_position[2]) * 1e6, 1)  # -g Δt²: a free fall's backward-Euler step
    -9.8
    """

    def __init__(self, arm, actuators=(), loads=(), *, dt, damping=None, initial=None,
                 base=None, stations=101, tol=1e-6, alpha=-0.5):
        self.dt = positive(dt, "dt", "s")
        self.alpha = real(alpha, "alpha")
        if not -0.5 <= self.alpha <= 0.0:
            raise ValueError(f"alpha must lie in [-0.5, 0] (BDF-α), got {format_value(alpha)}")
        self.tol = check_tol(tol)
        stations = count(stations, "stations", 3)
        if damping is not None and not isinstance(damping, Damping):
            raise TypeError(f"damping must be a softarm.Damping or None, got "
                            f"{format_value(damping)}")
        self.damping = damping
        self.actuators = _actuator_loads(actuators)
        self._solver = Solver(arm, s=2, stability=False)
        self.arm = self._solver.arm
        #: the inputs' rules: the statics' (a tendon cannot push) and their size limit
        self._rules = InputRules(self.arm, self.actuators)
        everything = [*as_loads(loads), *self.actuators]
        cuts = ()  # (an initial equilibrium's loads over part of the arm cut it there too)
        if isinstance(initial, Equilibrium) and initial.arm == self._solver.arm:
            cuts = tuple(c for load in initial.loads for c in load.cuts(initial.arm))
        self.loads, shape, _, pieces, channels = self._solver._prepare(everything, cuts)
        self.loads = self.loads[:len(self.loads) - len(self.actuators)]
        contact = channels.resolve_contact(dt=self.dt)
        if contact is not None:  # (the law the steps use, on the trajectory's loads)
            self.loads = tuple(contact if load.kind == "contact" else load
                               for load in self.loads)
        #: the contact law of the steps, and the arm's surface radius at the stations
        self._contact = contact
        self._contact_radii = None
        # the law's estimated stiffness per case before the time step's cap (B,), sized
        # for the largest inputs given so far (_follow_contact); None: a law of the user's
        given = channels._contact_given
        self._contact_sized = None if given is None or given.stiffness is not None else \
            channels._contact_stiffness(given.band(channels.length))
        self.shape = shape
        self._channels = channels
        self._act = channels.arm_tuple()[1]
        # time-varying inputs: the loads at zero inputs plus the inputs times their unit
        # channels (the channels are affine in the inputs, statics/README.md)
        self.inputs = np.array([v for load in self.actuators for name in load.inputs
                                for v in np.ravel(np.asarray(getattr(load, name), float))])
        self._unit = None
        if self.actuators:
            width = channels.piece.shape[2]
            unit, unit_tip = self._solver._input_channels(everything, pieces, width)
            n = self.inputs.size
            self._unit = (np.ascontiguousarray(unit[-n:]), np.ascontiguousarray(unit_tip[-n:]))
            self._loads0 = (channels.piece - np.einsum("i,ipw->pw", self.inputs, unit[-n:]),
                            channels.tip_loads - self.inputs @ unit_tip[-n:])
        self._motion, self._pose = _check_base(base)
        self.length = self._solver.length
        # the memory of the state and of a run's factorisations (a thread's each), before
        # anything of the stations' size is allocated (10⁹ stations: a ValueError, not an OOM)
        cases = int(np.prod(shape))
        state, storage = _node_bytes()
        threads = threads_for(cases, 1)
        check_allocation(cases, stations + 2 * pieces[0].size, "stations",
                         per_station=state + storage * threads / cases, per_case=0.0,
                         hint="simulate fewer cases or stations at a time")
        s, h, node_piece, at, s_out = _grid(self.length, pieces[0], stations)
        self.s = s_out
        if self._contact is not None:
            self._contact_radii = self._contact.station_radii(self.arm, self.s)
        self.s.setflags(write=False)
        self._nodes, self._h, self._node_piece, self._at = s, h, node_piece, at
        # A start at rest knows no acceleration: its first step is backward Euler (BDF-α's
        # history of ẋ would inject the wrong one, an O(Δt) error for good), then BDF-α.
        self._coef = _bdf_alpha(self.dt, self.alpha)
        self._coef_first = np.array([1.0 / self.dt, -1.0 / self.dt, 0.0, 0.0, self.dt, 0.0])
        self._props = self._properties(pieces, self._coef)
        self._props_first = self._properties(pieces, self._coef_first)
        self._pieces = pieces
        self._tendon_columns = channels.tendons()[0] if self._act is not None else \
            np.zeros(0, dtype=np.int64)
        self._loads = np.ascontiguousarray(channels.piece)
        self._tip = np.ascontiguousarray(channels.tip_loads)
        self._grid = (self._h, self._node_piece, np.ascontiguousarray(s))
        self._gravity = self._gravity_of(self.loads, shape)
        data = self._solver._data
        # The scales of the unknowns and of the equations' rows (the tolerance is relative
        # to them): positions by L, forces by the bending scale EI/L² (a transverse force
        # error δV bends the arm by δV L²/EI), except the axial force, by EA (its error
        # stretches the arm by δN/EA only; at EI/L² the fast axial waves, which the
        # predictor cannot follow and which move no point by tol, cost two iterations a
        # step), moments by EI/L, velocities by L/Δt and 1/Δt.
        axial = float(np.min(pieces[8][:, 0, 0]))
        self._scales = np.array([self.length] * 3 + [1.0] * 3
                                + [axial, data.force_scale, data.force_scale]
                                + [data.force_scale * self.length] * 3
                                + [self.length / self.dt] * 3 + [1.0 / self.dt] * 3)
        self._options = np.array([self.tol, MAX_ITERATIONS], dtype=np.float64)
        self._signature = (id(self.arm), s.tobytes(), self.dt, self.alpha, shape,
                           channels.signature())
        self.t0 = 0.0
        self._initial = self._initial_arrays(initial)
        self.reset()

    # ------------------------------------------------------------------ set-up

    def _properties(self, pieces, coef) -> np.ndarray:
        """(P, DPROPS): each piece's K, B, (K + c0 B)⁻¹, ε⁰, μ and ρJ."""
        k = kernels
        P = pieces[0].size
        segments = self.arm.segments
        props = np.zeros((P, k.DPROPS))
        c0 = coef[0]
        for j in range(P):
            segment = segments[int(pieces[12][j])]
            K = pieces[8][j]
            mu = segment.linear_density
            inertia = segment.rotary_inertia
            if mu is None or inertia is None:
                raise ValueError(
                    "dynamics needs the arm's mass and rotary inertia: give the material a "
                    "density, or mass_per_length and inertia_per_length to an arm built "
                    f"from its stiffnesses (segment {int(pieces[12][j])} has "
                    f"mass_per_length={format_value(mu)}, inertia_per_length="
                    f"{format_value(None if inertia is None else inertia.tolist())})")
            B = (self.damping.matrix_for(K) if self.damping is not None
                 else np.zeros((6, 6)))
            props[j, k._PK:k._PK + 36] = K.ravel()
            props[j, k._PB:k._PB + 36] = B.ravel()
            props[j, k._PKD:k._PKD + 36] = np.linalg.inv(K + c0 * B).ravel()
            props[j, k._PF0:k._PF0 + 6] = pieces[3][j]
            props[j, k._PMU] = mu
            props[j, k._PRJ:k._PRJ + 3] = inertia
        return props

    @staticmethod
    def _actuation(pieces, props, act):
        """A thread's (law arm, law scratch) for the actuated law, or None (``act`` None):
        the statics' arm tuple with the damping folded in, K + c0 B and its inverse (from
        ``props``), and f⁰ as a scratch the kernel fills per node."""
        if act is None:
            return None
        k = kernels
        P = pieces[0].size
        compliance = np.ascontiguousarray(props[:, k._PKD:k._PKD + 36].reshape(P, 6, 6))
        stiffness = np.ascontiguousarray(np.linalg.inv(compliance))
        law_arm = (pieces[0], pieces[1], compliance, np.zeros((P, 6)), pieces[4], False,
                   pieces[6], pieces[7], stiffness)
        A = max(1, act[0].shape[0])
        return law_arm, (np.empty((6, 7)), np.zeros((A, 8)), np.zeros((6, 6)), np.zeros((6, 6)))

    def _thread_actuation(self, props, slot: int):
        """:meth:`_actuation` for ``props`` (the first step's or the others') and a thread's
        ``slot``, made once and kept (made again at every step, it cost the 3-tendon robot's
        Simulator.step 8 µs: its pieces' compliances inverted)."""
        kept = self.__dict__.setdefault("_actuations", {})
        key = (id(props), slot)
        if key not in kept:
            kept[key] = self._actuation(self._pieces, props, self._act)
        return kept[key]

    def _follow_contact(self, inputs) -> None:
        """The contact law sized for ``inputs`` (C, ..., n) too, C = 1 or the batch's cases:
        the penalty's estimated stiffness (the statics' estimate from the loads' size,
        resolve_contact) of the loads at those inputs, bounded above by |loads at zero
        inputs| + Σ max|qᵢ| |unit channel i| over the rows, and the law remade (its stiffness
        and, past the time step's cap μ/Δt², its band: contact.md, "Dynamics") where that
        is above the law's now. The law only grows: sized at construction for the inputs
        the actuators had, a law for 0 N let a finger pulled to 15 N pass 34 mm through
        the cylinder it closes on (issue 42)."""
        if self._contact_sized is None or not self.actuators:
            return
        q = np.abs(np.asarray(inputs, dtype=np.float64))
        largest = q.reshape(q.shape[0], -1, q.shape[-1]).max(axis=1)  # (C, n)
        unit, unit_tip = self._unit
        B = int(np.prod(self.shape))
        piece = np.broadcast_to(np.abs(self._loads0[0]) + np.einsum(
            "cn,npw->cpw", largest, np.abs(unit)), self._loads0[0].shape)
        tip = np.broadcast_to(np.abs(self._loads0[1]) + largest @ np.abs(unit_tip),
                              self._loads0[1].shape)
        channels = self._channels
        band = channels._contact_given.band(channels.length)
        needed = channels._contact_stiffness(band, piece.reshape(B, *piece.shape[1:]),
                                             tip.reshape(B, -1))
        if np.all(needed <= self._contact_sized):
            return
        self._contact_sized = np.maximum(self._contact_sized, needed)
        contact = channels.resolve_contact(self._contact_sized.copy(), dt=self.dt)
        self.loads = tuple(contact if load.kind == "contact" else load for load in self.loads)
        self._contact = contact
        k = kernels
        for array in (self._loads, self._loads0[0]):  # (each case's k in its channel CT)
            array[:, :, k.CT] = channels.piece[:, :, k.CT]
        self._act = channels.arm_tuple()[1]  # (the obstacles' rows and the law's band)
        if self._factors is not None:
            self._factors[3][:] = 0  # (the step's kept Jacobian is another law's)

    @staticmethod
    def _gravity_of(loads, shape) -> np.ndarray:
        g = np.zeros((*shape, 3))
        for load in loads:
            if isinstance(load, Gravity):
                g = g + np.asarray(load.acceleration)
        return np.ascontiguousarray(np.broadcast_to(g, (*shape, 3)).reshape(-1, 3))

    def _base_rows(self, times) -> np.ndarray:
        """(1, T, 18): the base's p, R (row-major), q and ω (material) at ``times``."""
        rows = np.zeros((1, len(times), 18))
        if self._motion is None:
            rows[0, :, :3] = self._pose[:3, 3]
            rows[0, :, 3:12] = self._pose[:3, :3].ravel()
            return rows
        d = _BASE_DIFFERENCE * self.dt
        for i, t in enumerate(times):
            t = float(t)
            pose = self._base_at(t)
            if t - d >= self.t0:  # a central difference
                rate = (self._base_at(t + d) - self._base_at(t - d)) / (2 * d)
            else:  # at the start: one-sided, of second order too (never called before it)
                rate = (4.0 * self._base_at(t + d) - self._base_at(t + 2 * d)
                        - 3.0 * pose) / (2 * d)
            R = pose[:3, :3]
            rows[0, i, :3] = pose[:3, 3]
            rows[0, i, 3:12] = R.ravel()
            rows[0, i, 12:15] = R.T @ rate[:3, 3]
            W = R.T @ rate[:3, :3]
            rows[0, i, 15:18] = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0],
                                                W[1, 0] - W[0, 1]])
        return rows

    def _base_at(self, t: float) -> np.ndarray:
        """The user's base pose at time ``t`` (s, a Python float, never before the start)."""
        try:
            pose = self._motion(t)
        except Exception as error:
            raise ValueError(f"base({format_value(t)}) raised {type(error).__name__}: "
                             f"{error}") from None
        return rigid_transform(pose, f"base({format_value(t)})")

    def _initial_arrays(self, initial) -> tuple:
        """(Z, Zold, H, aux) of the initial state: a State's own; or at rest: the unloaded
        arm (ε = ε⁰, no stress), or the equilibrium of an Equilibrium's loads solved again
        on this grid (:meth:`_settle`)."""
        k = kernels
        B = int(np.prod(self.shape))
        self._initial_lengths = None  # the tendons' lengths at the start, where known
        if isinstance(initial, State):
            if initial._signature != self._signature:
                raise ValueError("initial: this State belongs to another simulation (its arm, "
                                 "stations, dt, alpha, actuators or batch shape differ)")
            self.t0 = initial.time
            self._starts_at_rest = initial._fresh
            if initial.tendon_lengths is not None:
                self._initial_lengths = np.reshape(initial.tendon_lengths, (B, -1)).copy()
            return tuple(a.copy() for a in initial._arrays)
        if initial is not None and not isinstance(initial, Equilibrium):
            raise TypeError("initial must be None, a softarm.Equilibrium or a "
                            f"softarm.State, got {format_value(initial)}")
        if initial is not None and initial.arm != self.arm:
            raise ValueError("initial: the Equilibrium is of another arm")
        self._starts_at_rest = True
        base0 = self._base_rows([self.t0])[0, 0]
        pose0 = np.eye(4)
        pose0[:3, 3], pose0[:3, :3] = base0[:3], base0[3:12].reshape(3, 3)
        unique = np.unique(self._nodes)
        if initial is None and self._contact is not None:  # (the statics' rule and words)
            _check_outside(Solver(self.arm, s=2, base=pose0, stability=False, tol=self.tol),
                           self._contact.replace(stiffness=None))
        solver = Solver(self.arm, s=unique, base=pose0, stability=False, tol=1e-10)
        loads = () if initial is None else self._stepped(initial.loads)
        eq = solver.solve_from_unloaded(loads)
        if initial is not None and self._contact is not None:
            self._check_start(eq, unique)
            self._say_the_law_differs(initial, eq)
        S = unique.size
        poses = np.broadcast_to(eq.poses, (*self.shape, S, 4, 4)).reshape(B, S, 4, 4)
        stresses = np.broadcast_to(eq.stresses, (*self.shape, S, 6)).reshape(B, S, 6)
        index = np.searchsorted(unique, self._nodes)
        G = self._nodes.size
        Z = np.zeros((B, G, k.DYN))
        at_nodes = poses[:, index]
        Z[:, :, k._DP:k._DP + 3] = at_nodes[..., :3, 3]
        Z[:, :, k._DR:k._DR + 9] = at_nodes[..., :3, :3].reshape(B, G, 9)
        H = np.zeros((B, G, k.DHIST))
        for j in range(self._props.shape[0]):
            mine = self._node_piece == j
            K = self._props[j, k._PK:k._PK + 36].reshape(6, 6)
            rod = stresses[:, index][:, mine]
            H[:, mine, 0:6] = self._props[j, k._PF0:k._PF0 + 6] + np.linalg.solve(
                K, rod[..., None])[..., 0]
        if initial is not None:
            Z[:, :, k._DN:k._DN + 6] = stresses[:, index]  # (the rod's: a first guess)
            self._settle(loads, Z, H, base0)
        for o in (0, 36):  # x and its slope in s: the same two steps before, at rest
            H[..., o + 12:o + 24] = H[..., o:o + 12]
            H[..., o + 24:o + 36] = 0.0
        return Z, np.stack([Z, Z], axis=1), H, np.zeros((B, 2))

    def _check_start(self, eq, s) -> None:
        """ValueError, as the statics' for the unloaded arm (statics.solver._check_outside),
        if the initial equilibrium ``eq`` (on the nodes ``s``) is inside an obstacle beyond
        tol·L at some node: a step from there has no answer (Newton fails, and once said
        "a section turned inside out")."""
        contact = self._contact._with_checked_stiffness(None)  # (its geometry only)
        gaps, _ = contact.gaps(eq.positions, contact.station_radii(self.arm, s))
        inside = gaps < -self.tol * self.length
        if not inside.any():
            return
        flat = int(np.argmax(inside.reshape(-1)))
        case, station = divmod(flat, s.size)
        raise ValueError(
            f"Contact: the initial equilibrium{load_case(case, gaps.shape[:-1])} starts "
            f"inside an obstacle (its surface {-float(gaps.reshape(-1)[flat]):.3g} m deep at "
            f"station s = {float(s[station]):.6g} m): no motion from it is defined; move the "
            "obstacles or the base, or start from another shape")

    def _say_the_law_differs(self, initial, start) -> None:
        """An ApproximationWarning where the Equilibrium ``initial`` was solved with another
        contact law than the steps' (the statics' default is stiffer, in a narrower band):
        the arm starts at rest under the steps' law (``start``), off the Equilibrium's shape
        by about the difference of the bands, which it says for the tip."""
        given = next(load for load in initial.loads if load.kind == "contact")
        law = self._contact
        try:  # (one number or one per case, either side)
            same = given.distance == law.distance and given.stiffness is not None and \
                bool(np.all(np.asarray(given.stiffness) == np.asarray(law.stiffness)))
        except ValueError:  # (batch shapes that do not broadcast: not the same law)
            same = False
        if same:
            return
        off = float(np.max(np.linalg.norm(start.positions[..., -1, :]
                                          - initial.positions[..., -1, :], axis=-1)))
        # (a free tip held exactly has no law: statics/tip_contact.py)
        solved = "with its tip held exactly (no contact distance), unlike" \
            if given.distance is None else \
            f"with another contact law (distance {given.distance:.3g} m) than"
        warnings.warn(
            f"initial: the Equilibrium was solved {solved} the time steps (distance "
            f"{float(np.max(law.distance)):.3g} m, the stiffness at most μ/Δt²: "
            f"docs/contact.md, \"Dynamics\"); the arm starts at rest under the steps' law, "
            f"its tip {off:.3g} m from the Equilibrium's", ApproximationWarning, stacklevel=4)

    def _stepped(self, loads) -> tuple:
        """``loads`` with their Contact's law replaced by the one the steps use: an
        equilibrium solved with the statics' law (stiffer, in a narrower band) is balanced
        again with the steps', so that the arm starts at rest under the law that moves it
        (contact.md, "Dynamics"), not pushed off by the difference."""
        if self._contact is None:
            return tuple(loads)
        law = self._contact
        k = np.asarray(law.stiffness)
        if k.ndim:  # one per case: a static solve takes one law (Contact.stiffness)
            if np.any(k != k.flat[0]):
                raise ValueError(
                    f"initial: this batch's time steps use a contact law per case (stiffness "
                    f"{k.min():.4g} to {k.max():.4g} N/m², sized for each case's loads), and "
                    "an Equilibrium is balanced again under one law: give the Contact its "
                    "stiffness and distance (one law for every case, contact.md), or "
                    "simulate each case from its own equilibrium")
            law = law.replace(stiffness=float(k.flat[0]))
        return tuple(law if load.kind == "contact" else load for load in loads)

    def _settle(self, loads, Z, H, base0) -> None:
        """Z, H ← the equilibrium of the initial Equilibrium's ``loads`` (:meth:`_stepped`)
        at rest on this grid: the equations
        of a step without inertia (c0 = 0: no time derivative), by Newton from the solver's
        answer. The same discretisation as the steps, so the arm starts at rest to tol
        (the solver's own answer differs from it by the grid's O(h⁴) error), and the
        total wrench of rod and actuators is the state's."""
        k = kernels
        _, shape, _, pieces, channels = self._solver._prepare(loads, tuple(self._pieces[0]))
        if not np.array_equal(pieces[0], self._pieces[0]):
            raise ValueError("initial: the Equilibrium's loads cut the arm where this "
                             "simulation does not (loads over part of the arm)")
        B, P = Z.shape[0], pieces[0].size
        try:
            piece = np.broadcast_to(channels.piece.reshape(*shape, P, -1),
                                    (*self.shape, P, channels.piece.shape[-1]))
            tip = np.broadcast_to(channels.tip_loads.reshape(*shape, -1),
                                  (*self.shape, channels.tip_loads.shape[-1]))
        except ValueError:
            raise ValueError(f"initial: the Equilibrium's batch shape {shape} does not "
                             f"broadcast to the loads' {self.shape}") from None
        act = channels.arm_tuple()[1]
        coef = np.zeros(6)
        props = self._properties(pieces, coef)
        base = base0.reshape(1, 1, 18).copy()
        base[..., 12:] = 0.0
        dummy = {name: np.zeros((B, 1, self._at.size, width)) for name, width in
                 (("p", 3), ("R", 9), ("v", 3), ("w", 3), ("e", 6), ("s", 6))}
        info, done = np.zeros((B, 1, 4)), np.zeros(B, dtype=np.int64)
        options = np.array([min(self.tol, 1e-9), 4 * MAX_ITERATIONS])
        tendons = None  # (their lengths by the steps' own rule: _tendon_lengths' is O(h²))
        if self._tendon_columns.size:
            tendons = np.zeros((B, 1, act[0].shape[0]))
        k.dynamic_steps(Z, np.stack([Z, Z], axis=1), H, np.zeros((B, 2)), props,
                        np.ascontiguousarray(piece.reshape(B, P, -1)),
                        np.ascontiguousarray(tip.reshape(B, -1)), self._grid, coef,
                        self._scales, options, base, self._gravity, self._at, 0, B,
                        self._storage(False, 1), dummy["p"], dummy["R"], dummy["v"],
                        dummy["w"], dummy["e"], dummy["s"], np.zeros((B, 1, 4)), info, done,
                        act, self._actuation(pieces, props, act), None, tendons)
        if tendons is not None:
            self._initial_lengths = tendons[:, 0, self._tendon_columns]
        if np.any(done < 1):
            b = int(np.flatnonzero(done < 1)[0])
            raise ConvergenceError("initial: the Equilibrium's loads could not be balanced "
                                   "on the simulation's stations (Newton from the solver's "
                                   "answer)", float(info[b, 0, 0]))

    def _tendon_lengths(self, H) -> np.ndarray | None:
        """(B, tendons): each tendon's length ∫ |v + u × r + r'| ds (the trapezoidal rule on
        the nodes) for the strains in H, or None without tendons: the unloaded start's (a
        settled start and the steps take Hermite's rule in the kernel, fourth order; the
        two agree where |w| is constant along a piece, as on an unloaded arm with straight
        or helical paths)."""
        if not self._tendon_columns.size:
            return None
        k = kernels
        routes, active = self._act[0], self._act[2]
        out = np.zeros((H.shape[0], self._tendon_columns.size))
        v, u = H[..., 0:3], H[..., 3:6]
        for i, a in enumerate(self._tendon_columns):
            on = np.flatnonzero(active[self._node_piece, a] != 0.0)
            # the path's offset and slope at the nodes where it runs (the kernel's own route
            # function, node by node), then |w| for every node and case at once
            y, z, dy, dz = np.array([k._route(routes, np.int64(a), float(s))
                                     for s in self._nodes[on]]).reshape(-1, 4).T
            vn, un = v[:, on], u[:, on]
            w = np.zeros((H.shape[0], self._nodes.size))
            w[:, on] = np.sqrt((vn[..., 0] + un[..., 1] * z - un[..., 2] * y) ** 2
                               + (vn[..., 1] - un[..., 0] * z + dy) ** 2
                               + (vn[..., 2] + un[..., 0] * y + dz) ** 2)
            out[:, i] = np.sum(0.5 * self._h * (w[:, :-1] + w[:, 1:]), axis=1)
        return out

    def reset(self) -> None:
        """Back to the initial state (and its time)."""
        self._arrays = tuple(a.copy() for a in self._initial)
        self.time = self.t0
        self._q = self.inputs[None].copy() if self.actuators else None  # (C, n)
        self._lengths_now = self._initial_lengths  # the current state's, if known
        #: (case index, time the failed step would have reached (s), residual) of every
        #: case that failed in a run(failures="keep")
        self.failures = []
        self._failed = np.zeros(self.shape, dtype=bool)
        self._fresh = self._starts_at_rest
        self._factors = None
        self._state = None

    @property
    def state(self) -> State:
        """The current state."""
        if self._state is None:
            self._state = self._make_state(self._record_now(), np.zeros(self.shape),
                                           np.zeros(self.shape, dtype=np.int64))
        return self._state

    # ------------------------------------------------------------------ stepping

    def _storage(self, per_case: bool, B: int):
        k = kernels
        n = k.DUNK * (self._nodes.size - 1) + 6
        C = B if per_case else 1
        return (np.zeros((C, n, 3 * k._DKL + 1)), np.zeros((C, n, k._DKL)),
                np.zeros((C, 3, n), dtype=np.int64), np.zeros((C, 2)),
                np.empty((2, self._nodes.size, k.DUNK, k.DUNK)))

    def _advance(self, steps: int, factors, threads: int | None = None, *, arrays,
                 inputs=None):
        """Run ``steps`` steps in the kernel on ``arrays`` (copies of the state, advanced in
        place); returns (times, outputs, energies, info, steps done per case). From a start
        at rest, the first step is backward Euler (see __init__). ``inputs`` (steps, n): the
        actuators' inputs at the new step times, None: constant."""
        times = self.time + self.dt * np.arange(1, steps + 1)
        first = 1 if self._fresh else 0
        parts = []
        skip = self._failed.ravel().copy()
        for a, b, coef, props in ((0, first, self._coef_first, self._props_first),
                                  (first, steps, self._coef, self._props)):
            if b > a:
                q = None if inputs is None else inputs[:, a:b]
                if factors is not None and factors[5] is not coef:
                    factors[3][:] = 0  # (the Jacobian changes with the scheme)
                    factors[5] = coef
                parts.append(self._kernel_run(arrays, times[a:b], coef, props,
                                              None if factors is None else tuple(factors[:5]),
                                              threads, q, skip))
                skip |= parts[-1][3] < b - a  # (a case failed in the first part: not after)
        if len(parts) == 1:
            return (times, *parts[0])
        (out1, e1, i1, d1), (out2, e2, i2, d2) = parts
        out = {name: np.concatenate([out1[name], out2[name]], axis=1) for name in out1}
        done = np.where(d1 < 1, d1, 1 + d2)
        return (times, out, np.concatenate([e1, e2], 1), np.concatenate([i1, i2], 1), done)

    def _kernel_run(self, arrays, times, coef, props, factors, threads, q, skip):
        """The kernel over ``times`` (advancing ``arrays`` in place where a case succeeds)."""
        k = kernels
        Z, Zold, H, aux = arrays
        B, S, steps = Z.shape[0], self._at.size, times.size
        base = self._base_rows(times)
        out = {name: np.zeros((B, steps, S, width)) for name, width in
               (("positions", 3), ("rotations", 9), ("velocities", 3), ("spins", 3),
                ("strains", 6), ("stresses", 6))}
        energy = np.zeros((B, steps, 4))
        info = np.zeros((B, steps, 4))
        done = np.where(skip, -1, 0).astype(np.int64)  # (-1: the kernel skips the case)
        tendons = None
        if self._act is not None:
            tendons = np.zeros((B, steps, max(1, self._act[0].shape[0])))
        loads, tip, schedule = self._loads, self._tip, None
        if q is not None:
            loads, tip = self._loads0
            schedule = (np.ascontiguousarray(q, dtype=np.float64), *self._unit)
        shared = factors is None
        count_ = max(1, threads or 1)
        local = [self._storage(False, 1) for _ in range(count_)] if shared else None
        actuations = [self._thread_actuation(props, slot) for slot in range(count_)]
        # a step with friction that fails is solved again along a continuation in the
        # friction's band, which the kernel writes into act[6] (and restores): a thread's own
        acts = [self._act] * count_
        if self._act is not None and np.any(self._act[6][:, 3] > 0.0):
            acts = [(*self._act[:6], self._act[6].copy(), *self._act[7:])
                    for _ in range(count_)]
        slots = iter(range(count_))

        def run(first, last):
            slot = next(slots)
            mine = local[slot] if shared else factors
            k.dynamic_steps(Z, Zold, H, aux, props, loads, tip, self._grid, coef, self._scales,
                            self._options, base, self._gravity, self._at, first, last, mine,
                            out["positions"], out["rotations"], out["velocities"],
                            out["spins"], out["strains"], out["stresses"], energy, info, done,
                            acts[slot], actuations[slot], schedule, tendons)

        if shared and threads and threads > 1:
            in_threads(run, B, threads)
        else:
            run(0, B)
        if tendons is not None:
            out["tendons"] = tendons
        return out, energy, info, done

    def step(self, inputs=None) -> State:
        """One implicit step of Δt from the current state; returns the new state.

        ``inputs`` (n,) or (B..., n): the actuators' inputs at the end of the step (tensions
        in N, pressures in Pa, field components in T, in the order of the actuators' inputs,
        as :class:`~softarm.ForwardSolver`'s; batch axes first to give each case its own),
        kept for the next steps; None: as before (at first, the actuators' own values).
        They obey the statics' rules (:class:`~softarm.loads.InputRules`: finite, a tension
        >= 0, within the loads' size limit), else ValueError naming the input. Raises
        ConvergenceError (with the step's residual) if a case's step cannot be solved: the
        simulator's state (and inputs) are then unchanged. The contact law, if the loads
        hold one, grows with the inputs (docs/contact.md, "Dynamics")."""
        q = self._q if inputs is None else self._checked_inputs(inputs, 1)[:, 0]
        if inputs is not None:
            self._follow_contact(q)
        if self._factors is None:  # (kept between steps: the chord iteration's factors)
            cases = int(np.prod(self.shape))
            check_allocation(cases, self._nodes.size, "step", per_station=_node_bytes()[1],
                             per_case=0.0, hint="step fewer cases at a time, or run() them "
                             "(its threads share their factorisations)")
            self._factors = [*self._storage(True, cases), None]
        arrays = tuple(a.copy() for a in self._arrays)
        times, out, _, info, done = self._advance(
            1, self._factors, arrays=arrays, inputs=None if q is None else q[:, None])
        self._check(done, info, 1, times)
        self._q = q
        self._arrays = arrays
        self._fresh = False
        self.time = float(times[-1])
        for value in out.values():  # (fresh: the State takes them without a copy)
            value.setflags(write=False)
        self._state = self._make_state(
            {name: value[:, 0] for name, value in out.items()},
            info[:, 0, 3].reshape(self.shape), info[:, 0, 1].astype(np.int64).reshape(
                self.shape))
        return self._state

    def run(self, steps: int, inputs=None, *, failures: str = "raise") -> Trajectory:
        """``steps`` steps from the current state, in one compiled call (the cases of a
        batch in threads); returns the trajectory, the current state first.

        ``inputs``: the actuators' inputs over time, a callable t -> (n,) or an array
        (steps + 1, n) at the trajectory's times (row 0, the current time, is not used),
        the batch axes first ((B..., n), (B..., steps + 1, n)) to give each case its own;
        None: constant (as the last step left them). The statics' rules hold for every row
        (:meth:`step`); the contact law is sized for the largest. A run whose trajectory
        cannot fit in memory is refused first (ValueError: run fewer steps at a time).

        ``failures``: "raise" (default): a case whose step cannot be solved raises a
        ConvergenceError and the simulator's state is unchanged. "keep" (a long batch, a
        sweep): the other cases go on; a failed case stays at its last solved step, its
        values after it are NaN, ``Trajectory.failed`` marks it and :attr:`failures` says
        when and with what residual (later runs skip it)."""
        if failures not in ("raise", "keep"):
            raise ValueError(f"failures must be 'raise' or 'keep', got {format_value(failures)}")
        steps = count(steps, "steps", 1)
        self._check_run(steps, "run")
        B = int(np.prod(self.shape))
        first = self.state
        threads = threads_for(B, 1)
        times = self.time + self.dt * np.arange(1, steps + 1)
        q = None
        if self.actuators:
            q = (np.broadcast_to(self._q[:, None], (len(self._q), steps, self.inputs.size))
                 if inputs is None else self._schedule(inputs, times))
            if inputs is not None:
                self._follow_contact(q)
        elif inputs is not None:
            raise ValueError("inputs: these loads have no actuators (give them as "
                             f"actuators=...), got {format_value(inputs)}")
        arrays = tuple(a.copy() for a in self._arrays)
        times, out, energy, info, done = self._advance(steps, None, threads, arrays=arrays,
                                                       inputs=q)
        if failures == "raise":
            self._check(done, info, steps, times)
        else:
            self._mark_failures(done, info, steps, times, out, energy)
        if q is not None:
            self._q = np.array(q[:, -1])
        if "tendons" in out and self._tendon_columns.size:
            self._lengths_now = out["tendons"][:, -1][:, self._tendon_columns]
        self._arrays = arrays
        self._fresh = False
        self.time = float(times[-1])
        self._factors = None
        self._state = None  # (the final state is made from the new arrays)
        start = self._record_now(initial=first)
        return self._trajectory(first, times, out, energy, info, start)

    def _check_run(self, steps: int, name: str) -> int:
        """ValueError (check_allocation's) if the trajectory of ``steps`` steps cannot fit in
        memory: per case, step and station the kernel's outputs (30 numbers), joined to the
        first step's (a start at rest) and copied into the trajectory (three copies at
        most); per case and step its energies, errors, iterations, tendon lengths and
        inputs (several copies). Else the bytes."""
        tendons = 0 if self._act is None else max(1, self._act[0].shape[0])
        per_step = 8 * (2 * 4 + 4 + 2 + 3 * tendons + 2 * self.inputs.size + 1)
        return check_allocation(
            int(np.prod(self.shape)), self._at.size, f"{name}({steps} steps)",
            per_station=3 * 30 * 8 * float(steps), per_case=float(per_step) * steps,
            hint="run fewer steps at a time (each run continues from the last)")

    def _case(self, b: int) -> tuple[int, ...]:
        """The batch index of flat case ``b``."""
        return tuple(int(i) for i in np.unravel_index(b, self.shape)) if self.shape else ()

    def _mark_failures(self, done, info, steps, times, out, energy) -> None:
        """Record the cases that failed in this run and blank their values from the failed
        step on (NaN); cases that had failed before are blanked throughout."""
        failed = self._failed.ravel()
        for b in np.flatnonzero(done < steps):
            first = max(int(done[b]), 0)
            if done[b] >= 0:  # a new failure
                self.failures.append((self._case(b), float(times[first]),
                                      float(info[b, first, 0])))
                failed[b] = True
            for array in (*out.values(), energy):
                array[b, first:] = np.nan
            info[b, first:, 3] = np.nan  # (its errors; its iterations 0)
            info[b, first:, 1] = 0.0
        self._failed = failed.reshape(self.shape)

    def _checked_inputs(self, values, rows: int, name: str = "inputs") -> np.ndarray:
        """``values`` as (C, rows, n) finite floats, C = 1 (the same for every case) or the
        batch's case count (batch axes first), admissible (the loads' own rules and size
        limit, :class:`~softarm.loads.InputRules`: a tension >= 0, ...), else ValueError
        naming ``inputs`` (``name``: where they come from, ``inputs(0.002)``)."""
        n = self.inputs.size
        if not n:
            raise ValueError("inputs: these loads have no actuators (give them as "
                             f"actuators=...), got {format_value(values)}")
        try:
            q = np.asarray(values, dtype=np.float64)
        except (TypeError, ValueError):
            q = None
        one = ((n,), (rows, n)) if rows == 1 else ((rows, n),)
        batched = ((*self.shape, n), (*self.shape, rows, n)) if rows == 1 else \
            ((*self.shape, rows, n),)
        if q is None or (q.shape not in one and (not self.shape or q.shape not in batched)):
            wanted = "(n,)" if rows == 1 else "(steps + 1, n)"
            raise ValueError(f"inputs must be an array {wanted} of the actuators' n = {n} "
                             + ("" if rows == 1 else "inputs (or a callable of t), ")
                             + (f"with the batch axes {self.shape} first if they differ per "
                                "case, " if self.shape else "")
                             + f"got {format_value(values)}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"inputs must be finite, got {format_value(values)}")
        self._rules.check(q, name)  # (q as given: the message indexes the user's array)
        cases = 1 if q.shape in one else int(np.prod(self.shape))
        return q.reshape(cases, rows, n)

    def _schedule(self, inputs, times) -> np.ndarray:
        """The inputs (C, steps, n) at the new step ``times`` from a callable or an array."""
        if callable(inputs):
            rows = []
            for t in times:
                at = f"inputs({format_value(float(t))})"
                try:
                    rows.append(self._checked_inputs(inputs(float(t)), 1, at))
                except ValueError as error:
                    text = str(error)
                    raise ValueError(text if text.startswith(at) else f"{at}: {text}") from None
            widest = max(row.shape[0] for row in rows)
            return np.concatenate([np.broadcast_to(row, (widest, 1, row.shape[2]))
                                   for row in rows], axis=1)
        return self._checked_inputs(inputs, times.size + 1)[:, 1:]

    def _check(self, done, info, steps, times) -> None:
        failed = np.flatnonzero((done < steps) & (done >= 0))
        if failed.size:
            b = int(failed[0])
            t = int(done[b])
            raise ConvergenceError(
                f"the time step to t = {times[t]:.6g} s (step {t + 1}) could not be solved "
                f"for case {self._case(b)}: Newton "
                f"did not converge to tol {self.tol:g} in {MAX_ITERATIONS} iterations, or "
                "its answer left the model (an axial stretch v₁ <= 0: a section turned inside "
                f"out); {self._advice()}; the state is unchanged",
                float(info[b, t, 0]), f"{MAX_ITERATIONS} Newton iterations")

    def _advice(self) -> str:
        """What may help a step that failed. With friction, a wider regularisation (the step
        has been tried along a band widened and narrowed back already: docs/contact.md)."""
        contact = self._contact
        if contact is not None and contact.friction > 0.0:
            return (f"with friction, a larger Contact.slip_velocity may help (now "
                    f"{contact.slip_velocity:g} m/s; the step was also tried from a band up "
                    "to 1e4 times wider, narrowed back: docs/contact.md), or damping")
        return "a smaller dt, a looser tol or damping may help"

    # ------------------------------------------------------------------ results

    def _record_now(self, initial=None) -> dict:
        """The outputs of the current state (stations), shape (B, S, ...)."""
        if initial is not None:
            shape = (-1, self._at.size)
            return {"positions": initial.positions.reshape(*shape, 3),
                    "rotations": initial.rotations.reshape(*shape, 9),
                    "velocities": initial.velocities.reshape(*shape, 3),
                    "spins": initial.angular_velocities.reshape(*shape, 3),
                    "strains": initial.strains.reshape(*shape, 6),
                    "stresses": initial.stresses.reshape(*shape, 6)}
        k = kernels
        Z, _, H, _ = self._arrays
        z = Z[:, self._at]
        R = z[..., k._DR:k._DR + 9].reshape(*z.shape[:2], 3, 3)
        f0 = self._props[self._node_piece[self._at], k._PF0:k._PF0 + 6]
        return {"positions": z[..., k._DP:k._DP + 3],
                "rotations": z[..., k._DR:k._DR + 9],
                "velocities": np.einsum("...ij,...j->...i", R, z[..., k._DQ:k._DQ + 3]),
                "spins": np.einsum("...ij,...j->...i", R, z[..., k._DW:k._DW + 3]),
                "strains": H[:, self._at, 0:6] - f0,
                "stresses": z[..., k._DN:k._DN + 6]}

    def _make_state(self, record, error, iterations) -> State:
        shape, S = self.shape, self._at.size
        lengths = record.get("tendons")
        if not self._tendon_columns.size:  # (no tendon: chambers, magnets or none)
            lengths = None
        elif lengths is not None:
            lengths = lengths[:, self._tendon_columns]
        elif self._lengths_now is not None:  # (the last step's, from the kernel)
            lengths = self._lengths_now
        else:
            lengths = self._tendon_lengths(self._arrays[2])  # (at the start: by quadrature)
        self._lengths_now = lengths
        return State(
            time=self.time, s=self.s,
            positions=_frozen(record["positions"].reshape(*shape, S, 3)),
            rotations=_frozen(record["rotations"].reshape(*shape, S, 3, 3)),
            velocities=_frozen(record["velocities"].reshape(*shape, S, 3)),
            angular_velocities=_frozen(record["spins"].reshape(*shape, S, 3)),
            strains=_frozen(record["strains"].reshape(*shape, S, 6)),
            stresses=_frozen(record["stresses"].reshape(*shape, S, 6)),
            error=_frozen(error), iterations=np.asarray(iterations),
            tendon_lengths=None if lengths is None else _frozen(
                lengths.reshape(*shape, lengths.shape[-1])),
            _arrays=_shared(self._arrays), _signature=self._signature,
            _fresh=self._fresh)

    def _energy_now(self, first: State) -> np.ndarray:
        """(B, 4): the energies of ``first`` (the trajectory's first row), from its arrays."""
        k = kernels
        Z, _, H, aux = first._arrays
        w = np.zeros(self._nodes.size)
        w[:-1] += 0.5 * self._h
        w[1:] += 0.5 * self._h
        props = self._props[self._node_piece]
        mu = props[..., k._PMU]
        rj = props[..., k._PRJ:k._PRJ + 3]
        q, om = Z[..., k._DQ:k._DQ + 3], Z[..., k._DW:k._DW + 3]
        kinetic = 0.5 * np.sum(w * (mu * np.sum(q**2, -1) + np.sum(rj * om**2, -1)), -1)
        K = props[..., k._PK:k._PK + 36].reshape(-1, 6, 6)
        e = H[..., 0:6] - props[..., k._PF0:k._PF0 + 6]
        elastic = 0.5 * np.sum(w * np.einsum("...i,...ij,...j->...", e, K, e), -1)
        gravity = -np.sum(w * mu * np.einsum("...i,...ki->...k", self._gravity,
                                              Z[..., k._DP:k._DP + 3]), -1)
        return np.stack([kinetic, elastic, gravity, aux[:, 0]], -1)

    def _trajectory(self, first, times, out, energy, info, start) -> Trajectory:
        shape, S = self.shape, self._at.size
        T = times.size + 1

        def joined(name, width):
            both = np.concatenate([start[name].reshape(-1, 1, S, width), out[name]], axis=1)
            return both.reshape(*shape, T, S, width)

        energies = np.concatenate([self._energy_now(first)[:, None], energy], axis=1)
        energies = energies.reshape(*shape, T, 4)
        errors = np.concatenate([np.zeros((info.shape[0], 1)), info[..., 3]], axis=1)
        lengths = None
        if first.tendon_lengths is not None:
            lengths = np.concatenate([first.tendon_lengths.reshape(-1, 1, self._tendon_columns
                                                                   .size),
                                      out["tendons"][..., self._tendon_columns]], axis=1)
            lengths = _frozen(lengths.reshape(*shape, T, -1))
        iterations = np.concatenate([np.zeros((info.shape[0], 1)), info[..., 1]], axis=1)
        return Trajectory(
            times=_frozen(np.concatenate([[first.time], times])), s=self.s,
            positions=_frozen(joined("positions", 3)),
            rotations=_frozen(joined("rotations", 9).reshape(*shape, T, S, 3, 3)),
            velocities=_frozen(joined("velocities", 3)),
            angular_velocities=_frozen(joined("spins", 3)),
            strains=_frozen(joined("strains", 6)), stresses=_frozen(joined("stresses", 6)),
            energy=Energy(*(_frozen(energies[..., i]) for i in range(4))),
            errors=_frozen(errors.reshape(*shape, T)),
            iterations=iterations.astype(np.int64).reshape(*shape, T),
            tendon_lengths=lengths, final=self.state, failed=self._failed.copy(),
            contact=self._contact, contact_radii=self._contact_radii)


def simulate(arm, loads=(), *, duration, dt, actuators=(), inputs=None, damping=None,
             initial=None, base=None, stations=101, tol=1e-6, alpha=-0.5) -> Trajectory:
    """The motion of an arm over ``duration`` seconds, in implicit steps of ``dt``.

    The parameters are :class:`Simulator`'s; ``duration`` (s) must be a whole number of
    steps (to 1e-9). Returns a :class:`Trajectory` of steps + 1 times, the initial state
    first. Raises ValueError for bad input (inputs the statics refuse, an arm that starts
    inside an obstacle, a trajectory that cannot fit in memory: docs/dynamics.md,
    "Failures"), ConvergenceError (with the residual) if a step cannot be solved.

    Examples
    --------
    >>> from softarm import Arm, Circle, Gravity, Material
    >>> arm = Arm(0.5, Circle(0.02), Material(1e6, poisson_ratio=0.5, density=1100.0))
    >>> path = simulate(arm, [Gravity()], duration=0.01, dt=1e-3, stations=21)
    >>> path.positions.shape, path.times[-1]
    ((11, 21, 3), np.float64(0.01))
    """
    duration = positive(duration, "duration", "s")
    dt = positive(dt, "dt", "s")
    steps = round(duration / dt)
    if steps < 1 or abs(steps * dt - duration) > 1e-9 * duration:
        raise ValueError(f"duration must be a whole number of time steps dt = {dt!r} s, got "
                         f"duration={duration!r} s ({duration / dt:.6g} steps)")
    simulator = Simulator(arm, actuators, loads, dt=dt, damping=damping, initial=initial,
                          base=base, stations=stations, tol=tol, alpha=alpha)
    return simulator.run(steps, inputs)

