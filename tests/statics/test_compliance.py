"""Exact tip compliance (issue 13 §3): ``softarm.solve(..., jacobians=True)``.

``eq.tip_compliance`` (B..., 6, 6) maps a small extra *dead* tip wrench (δF; δM), spatial
components, the moment about the tip point, to the tip's (δp; δθ), spatial components, with
δR(L) = δθ~ R(L) (a left, spatial small rotation). ``eq.compliance`` (B..., S, 6, 6) is the same
map to every output station's (δp(s); δθ(s)).

References, none of them the library's own Jacobian code:

- central finite differences of the solver itself at a fixed step count (``steps=``), the
  rotation difference taken with ``scipy.spatial.transform.Rotation``;
- the linear Timoshenko cantilever (bending, shear, extension, torsion) in closed form;
- the skew part of the tip stiffness K = C⁻¹, derived here (see :func:`skew_of_stiffness`).

Comparisons are made entry by entry on the scale sqrt(|C_ii C_jj|) of the reference (the
natural unit of C_ij: forces and moments, positions and angles have different units).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

import softarm
from softarm import Arm, Circle, Gravity, Material, Rectangle, SegmentedArm, TipLoad

#: Fixed RK4 step count of every finite-difference comparison (the same for the perturbed
#: solves and the exact compliance, so both describe the same discrete problem).
STEPS = 200
#: Relative finite-difference step (of the bending force and moment scales EI/L², EI/L):
#: truncation O(h²) ≈ 1e-8, round-off ≈ Newton threshold 1e-12 / 1e-4 = 1e-8.
H_REL = 1e-4


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def bending_scale(arm) -> float:
    """The largest bending stiffness EI of the arm's segments, N m²."""
    return max(float(np.max(np.diag(seg.stiffness)[4:])) for seg in arm.segments)


def wrench_scale(arm) -> np.ndarray:
    """(EI/L² ×3, EI/L ×3): the force and moment scales of the arm."""
    EI, L = bending_scale(arm), arm.length
    return np.array([EI / L**2] * 3 + [EI / L] * 3)


def solve_jac(arm, loads, **options):
    return softarm.solve(arm, loads, jacobians=True, **options)


def fd_compliance(arm, loads, *, base=None, s=None, steps=STEPS):
    """Central finite differences of the solver: (S, 6, 6), the same layout as eq.compliance.

    Column i perturbs an extra dead TipLoad by ±h e_i (one batch of 12 cases, each solved with
    the same fixed step count); δp = (p⁺ - p⁻)/2h and δθ = vee(log(R⁺ R⁻ᵀ))/2h, spatial.
    """
    h = H_REL * wrench_scale(arm)
    dw = np.concatenate([np.diag(h), -np.diag(h)])  # (12, 6)
    eq = softarm.solve(arm, [*loads, TipLoad(force=dw[:, :3], moment=dw[:, 3:])],
                       method="numeric", steps=steps, base=base, s=s)
    P, R = eq.positions, eq.rotations  # (12, S, 3), (12, S, 3, 3)
    dp = (P[:6] - P[6:]) / (2 * h[:, None, None])
    relative = np.einsum("bsij,bskj->bsik", R[:6], R[6:])  # R⁺ R⁻ᵀ
    rotvec = Rotation.from_matrix(relative.reshape(-1, 3, 3)).as_rotvec()
    dtheta = rotvec.reshape(dp.shape) / (2 * h[:, None, None])
    columns = np.concatenate([dp, dtheta], axis=-1)  # (6 columns, S, 6 rows)
    return np.moveaxis(columns, 0, -1)


