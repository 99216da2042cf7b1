"""Every rotation-angle-dependent coefficient of the SO(3)/SE(3) maps, accurate for all θ.

Each coefficient is an even function of the rotation angle θ and is evaluated from θ² so that
callers never need a square root of a possibly-zero norm. Where a cancellation-free identity
exists it is used directly (``sinc``, ``cosc``). Otherwise the coefficient is evaluated by a
Horner series in θ² for θ < ``SERIES_LIMIT`` and by its closed form above it, switched without
branching on array values (``np.where`` with a safe argument), so there is no ad-hoc epsilon
anywhere.

The series coefficients are computed once, exactly, with :mod:`fractions`:

=========  ======================================  ==========================================
name       closed form                             Taylor coefficient of θ^(2k)
=========  ======================================  ==========================================
sinc       sin θ / θ                               (-1)^k / (2k+1)!
cosc       (1 - cos θ) / θ²                        (-1)^k / (2k+2)!
sinc3      (θ - sin θ) / θ³                        (-1)^k / (2k+3)!
jinv       1/θ² - (1 + cos θ) / (2 θ sin θ)        (-1)^k B_(2k+2) / (2k+2)!  (Bernoulli B)
tuw3       (2 cosc - sinc) / θ²                    (-1)^k (2k+2) / (2k+4)!
tuw4       (cosc - 3 sinc3) / θ²                   (-1)^(k+1) (2k+2) / (2k+5)!
=========  ======================================  ==========================================

With the paper's α = sinθ/θ and β = 2(1 - cosθ)/θ² (Grazioso et al. 2018, eq. 71):
α = ``sinc``, β/2 = ``cosc``, (1 - α)/θ² = ``sinc3``, (β - α)/θ² = ``tuw3`` and
(β/2 - 3(1 - α)/θ²)/θ² = ``tuw4`` (the coefficients of T_uω+, eqs. 74-75, corrected in C1 of
docs/closed-forms.md).
``jinv`` is the ω~² coefficient of the inverse SO(3) Jacobian; it is singular at θ = 2π, where
the exponential map itself is singular.
"""

from __future__ import annotations

from fractions import Fraction
from math import factorial

import numpy as np

__all__ = ["SERIES_LIMIT", "cosc", "jinv", "sinc", "sinc3", "tuw3", "tuw4"]

#: Angle below which the Horner series is used (rad). All series below converge to full
#: double precision here with ``_TERMS`` terms, while the closed forms lose at most a digit above.
SERIES_LIMIT = 3.0
_TERMS = 30


def _bernoulli(n: int) -> Fraction:
    """Bernoulli number B_n (B_1 = -1/2 convention), exactly."""
    b = [Fraction(1)]
    for m in range(1, n + 1):
        b.append(-sum(Fraction(factorial(m + 1), factorial(j) * factorial(m + 1 - j)) * b[j]
                      for j in range(m)) / (m + 1))
    return b[n]


def _coefficients(term) -> np.ndarray:
    return np.array([float(term(k)) for k in range(_TERMS)])


_SINC3 = _coefficients(lambda k: Fraction((-1) ** k, factorial(2 * k + 3)))
_JINV = _coefficients(lambda k: (-1) ** k * _bernoulli(2 * k + 2) / factorial(2 * k + 2))
_TUW3 = _coefficients(lambda k: Fraction((-1) ** k * (2 * k + 2), factorial(2 * k + 4)))
_TUW4 = _coefficients(lambda k: Fraction((-1) ** (k + 1) * (2 * k + 2), factorial(2 * k + 5)))


def _horner(coefficients: np.ndarray, x: np.ndarray) -> np.ndarray:
    out = np.full_like(x, coefficients[-1])
    for c in coefficients[-2::-1]:
        out = out * x + c
    return out


def _switch(theta2, series, closed_form):
    """Series for θ < SERIES_LIMIT, ``closed_form(θ, θ²)`` otherwise, branch-free."""
    theta2 = np.asarray(theta2, dtype=np.float64)
    small = theta2 < SERIES_LIMIT**2
    theta2_safe = np.where(small, SERIES_LIMIT**2, theta2)
    theta_safe = np.sqrt(theta2_safe)
    return np.where(small, _horner(series, theta2), closed_form(theta_safe, theta2_safe))


def sinc(theta2):
    """sin θ / θ as a function of θ², exact at θ = 0 (paper's α, eq. 71)."""
    theta = np.sqrt(np.asarray(theta2, dtype=np.float64))
    return np.sinc(theta / np.pi)


def cosc(theta2):
    """(1 - cos θ)/θ² as a function of θ², by the half-angle identity ½ sinc²(θ/2) (β/2)."""
    theta = np.sqrt(np.asarray(theta2, dtype=np.float64))
    return 0.5 * np.sinc(theta / (2 * np.pi)) ** 2


def sinc3(theta2):
    """(θ - sin θ)/θ³ as a function of θ² (the paper's (1 - α)/θ², eqs. 73-74)."""
    return _switch(theta2, _SINC3, lambda t, t2: (t - np.sin(t)) / (t2 * t))


def jinv(theta2):
    """1/θ² - (1 + cos θ)/(2 θ sin θ): ω~² coefficient of the inverse SO(3) Jacobian.

    Above the series range it is evaluated as 1/θ² - 1/(2 θ tan(θ/2)) (the same value, since
    (1 + cos θ)/sin θ = cot(θ/2)): 1 + cos θ cancels near θ = π and 1 - cos θ near θ = 2π, while
    tan(θ/2) is accurate on the whole range (θ/2 is exact).
    """
    return _switch(theta2, _JINV, lambda t, t2: 1.0 / t2 - 1.0 / (2.0 * t * np.tan(0.5 * t)))


def tuw3(theta2):
    """(β - α)/θ² = (2 (1 - cos θ)/θ² - sin θ/θ)/θ², a coefficient of T_uω+ (eq. 75)."""
    return _switch(theta2, _TUW3, lambda t, t2: (2.0 * (1.0 - np.cos(t)) / t2 - np.sin(t) / t) / t2)


def tuw4(theta2):
    """(β/2 - 3(1 - α)/θ²)/θ², a coefficient of T_uω+ (eq. 75)."""
    return _switch(
        theta2,
        _TUW4,
        lambda t, t2: ((1.0 - np.cos(t)) / t2 - 3.0 * (t - np.sin(t)) / (t2 * t)) / t2,
    )
