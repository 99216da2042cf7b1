"""Which load cases are stiff: where single shooting's map grows like e^{kL} beyond what
double precision carries, and the multiple-shooting route (``_kernels.solve_stiff_cases``)
takes them (docs/solver.md, "Multiple shooting")."""

from __future__ import annotations

import numpy as np

__all__ = ["STIFF_KL", "tension_kl"]

#: Cases whose estimated kL = L √(F/EI) (F the largest load's force, EI the softest bending
#: stiffness) reaches this go to multiple shooting: at kL = 15 single shooting's tangents
#: have grown by e^15 = 3e6, and it was measured to fail from kL ≈ 22 (a hanging hose) and
#: 32 (a rod in tension).
STIFF_KL = 15.0


def tension_kl(k, pieces, tip, arm) -> np.ndarray:
    """kL per case, estimated from the kernel's load channels (``pieces`` (B, P, C), ``tip``
    (B, 12); ``k`` the kernel module) (B,): L √(F / EI_min), F the larger of the tip
    force and the sum of the distributed and point forces, each as the sum of its
    components' magnitudes (an upper bound of the tension anywhere). Not the actuators': a
    tendon's tension or a chamber's pressure is internal, it compresses the backbone
    (oscillating Jacobi fields, not growing ones), and single shooting was measured to solve
    a tendon robot at τL²/EI = 1e4. ``arm``: the kernel's (arm, act) pair."""
    lengths = arm[0][1]
    f_tip = np.abs(tip[:, k.TD:k.TD + 3]).sum(-1) + np.abs(tip[:, k.TF:k.TF + 3]).sum(-1)
    f_along = (np.abs(pieces[:, :, k.FD:k.FD + 3]).sum(-1)
               + np.abs(pieces[:, :, k.FF:k.FF + 3]).sum(-1)) @ lengths
    f_points = (np.abs(pieces[:, :, k.JD:k.JD + 3]).sum(-1)
                + np.abs(pieces[:, :, k.JF:k.JF + 3]).sum(-1)).sum(-1)
    force = np.maximum(f_tip, f_along + f_points)
    C = arm[0][2]
    soft = float(np.max(C[:, [4, 5], [4, 5]]))
    return arm[0][6] * np.sqrt(force * soft)
