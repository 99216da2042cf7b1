"""Exact planar cantilever (elliptic integrals) against published tables and a shooting solver."""

from __future__ import annotations

import json
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from softarm.analytic import _elastica_math
from softarm.analytic._elastica_math import K_MAX, planar_elastica
from softarm.validation import reference_table


def _table(name):
    return reference_table(name)  # softarm/validation/data, shipped with the package


def shoot(k, phi, s, axial_ratio=0.0, shear_ratio=0.0, *, kappa0_guess):
    """Independent reference: forward shooting of the planar Reissner rod with solve_ivp.

    State (θ, m = θ', x, z); the dead force n = k (cos φ, sin φ) is resolved on the material frame,
    the strains follow from the linear law, r' = (1 + ε) d1 + γ d3 and m' = −(r' × n). The clamp
    curvature is found by Brent's method so that m(1) = 0, in a bracket around ``kappa0_guess``.
    """
    n = k * np.array([np.cos(phi), np.sin(phi)])

    def rhs(_, y):
        theta, m = y[0], y[1]
        d1 = np.array([np.cos(theta), np.sin(theta)])
        d3 = np.array([-np.sin(theta), np.cos(theta)])
        r_prime = (1.0 + axial_ratio * (n @ d1)) * d1 + shear_ratio * (n @ d3) * d3
        return [m, -(r_prime[0] * n[1] - r_prime[1] * n[0]), r_prime[0], r_prime[1]]

    def run(m0):
        return solve_ivp(
            rhs,
            (0.0, 1.0),
            [0.0, m0, 0.0, 0.0],
            method="DOP853",
            rtol=1e-12,
            atol=1e-14,
            dense_output=True,
        )

    lo, hi = 0.9 * kappa0_guess - 1e-3, 1.1 * kappa0_guess + 1e-3
    m0 = brentq(lambda m0: run(m0).y[1, -1], lo, hi, xtol=1e-15, rtol=1e-15)
    return run(m0).sol(s)


# --------------------------------------------------------------------------------------------
# Published and tabulated references
# --------------------------------------------------------------------------------------------
def test_mattiasson_table_every_k():
    # Mattiasson (1981) Table 1 / Bisshopp & Drucker (1945), recomputed to 8 digits:
    # softarm/validation/data/mattiasson_cantilever.json "computed_here"."table".
    rows = _table("mattiasson_cantilever.json")["computed_here"]["table"]
    k = np.array([row["k"] for row in rows])
    sol = planar_elastica(k, np.pi / 2, np.array([0.0, 1.0]))
    np.testing.assert_allclose(sol.z[:, -1], [r["w_over_L"] for r in rows], rtol=0, atol=1e-7)
    np.testing.assert_allclose(1 - sol.x[:, -1], [r["u_over_L"] for r in rows], rtol=0, atol=1e-7)
    np.testing.assert_allclose(
        sol.tip_angle, [r["tip_rotation_rad"] for r in rows], rtol=0, atol=1e-7
    )
    np.testing.assert_allclose(sol.x[:, -1], [r["x_tip_over_L"] for r in rows], rtol=0, atol=1e-7)


def test_mattiasson_published_five_digits():
    # Mattiasson (1981) Table 1 as quoted (5 digits) in public test suites:
    # softarm/validation/data/mattiasson_cantilever.json "found_values"[0].
    found = _table("mattiasson_cantilever.json")["found_values"][0]["values"]
    k = np.array([float(key) for key in found])
    sol = planar_elastica(k, np.pi / 2, np.array([1.0]))
    for i, values in enumerate(found.values()):
        assert abs(sol.z[i, -1] - values["w_over_L"]) <= 5e-6
        assert abs(1 - sol.x[i, -1] - values["u_over_L"]) <= 5e-6


