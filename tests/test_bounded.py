"""The compiled bounded least-squares step (``softarm.statics._bounded``) against scipy's
bounded-variable least squares (``scipy.optimize.lsq_linear(method="bvls")``, an independent
implementation) on random problems: boxes with finite and infinite sides, columns scaled over
orders of magnitude, square and tall A."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from softarm.statics._bounded import box_least_squares, regularised_step


def _problem(rng):
    n = int(rng.integers(1, 8))
    m = n + int(rng.integers(0, 8))
    A = rng.normal(size=(m, n)) * np.exp(2.0 * rng.normal(size=n))
    b = 3.0 * rng.normal(size=m)
    lower, upper = -rng.uniform(0.0, 2.0, n), rng.uniform(0.0, 2.0, n)
    lower[rng.random(n) < 0.3] = -np.inf
    upper[rng.random(n) < 0.3] = np.inf
    return A, b, lower, upper


@pytest.mark.parametrize("seed", range(4))
def test_box_least_squares_matches_scipy_bvls(seed):
    rng = np.random.default_rng(seed)
    for _ in range(100):
        A, b, lower, upper = _problem(rng)
        x = box_least_squares(A, b, lower, upper)
        reference = lsq_linear(A, b, bounds=(lower, upper), method="bvls", tol=1e-14).x
        assert np.all((lower <= x) & (x <= upper))
        cost = np.sum((A @ x - b) ** 2)
        assert cost <= np.sum((A @ reference - b) ** 2) + 1e-11 * np.sum(b**2)
        np.testing.assert_allclose(x, reference, rtol=0.0,
                                   atol=1e-8 * (1.0 + np.max(np.abs(reference))))


def test_box_least_squares_without_bounds_is_least_squares():
    rng = np.random.default_rng(7)
    A, b = rng.normal(size=(9, 4)), rng.normal(size=9)
    x = box_least_squares(A, b, np.full(4, -np.inf), np.full(4, np.inf))
    np.testing.assert_allclose(x, np.linalg.lstsq(A, b, rcond=None)[0], rtol=1e-12, atol=1e-13)


def test_box_least_squares_with_all_variables_at_bounds():
    """The unconstrained optimum (2, -3) lies outside the box [0, 1]²: the answer is the
    box corner (1, 0), each variable's slope pointing out of the box."""
    A, b = np.eye(2), np.array([2.0, -3.0])
    x = box_least_squares(A, b, np.zeros(2), np.ones(2))
    np.testing.assert_array_equal(x, [1.0, 0.0])


@pytest.mark.parametrize("seed", range(3))
def test_regularised_step_matches_scipy_on_the_stacked_system(seed):
    """inverse statics' step: the stacked system [J s; √μ σ I; √ε σ I] δu ≈ [b; 0; -√ε σ u]
    built here with numpy and solved by scipy's bvls, against the compiled build and solve."""
    rng = np.random.default_rng(10 + seed)
    for _ in range(50):
        n = int(rng.integers(1, 7))
        m = int(rng.integers(1, 7))
        J, b = rng.normal(size=(m, n)), rng.normal(size=m)
        scales = np.exp(rng.normal(size=n))
        q = rng.uniform(0.0, 2.0, n)
        lower, upper = np.zeros(n), np.where(rng.random(n) < 0.5, np.inf, 2.5)
        mu = 0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-4, 0)
        Js = J * scales
        sigma = np.sqrt(np.sum(Js**2))
        rows = np.vstack([Js, np.sqrt(mu) * sigma * np.eye(n), 1e-6 * sigma * np.eye(n)])
        rhs = np.concatenate([b, np.zeros(n), -1e-6 * sigma * q / scales])
        reference = lsq_linear(rows, rhs, bounds=(lower / scales - q / scales,
                                                  upper / scales - q / scales),
                               method="bvls", tol=1e-14).x * scales
        step = regularised_step(J, b, q, scales, mu, lower, upper)
        assert np.all((lower <= q + step + 1e-15) & (q + step <= upper + 1e-15))
        np.testing.assert_allclose(step, reference, rtol=0.0,
                                   atol=1e-8 * (1.0 + np.max(np.abs(reference))))


def test_the_step_of_a_task_that_is_not_redundant_has_no_effort_term(rng):
    # regularised_step(redundant=False): min |J s δu - b|² + μ σ² |δu|² in the box, without
    # the ε σ² |u + δu|² rows (scipy's bvls on that stacked system: the reference)
    for _ in range(30):
        n = int(rng.integers(1, 5))
        m = n + int(rng.integers(0, 3))  # (a full-rank, not redundant task)
        J, b = rng.normal(size=(m, n)), rng.normal(size=m)
        scales = np.exp(2.0 * rng.normal(size=n))
        q = rng.uniform(0.0, 2.0, n)
        lower, upper = np.zeros(n), np.full(n, 2.5)
        mu = 0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-4, 0)
        Js = J * scales
        sigma = np.sqrt(np.sum(Js**2))
        rows = np.vstack([Js, np.sqrt(mu) * sigma * np.eye(n)])
        rhs = np.concatenate([b, np.zeros(n)])
        reference = lsq_linear(rows, rhs, bounds=(lower / scales - q / scales,
                                                  upper / scales - q / scales),
                               method="bvls", tol=1e-14).x * scales
        step = regularised_step(J, b, q, scales, mu, lower, upper, redundant=False)
        np.testing.assert_allclose(step, reference, rtol=0.0,
                                   atol=1e-8 * (1.0 + np.max(np.abs(reference))))
