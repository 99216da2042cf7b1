"""Which load cases are stiff: where single shooting's map grows like e^{kL} beyond what
double precision carries, and the multiple-shooting route (``_kernels.solve_stiff_cases``)
takes them (docs/solver.md, "Multiple shooting")."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["STIFF_KL", "tension_kl"]

#: Cases whose estimated kL = L √(F/EI) (F the largest load's force, EI the softest bending
#: stiffness) reaches this go to multiple shooting: at kL = 15 single shooting's tangents
#: have grown by e^15 = 3e6, and it was measured to fail from kL ≈ 22 (a hanging hose) and
#: 32 (a rod in tension).
STIFF_KL = 15.0


def tension_kl(pieces, tip, lengths, length: float, soft: float) -> np.ndarray:
    """kL per case (B,), estimated from the kernel's load channels (``pieces`` (B, P, C),
    ``tip`` (B, 12); ``lengths`` (P,) the pieces', ``length`` L, ``soft`` the largest
    bending compliance 1/EI of the arm): L √(F / EI), F the larger of the tip force and the
    sum of the distributed and point forces, each as the sum of its components' magnitudes
    (an upper bound of the tension anywhere). Not the actuators': a tendon's tension or a
    chamber's pressure is internal, it compresses the backbone (oscillating Jacobi fields,
    not growing ones), and single shooting was measured to solve a tendon robot at
    τL²/EI = 1e4. (The channels' layout is _kernels': FD, FF at 0-5, JD at 12, JF at 18; TD
    at 0, TF at 6. A control loop calls this once a solve: a few µs, not more.)"""
    if pieces.shape[0] == 1:  # one case (the control loop): Python floats, 4× faster
        along = points = 0.0
        for row, piece_length in zip(pieces[0, :, :21].tolist(), lengths.tolist(),
                                     strict=True):
            along += sum(abs(v) for v in row[0:6]) * piece_length
            points += sum(abs(v) for v in row[12:15]) + sum(abs(v) for v in row[18:21])
        t = tip[0].tolist()
        at_tip = sum(abs(v) for v in t[0:3]) + sum(abs(v) for v in t[6:9])
        return np.array([length * math.sqrt(max(at_tip, along + points) * soft)])
    forces = np.abs(pieces[..., :21])
    along = forces[..., 0:6].sum(-1) @ lengths
    points = forces[..., 12:15].sum((-1, -2)) + forces[..., 18:21].sum((-1, -2))
    tip = np.abs(tip)
    at_tip = tip[:, 0:3].sum(-1) + tip[:, 6:9].sum(-1)
    return length * np.sqrt(np.maximum(at_tip, along + points) * soft)