@pytest.mark.parametrize("case", range(3))
def test_shear_deformable_tip_force(case):
    # softarm/validation/data/rod_benchmarks.json "shear_deformable_tip_force" (OpenSees gallery
    # FrameCircle: L = 1, EI = 10, EA = 1e8, F = 10 so k = 1; GA = 500, 10, inf), values
    # "computed_here" by an independent shooting solution.
    bench = _table("rod_benchmarks.json")["shear_deformable_tip_force"]
    params, row = bench["found"]["params"], bench["computed_here"][case]
    ei = params["E"] * params["I"]
    ea = params["E"] * params["A"]
    ga = float(row["GA"])
    k = params["F"] * params["L"] ** 2 / ei
    sol = planar_elastica(
        k,
        np.pi / 2,
        np.array([0.0, 1.0]),
        axial_ratio=ei / (ea * params["L"] ** 2),
        shear_ratio=ei / (ga * params["L"] ** 2),
    )
    assert abs(sol.x[-1] - row["tip_x"]) <= 1e-7
    assert abs(sol.z[-1] - row["tip_transverse"]) <= 1e-7
    assert abs(sol.tip_angle - row["tip_rotation_rad"]) <= 1e-7


# --------------------------------------------------------------------------------------------
# Second numerical method
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("phi_deg", [30.0, 60.0, 120.0, 170.0, -45.0])
@pytest.mark.parametrize("k", [0.5, 3.0, 10.0])
@pytest.mark.parametrize("ratios", [(0.0, 0.0), (0.02, 0.05), (1e-7, 0.02)])
def test_against_shooting(phi_deg, k, ratios):
    s = np.linspace(0.0, 1.0, 9)
    phi = np.deg2rad(phi_deg)
    sol = planar_elastica(k, phi, s, axial_ratio=ratios[0], shear_ratio=ratios[1])
    ref = shoot(k, phi, s, *ratios, kappa0_guess=sol.curvature[0])
    np.testing.assert_allclose(sol.theta, ref[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.curvature, ref[1], rtol=0, atol=1e-9 * max(1.0, k))
    np.testing.assert_allclose(sol.x, ref[2], rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.z, ref[3], rtol=0, atol=1e-9)
    assert sol.theta[-1] == sol.tip_angle


def test_quadrature_path_matches_closed_form():
    # A vanishing shear compliance sends the position along the force through the quadrature;
    # it must meet the inextensible closed form (difference O(k * shear_ratio) = 1e-10).
    s = np.linspace(0.0, 1.0, 7)
    for k, phi in [(100.0, 1.2), (1e4, 2.5), (5.0, 0.2)]:
        closed = planar_elastica(k, phi, s)
        quad = planar_elastica(k, phi, s, shear_ratio=1e-14)
        np.testing.assert_allclose(quad.x, closed.x, rtol=0, atol=1e-9)
        np.testing.assert_allclose(quad.z, closed.z, rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("k", "phi", "ratios"),
    [(3.0, 1.1, (0.0, 0.0)), (8.0, 2.2, (0.06, 0.01)), (0.7, 0.5, (0.01, 0.87))],
)
def test_arc_length_matches_energy_first_integral(k, phi, ratios):
    # Independent of the χ parametrisation: ds = dθ/θ' with θ' from the energy form of the first
    # integral, θ'²/(2k) = cos δ_L − cos δ + (e/2)(cos²δ_L − cos²δ), δ = φ − θ, integrated from
    # each station to the tip by mpmath's tanh-sinh rule in δ = δ_L + u² (no √ singularity;
    # the differences of cosines written as products of sines).
    e = k * (ratios[0] - ratios[1])
    s = np.array([0.0, 0.3, 0.8])
    sol = planar_elastica(k, phi, s, axial_ratio=ratios[0], shear_ratio=ratios[1])
    with mp.workdps(30):
        d_tip = mp.mpf(phi) - mp.mpf(float(sol.tip_angle))

        def ds(u):
            h, w = u * u, 2 * d_tip + u * u  # δ − δ_L, δ + δ_L
            energy = 2 * mp.sin(w / 2) * mp.sin(h / 2) + e / 2 * mp.sin(h) * mp.sin(w)
            return 2 * u / mp.sqrt(2 * k * energy)

        arcs = [mp.quad(ds, [0, mp.sqrt(mp.mpf(phi) - mp.mpf(t) - d_tip)]) for t in sol.theta]
    np.testing.assert_allclose(np.array(arcs, dtype=float), 1.0 - s, rtol=0, atol=1e-13)


def test_newton_converges_in_a_few_steps():
    # The tip condition from the bound tan χ_0 ≥ sinh √k (five evaluations at most for
    # Mattiasson's loads), the stations from am(u | m') in one evaluation (the last Newton step
    # is within its quadratic error bound).
    k = np.array([0.1, 1.0, 5.0, 10.0, 20.0, 1e3])
    half = np.full_like(k, np.sqrt(0.5))  # a = π/2
    rho, count = _elastica_math._solve_tip(half, half, np.sqrt(k), np.zeros_like(k))
    assert count <= 5
    s_dl, c_dl, _ = _elastica_math._tip_geometry(half, half, *_elastica_math._sin_cos_from_rho(rho))
    ex = (..., None)
    *_, count = _elastica_math._solve_stations(
        np.linspace(0.0, 1.0, 101), np.sqrt(k)[ex], rho[ex], s_dl[ex], c_dl[ex], 0.0
    )
    assert count == 1


def test_cumulative_chebyshev_quadrature():
    # ∫_0^s (exp t + cos 7t) dt = exp s − 1 + sin(7s)/7, at stations and batched.
    n = 40
    nodes = _elastica_math._chebyshev_points(n)
    assert nodes[0] == 1.0 and nodes[-1] == 0.0
    s = np.linspace(0.0, 1.0, 13)
    values = np.exp(nodes) + np.cos(7 * nodes) * np.array([[1.0], [2.0]])
    want = np.exp(s) - 1 + np.sin(7 * s) / 7 * np.array([[1.0], [2.0]])
    # the DCT route, and the kept weights (first call fills them, the second reuses them)
    for _ in range(2):
        for rule in (_elastica_math._cumulative_chebyshev_direct,
                     _elastica_math._cumulative_chebyshev):
            np.testing.assert_allclose(rule(values, s), want, rtol=0, atol=1e-15)


# --------------------------------------------------------------------------------------------
# Limits and exact special cases
# --------------------------------------------------------------------------------------------
def test_small_load_matches_linear_beam_theory():
    # Euler-Bernoulli cantilever with tip load P: z = (P L³/EI)(σ²/2 − σ³/6), θ = k(σ − σ²/2),
    # M = P (L − s); the non-linear correction is O(k²) relative.
    s = np.linspace(0.0, 1.0, 11)
    k = 1e-6
    sol = planar_elastica(k, np.pi / 2, s)
    np.testing.assert_allclose(sol.z, k * (s**2 / 2 - s**3 / 6), rtol=1e-10, atol=0)
    np.testing.assert_allclose(sol.theta, k * (s - s**2 / 2), rtol=1e-10, atol=0)
    np.testing.assert_allclose(sol.curvature, k * (1 - s), rtol=1e-10, atol=1e-300)
    np.testing.assert_allclose(sol.x, s, rtol=0, atol=1e-12)
    # Oblique: beam-column (second-order) theory, θ'' = −Q + T θ with Q = k sin φ, T = k cos φ:
    # θ = (Q/T)(1 − cosh μ(1−s)/cosh μ), μ = √T, z ≈ ∫θ (Timoshenko & Gere, Theory of Elastic
    # Stability, §1.11); its error is O(k²) relative. Evaluated in mpmath (50 digits).
    phi = 0.7
    sol = planar_elastica(k, phi, s)
    with mp.workdps(50):
        q, tension = mp.mpf(k) * mp.sin(mp.mpf(phi)), mp.mpf(k) * mp.cos(mp.mpf(phi))
        mu = mp.sqrt(tension)
        theta_ref = [q / tension * (1 - mp.cosh(mu * (1 - mp.mpf(x))) / mp.cosh(mu)) for x in s]
        z_ref = [
            q / tension * (x - (mp.sinh(mu) - mp.sinh(mu * (1 - x))) / (mu * mp.cosh(mu)))
            for x in map(mp.mpf, s)
        ]
    np.testing.assert_allclose(sol.theta, np.array(theta_ref, dtype=float), rtol=1e-11, atol=0)
    np.testing.assert_allclose(sol.z, np.array(z_ref, dtype=float), rtol=0, atol=1e-15)
    # Tiny loads keep the angle's relative precision.
    for tiny in [1e-12, 1e-30, 1e-200]:
        sol = planar_elastica(tiny, np.pi / 2, s)
        np.testing.assert_allclose(sol.tip_angle, tiny / 2, rtol=1e-12)


def test_small_load_timoshenko_shear():
    # Timoshenko cantilever: w(s) = (P/EI)(L s²/2 − s³/6) + P s/GA, i.e. k(σ²/2 − σ³/6) + k g σ.
    s = np.linspace(0.0, 1.0, 11)
    k, g = 1e-6, 0.3
    sol = planar_elastica(k, np.pi / 2, s, shear_ratio=g)
    np.testing.assert_allclose(sol.z, k * (s**2 / 2 - s**3 / 6) + k * g * s, rtol=1e-9, atol=1e-16)
    np.testing.assert_allclose(sol.shear_strain, k * g, rtol=1e-9)


def test_trivial_loads_are_exactly_straight():
    s = np.linspace(0.0, 1.0, 5)
    for k, phi in [(0.0, 1.0), (0.0, 0.0), (7.0, 0.0), (7.0, 2 * np.pi)]:
        sol = planar_elastica(k, phi, s)
        assert np.all(sol.theta == 0.0)
        assert np.all(sol.z == 0.0)
        assert np.all(sol.curvature == 0.0)
        np.testing.assert_array_equal(sol.x, s)
        assert sol.tip_angle == 0.0
    # Pure tension of an extensible rod: uniform stretch P/EA.
    sol = planar_elastica(2.0, 0.0, s, axial_ratio=0.01)
    np.testing.assert_allclose(sol.x, 1.02 * s, rtol=1e-15)
    np.testing.assert_allclose(sol.axial_strain, 0.02, rtol=1e-15)


def test_compression_below_and_above_euler_load():
    s = np.linspace(0.0, 1.0, 5)
    # Below k = π²/4: straight (up to the 1.2e-16 rad imperfection the float π carries).
    sol = planar_elastica(2.0, np.pi, s)
    assert np.max(np.abs(sol.z)) < 1e-14
    np.testing.assert_allclose(sol.x, s, rtol=0, atol=1e-15)
    # Above: Euler's buckled cantilever, K(p) = √k, tip rotation 2 arcsin p, tip deflection
    # 2p/√k, x_tip = 2E(p)/√k − 1 (Timoshenko & Gere, Theory of Elastic Stability, §2.7).
    for k in [2.5, 4.0, 9.0]:
        m = brentq(lambda m, k=k: ellipk(m) - np.sqrt(k), 0.0, 1.0 - 1e-15, xtol=1e-16)
        p = np.sqrt(m)
        sol = planar_elastica(k, np.pi, s)
        np.testing.assert_allclose(sol.tip_angle, 2 * np.arcsin(p), rtol=0, atol=1e-9)
        np.testing.assert_allclose(sol.z[-1], 2 * p / np.sqrt(k), rtol=0, atol=1e-9)
        np.testing.assert_allclose(sol.x[-1], 2 * ellipe(m) / np.sqrt(k) - 1, rtol=0, atol=1e-9)
        # The side is sign(sin φ) of the float: −π buckles the other way.
        mirror = planar_elastica(k, -np.pi, s)
        np.testing.assert_array_equal(mirror.z, -sol.z)


def test_signs_and_mirror_symmetry():
    s = np.linspace(0.0, 1.0, 6)
    sol = planar_elastica(2.0, np.pi / 2, s)
    # Force along +z: deflection and rotation towards +z, curvature θ' ≥ 0 (Grazioso notes).
    assert np.all(sol.z[1:] > 0) and np.all(sol.theta[1:] > 0) and np.all(sol.curvature >= 0)
    for phi in [0.3, 2.0, 3.0]:
        up = planar_elastica(3.0, phi, s, shear_ratio=0.05)
        down = planar_elastica(3.0, -phi, s, shear_ratio=0.05)
        np.testing.assert_array_equal(down.z, -up.z)
        np.testing.assert_array_equal(down.theta, -up.theta)
        np.testing.assert_array_equal(down.x, up.x)
        np.testing.assert_array_equal(down.shear_strain, -up.shear_strain)
        # φ is taken modulo 2π.
        np.testing.assert_allclose(
            planar_elastica(3.0, phi + 2 * np.pi, s).z,
            planar_elastica(3.0, phi, s).z,
            rtol=0,
            atol=1e-13,
        )


@settings(max_examples=60, deadline=None)
@given(
    k=st.floats(1e-8, 200.0),
    phi=st.floats(-np.pi, np.pi),
    g=st.sampled_from([0.0, 1e-3, 0.2]),
)
# a compressed, shearable column past its critical load: a Newton step of the tip condition
# left the range (cosh ρ overflowed) and Carlson's R_F(0, 0, 1) never returned (CI found it)
@example(k=np.pi ** 2 / 4, phi=np.pi, g=0.2)
def test_moment_equals_tip_force_lever_arm(k, phi, g):
    # Global equilibrium of the segment [s, L]: EI θ'(s) = ((r(L) − r(s)) × F)·(x→z), and the
    # fundamental branch has no inflection point: θ' keeps one sign and θ is monotone.
    g = min(g, 0.9 / k)
    s = np.linspace(0.0, 1.0, 13)
    sol = planar_elastica(k, phi, s, shear_ratio=g)
    lever = (sol.x[-1] - sol.x) * np.sin(phi) - (sol.z[-1] - sol.z) * np.cos(phi)
    np.testing.assert_allclose(sol.curvature, k * lever, rtol=0, atol=1e-11 * max(1.0, k))
    sign = np.sign(sol.tip_angle)
    assert np.all(sign * sol.curvature >= 0)
    assert np.all(sign * np.diff(sol.theta) >= -1e-15)


# --------------------------------------------------------------------------------------------
# Arrays, robustness, validation
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("batch", [(), (1,), (3, 1, 2)])
def test_batched_equals_looped(batch, rng):
    s = np.linspace(0.0, 1.0, 4)
    k = rng.uniform(0.0, 15.0, size=batch)
    phi = rng.uniform(-np.pi, np.pi, size=batch)
    for ratios in [(None, None), (0.01, 0.03)]:
        sol = planar_elastica(k, phi, s, axial_ratio=ratios[0], shear_ratio=ratios[1])
        assert sol.theta.shape == (*batch, 4) and sol.tip_angle.shape == batch
        for index in np.ndindex(*batch):
            one = planar_elastica(
                k[index], phi[index], s, axial_ratio=ratios[0], shear_ratio=ratios[1]
            )
            for got, want in zip(sol, one, strict=True):
                np.testing.assert_allclose(got[index], want, rtol=0, atol=1e-14)


# One load is solved by _lone (float arithmetic for the load's unknowns, ellipj's amplitude
# taken directly where cos χ_0 >= 0.1, product forms for the curvature), a batch by _batch (the
# Newton-polished amplitude, arctangent forms): two evaluations of the closed form that must
# agree. The loads cover every branch of both: straight, near tension (a < 1e-8), compression
# below and above the Euler load, cos χ_0 above and below 0.1, √(k f_L) above 12 (asymptotic
# starts), e ≠ 0 (Chebyshev quadrature) and tiny loads.
_ROUTE_LOADS = [
    (0.0, 1.0, (0.0, 0.0)), (2.0, 0.0, (0.01, 0.0)), (3.0, 3e-9, (0.0, 0.0)),
    (2.0, np.pi, (0.0, 0.0)), (3.0, -np.pi, (0.0, 0.0)), (1e-9, np.pi / 2, (0.0, 0.0)),
    (0.1, np.pi / 2, (0.0, 0.0)), (5.0, np.pi / 2, (1e-9, 1e-9)), (10.0, np.pi / 2, (0.0, 0.0)),
    (20.0, 2.0, (0.0, 0.0)), (400.0, 1.0, (0.0, 0.0)), (1e4, 2.5, (0.0, 0.0)),
    (8.0, 2.2, (0.06, 0.01)), (0.7, -0.5, (0.01, 0.87)), (86.0, -0.39, (0.0063, 0.001)),
    (3.0, 7.5, (0.0, 0.05)),
]


@pytest.mark.parametrize(("k", "phi", "ratios"), _ROUTE_LOADS)
def test_one_load_route_equals_batch_route(k, phi, ratios, rng):
    s = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, 40)), [1.0]])
    lone = planar_elastica(k, phi, s, axial_ratio=ratios[0], shear_ratio=ratios[1])
    batch = planar_elastica(np.array([k]), phi, s, axial_ratio=ratios[0],
                            shear_ratio=ratios[1])
    for name, got, want in zip(lone._fields, lone, batch, strict=True):
        want = want[0]
        scale = max(1.0, float(np.max(np.abs(want))))
        np.testing.assert_allclose(got, want, rtol=0, atol=2e-14 * scale, err_msg=name)
    assert lone.theta[-1] == lone.tip_angle


