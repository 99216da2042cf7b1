"""Which load cases are stiff: where single shooting's map grows like e^{kL} beyond what
double precision carries, and the multiple-shooting route (``softarm.kernels.solve_stiff_cases``)
takes them (docs/solver.md, "Multiple shooting")."""

from __future__ import annotations

import math

import numpy as np

from ..loads import largest_force

__all__ = ["STIFF_KL", "tension_kl"]

#: Cases whose estimated kL = L √(F/EI) (F the loads' largest force, EI the softest bending
#: stiffness) reaches this go to multiple shooting: at kL = 15 single shooting's tangents
#: have grown by e^15 = 3e6, and it was measured to fail from kL ≈ 22 (a hanging hose) and
#: 32 (a rod in tension, and one pulled by a field gradient on its magnetisation).
STIFF_KL = 15.0


def tension_kl(arm, loads, shape: tuple, soft: float) -> np.ndarray:
    """kL per case, flattened (B,) of the batch ``shape``: L √(F / EI), F the loads' largest
    force (:func:`softarm.loads.largest_force`: every force a load can apply from outside,
    at points, along the arm, on its magnets, summed; an upper bound of the tension
    anywhere), ``soft`` the largest bending compliance 1/EI of the arm. Each load measures
    itself through its own ``apply``: this function knows no load kind. Actuators count
    nothing: a tendon's tension or a chamber's pressure is internal, it compresses the
    backbone (oscillating Jacobi fields, not growing ones), and single shooting was measured
    to solve a tendon robot and a chamber at τL²/EI = p A L²/EI = 1e4 (docs/solver.md). (A
    control loop calls this once a solve: a few µs.)"""
    force = largest_force(arm, loads)
    if isinstance(force, float):  # every load single (np.ndim: 2 µs)
        kl = arm.length * math.sqrt(force * soft)
        return np.array([kl]) if shape == () else np.full(math.prod(shape), kl)
    return arm.length * np.sqrt(np.broadcast_to(force, shape).reshape(-1) * soft)