def timoshenko(arm, s) -> np.ndarray:
    """Linear Timoshenko cantilever, straight arm along e1 clamped at the origin: (S, 6, 6).

    Under a tip force F and moment M (about the tip), the moment at s is
    M + (L - s) e1 × F and the force F; with κ = m/EI, γ = F/GA, ε = F₁/EA, twist M₁/GJ:

        p_x(s) = s F_x/EA,                 θ_x(s) = s M_x/GJ,
        p_y(s) = M_z s²/2EIz + F_y (L s²/2 - s³/6)/EIz + F_y s/GAy,
        θ_z(s) = M_z s/EIz + F_y (L s - s²/2)/EIz,
        p_z(s) = -M_y s²/2EIy + F_z (L s²/2 - s³/6)/EIy + F_z s/GAz,
        θ_y(s) = M_y s/EIy - F_z (L s - s²/2)/EIy

    (Timoshenko & Gere, Mechanics of Materials, cantilever tables, plus the shear term F s/GA).
    The linearised Cosserat rod about the unloaded straight arm is exactly this beam.
    """
    L = arm.length
    EA, GAy, GAz, GJ, EIy, EIz = np.diag(arm.segments[0].stiffness)
    s = np.asarray(s, dtype=float)
    C = np.zeros((s.size, 6, 6))
    bend = L * s**2 / 2 - s**3 / 6
    slope = L * s - s**2 / 2
    C[:, 0, 0] = s / EA
    C[:, 3, 3] = s / GJ
    C[:, 1, 1] = bend / EIz + s / GAy
    C[:, 1, 5] = s**2 / (2 * EIz)
    C[:, 5, 1] = slope / EIz
    C[:, 5, 5] = s / EIz
    C[:, 2, 2] = bend / EIy + s / GAz
    C[:, 2, 4] = -(s**2) / (2 * EIy)
    C[:, 4, 2] = -slope / EIy
    C[:, 4, 4] = s / EIy
    return C


def assert_compliance_close(C, reference, rtol, scale_of=None):
    """|C_ij - ref_ij| <= rtol sqrt(|D_ii D_jj|), D = scale_of (default the reference)."""
    D = reference if scale_of is None else scale_of
    diag = np.abs(np.diagonal(D, axis1=-2, axis2=-1))
    scale = np.sqrt(diag[..., :, None] * diag[..., None, :])
    error = np.abs(np.asarray(C) - reference) / scale
    assert np.all(error <= rtol), f"worst relative error {np.max(error):.3e} > {rtol:.1e}"


def skew_of_stiffness(M_dead=(0.0, 0.0, 0.0), F_follower=(0.0, 0.0, 0.0),
                      M_follower=(0.0, 0.0, 0.0)):
    """The skew part ½(K - Kᵀ) of the tip stiffness K = C⁻¹ (dimensional, spatial).

    Derivation. Keep the tip pose g as the variable: the arm's internal tip wrench
    W(g) = (n(L); m(L)) (spatial, moment about the tip) does the work dU = n·δp + m·δθ for the
    spatial perturbation δR = δθ~ R, U the arm's potential energy (elastic, plus gravity)
    minimised over the interior at fixed tip pose. In the chart g(a, φ) = (exp(φ~) R, p + a),
    δθ = J_l(φ) dφ, so ∂U/∂(a, φ) = (n; J_l(φ)ᵀ m) and, with J_l(φ)ᵀ = I - ½ φ~ + O(φ²),
    the symmetric Hessian of U at φ = 0 is H = ∂W/∂(δp, δθ) + [[0, 0], [0, ½ m~]].
    Equilibrium W(g) = W_applied(g) + (δF; δM); a dead tip wrench has ∂W_applied = 0, a
    follower force F = R f gives δF = δθ~ F = -F~ δθ, a follower moment -M_f~ δθ. Hence

        K = H - [[0, 0], [0, ½ m~]] + [[0, F_f~], [0, M_f~]],   m = m(L) = M_dead + M_f,

    and skew(K) = [[0, ½ F_f~], [½ F_f~, -½ M_dead~ + ½ M_f~]]: dead tip moment -½ M~ (θθ
    block); follower tip force ½ F~ in BOTH off-diagonal blocks (F = R(L) f, spatial);
    follower tip moment +½ M~. Dead forces and gravity: K symmetric. (Checked by finite
    differences of the current solver before asserting; see the report of this test file.)
    """
    S = np.zeros((6, 6))
    S[:3, 3:] = 0.5 * hat(F_follower)
    S[3:, :3] = 0.5 * hat(F_follower)
    S[3:, 3:] = -0.5 * hat(M_dead) + 0.5 * hat(M_follower)
    return S


# --- load cases ------------------------------------------------------------------------------

SOFT = Material(1.0e6, poisson_ratio=0.45, density=1100.0)


def _base_pose():
    H = np.eye(4)
    H[:3, :3] = expm(hat([0.4, -0.9, 0.3]))
    H[:3, 3] = [0.05, -0.1, 0.2]
    return H