def test_broadcasting_k_against_phi():
    s = np.array([0.5, 1.0])
    sol = planar_elastica(np.array([1.0, 2.0, 3.0])[:, None], np.array([0.5, 1.5]), s)
    assert sol.z.shape == (3, 2, 2) and sol.tip_angle.shape == (3, 2)


def test_extreme_inputs_are_finite():
    s = np.linspace(0.0, 1.0, 7)
    k = np.array([0.0, 1e-300, 1e-8, np.pi**2 / 4, 50.0, 1e4, K_MAX])[:, None]
    phi = np.array([0.0, 1e-222, 1e-12, 1e-3, np.pi / 2, np.pi - 1e-12, np.pi, -np.pi, 1e3])
    cases = [
        (k, phi, s, {}),
        (  # k (1 + |e|) <= K_MAX: e = k (a_r - g_r) = -0.25 at k = K_MAX / 2
            np.array([0.0, 1e-300, np.pi**2 / 4, K_MAX / 2])[:, None],
            phi[[0, 1, 3, 6, 8]],
            s[::3],
            {"axial_ratio": 1e-9, "shear_ratio": 5e-6},
        ),
    ]
    for k_, phi_, s_, ratios in cases:
        sol = planar_elastica(k_, phi_, s_, **ratios)
        for field in sol:
            assert np.all(np.isfinite(field))
        assert np.all(np.abs(sol.theta) <= np.pi)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"k": -1.0}, "k must"),
        ({"k": 2 * K_MAX}, "k must"),
        ({"k": np.nan}, "k must be finite"),
        ({"phi": np.inf}, "phi must be finite"),
        ({"s_over_L": [0.0, 1.5]}, r"\[0, 1\]"),
        ({"s_over_L": [[0.0, 1.0]]}, "1-D"),
        ({"shear_ratio": -0.1}, ">= 0"),
        ({"k": 20.0, "shear_ratio": 0.1}, "< 1"),
        # the clamp's boundary layer underflows beyond k (1 + |e|) ~ 1.2e5 (mpmath check)
        ({"k": 0.9 * K_MAX, "shear_ratio": 0.5 / K_MAX}, r"k \(1 \+ \|k"),
        ({"k": 20.0, "axial_ratio": 0.06}, "< 1"),
    ],
)
def test_invalid_inputs(kwargs, match):
    args = {"k": 1.0, "phi": 1.0, "s_over_L": [0.0, 1.0], **kwargs}
    with pytest.raises(ValueError, match=match):
        planar_elastica(args.pop("k"), args.pop("phi"), args.pop("s_over_L"), **args)


def test_a_slope_that_overflows_is_bisected_not_taken_as_converged():
    """k = 30 at 179.95° (issue 42's grid): the tip condition's first Newton step lands at
    ρ ≈ 378, where the slope comes out infinite; the step residual/slope = 0 was taken as
    converged and every position was NaN. Both routes now agree with the pseudo-arclength
    reference of that grid (tests/data/near_axial_paths.json, the planar path followed from
    the unloaded arm, with EA = GA = 1e12 EI/L²: inextensible to 1e-11)."""
    cases = json.loads((Path(__file__).parents[1] / "data" / "near_axial_paths.json")
                       .read_text())["cases"]
    stored = next(c for c in cases if c["angle_deg"] == 179.95 and c["magnitude"] == 30.0)
    phi = np.radians(179.95)
    lone = planar_elastica(30.0, phi, np.array([0.0, 1.0]))
    batch = planar_elastica(np.array([30.0]), np.array([phi]), np.array([0.0, 1.0]))
    for sol in (lone, batch):
        tip = np.array([np.ravel(sol.x)[-1], np.ravel(sol.z)[-1]])
        np.testing.assert_allclose(tip, stored["tip"], rtol=0, atol=1e-9)
