"""The compiled closed forms for one load (analytic/_compiled.py) against independent references.

The elliptic functions against 40-digit mpmath, the screw poses against scipy's matrix
exponential; the compiled elastica against the numpy batch route is in
test_elastica_math.py (test_one_load_route_equals_batch_route).
"""

from __future__ import annotations

import math
import subprocess
import sys

import mpmath as mp
import numpy as np
import pytest
from scipy.linalg import expm

from softarm.analytic import _compiled, _elastica_math
from softarm.analytic._elastica_math import planar_elastica

mp.mp.dps = 40


def _hat(xi):
    """se(3) 4×4 matrix of (u; ω), linear part first."""
    u, w = xi[:3], xi[3:]
    out = np.zeros((4, 4))
    out[:3, :3] = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
    out[:3, 3] = u
    return out


def _arguments(rng, count):
    """x, y ≥ 0 over many decades (zeros included) and z > 0, as the elastica meets them."""
    x = 10.0 ** rng.uniform(-30, 0, count)
    y = rng.uniform(0.0, 1.0, count)
    z = 10.0 ** rng.uniform(-12, 0, count)
    x[:5] = 0.0
    return x, y, z


def test_carlson_rf_against_mpmath(rng):
    for x, y, z in zip(*_arguments(rng, 200), strict=True):
        for args in ((x, y, 1.0), (x, z, y + 1e-3), (z, z, z)):
            want = float(mp.elliprf(*(mp.mpf(float(v)) for v in args)))
            assert _compiled.carlson_rf(*args) == pytest.approx(want, rel=2e-15, abs=0.0)


def test_carlson_rd_against_mpmath(rng):
    for x, y, z in zip(*_arguments(rng, 200), strict=True):
        for args in ((x, 1.0, z), (x, y + 1e-3, 1.0), (z, z, z)):
            want = float(mp.elliprd(*(mp.mpf(float(v)) for v in args)))
            assert _compiled.carlson_rd(*args) == pytest.approx(want, rel=2e-15, abs=0.0)


def test_carlson_integrals_diverge_where_two_arguments_vanish():
    """R_F with two zero arguments, R_D with x = y = 0 or z = 0: +inf, their limit (mpmath's
    value there), returned at once; the duplication never ended there (a tip-condition
    Newton step that left the range, cosh ρ overflowing, hung the planar elastica). Beside
    those points both stay finite and equal mpmath's, growing as the arguments vanish."""
    for args in ((0.0, 0.0, 1.0), (0.0, 2.0, 0.0), (3.0, 0.0, 0.0)):
        assert _compiled.carlson_rf(*args) == math.inf == float(mp.elliprf(*args))
    for args in ((0.0, 0.0, 1.0), (1.0, 2.0, 0.0)):
        assert _compiled.carlson_rd(*args) == math.inf == float(mp.elliprd(*args))
    previous = 0.0
    for tiny in (1e-10, 1e-100, 1e-300, 5e-324):
        value = _compiled.carlson_rf(tiny, tiny, 1.0)
        assert value == pytest.approx(float(mp.elliprf(tiny, tiny, 1.0)), rel=2e-15)
        assert previous < value < math.inf
        previous = value
        assert _compiled.carlson_rd(tiny, tiny, 1.0) == pytest.approx(
            float(mp.elliprd(tiny, tiny, 1.0)), rel=2e-15)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-3, 1e-9, 1e-16, 0.0])
def test_jacobi_sn_cn_against_mpmath(mc):
    # a start for Newton's method: documented to about 1e-12 for u <= 12 (the kernel's range)
    scratch = np.empty(17)
    for u in np.linspace(0.0, 12.0, 25):
        sn, cn = _compiled.jacobi_sn_cn(u, mc, scratch)
        m = 1 - mp.mpf(mc)
        assert sn == pytest.approx(float(mp.ellipfun("sn", u, m=m)), abs=1e-11)
        assert cn == pytest.approx(float(mp.ellipfun("cn", u, m=m)), abs=1e-11)


@pytest.mark.parametrize("mc", [0.7, 1e-2, 1e-6])
def test_taylor_start_is_fifth_order(mc):
    # χ(u + h) predicted from am(u) errs by O(h⁵): halving h divides the error by ~32
    m = 1 - mp.mpf(mc)
    errors = []
    for h in (0.2, 0.1, 0.05):
        u = 0.8
        sn, cn = (float(mp.ellipfun(f, u, m=m)) for f in ("sn", "cn"))
        rho = _compiled._taylor_start(h, sn, cn, mc)
        want = mp.log(mp.ellipfun("sn", u + h, m=m) / mp.ellipfun("cn", u + h, m=m))
        errors.append(abs(rho - float(want)))
    assert errors[2] < 1e-6
    assert errors[0] / errors[1] > 16 and errors[1] / errors[2] > 16


@pytest.mark.parametrize("twist", [0.0, 0.7, -2.3])
def test_screw_against_the_matrix_exponential(twist, rng):
    # H(s) = exp(s (u; ω)^) exp(s (0; τ e1)^), and the extra columns Σ b_y(τ s) extra[y]
    s = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 2.0, 9))])
    for omega in (rng.normal(size=3), np.zeros(3), np.array([0.0, 0.0, 1e-9])):
        u = rng.normal(size=3)
        extra = rng.normal(size=(3, 5))
        out = np.empty((s.size, 21))
        _compiled.screw(u, omega, twist, s, extra, out)
        for j, sj in enumerate(s):
            want = expm(sj * _hat(np.concatenate([u, omega]))) @ expm(
                sj * _hat(np.array([0.0, 0.0, 0.0, twist, 0.0, 0.0])))
            # expm (scaling and squaring) itself errs by ~1e-14 at angles of a few rad
            np.testing.assert_allclose(out[j, :16].reshape(4, 4), want, rtol=0, atol=1e-13)
            b = np.array([1.0, 1.0 - np.cos(twist * sj), np.sin(twist * sj)])
            np.testing.assert_allclose(out[j, 16:], b @ extra, rtol=0, atol=1e-14)


def test_station_order_does_not_matter(rng):
    # the compiled route starts each station from the last one solved: any order, the same
    # roots (to a few ulps) as in increasing order
    s = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, 30)), [1.0]])
    order = rng.permutation(s.size)
    for k, phi, ratios in [(3.0, 1.9, (0.0, 0.0)), (40.0, 2.5, (0.002, 0.01)),
                           (300.0, 0.4, (0.0, 0.0))]:
        ahead = planar_elastica(k, phi, s, axial_ratio=ratios[0], shear_ratio=ratios[1])
        mixed = planar_elastica(k, phi, s[order], axial_ratio=ratios[0],
                                shear_ratio=ratios[1])
        for got, want in zip(mixed[:-1], ahead[:-1], strict=True):
            scale = max(1.0, float(np.max(np.abs(want))))
            np.testing.assert_allclose(got, want[order], rtol=0, atol=2e-14 * scale)


def test_constants_agree_with_the_batch_route():
    # restated in _compiled.py (numba's cache sees that file only)
    assert _compiled._RHO_MAX == _elastica_math._RHO_MAX
    assert _compiled._MAX_STEPS == _elastica_math._MAX_STEPS
    assert _compiled._EPS == np.finfo(np.float64).eps


def test_import_softarm_does_not_import_numba():
    code = "import sys, softarm, softarm.analytic; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["False"]