def _cases():
    stiff = Arm.from_stiffness(1.0, EA=1e3, GAy=5e2, GAz=8e2, GJ=0.8, EIy=1.0, EIz=1.3)
    soft = Arm(0.3, Circle(0.01), SOFT)
    direction = np.array([0.3, -0.5, 1.0]) / np.linalg.norm([0.3, -0.5, 1.0])
    curved = SegmentedArm([Arm(0.25, Circle(0.012), SOFT, curvature=(0.5, 0.0, 2.0)),
                           Arm(0.15, Circle(0.008), SOFT, curvature=(0.0, -1.0, 0.0))])
    # name: (arm, loads (a function: the new load kinds are built only when a test runs),
    #        base pose, conservative)
    return {
        "unloaded": (Arm(0.3, Rectangle(0.02, 0.012), SOFT), lambda: [], None, True),
        "dead_tip_force_k2_3d": (stiff, lambda: [TipLoad(force=2.0 * direction)], None, True),
        "gravity_and_tip_force_soft": (
            soft, lambda: [Gravity(), TipLoad(force=[0.0, 0.01, -0.02])], None, True),
        "follower_tip_force": (
            stiff, lambda: [TipLoad(force=[0.2, 0.9, -0.6], follower=True)], None, False),
        "precurved_two_segments": (
            curved, lambda: [Gravity([0.0, -3.0, -9.81]), TipLoad(force=[0.02, -0.01, 0.03])],
            None, True),
        "base_pose": (soft, lambda: [Gravity(), TipLoad(force=[0.01, 0.0, -0.015])],
                      _base_pose(), True),
        "dead_tip_moment": (
            stiff, lambda: [TipLoad(force=[0.3, 0.0, 0.5], moment=[0.3, -0.8, 0.5])], None,
            False),
        # state-dependent loads: δn is not constant along the arm (the 12-component tangents)
        "follower_distributed_force": (
            curved, lambda: [softarm.DistributedForce([0.0, 0.3, -0.5], follower=True)], None,
            False),
        "follower_distributed_moment_on_a_span": (
            curved, lambda: [softarm.DistributedMoment([0.005, 0.02, -0.015], follower=True,
                                                       span=(0.1, 0.3))], None, False),
    }


CASES = _cases()
CONSERVATIVE = [name for name, case in CASES.items() if case[3]]


# --- finite differences ----------------------------------------------------------------------

@pytest.mark.parametrize("name", list(CASES))
def test_tip_compliance_equals_finite_differences(name):
    arm, make_loads, base, _ = CASES[name]
    loads = make_loads()
    s = np.linspace(0.0, arm.length, 5)
    eq = solve_jac(arm, loads, base=base, s=s, steps=STEPS)
    fd = fd_compliance(arm, loads, base=base, s=s)
    assert eq.tip_compliance.shape == (6, 6)
    assert eq.compliance.shape == (5, 6, 6)
    assert_compliance_close(eq.tip_compliance, fd[-1], 1e-6)
    # every station (s = 0 is clamped: compared on the tip's scale)
    assert_compliance_close(eq.compliance, fd, 1e-6, scale_of=np.broadcast_to(fd[-1], fd.shape))


def test_finite_difference_reference_reproduces_timoshenko():
    # Validates the finite-difference helper and the closed form against each other with the
    # CURRENT solver (no jacobians needed): central differences at h = 1e-4 agree to ~6e-8.
    arm = CASES["unloaded"][0]
    s = np.linspace(0.0, arm.length, 7)
    assert_compliance_close(fd_compliance(arm, [], s=s), timoshenko(arm, s), 1e-6,
                            scale_of=np.broadcast_to(timoshenko(arm, [arm.length])[0],
                                                     (7, 6, 6)))


# --- closed form -----------------------------------------------------------------------------

@pytest.mark.parametrize("arm", [
    Arm(0.3, Rectangle(0.02, 0.012), SOFT),
    Arm.from_stiffness(2.0, EA=3e3, GAy=40.0, GAz=90.0, GJ=0.6, EIy=1.0, EIz=2.5),
], ids=["soft_rectangle", "shear_soft_anisotropic"])
def test_unloaded_straight_arm_is_the_timoshenko_cantilever(arm):
    s = np.linspace(0.0, arm.length, 9)
    eq = solve_jac(arm, [], s=s)
    exact = timoshenko(arm, s)
    assert_compliance_close(eq.tip_compliance, exact[-1], 1e-10)
    assert_compliance_close(eq.compliance, exact, 1e-10,
                            scale_of=np.broadcast_to(exact[-1], exact.shape))


# --- structure: symmetry and the skew part of the stiffness ----------------------------------

