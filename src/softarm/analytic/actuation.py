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
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..loads import as_loads, batch_shape
from ._common import build, checked_stations, constant_strain_poses

__all__ = ["actuated"]


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
    """The constant strain (B, 6) of one piece: tendons [(τ (B,), r (3,))], chambers
    [(p A (B,), r (3,))]."""
    e1 = np.array([1.0, 0.0, 0.0])
    B = max([1] + [q.shape[0] for q, _ in tendons + chambers])
    wrench = np.zeros((B, 6))
    guess = np.zeros((B, 6))
    for q, r in chambers:
        wrench += q[:, None] * np.concatenate([e1, np.cross(r, e1)])
    guess += wrench
    for q, r in tendons:
        guess -= q[:, None] * np.concatenate([e1, np.cross(r, e1)])
    eps = f0 + np.linalg.solve(K, guess[..., None])[..., 0]
    for _ in range(50):
        F = (eps - f0) @ K.T - wrench
        H = np.broadcast_to(K, (B, 6, 6)).copy()
        for q, r in tendons:
            w = eps[:, :3] + np.cross(eps[:, 3:], r)
            norm = np.linalg.norm(w, axis=-1)
            t = w / norm[:, None]
            F += q[:, None] * np.concatenate([t, np.cross(r, t)], axis=-1)
            J = np.concatenate([np.eye(3), -_hat(r)], axis=1)  # δw = J δε
            P = (np.eye(3) - t[:, :, None] * t[:, None, :]) * (q / norm)[:, None, None]
            H += J.T @ P @ J
        step = np.linalg.solve(H, -F[..., None])[..., 0]
        eps = eps + step
        if np.max(np.abs(step), initial=0.0) <= 1e-15 * (1.0 + np.max(np.abs(eps))):
            break
    return eps


def _hat(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def actuated(arm, loads, s=None):
    """The exact equilibrium of ``arm`` under straight tendons and straight chambers alone
    (batched tensions and pressures broadcast), or None if other loads or non-straight paths
    are present. Any arm (segmented, curved, any 6 × 6 K).

    Returns an :class:`~softarm.Equilibrium` with ``method = "analytic.actuated"``, the rod's
    own stresses K (ε - f⁰), a zero base wrench (no external load) and the tendons' tensions,
    lengths and length changes.

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
    segments = arm.segments
    bounds = np.array(arm.boundaries)
    cuts = {float(c) for c in bounds}
    for _, _, _, span in target.actuators:
        cuts.update(float(c) for c in span)
    cuts = np.array(sorted(c for c in cuts if 0.0 <= c <= arm.length))
    starts, ends = cuts[:-1], cuts[1:]
    poses = np.empty((count, s.size, 4, 4))
    strains = np.empty((count, s.size, 6))
    stresses = np.empty((count, s.size, 6))
    start_pose = np.broadcast_to(np.eye(4), (count, 4, 4)).copy()
    tendons = [a for a, act in enumerate(target.actuators) if act[0]]
    lengths = np.zeros((count, len(tendons)))
    unloaded = np.zeros(len(tendons))
    for s0, s1 in zip(starts, ends, strict=True):
        middle = 0.5 * (s0 + s1)
        k = min(int(np.searchsorted(bounds, middle)) - 1, len(segments) - 1)
        segment = segments[k]
        K, f0 = segment.stiffness, segment.reference_strain
        active = [(is_tendon, np.broadcast_to(q, shape).reshape(count),
                   routing.position(0.0)) for is_tendon, q, routing, span in target.actuators
                  if span[0] <= middle <= span[1]]
        eps = _root(K, f0, [(q, r) for t, q, r in active if t],
                    [(q, r) for t, q, r in active if not t])
        eps = np.broadcast_to(eps, (count, 6))
        at = (s >= s0) & ((s < s1) | ((s1 == arm.length) & (s == s1)))
        local = constant_strain_poses(eps, s[at] - s0)
        poses[:, at] = start_pose[:, None] @ local
        strains[:, at] = (eps - f0)[:, None, :]
        stresses[:, at] = ((eps - f0) @ K.T)[:, None, :]
        start_pose = start_pose @ constant_strain_poses(eps, np.array([s1 - s0]))[:, 0]
        for i, a in enumerate(tendons):
            _, _, routing, span = target.actuators[a]
            if span[0] <= middle <= span[1]:
                r = routing.position(0.0)
                w = eps[:, :3] + np.cross(eps[:, 3:], r)
                lengths[:, i] += (s1 - s0) * np.linalg.norm(w, axis=-1)
                unloaded[i] += (s1 - s0) * np.linalg.norm(f0[:3] + np.cross(f0[3:], r))
    result = build(arm, s, poses.reshape(*shape, s.size, 4, 4),
                   strains.reshape(*shape, s.size, 6), loads, "analytic.actuated", True,
                   stresses=stresses.reshape(*shape, s.size, 6))
    extra = {"base_wrench": _frozen(np.zeros((*shape, 6)))}
    if tendons:
        tensions = np.stack([np.broadcast_to(target.actuators[a][1], shape) for a in tendons],
                            axis=-1)
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
