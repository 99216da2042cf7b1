"""The θ-dependent coefficients of softarm.lie._series against high-precision mpmath.

Each coefficient takes θ²; the reference evaluates the closed form of the same coefficient at
the exact binary value of that θ² in mpmath with 120 working digits. The closed forms cancel
catastrophically for small θ (tuw4 loses about 4·|log10 θ| digits: 32 at θ = 1e-8), so 120
working digits leave more than 40 correct ones everywhere sampled; ``test_reference_has_40_digits``
checks that claim.

Accuracy is stated in units of the double-precision machine epsilon (2⁻⁵² ≈ 2.2e-16) and scaled
by the condition number cond = |θ² f'(θ²)/f| of the coefficient as a function of its argument:
an error of half an ulp in θ² (or in the θ = √θ² every evaluation needs) is amplified by cond,
and no implementation working in double precision can do better. On [0, π] only sinc is
ill-conditioned (cond = ½|θ cot θ - 1|: 38 at θ = 3.1, 1.6e8 at π - 1e-8, since sin θ → 0); the
others have cond < 1 there. A few angles in (π, 2π) are sampled too (rotation vectors of segment
twists can exceed π); towards 2π every coefficient but sinc3 and tuw4 is ill-conditioned (jinv
is singular at 2π).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from softarm.lie import _series

EPS = np.finfo(np.float64).eps
DIGITS = 120

# Worst relative error / (EPS · max(1, cond)) measured on the sample below and on 3000 further
# random θ in [1e-8, 3.1]: sinc 0.77, cosc 1.64, sinc3 0.94, jinv 0.99, tuw3 1.70, tuw4 4.47
# (tuw4's closed form just above the switch: (1-cos θ)/θ² - 3(θ - sin θ)/θ³ cancels by ~3x).
BOUND_EPS = {"sinc": 1.0, "cosc": 2.0, "sinc3": 1.5, "jinv": 1.5, "tuw3": 2.0, "tuw4": 5.0}


def closed_form(name: str, theta2):
    """The coefficient's closed form in mpmath at the exact value θ² (the _series docstring)."""
    x = mpmath.mpf(theta2)
    t = mpmath.sqrt(x)
    s, c = mpmath.sin(t), mpmath.cos(t)
    return {
        "sinc": lambda: s / t,
        "cosc": lambda: (1 - c) / x,
        "sinc3": lambda: (t - s) / (x * t),
        "jinv": lambda: 1 / x - (1 + c) / (2 * t * s),
        "tuw3": lambda: (2 * (1 - c) / x - s / t) / x,
        "tuw4": lambda: ((1 - c) / x - 3 * (t - s) / (x * t)) / x,
    }[name]()


def sample_angles() -> np.ndarray:
    limit = _series.SERIES_LIMIT
    around_switch = [np.nextafter(limit, 0.0), limit, np.nextafter(limit, 4.0)]
    around_switch += list(limit + np.arange(-4, 5) * 1e-6) + list(limit + np.arange(-4, 5) * 1e-3)
    near_pi = [3.1, 3.14, np.pi - 1e-4, np.pi - 1e-8, np.pi]
    beyond_pi = [4.0, 5.0, 6.0, 2 * np.pi - 1e-3, 2 * np.pi - 1e-6]
    return np.unique(np.concatenate([np.logspace(-8, np.log10(3.1), 150), around_switch,
                                     near_pi, beyond_pi]))


THETA = sample_angles()


@pytest.mark.parametrize("name", sorted(BOUND_EPS))
def test_coefficient_against_mpmath(name):
    function = getattr(_series, name)
    theta2 = THETA**2
    values = function(theta2)
    assert values.shape == theta2.shape and values.dtype == np.float64
    worst = 0.0
    with mpmath.workdps(DIGITS):
        for value, x in zip(values, theta2, strict=True):
            reference = closed_form(name, x)
            slope = mpmath.diff(lambda y: closed_form(name, y), mpmath.mpf(x))
            cond = float(abs(mpmath.mpf(x) * slope / reference))
            error = float(abs((mpmath.mpf(value) - reference) / reference))
            scaled = error / (EPS * max(1.0, cond))
            worst = max(worst, scaled)
            assert scaled <= BOUND_EPS[name], (
                f"{name}(θ={np.sqrt(x)!r}): relative error {error:.3e} = {error / EPS:.2f} eps, "
                f"cond {cond:.3g}"
            )
    # The bound is honest, not loose: the worst case uses a fair share of it.
    assert worst > BOUND_EPS[name] / 8


@pytest.mark.parametrize("name", sorted(BOUND_EPS))
def test_scalar_and_zero(name):
    # Limits at θ = 0 from the Taylor coefficients in the _series docstring table:
    # sinc 1, cosc 1/2!, sinc3 1/3!, jinv B_2/2! = 1/12, tuw3 2/4!, tuw4 -2/5!.
    at_zero = {"sinc": 1.0, "cosc": 0.5, "sinc3": 1 / 6, "jinv": 1 / 12, "tuw3": 1 / 12,
               "tuw4": -1 / 60}
    value = getattr(_series, name)(0.0)
    assert np.shape(value) == ()
    assert value == pytest.approx(at_zero[name], rel=EPS)


def test_reference_has_40_digits():
    # The worst cancellation sampled (tuw4 at θ = 1e-8) agrees between 120 and 160 digits to 40.
    x = 1e-8**2
    with mpmath.workdps(DIGITS):
        low = closed_form("tuw4", x)
    with mpmath.workdps(DIGITS + 40):
        high = closed_form("tuw4", x)
        assert abs((low - high) / high) < mpmath.mpf(10) ** -40
