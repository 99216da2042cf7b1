"""Checks of the hard-contact pin reference (tests/_pin_reference.py), as contact_refs asks.

The soft arm (L = 0.5 m, r = 1 cm, E = 1 MPa, G = E/3, its weight w = 3.08 N/m) clamped along
+x, a pin of radius 5 mm under it at x_p = 0.6 L, touching the straight arm (gap0 = 0), a
dead tip force P = 0.1 N downwards. Measured (this file's solves):

* the wrap is [0.3054789, 0.3057091] m, 0.23 mm long (≈ ρ F/GA: the two edge zones merged,
  see the module docstring), pressure 6186-6187 N/m; the pin's force on the arm
  (0.4640, 0, 1.3466) N, its moment about the origin 0.4110 N m (about −y); the tip at
  (0.449947, 0, −0.127359) m;
* refinement (solve_bvp tol 1e-8, 401 nodes, against 1e-10, 1718 nodes): 1.5e-12 m in the
  positions, 3e-13 m in the wrap's ends;
* the penalty solution (whole arm, no zones) against the hard one, largest position difference
  over the arm: k = 1e8 7.2e-5 m, 1e9 9.1e-6 m, 1e10 1.03e-6 m, 1e11 1.04e-7 m (N/m²): the
  rate in 1/k grows from 0.90 to 0.996 towards 1 (the penalty's edge layers, of width
  √(GA/k), are not yet small against the wrap at 1e9); the penalty's own error ~2e-10 m;
  the pin's force from the penalty's balance differs by 2.2e-4 .. 3.2e-7 N;
* global balance to round-off; the pressure > 0 and the gap ≥ 0 everywhere.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from _pin_reference import pin_penalty, pin_reference, soft_arm

ARM = soft_arm()
L = ARM["L"]
R_PIN = 0.005  # m
X_P = 0.6 * L  # m


def _args(P=0.1, gap0=0.0):
    return (L, ARM["EA"], ARM["GA"], ARM["EI"], ARM["r"], ARM["w"], P, R_PIN, X_P,
            -(R_PIN + ARM["r"]) - gap0)


@pytest.fixture(scope="module")
def hard():
    return pin_reference(*_args())


@pytest.fixture(scope="module")
def pressed():
    """A harder push from a gap: P = 0.2 N, the straight arm 2 mm above the pin."""
    return pin_reference(*_args(0.2, 0.002))


@pytest.fixture(scope="module")
def penalties():
    """Penalty solutions for k = 1e8 .. 1e11 N/m², each started from the softer one."""
    out, pen = {}, pin_penalty(*_args(), 1e7)
    for k in (1e8, 1e9, 1e10, 1e11):
        pen = out[k] = pin_penalty(*_args(), k, softer=pen)
    return out


STATIONS = np.linspace(0.0, L, 4001)


@pytest.mark.slow
def test_refinement_moves_nothing(hard):
    fine = pin_reference(*_args(), tol=1e-10)
    assert fine.nodes > 3 * hard.nodes  # a real refinement (measured 1718 against 401)
    assert np.max(np.abs(fine.positions(STATIONS) - hard.positions(STATIONS))) < 1e-10
    assert np.max(np.abs(np.subtract(fine.wrap, hard.wrap))) < 1e-10
    assert np.max(np.abs(fine.contact_force - hard.contact_force)) < 1e-9


@pytest.mark.slow
def test_penalty_converges_to_the_hard_contact_at_rate_one(hard, penalties):
    errors = {k: np.max(np.abs(pen.positions(STATIONS) - hard.positions(STATIONS)))
              for k, pen in penalties.items()}
    ks = sorted(errors)
    rates = [np.log10(errors[a] / errors[b]) for a, b in itertools.pairwise(ks)]
    # measured 7.2e-5, 9.1e-6, 1.03e-6, 1.04e-7 m; rates 0.90, 0.94, 0.99
    assert errors[1e11] < 1.5e-7
    assert all(0.85 < rate < 1.1 for rate in rates)
    assert rates[-1] > 0.95  # O(1/k) once the penalty's edge layers are thin
    # the penalty's own discretisation error is far below what it is compared to (tol 7e-7:
    # the tightest that every machine reaches, _pin_reference.pin_penalty)
    tighter = pin_penalty(*_args(), 1e10, softer=penalties[1e10], tol=7e-7)
    own = np.max(np.abs(tighter.positions(STATIONS) - penalties[1e10].positions(STATIONS)))
    assert own < 1e-3 * errors[1e10]
    # the pin's force, from each penalty solution's own balance (clamp reaction, weight, tip)
    P, w = 0.1, ARM["w"]
    force = {k: pen.state(0.0)[3:5, 0] + np.array([0.0, w * L + P])
             for k, pen in penalties.items()}
    gaps = [np.max(np.abs(force[k] - hard.contact_force[[0, 2]])) for k in ks]
    assert gaps[-1] < 1e-6  # N; measured 2.2e-4, 2.8e-5, 3.2e-6, 3.2e-7 for k = 1e8 .. 1e11
    assert all(a > 5.0 * b for a, b in itertools.pairwise(gaps))


def _arm_quadrature(ref, points=200):
    """Gauss-Legendre stations and weights on each of the three zones (smooth in each)."""
    x, w = np.polynomial.legendre.leggauss(points)
    ends = [0.0, *ref.wrap, ref.length]
    s = np.concatenate([a + (b - a) * (x + 1) / 2 for a, b in itertools.pairwise(ends)])
    wts = np.concatenate([w * (b - a) / 2 for a, b in itertools.pairwise(ends)])
    return s, wts


@pytest.mark.parametrize("case, P", [("hard", 0.1), ("pressed", 0.2)])
def test_global_force_and_moment_balance(case, P, request):
    ref = request.getfixturevalue(case)
    w = ARM["w"]
    tip_force = np.array([0.0, 0.0, -P])
    clamp_force = -ref.internal_force(0.0)[0]
    weight = np.array([0.0, 0.0, -w * L])
    residual = clamp_force + weight + ref.contact_force + tip_force
    assert np.max(np.abs(residual)) < 1e-9 * np.linalg.norm(ref.contact_force)
    # moments about the origin, about −y: x F_z − z F_x
    s, wts = _arm_quadrature(ref)
    weight_moment = np.sum(wts * ref.positions(s)[:, 0] * (-w))
    tip = ref.tip
    moment = (-ref.internal_moment(0.0)[0] + weight_moment + ref.contact_moment
              + tip[0] * tip_force[2] - tip[2] * tip_force[0])
    assert abs(moment) < 1e-9 * abs(ref.contact_moment)


@pytest.mark.parametrize("case", ["hard", "pressed"])
def test_pressure_positive_no_penetration_and_on_the_circle(case, request):
    ref = request.getfixturevalue(case)
    a, b = ref.wrap
    on = np.linspace(a, b, 201)
    assert np.min(ref.pressure(on)) > 0.0
    # no penetration on the free arms, sampled finely right up to the wrap's ends
    near = np.concatenate([a - np.geomspace(1e-9, 0.05, 400), b + np.geomspace(1e-9, 0.05, 400)])
    free = np.concatenate([STATIONS[(STATIONS < a) | (STATIONS > b)], near])
    assert np.min(ref.gap(free)) > -1e-12
    # equation (P) keeps the constitutive tangent on the circle's tangent all along the wrap
    t = ref.tangent(on)
    normal = ref.normal(on)[:, [0, 2]]
    assert np.max(np.abs(np.sum(t * normal, axis=-1))) < 1e-9


def test_short_wrap_matches_the_merged_edge_zone_estimate(hard):
    """Module docstring: c ≈ GA (1/ρ + m/EI) up to O(n/EA) and O((w + |m n|/EI)/c), here
    ~5e-3 (measured 2.4e-3), on a wrap far shorter than √(EI/GA), with |m| ≪ EI/ρ."""
    EI, GA, rho = ARM["EI"], ARM["GA"], R_PIN + ARM["r"]
    on = np.linspace(*hard.wrap, 51)
    estimate = GA * (1.0 / rho + hard.internal_moment(on) / EI)
    assert np.max(np.abs(hard.pressure(on) / estimate - 1.0)) < 1e-2
    assert np.diff(hard.wrap)[0] < 0.05 * np.sqrt(EI / GA)
    assert np.max(np.abs(hard.internal_moment(on))) < 0.2 * EI / rho


def test_an_arm_that_misses_the_pin_is_refused():
    args = list(_args())
    args[-1] = -0.5  # the arm cannot reach 0.5 m down at x = 0.3 m
    with pytest.raises(ValueError, match="does not touch the pin"):
        pin_reference(*args)
