"""Reference solutions written out from their sources, independent of softarm's own code.

Nothing here imports :mod:`softarm.analytic` or :mod:`softarm.statics`: these are the formulas
the validation compares softarm *against* (the paper's equations as corrected in
docs/closed-forms.md, C1-C9, and classical closed forms). Rotations use
:func:`scipy.linalg.expm` rather than :mod:`softarm.lie`, so a bug there cannot hide here.

Conventions: SI units, base clamped at the origin with R(0) = I, arm axis along +x.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

__all__ = [
    "helix_tip",
    "pure_bending",
    "rollup",
    "small_displacement_shear",
    "torsion_angle",
]


def _skew(w) -> np.ndarray:
    w = np.asarray(w, dtype=np.float64)
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def pure_bending(s, tau: float, EI: float) -> tuple[np.ndarray, np.ndarray]:
    """Circle of a tip moment τ about +y: positions (eq. 37) and section angles (eq. 38).

    Grazioso et al. 2018, eqs. 37-38 (eq. 38 as re-assembled in C5): with
    κ = τ/EI, p(s) = (sin(sκ)/κ, 0, -(1 - cos(sκ))/κ) and R(s) is a rotation about +y by sκ.

    Returns
    -------
    positions : ndarray, shape (N, 3), m
    angles : ndarray, shape (N,), rad, rotation of the section about +y.
    """
    s = np.asarray(s, dtype=np.float64)
    kappa = tau / EI
    x = s * np.sinc(s * kappa / np.pi)  # sin(sκ)/κ, also for κ = 0
    z = -0.5 * kappa * s**2 * np.sinc(s * kappa / (2 * np.pi)) ** 2  # -(1 - cos sκ)/κ
    return np.stack([x, np.zeros_like(s), z], axis=-1), s * kappa


def rollup(s, moment: float, EI: float) -> tuple[np.ndarray, np.ndarray]:
    """Circular arc under a tip moment M about +z (Simo & Vu-Quoc 1986, roll-up).

    x(s) = (EI/M) sin(sM/EI), y(s) = (EI/M)(1 - cos(sM/EI)) (rod_benchmarks.json,
    ``rollup_end_moment.analytic``); the section turns about +z by sM/EI.

    Returns positions (N, 3) in m and angles (N,) in rad.
    """
    positions, angles = pure_bending(s, moment, EI)
    x, _, z = np.moveaxis(positions, -1, 0)
    return np.stack([x, -z, np.zeros_like(x)], axis=-1), angles


def small_displacement_shear(s, P: float, L: float, EI: float, GA: float):
    """Small-displacement shear-load solution, Grazioso et al. 2018, eqs. 58-59.

    z(α) = α P/GA + (P L³/6EI)(3α²/L² - α³/L³) (eq. 58) and the section rotation about y
    θ(α) = -(P L²/EI)(α/L - α²/2L²) (eq. 59), for a tip force P along +z. x(α) = α.

    Returns
    -------
    z : ndarray, shape (N,), m
    theta : ndarray, shape (N,), rad
    """
    a = np.asarray(s, dtype=np.float64)
    z = a * P / GA + P * L**3 / (6 * EI) * (3 * a**2 / L**2 - a**3 / L**3)
    theta = -P * L**2 / EI * (a / L - a**2 / (2 * L**2))
    return z, theta


def torsion_angle(T: float, L: float, GJ: float) -> float:
    """Twist of a straight arm under an end torque T about its axis: φ = T L / GJ (rad)."""
    return T * L / GJ


def helix_tip(moment, L: float, B: float, GJ: float, follower: bool) -> tuple[np.ndarray,
                                                                               np.ndarray]:
    """Exact tip pose under an end moment for equal bending stiffnesses B (C4).

    With no force the spatial moment M is constant and
    R(s) = exp(s M/B) exp(s c e1), c = M₁(1/GJ - 1/B); the centreline is the translation part
    of exp_SE3(s [e1; M/B]), a helix about M. A dead moment gives M directly; a follower
    moment with material components g gives M = exp(L c e1) g, c from g₁ (= M₁).

    Returns the tip position (3,) in m and the tip rotation (3, 3).
    """
    g = np.asarray(moment, dtype=np.float64)
    c = g[0] * (1.0 / GJ - 1.0 / B)
    M = expm(L * c * _skew([1.0, 0.0, 0.0])) @ g if follower else g
    twist = np.zeros((4, 4))
    twist[:3, :3] = _skew(M / B)
    twist[:3, 3] = [1.0, 0.0, 0.0]
    H = expm(L * twist)
    R = H[:3, :3] @ expm(L * c * _skew([1.0, 0.0, 0.0]))
    return H[:3, 3], R