@pytest.mark.parametrize("name", CONSERVATIVE)
def test_compliance_is_symmetric_for_conservative_loads(name):
    # Dead forces and gravity derive from a potential: K = C⁻¹ is a Hessian, symmetric. The
    # discrete compliance is symmetric to its discretisation error. Measured by finite
    # differences of today's solver at the step count that meets tol = 1e-8: |C - Cᵀ| up to
    # 5.5× the error estimate (relative to max |C| in the arm's units), so 10·tol holds.
    arm, make_loads, base, _ = CASES[name]
    loads = make_loads()
    tol = 1e-8
    C = _nondimensional(arm, solve_jac(arm, loads, base=base, tol=tol).tip_compliance)
    np.testing.assert_allclose(C.T, C, rtol=0, atol=10 * tol * np.max(np.abs(C)))


def _nondimensional(arm, C):
    """C in units of the arm: lengths L, forces EI/L², moments EI/L (angles in rad)."""
    L = arm.length
    return np.diag([1 / L] * 3 + [1.0] * 3) @ C @ np.diag(wrench_scale(arm))


def _nondimensional_stiffness(arm, C):
    """K = C⁻¹ in units of the arm (forces EI/L², moments EI/L, lengths L).

    C's discretisation error (≈ 5·tol relative) is amplified by cond(C) ≈ 60 in K: the exact
    skew parts are asserted to 1e3·tol of max |K| (1e-7 at tol = 1e-10).
    """
    return np.linalg.inv(_nondimensional(arm, C))


def test_dead_tip_moment_stiffness_skew_part_is_minus_half_M_hat():
    arm, make_loads, _, _ = CASES["dead_tip_moment"]
    loads = make_loads()
    tol = 1e-10
    C = solve_jac(arm, loads, tol=tol).tip_compliance
    K = _nondimensional_stiffness(arm, C)
    M = loads[0].moment / wrench_scale(arm)[3]
    expected = skew_of_stiffness(M_dead=M)
    assert np.max(np.abs(expected)) > 0.2  # far from symmetric
    np.testing.assert_allclose(0.5 * (K - K.T), expected, rtol=0,
                               atol=1e3 * tol * np.max(np.abs(K)))


@pytest.mark.parametrize("moment", [[0.0, 0.0, 0.0], [0.2, 0.5, -0.3]], ids=["force", "wrench"])
def test_follower_tip_load_stiffness_skew_part(moment):
    # follower force F = R(L) f: +½ F~ in both off-diagonal blocks; follower moment +½ M~
    arm = CASES["follower_tip_force"][0]
    load = TipLoad(force=[0.2, 0.9, -0.6], moment=moment, follower=True)
    tol = 1e-10
    eq = solve_jac(arm, [load], tol=tol)
    K = _nondimensional_stiffness(arm, eq.tip_compliance)
    R = eq.rotations[-1]
    scale = wrench_scale(arm)
    expected = skew_of_stiffness(F_follower=R @ load.force / scale[0],
                                 M_follower=R @ load.moment / scale[3])
    np.testing.assert_allclose(0.5 * (K - K.T), expected, rtol=0,
                               atol=1e3 * tol * np.max(np.abs(K)))


def test_skew_part_derivation_against_finite_differences():
    # The derivation of skew_of_stiffness, checked on the CURRENT solver by finite differences
    # (no jacobians needed): dead moment, follower force and follower moment together.
    arm = CASES["follower_tip_force"][0]
    loads = [TipLoad(force=[0.3, 0.0, 0.5], moment=[0.3, -0.8, 0.5]),
             TipLoad(force=[0.2, 0.9, -0.6], moment=[0.2, 0.5, -0.3], follower=True)]
    s = np.array([0.0, arm.length])
    C = fd_compliance(arm, loads, s=s)[-1]
    R = softarm.solve(arm, loads, method="numeric", steps=STEPS, s=s).rotations[-1]
    K = _nondimensional_stiffness(arm, C)
    scale = wrench_scale(arm)
    expected = skew_of_stiffness(M_dead=loads[0].moment / scale[3],
                                 F_follower=R @ loads[1].force / scale[0],
                                 M_follower=R @ loads[1].moment / scale[3])
    np.testing.assert_allclose(0.5 * (K - K.T), expected, rtol=0, atol=1e-6)


# --- per station -----------------------------------------------------------------------------

def test_station_compliance_at_the_ends():
    arm, make_loads, _, _ = CASES["precurved_two_segments"]
    loads = make_loads()
    eq = solve_jac(arm, loads, s=11)
    assert_compliance_close(eq.compliance[-1], eq.tip_compliance, 1e-13)  # the same state
    scale = np.max(np.abs(eq.tip_compliance))
    np.testing.assert_allclose(eq.compliance[0], 0.0, rtol=0, atol=1e-14 * scale)  # clamped


