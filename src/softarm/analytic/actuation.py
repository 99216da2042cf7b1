"""Exact closed forms of an arm under its actuators alone: straight tendons and chambers.

With no external load the total wrench (rod, tendons and fluid together) vanishes all along
the arm, so the constitutive law with its actuators (``docs/actuation.md``),

    K (ε - f⁰) + Σ_tendons τ (t; r × t) = Σ_chambers p A (e1; r × e1),
    t = w/|w|,  w = v + u × r + r',

fixes the strain ε section by section. Where every path is straight (r constant, r' = 0)
the strain is constant between the places where an actuator starts or ends or a segment
changes, and the pose is a product of exponentials, g(s) = Π exp(ℓ_k ξ_k) (any 6 × 6 K; for
a diagonal K and f⁰ = (e1; 0), t = e1 and each piece is a circular arc of curvature
|Σ τ r|/EI towards the tendons, away from the chambers). The algebraic equation is solved by
Newton's method to round-off (the left side is the gradient of a strictly convex function for
τ ≥ 0: the root is unique).

The limit of a tendon (docs/actuation.md, "The model's limits"). The convex function
½ (ε - f⁰)ᵀ K (ε - f⁰) + Σ τ |w(ε)| has a kink where a tendon's w = 0, and its minimiser
sits on that kink once the tendon pulls hard enough: then no smooth root exists (the tendon's
path has no length and no direction to pull in), and Newton's method does not converge. For
one tendon on a piece, with C = J K⁻¹ Jᵀ (3 × 3, J = [I, -r~]) and w₀ = J f⁰ + r' its
unloaded tangent, the stationarity condition gives w = w₀ - τ C t, so a smooth root is
t = (ρ I + τ C)⁻¹ w₀ with |t| = 1 for some ρ = |w| > 0; |(ρ I + τ C)⁻¹ w₀| decreases in ρ,
so it exists exactly while τ < τ_c = |C⁻¹ w₀| (a diagonal K, a straight arm and r = (0, y, z):
τ_c = 1/(1/EA + z²/EIy + y²/EIz), w₁ = 1 - τ/τ_c). With several tendons or chambers on a
piece there is no such formula: :func:`_tendon_limit` finds the load factor by bisection, the
root being unique for every λ. A smooth root whose tendon runs backwards through the
sections (w₁ <= 0: the arm inside out at the tendon) is refused too.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import NamedTuple

import numpy as np

from .._admissible import check_stretch, load_case, tendon_limit
from .._validate import PART_BYTES, check_allocation
from ..errors import ConvergenceError
from ..loads import as_loads, batch_shape, check_magnitudes, path_tangent
from ._common import build, checked_stations, constant_strain_poses

__all__ = ["actuated", "solve_actuated"]


class _Actuators:
    """A :class:`~softarm.loads.LoadTarget` that records the actuators and notes anything
    else (fails closed: a load it does not know makes the closed form inapplicable)."""

    def __init__(self, arm):
        self.arm, self.length = arm, arm.length
        self.actuators = []  # (is_tendon, magnitude (B...), routing, span)
        self.other = False

    def actuator(self, kind, magnitude, routing, span):
        self.actuators.append((kind == "tendon", np.asarray(magnitude, dtype=np.float64),
                               routing, span))

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        self.other = True
        return lambda *args, **kwargs: None


def _is_straight(routing) -> bool:
    return routing.degree == 1 and routing.helix[0] == 0.0


def _root(K, f0, tendons, chambers):
    """The constant strain of one piece, (ε (B, 6), converged (B,), residual (B,)):
    tendons [(τ (B,), r, r')], chambers [(p A (B,), r, r')], r and r' (3,) constant.

    Newton's method on the convex energy Φ(ε) = ½ (ε - f⁰)ᵀ K (ε - f⁰) - Wᵀ ε + Σ τ |w(ε)|
    (W the chambers' wrench; its gradient is the law) from the tendons-along-d1 guess, exact
    for a diagonal K and a straight arm, each step halved until Φ decreases enough: the fast
    route of every case. ``converged``: the law holds to round-off; ``residual``: its
    largest imbalance (N, N m) at the last finite iterate. A case it leaves unconverged is followed
    by :class:`_Path`: past a tendon's limit no smooth root exists, and where K couples
    extension, shear and bending near the limit a Newton step can overshoot along a
    tendon's own direction t (Φ is only linear there) and stall on the kink although a root
    exists."""
    e1 = np.array([1.0, 0.0, 0.0])
    B = max([1] + [q.shape[0] for q, _, _ in tendons + chambers])
    wrench = np.zeros((B, 6))
    guess = np.zeros((B, 6))
    for q, r, _ in chambers:
        wrench += q[:, None] * np.concatenate([e1, np.cross(r, e1)])
    guess += wrench
    scale = np.max(np.abs(wrench), axis=-1)
    for q, r, _ in tendons:
        guess -= q[:, None] * np.concatenate([e1, np.cross(r, e1)])
        scale = scale + q * (1.0 + np.linalg.norm(r))
    eps = f0 + np.linalg.solve(K, guess[..., None])[..., 0]
    moved = np.full(B, np.inf)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # |w| = 0
        energy, F, H = _energy(K, f0, wrench, tendons, eps, True)
        first = np.max(np.abs(F), axis=-1)  # (the guess's, where the last is not finite)
        for _ in range(12):
            usable = np.isfinite(H).all(axis=(-2, -1)) & np.isfinite(F).all(axis=-1)
            converged = usable & (np.max(np.abs(F), axis=-1) <= 1e-10 * (
                scale + np.max(np.abs((eps - f0) @ K.T), axis=-1)))
            # (once the law holds, one more step takes ε to round-off: quadratic convergence)
            if (converged & (moved <= 1e-14 * (1.0 + np.max(np.abs(eps), axis=-1)))
                    | ~usable).all() or (converged & (moved == np.inf)).all():
                break
            H[~usable], F[~usable] = K, 0.0  # (no step there: not converged)
            step = _newton_steps(H, F)
            slope = np.einsum("bi,bi->b", F, step)
            factor = np.ones(B)
            for _ in range(40):  # halve the step until Φ decreases enough (Armijo, with
                # room for Φ's round-off: near the root a full step changes Φ by less)
                trial = eps + factor[:, None] * step
                enough = _energy(K, f0, wrench, tendons, trial) <= \
                    energy + 1e-4 * factor * slope + 1e-14 * np.abs(energy)
                if enough.all():
                    break
                factor = np.where(enough, factor, 0.5 * factor)
            moved = np.where(usable, np.max(np.abs(trial - eps), axis=-1), 0.0)
            eps = np.where(usable[:, None], trial, eps)
            energy, F, H = _energy(K, f0, wrench, tendons, eps, True)
        # (of the last iterate: after the twelfth step too)
        converged = np.isfinite(H).all(axis=(-2, -1)) & (np.max(np.abs(F), axis=-1) <= 1e-10 * (
            scale + np.max(np.abs((eps - f0) @ K.T), axis=-1)))
    residual = np.max(np.abs(F), axis=-1)
    return eps, converged, np.where(np.isfinite(residual), residual, first)


def _energy(K, f0, wrench, tendons, eps, derivatives=False):
    """Φ(ε) (B,) of :func:`_root`; with ``derivatives`` also its gradient F (B, 6) (the law's
    imbalance) and Hessian H = K + Σ τ Jᵀ (I - t tᵀ) J / |w| (B, 6, 6), J = [I, -r~]."""
    d = eps - f0
    Kd = d @ K.T
    energy = 0.5 * np.einsum("bi,bi->b", d, Kd) - np.einsum("bi,bi->b", wrench, eps)
    F = Kd - wrench
    H = np.broadcast_to(K, (eps.shape[0], 6, 6)).copy() if derivatives else None
    for q, r, dr in tendons:
        w = path_tangent(r, dr, eps)
        norm = np.linalg.norm(w, axis=-1)
        energy = energy + q * norm
        if derivatives:
            t = w / norm[:, None]
            F += q[:, None] * np.concatenate([t, np.cross(r, t)], axis=-1)
            P = (np.eye(3) - t[:, :, None] * t[:, None, :]) * (q / norm)[:, None, None]
            J = _jacobian(r)
            H += J.T @ P @ J
    return (energy, F, H) if derivatives else energy


def _newton_steps(H, F) -> np.ndarray:
    """-H⁻¹ F per case (B, 6); zero for a case whose H is singular in floating point (a
    tendon's τ/|w| so large, next to its kink, that K is lost in it: no step)."""
    try:
        return np.linalg.solve(H, -F[..., None])[..., 0]
    except np.linalg.LinAlgError:
        steps = np.zeros_like(F)
        for b in range(F.shape[0]):
            try:
                steps[b] = np.linalg.solve(H[b], -F[b])
            except np.linalg.LinAlgError:
                pass
        return steps


def _jacobian(r) -> np.ndarray:
    """J = [I, -r~] (3, 6): δw = J δε for a path at r (3,)."""
    return np.array([[1.0, 0.0, 0.0, 0.0, r[2], -r[1]], [0.0, 1.0, 0.0, -r[2], 0.0, r[0]],
                     [0.0, 0.0, 1.0, r[1], -r[0], 0.0]])


class _Path:
    """The root of one piece and one case followed from the unloaded arm as every actuator
    grows with the load factor λ from 0 to 1, in the unknowns z = (t_i, ρ_i) of each tendon
    (its direction and |w|) instead of ε.

    With ε = f⁰ + K⁻¹ (λ W - λ Σ_j τ_j J_jᵀ t_j) the law holds for any t, and the tendon
    tangents are w_i = w₀_i + λ (J_i K⁻¹ W - Σ_j τ_j C_ij t_j), C_ij = J_i K⁻¹ J_jᵀ,
    w₀_i = J_i f⁰ + r_i' (the unloaded tangent). A root is t_i = w_i/|w_i|, i.e.

        w_i(t, λ) - ρ_i t_i = 0,   ½ (|t_i|² - 1) = 0,   ρ_i = |w_i| > 0:

    polynomial equations, smooth through a tendon's kink (there ρ_i = 0, and its Jacobian,
    with -λ τ C and -ρ I on the diagonal, stays regular), whose solution with every ρ_i > 0
    is the unique root of the convex problem. So the limit is where ρ_i(λ) (the path's
    length) or t_i,1(λ) (the path running backwards) first reaches 0 along a continuation in
    λ: an event of a smooth path, located to round-off, not a failure of Newton's method.
    One tendon: ρ = 0 where |t| = |(λ τ C)⁻¹ w₀| = 1, λ_c τ = |C⁻¹ w₀| (module docstring).
    """

    def __init__(self, piece, case: int):
        K, f0 = piece.K, piece.f0
        e1 = np.array([1.0, 0.0, 0.0])
        compliance = np.linalg.inv(K)
        wrench = np.zeros(6)
        self.tendons = []  # (number, τ)
        Js, w0 = [], []
        for is_tendon, q, (r, dr), number in piece.active:
            if is_tendon:
                self.tendons.append((number, float(q[case])))
                Js.append(_jacobian(r))
                w0.append(path_tangent(r, dr, f0))
            else:
                wrench += float(q[case]) * np.concatenate([e1, np.cross(r, e1)])
        T = len(self.tendons)
        self.T, self.f0, self.compliance, self.wrench = T, f0, compliance, wrench
        self.J = np.array(Js)  # (T, 3, 6)
        self.tau = np.array([tau for _, tau in self.tendons])
        self.w0 = np.array(w0)
        self.A = self.J @ compliance @ wrench  # (T, 3)
        # C_ij τ_j as one (3T, 3T) matrix
        C = np.einsum("iak,kl,jbl->iajb", self.J, compliance, self.J)
        self.C = (C * self.tau[None, None, :, None]).reshape(3 * T, 3 * T)

    def start(self) -> np.ndarray:
        """z at λ = 0: t_i = w₀_i/|w₀_i|, ρ_i = |w₀_i|."""
        rho = np.linalg.norm(self.w0, axis=-1)
        return np.concatenate([(self.w0 / rho[:, None]).ravel(), rho])

    def residual(self, z, lam):
        """(F (4T,), ∂F/∂z (4T, 4T), ∂F/∂λ (4T,))."""
        T = self.T
        t, rho = z[:3 * T], z[3 * T:]
        drift = self.A.ravel() - self.C @ t
        w = self.w0.ravel() + lam * drift
        F = np.concatenate([w - np.repeat(rho, 3) * t,
                            0.5 * (np.einsum("ia,ia->i", t.reshape(T, 3), t.reshape(T, 3))
                                   - 1.0)])
        D = np.zeros((4 * T, 4 * T))
        D[:3 * T, :3 * T] = -lam * self.C - np.diag(np.repeat(rho, 3))
        for i in range(T):
            D[3 * i:3 * i + 3, 3 * T + i] = -t[3 * i:3 * i + 3]
            D[3 * T + i, 3 * i:3 * i + 3] = t[3 * i:3 * i + 3]
        return F, D, np.concatenate([drift, np.zeros(T)])

    def correct(self, z, lam):
        """Newton's method at fixed λ: z or None (not converged in 12 steps)."""
        for _ in range(12):
            F, D, _ = self.residual(z, lam)
            try:
                dz = np.linalg.solve(D, -F)
            except np.linalg.LinAlgError:
                return None
            z = z + dz
            if np.max(np.abs(dz)) <= 1e-14 * (1.0 + np.max(np.abs(z))):
                return z
        return None

    def events(self, z) -> np.ndarray:
        """(ρ_i/|w₀_i|, t_i,1) of every tendon: the path's length (relative) and whether it
        runs forwards; the first to reach 0 is the limit."""
        T = self.T
        return np.concatenate([z[3 * T:] / np.linalg.norm(self.w0, axis=-1),
                               z[:3 * T].reshape(T, 3)[:, 0]])

    def tangent(self, z, lam) -> np.ndarray:
        """dz/dλ = -(∂F/∂z)⁻¹ ∂F/∂λ along the path (NaN where ∂F/∂z is singular)."""
        _, D, dF = self.residual(z, lam)
        try:
            return -np.linalg.solve(D, dF)
        except np.linalg.LinAlgError:
            return np.full_like(z, np.nan)

    def follow(self):
        """(ε (6,) at λ = 1, None) if every tendon stays admissible up to the full load,
        else (None, (λ_c, tendon number, vanishes)): the first event, located by
        :meth:`_locate`. Near an event where several tendons' paths vanish together (a
        symmetric arrangement) ∂F/∂z may turn singular and the steps shrink: a path stalled
        with an event value below 1e-6 is that event."""
        lam, z, step = 0.0, self.start(), 0.25
        if np.any(self.events(z) <= 0.0):  # a tendon running backwards in the unloaded arm
            return None, self._event(z, 0.0)
        while lam < 1.0:
            new_lam = min(1.0, lam + step)
            new = self.correct(z + (new_lam - lam) * self.tangent(z, lam), new_lam)
            if new is None or np.max(np.abs(new - z)) > 0.5:
                step *= 0.5
                if step < 1e-12:
                    if np.min(self.events(z)) <= 1e-6:
                        return None, self._event(z, lam)
                    raise ConvergenceError("the actuated closed form could not follow a "
                                           f"piece's root beyond λ = {lam:.6g}", math.nan)
                continue
            if np.any(self.events(new) <= 0.0):
                return None, self._locate(z, lam, new, new_lam)
            lam, z, step = new_lam, new, min(2.0 * step, 1.0)
        T = self.T
        t = z[:3 * T].reshape(T, 3)
        return self.f0 + self.compliance @ (
            self.wrench - np.einsum("i,iak,ia->k", self.tau, self.J, t)), None

    def _locate(self, za, lam_a, zb, lam_b):
        """The load factor in (λa, λb] where the first event crosses 0: the secant method
        (Illinois) on its value, each point corrected from the admissible side's tangent; a
        point that does not converge counts as past the event (bisection then)."""
        index = int(np.argmin(self.events(zb)))
        ea, eb = self.events(za)[index], self.events(zb)[index]
        side = 0
        for _ in range(200):
            if lam_b - lam_a <= 1e-14 * lam_b:
                break
            lam = lam_b - eb * (lam_b - lam_a) / (eb - ea) if eb < 0.0 < ea \
                else 0.5 * (lam_a + lam_b)
            lam = min(max(lam, lam_a + 1e-3 * (lam_b - lam_a)), lam_b - 1e-3 * (lam_b - lam_a))
            z = self.correct(za + (lam - lam_a) * self.tangent(za, lam_a), lam)
            e = -np.inf if z is None else self.events(z)[index]
            if e > 0.0:
                za, lam_a, ea = z, lam, e
                if side == 1:
                    eb *= 0.5  # Illinois: the stale end's value halved
                side = 1
            else:
                lam_b, eb = lam, (e if z is not None else 0.0)
                if side == -1:
                    ea *= 0.5
                side = -1
            if abs(e) <= 1e-15:  # on the event itself
                lam_b = lam
                break
        return self._event(za, lam_b, index)

    def _event(self, z, lam, index=None):
        """(λ, tendon number, vanishes) of the event ``index`` (default the smallest)."""
        if index is None:
            index = int(np.argmin(self.events(z)))
        return lam, self.tendons[index % self.T][0], index < self.T


class _Piece(NamedTuple):
    """One piece of constant strain: [s0, s1] (m), the segment's K and f⁰, and its
    actuators (is_tendon, magnitude (count,), (r, r') (3,) of its straight path, tendon
    number or -1)."""

    s0: float
    s1: float
    K: np.ndarray
    f0: np.ndarray
    active: list

    def root(self):
        """:func:`_root` of every case."""
        return _root(self.K, self.f0, *(
            [(q, *path) for is_tendon, q, path, _ in self.active if is_tendon == kind]
            for kind in (True, False)))

    def tangents(self, eps):
        """(tendon numbers, w (T, B, 3)) of the tendons on this piece at the strains eps."""
        numbers = [n for is_tendon, _, _, n in self.active if is_tendon]
        return numbers, np.array([path_tangent(*path, eps)
                                  for is_tendon, _, path, _ in self.active if is_tendon])

    def admissible(self, eps, converged) -> np.ndarray:
        """(B,): a smooth root whose tendon paths run forwards (w₁ > 0)."""
        _, w = self.tangents(eps)
        return converged & (w[..., 0] > 0.0).all(axis=0) if w.size else converged


def _pieces(arm, target) -> list[_Piece]:
    """The pieces of constant strain of ``arm`` under the actuators of ``target``."""
    bounds = np.array(arm.boundaries)
    cuts = {float(c) for c in bounds}
    for _, _, _, span in target.actuators:
        cuts.update(float(c) for c in span)
    cuts = np.array(sorted(c for c in cuts if 0.0 <= c <= arm.length))
    numbers = np.cumsum([is_tendon for is_tendon, _, _, _ in target.actuators]) - 1
    pieces = []
    for s0, s1 in itertools.pairwise(cuts):
        middle = 0.5 * (s0 + s1)
        segment = arm.segments[min(int(np.searchsorted(bounds, middle)) - 1,
                                   len(arm.segments) - 1)]
        active = [(is_tendon, q, (routing.position(middle), routing.derivative(middle)),
                   int(n) if is_tendon else -1)
                  for (is_tendon, q, routing, span), n in zip(target.actuators, numbers,
                                                              strict=True)
                  if span[0] <= middle <= span[1]]
        pieces.append(_Piece(float(s0), float(s1), segment.stiffness,
                             segment.reference_strain, active))
    return pieces


def _checked_roots(pieces, loads, shape, count) -> list[np.ndarray]:
    """Every piece's constant strain ε (count, 6), or the error of the first load case
    (C order) whose loads lead a tendon out of the model (:class:`_Path`): the fast
    Newton's method for all cases, the path in λ for those it leaves unconverged or with a
    tendon running backwards."""
    roots = []
    limits = {}  # case -> (λ, piece, tendon number, vanishes, residual)
    for piece in pieces:
        eps, converged, residual = piece.root()
        eps = np.broadcast_to(eps, (count, 6)).copy()
        admissible = piece.admissible(eps, np.broadcast_to(converged, count))
        for case in np.flatnonzero(~admissible):
            if limits and case > min(limits):
                break  # (a later case: the first one is reported)
            try:
                root, limit = _Path(piece, int(case)).follow()
            except ConvergenceError as error:  # (name the case, with its Newton residual)
                raise ConvergenceError(
                    f"{error.message}{load_case(int(case), shape)}",
                    float(np.broadcast_to(residual, count)[case])) from None
            if root is not None:
                eps[case] = root
            elif case not in limits or limit[0] < limits[case][0]:
                limits[case] = (*limit[:1], piece, *limit[1:],
                                float(np.broadcast_to(residual, count)[case]))
        roots.append(eps)
    if limits:
        case = min(limits)
        lam, piece, number, vanishes, residual = limits[case]
        tendon = [load for load in loads if load.kind == "tendon"][number]
        tension = float(np.broadcast_to(tendon.tension, shape).reshape(-1)[case])
        raise tendon_limit(number, tendon.describe(), tension, load_case(case, shape), lam,
                           f"s in [{piece.s0:.6g}, {piece.s1:.6g}] m", residual, vanishes,
                           piece.s0)
    return roots


def actuated(arm, loads, s=None):
    """The exact equilibrium of ``arm`` under straight tendons and straight chambers alone
    (batched tensions and pressures broadcast), or None if other loads or non-straight paths
    are present. Any arm (segmented, curved, any 6 × 6 K).

    Returns an :class:`~softarm.Equilibrium` with ``method = "analytic.actuated"``, the rod's
    own stresses K (ε - f⁰), a zero base wrench (no external load) and the tendons' tensions,
    lengths and length changes.

    Raises
    ------
    InadmissibleStateError
        Where the loads lead out of the model (docs/actuation.md, "The model's limits"): a
        tendon beyond the tension its path can carry (its length |w| -> 0; one straight
        tendon at (y, z) on a straight arm with a diagonal K: τ_c = 1/(1/EA + z²/EIy +
        y²/EIz)), or an axial stretch v₁ <= 0.

    Examples
    --------
    >>> from softarm import Arm, Tendon
    >>> from softarm.routing import Straight
    >>> arm = Arm.from_stiffness(0.25, EA=1e4, GAy=1e4, GAz=1e4, GJ=0.01, EIy=0.01, EIz=0.01)
    >>> eq = actuated(arm, [Tendon(1.0, Straight(0.0, 0.01))], s=3)
    >>> round(float(eq.strains[0, 4]), 12)   # u_y = -τ z / EI
    -1.0
    """
    loads = as_loads(loads)
    check_magnitudes(arm, loads, "actuated")
    return solve_actuated(arm, loads, s)


def solve_actuated(arm, loads, s=None):
    """:func:`actuated` for loads whose sizes are checked (``softarm.solve`` checks them)."""
    if not any(load.inputs for load in loads):  # no actuator at all (most calls of auto)
        return None
    target = _Actuators(arm)
    for load in loads:
        load.apply(target)
        if target.other:  # (most calls: gravity or an external load beside the actuators)
            return None
    if not target.actuators or not all(
            _is_straight(routing) for _, _, routing, _ in target.actuators):
        return None
    s = checked_stations(s, arm.length)
    shape = batch_shape(loads)
    count = int(np.prod(shape))
    target.actuators = [(is_tendon, np.broadcast_to(q, shape).reshape(count), routing, span)
                        for is_tendon, q, routing, span in target.actuators]
    pieces = _pieces(arm, target)
    # every piece's root and the model's limits first, before any pose
    roots = _checked_roots(pieces, loads, shape, count)
    check_stretch(np.stack([eps - piece.f0 for piece, eps in zip(pieces, roots, strict=True)],
                           axis=1).reshape(*shape, len(pieces), 6),
                  [piece.s0 for piece in pieces], what="the equilibrium (analytic.actuated)")
    check_allocation(count, s.size, "loads")  # (softarm.solve checked it already)
    # the result's own arrays (build freezes them: no copy), written through flat views
    fields = (np.empty((*shape, s.size, 4, 4)), np.empty((*shape, s.size, 6)),
              np.empty((*shape, s.size, 6)))
    poses, strains, stresses = (a.reshape(count, *a.shape[len(shape):]) for a in fields)
    start_pose = np.broadcast_to(np.eye(4), (count, 4, 4)).copy()
    tendons = [a for a, act in enumerate(target.actuators) if act[0]]
    lengths = np.zeros((count, len(tendons)))
    unloaded = np.zeros(len(tendons))
    for piece, eps in zip(pieces, roots, strict=True):
        s0, s1, K, f0 = piece.s0, piece.s1, piece.K, piece.f0
        at = (s >= s0) & ((s < s1) | ((s1 == arm.length) & (s == s1)))
        part = max(1, PART_BYTES // (256 * max(1, int(at.sum()))))  # (its work: 2 poses)
        for first in range(0, count, part):
            cases = slice(first, first + part)
            poses[cases, at] = start_pose[cases, None] @ constant_strain_poses(eps[cases],
                                                                              s[at] - s0)
        strains[:, at] = (eps - f0)[:, None, :]
        stresses[:, at] = ((eps - f0) @ K.T)[:, None, :]
        start_pose = start_pose @ constant_strain_poses(eps, np.array([s1 - s0]))[:, 0]
        numbers, w = piece.tangents(eps)
        _, w0 = piece.tangents(f0[None])
        for k, i in enumerate(numbers):
            lengths[:, i] += (s1 - s0) * np.linalg.norm(w[k], axis=-1)
            unloaded[i] += (s1 - s0) * float(np.linalg.norm(w0[k, 0]))
    result = build(arm, s, *fields[:2], loads, "analytic.actuated", True, stresses=fields[2])
    extra = {"base_wrench": _frozen(np.zeros((*shape, 6)))}
    if tendons:
        tensions = np.stack([target.actuators[a][1].reshape(shape) for a in tendons], axis=-1)
        extra.update(tendon_tensions=_frozen(tensions),
                     tendon_lengths=_frozen(lengths.reshape(*shape, len(tendons))),
                     tendon_length_changes=_frozen((lengths - unloaded).reshape(
                         *shape, len(tendons))))
        slack = tensions == 0.0
        slack.setflags(write=False)
        extra["tendon_slack"] = slack
    return dataclasses.replace(result, **extra)


def _frozen(array) -> np.ndarray:
    array = np.array(array, dtype=np.float64)
    array.setflags(write=False)
    return array