def test_base_pose_rotates_the_compliance():
    # Clamped at H = (R0, p0): the solution is H times the identity-base solution under the
    # loads rotated by R0ᵀ; a spatial perturbation then maps as blkdiag(R0, R0) C blkdiag(R0ᵀ)².
    arm, make_loads, H, _ = CASES["base_pose"]
    loads = make_loads()
    R0 = H[:3, :3]
    local = [Gravity(R0.T @ loads[0].acceleration), TipLoad(force=R0.T @ loads[1].force)]
    Q = np.kron(np.eye(2), R0)
    moved = solve_jac(arm, loads, base=H, tol=1e-10, s=5)
    at_identity = solve_jac(arm, local, tol=1e-10, s=5)
    assert_compliance_close(moved.compliance, Q @ at_identity.compliance @ Q.T, 1e-8,
                            scale_of=np.broadcast_to(moved.tip_compliance, (5, 6, 6)))


# --- batches and the default -----------------------------------------------------------------

@pytest.mark.parametrize("shape", [(), (3,), (2, 1, 2)])
def test_batched_equals_looped(shape, rng):
    arm = Arm(0.3, Circle(0.01), SOFT)
    force = rng.normal(size=(*shape, 3)) * 0.02
    moment = rng.normal(size=(*shape[:-1], 1, 3)) * 1e-3 if len(shape) > 1 else [0, 0, 1e-3]
    eq = solve_jac(arm, [Gravity(), TipLoad(force=force, moment=moment)], s=4, tol=1e-10)
    full = np.broadcast_shapes(shape, np.shape(moment)[:-1])
    assert eq.tip_compliance.shape == (*full, 6, 6)
    assert eq.compliance.shape == (*full, 4, 6, 6)
    F, M = np.broadcast_to(force, (*full, 3)), np.broadcast_to(moment, (*full, 3))
    for index in np.ndindex(*full):
        one = solve_jac(arm, [Gravity(), TipLoad(force=F[index], moment=M[index])], s=4,
                        tol=1e-10)
        assert_compliance_close(eq.tip_compliance[index], one.tip_compliance, 1e-9)
        assert_compliance_close(eq.compliance[index], one.compliance, 1e-9,
                                scale_of=np.broadcast_to(one.tip_compliance, (4, 6, 6)))


def test_without_jacobians_there_is_no_compliance():
    arm = Arm(0.3, Circle(0.01), SOFT)
    eq = softarm.solve(arm, [Gravity()], method="numeric")
    assert eq.tip_compliance is None and eq.compliance is None


def test_jacobians_force_the_numerical_route():
    # A pure tip moment has a closed form ("auto" takes it); jacobians=True must not.
    arm = Arm.from_stiffness(1.0, EA=1e3, GAy=1e3, GAz=1e3, GJ=0.8, EIy=1.0, EIz=1.0)
    load = TipLoad(moment=[0.0, 2.0, 0.0])
    eq = softarm.solve(arm, load, jacobians=True)
    assert eq.method.startswith("numeric")
    assert eq.tip_compliance.shape == (6, 6)


def test_kernel_implicit_function_theorem_against_numpy(rng):
    """The kernel's in-place implicit function theorem (the compliance and actuation
    Jacobians of every jacobians solve) against numpy's inverse and products on random
    blocks, and a singular ∂r/∂x: False with the arrays untouched."""
    from softarm import kernels as k

    n, A, S = 3, 2, 4
    J = rng.normal(size=(6 + A, 6 + n))
    E = rng.normal(size=(S, 6, 6 + n))
    Jx_inv = np.linalg.inv(J[:6, :6])
    through = Jx_inv @ J[:6, 6:]
    expected_E = np.concatenate([E[..., :6] @ Jx_inv, E[..., 6:] - E[..., :6] @ through], -1)
    expected_rows = np.concatenate([J[6:, :6] @ Jx_inv, J[6:, 6:] - J[6:, :6] @ through], -1)
    J_out, E_out = J.copy(), E.copy()
    assert k._implicit_function(J_out, E_out)
    np.testing.assert_allclose(E_out, expected_E, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(J_out[6:], expected_rows, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(J_out[:6], np.concatenate([Jx_inv, through], -1), rtol=1e-12,
                               atol=1e-12)
    singular = J.copy()
    singular[:6, 5] = 0.0  # (exactly: a rounded dependence leaves a tiny pivot)
    J_out, E_out = singular.copy(), E.copy()
    assert not k._implicit_function(J_out, E_out)
    assert np.array_equal(J_out, singular) and np.array_equal(E_out, E)
