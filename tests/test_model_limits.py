"""The model's limits on every route (issue 30, "Answers that break the model without a word").

- A tendon beyond the tension its path can carry: one straight tendon at offset z on a straight
  arm with a diagonal K has a smooth constant-strain root only while τ < τ_c = 1/(1/EA +
  z²/EI) (w₁ = 1 - τ (1/EA + z²/EI)); with a coupled K, τ_c = |C⁻¹ w₀|, C = J K⁻¹ Jᵀ,
  J = [I, -r~], w₀ = J f⁰ (docs/actuation.md, "The model's limits"). The references are these
  formulas computed here from the stiffnesses, and for a coupled K the secular equation
  |(ρ I + τ C)⁻¹ w₀| = 1 solved by scipy's brentq.
- An axial stretch v₁ <= 0 (the arm inside out): the reference is v₁ = 1 + n₁/EA (diagonal
  K), or v₁ = 1 + (K⁻¹)₁₂ n₂ at the clamp for a K that couples extension and shear.
- Loads too large to represent: a ValueError naming the load's field and its size, on every
  route, for every kind of load; no closed form returns NaN.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.optimize import brentq

import softarm
from softarm import ConvergenceError, InadmissibleStateError
from softarm.routing import Straight

EA, EI, L = 1e4, 0.01, 0.25
ARM = softarm.Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EI, EIy=EI, EIz=EI)
Z = 0.01
TAU_C = 1.0 / (1.0 / EA + Z * Z / EI)  # 99.0099 N: w₁ = 1 - τ/τ_c


def hat(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def coupled_arm():
    """A precurved arm whose K couples extension, shear, torsion and bending (SPD)."""
    rng = np.random.default_rng(1)
    scale = np.sqrt(np.diag([1e4, 5e3, 6e3, 0.008, 0.01, 0.012]))
    a = rng.normal(size=(6, 6)) * 0.2
    K = scale @ (np.eye(6) + 0.15 * (a + a.T)) @ scale
    curvature = (0.0, 0.5, -0.3)
    return softarm.Arm.from_stiffness_matrix(L, 0.5 * (K + K.T), curvature=curvature)


def tendon_limit_by_hand(arm, y, z):
    """(τ_c, C, w₀, J) of one straight tendon at (y, z) on a uniform arm."""
    r = np.array([0.0, y, z])
    J = np.hstack([np.eye(3), -hat(r)])
    C = J @ np.linalg.solve(arm.stiffness, J.T)
    w0 = J @ arm.reference_strain
    return float(np.linalg.norm(np.linalg.solve(C, w0))), C, w0, J


# --- 1. a tendon beyond its limit -------------------------------------------------------------

def test_the_limit_formula_is_the_diagonal_case_of_the_general_one():
    tau_c, *_ = tendon_limit_by_hand(ARM, 0.0, Z)
    assert tau_c == pytest.approx(TAU_C, rel=1e-14)


@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_straight_tendon_below_its_limit_has_w1_as_the_formula(method):
    tau = 0.9 * TAU_C
    eq = softarm.solve(ARM, softarm.Tendon(tau, Straight(0.0, Z)), method=method, s=5)
    v1, u_y = 1.0 + eq.strains[:, 0], eq.strains[:, 4]
    w1 = v1 + u_y * Z  # (v + u × r)₁ with r = (0, 0, z)
    np.testing.assert_allclose(w1, 1.0 - tau / TAU_C, rtol=0, atol=1e-9)


@pytest.mark.parametrize("method", ["auto", "numeric"])
@pytest.mark.parametrize("factor", [1.2, 2.0])
def test_straight_tendon_beyond_its_limit_is_refused(method, factor):
    """softarm 0.2's closed form kept t = e1 past τ_c and returned a state that broke the law
    by hundreds of newtons; its numerical route called the limit a fold."""
    tau = factor * TAU_C
    with pytest.raises(InadmissibleStateError) as caught:
        softarm.solve(ARM, softarm.Tendon(tau, Straight(0.0, Z)), method=method, s=5)
    error = caught.value
    assert isinstance(error, ConvergenceError)
    assert error.load_factor == pytest.approx(1.0 / factor, rel=1e-9 if method == "auto"
                                              else 1e-6)
    message = str(error)
    assert message.startswith("tendon 0 (tendon ")
    assert "its path's length vanishes (|w| -> 0" in message
    assert f"λ ≈ {1.0 / factor:.6g}" in message
    assert f"it can carry about {TAU_C:.6g} N, not {tau:.6g} N" in message
    assert re.search(r"at s (in \[0, 0.25\]|= 0) m", message)
    assert "(residual " in message


@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_centreline_tendon_beyond_EA_is_refused(method):
    """A tendon on the centreline only compresses: τ_c = EA (softarm 0.2 returned an arm inside
    out at 1.5 EA)."""
    with pytest.raises(InadmissibleStateError, match=r"tendon 0 .*length vanishes.*λ ≈ "
                                                      r"0\.666667.*about 10000 N") as caught:
        softarm.solve(ARM, softarm.Tendon(1.5 * EA, Straight(0.0, 0.0)), method=method, s=5)
    assert caught.value.load_factor == pytest.approx(2.0 / 3.0, rel=1e-6)


@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_several_tendons_on_a_piece(method):
    """Two tendons at the same offset pull as one of the summed tension; two at opposite
    offsets only compress the arm, w₁ = 1 - (τ₁ + τ₂)/EA (no bending)."""
    same = [softarm.Tendon(0.7 * TAU_C, Straight(0.0, Z)),
            softarm.Tendon(0.5 * TAU_C, Straight(0.0, Z))]
    with pytest.raises(InadmissibleStateError) as caught:
        softarm.solve(ARM, same, method=method, s=5)
    assert caught.value.load_factor == pytest.approx(1.0 / 1.2, rel=1e-6)
    opposite = [softarm.Tendon(0.4 * EA, Straight(0.0, Z)),
                softarm.Tendon(0.4 * EA, Straight(0.0, -Z))]
    eq = softarm.solve(ARM, opposite, method=method, s=5)
    np.testing.assert_allclose(eq.strains[..., 0], -0.8, rtol=0, atol=1e-9)
    np.testing.assert_allclose(eq.tendon_lengths, [L * 0.2] * 2, rtol=0, atol=1e-9 * L)
    beyond = [tendon.replace(tension=0.6 * EA) for tendon in opposite]
    with pytest.raises(InadmissibleStateError) as caught:
        softarm.solve(ARM, beyond, method=method, s=5)
    assert caught.value.load_factor == pytest.approx(1.0 / 1.2, rel=1e-6)


def test_coupled_stiffness_limit_and_root_against_the_secular_equation():
    """K coupling extension, shear, torsion and bending, a precurved arm: below τ_c the closed
    form's root is the secular equation's t = (ρ I + τ C)⁻¹ w₀ (|t| = 1, brentq on ρ), even
    at 0.999 τ_c where a plain Newton's method from the tendons-along-d1 guess stalls on the
    kink; above it, the limit λ = τ_c/τ."""
    arm = coupled_arm()
    y, z = 0.004, 0.008
    tau_c, C, w0, J = tendon_limit_by_hand(arm, y, z)
    f0 = arm.reference_strain
    for factor in (0.5, 0.99, 0.999):
        tau = factor * tau_c
        rho = brentq(lambda rho, tau=tau: np.linalg.norm(
            np.linalg.solve(rho * np.eye(3) + tau * C, w0)) - 1.0, 1e-14, 10.0, xtol=1e-16)
        t = np.linalg.solve(rho * np.eye(3) + tau * C, w0)
        strain = f0 - tau * np.linalg.solve(arm.stiffness, J.T @ t)
        eq = softarm.solve(arm, softarm.Tendon(tau, Straight(y, z)), s=5)
        assert eq.method == "analytic.actuated"
        np.testing.assert_allclose(eq.strains + f0, np.broadcast_to(strain, (5, 6)),
                                   rtol=1e-12, atol=1e-12)
        assert (J @ strain)[0] > 0.0
    for factor in (1.001, 1.5):
        with pytest.raises(InadmissibleStateError, match="length vanishes") as caught:
            softarm.solve(arm, softarm.Tendon(factor * tau_c, Straight(y, z)), s=5)
        assert caught.value.load_factor == pytest.approx(1.0 / factor, rel=1e-9)


def test_a_batch_reports_its_first_case_beyond_the_limit():
    """As for any failed case of a batch: one ConvergenceError naming the load case."""
    tensions = np.array([0.5, 1.5, 0.9, 2.0]) * TAU_C
    for method in ("auto", "numeric"):
        with pytest.raises(InadmissibleStateError,
                           match=r"for load case \(1,\): its path's length vanishes") as caught:
            softarm.solve(ARM, softarm.Tendon(tensions, Straight(0.0, Z)), method=method, s=5)
        assert caught.value.load_factor == pytest.approx(1.0 / 1.5, rel=1e-6)


def test_forward_solver_refuses_and_recovers():
    """The control loop's call: a chained path from the last answer; the error says what the
    tendon can carry (from the unloaded arm), the next call starts afresh."""
    model = softarm.ForwardSolver(ARM, [softarm.Tendon(0.0, Straight(0.0, Z))])
    model.solve([0.5 * TAU_C])
    with pytest.raises(InadmissibleStateError, match=rf"about {TAU_C:.6g} N, not "
                                                     rf"{1.2 * TAU_C:.6g} N"):
        model.solve([1.2 * TAU_C])
    state = model.solve([0.9 * TAU_C])
    fresh = softarm.solve(ARM, softarm.Tendon(0.9 * TAU_C, Straight(0.0, Z)), s=[L])
    assert fresh.method == "analytic.actuated"
    np.testing.assert_allclose(state.tip_position, fresh.tip_position, rtol=0,
                               atol=1e-6 * L)  # its tol


# --- 2. an axial stretch v₁ <= 0 --------------------------------------------------------------

@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_compression_beyond_EA_is_refused(method):
    """softarm 0.2 solved 1.5 EA with v₁ = -0.5, the tip at x = -0.15 L, and only warned that
    the state was unstable. v₁ = 1 + n₁/EA = -0.5."""
    with pytest.raises(InadmissibleStateError) as caught:
        softarm.solve(ARM, softarm.TipLoad(force=[-1.5 * EA, 0.0, 0.0]), method=method, s=5)
    message = str(caught.value)
    assert "the axial stretch v₁ = -0.5 <= 0 at s = 0 m, axial force n₁ = -1.5e+04 N" in message
    assert "inside out" in message and "turns through the cross-section's plane" in message
    assert caught.value.station == 0.0


def test_compression_below_EA_is_solved():
    eq = softarm.solve(ARM, softarm.TipLoad(force=[-0.5 * EA, 0.0, 0.0]), method="numeric",
                       s=5, stability=False)
    np.testing.assert_allclose(1.0 + eq.strains[:, 0], 0.5, rtol=0, atol=1e-12)


@pytest.mark.parametrize("closed_form", [
    lambda: softarm.analytic.axial_force(ARM, [-1.5 * EA, 0.0, 0.0], s=5),
    lambda: softarm.analytic.shear_force(ARM, [-1.5 * EA, 0.0, 1e-3], s=5),
    lambda: softarm.analytic.linear(ARM, force=[-1.5 * EA, 0.0, 0.0], s=5),
    lambda: softarm.analytic.actuated(
        ARM, softarm.Chamber(-1.5 * EA / 1e-4, 1e-4, Straight(0.0, 0.0)), s=5),
], ids=["axial_force", "shear_force", "linear", "actuated chamber"])
def test_closed_forms_refuse_an_arm_inside_out(closed_form):
    with pytest.raises(InadmissibleStateError, match=r"axial stretch v₁ = -0\.5 <= 0"):
        closed_form()


def test_shear_with_a_coupled_stiffness_turns_the_section_through_the_tangent():
    """K couples extension and shear, K₁₂ = 600 N: a transverse tip force n₂ gives
    v₁ = 1 + (K⁻¹)₁₂ n₂ at the clamp (R(0) = I, no extension-bending coupling)."""
    K = np.diag([1e3, 1e3, 1e3, 1e3, 1e3, 1e3])
    K[0, 1] = K[1, 0] = 600.0
    arm = softarm.Arm.from_stiffness_matrix(1.0, K)
    coupling = np.linalg.inv(K)[0, 1]
    force = 1.2 / -coupling  # v₁(0) = -0.2
    with pytest.raises(InadmissibleStateError,
                       match=rf"v₁ = {1.0 + coupling * force:.4g} <= 0 at s = 0 m"):
        softarm.solve(arm, softarm.TipLoad(force=[0.0, force, 0.0]), s=11)


def test_batch_solver_and_control_loop_refuse_only_the_bad_case():
    forces = np.zeros((3, 3))
    forces[:, 0] = [-0.5 * EA, -1.5 * EA, -0.2 * EA]
    for method in ("auto", "numeric"):
        with pytest.raises(InadmissibleStateError, match=r"for load case \(1,\) is outside"):
            softarm.solve(ARM, softarm.TipLoad(force=forces), method=method, s=5)
    # a chained Solver refuses and returns to the unloaded arm
    solver = softarm.statics.Solver(ARM, s=5, stability=False)
    solver.solve(softarm.TipLoad(force=forces[0]))
    with pytest.raises(InadmissibleStateError):
        solver.solve(softarm.TipLoad(force=forces[1]))
    after = solver.solve(softarm.TipLoad(force=forces[2]))
    np.testing.assert_allclose(1.0 + after.strains[:, 0], 0.8, rtol=0, atol=1e-12)
    # the control loop: a chamber on the centreline pulled to vacuum, v₁ = 1 + p A/EA
    model = softarm.ForwardSolver(ARM, [softarm.Chamber(0.0, 1e-4, Straight(0.0, 0.0))])
    with pytest.raises(InadmissibleStateError, match=r"v₁ = -0\.5 <= 0 at s = 0\.25 m"):
        model.solve([-1.5 * EA / 1e-4])
    state = model.solve([-0.5 * EA / 1e-4])
    assert state.tip[0, 3] == pytest.approx(0.5 * L, abs=1e-12)


def test_sweep_records_the_inadmissible_case_as_failed(tmp_path):
    pytest.importorskip("xarray")
    pytest.importorskip("zarr")
    from softarm.case import parse_case

    data = {"arm": {"length": L, "stiffness": {"EA": EA, "GAy": EA, "GAz": EA, "GJ": EI,
                                               "EIy": EI, "EIz": EI}},
            "load": [{"kind": "tip", "force": [-1.0, 0.0, 0.0]}],
            "solve": {"stations": 5},
            "sweep": {"design": "list", "parameter": [
                {"path": "load[1].force.x", "values": [0.5 * EA, -1.5 * EA, 0.2 * EA]}]}}
    ds = softarm.sweep.run(parse_case(data), chunk=3)
    np.testing.assert_array_equal(ds["status"].values, [0, 1, 0])
    assert "axial stretch v₁ = -0.5 <= 0" in ds["message"].values[1]
    np.testing.assert_allclose(ds["tip_position"].values[[0, 2], 0], [1.5 * L, 1.2 * L],
                               rtol=0, atol=1e-12)  # L (1 + F/EA)


STUBBY = softarm.Arm.from_stiffness(1.0, EA=1.0, GAy=1e3, GAz=1e3, GJ=1.0, EIy=1.0, EIz=1.0)


def test_continuation_refuses_the_first_point_inside_out():
    """EA = 1 N against 2 N of compression: v₁ = 1 - 2 λ, inside out beyond λ = 0.5 (the
    stubby arm is still stable there: π² EI/(4 L²) = 2.47 N)."""
    with pytest.raises(InadmissibleStateError) as caught:
        softarm.continuation(STUBBY, [softarm.TipLoad(force=[-2.0, 0.0, 0.0])])
    lam = caught.value.load_factor
    assert 0.5 <= lam <= 1.0
    assert f"λ = {lam:.6g} is outside the rod model: the axial stretch " \
           f"v₁ = {1.0 - 2.0 * lam:.4g} <= 0" in str(caught.value)


def test_critical_load_does_not_claim_stability_of_an_arm_inside_out():
    """softarm 0.2 answered None (stable up to max_factor) for states with v₁ = -2."""
    with pytest.raises(InadmissibleStateError, match=r"λ = 3 is outside the rod model: the "
                                                      r"axial stretch v₁ = -2 <= 0"):
        softarm.critical_load(STUBBY, [softarm.TipLoad(force=[-1.0, 0.0, 0.0])], max_factor=3.0)


# --- 3. loads too large to represent ----------------------------------------------------------

MAGNET = softarm.Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EI, EIy=EI, EIz=EI,
                                    mass_per_length=0.1, magnetization=(1e-3, 0.0, 0.0),
                                    tip_magnet=(0.0, 1e-3, 0.0))

#: one huge load of every kind, the field the message must name, and its size
HUGE = [
    (softarm.TipLoad(force=[0.0, 0.0, 1e200]), "TipLoad.force", "1e+200 N"),
    (softarm.TipLoad(force=[1e200, 0.0, 0.0]), "TipLoad.force", "1e+200 N"),
    (softarm.TipLoad(moment=[0.0, 1e200, 0.0]), "TipLoad.moment", "1e+200 N m"),
    (softarm.TipLoad(force=[0.0, 1e20, 0.0], follower=True), "TipLoad.force", "1e+20 N"),
    (softarm.PointLoad(0.1, force=[0.0, 1e20, 0.0]), "PointLoad.force", "1e+20 N"),
    (softarm.PointLoad(0.1, moment=[1e20, 0.0, 0.0]), "PointLoad.moment", "1e+20 N m"),
    (softarm.DistributedForce([0.0, 1e20, 0.0]), "DistributedForce.force", "1e+20 N/m"),
    (softarm.DistributedMoment([0.0, 0.0, 1e20]), "DistributedMoment.moment", "1e+20 N m/m"),
    (softarm.Gravity([0.0, 0.0, -1e20]), "Gravity.acceleration", "1e+20 m/s²"),
    (softarm.Tendon(1e155, Straight(0.0, 0.005)), "Tendon.tension", "1e+155 N"),
    (softarm.Tendon(routing=Straight(0.0, 0.005), displacement=-1e20), "Tendon.displacement",
     "1e+20 m"),
    (softarm.Chamber(1e160, 1e-5, Straight(0.0, 0.005)), "Chamber.pressure", "1e+160 Pa"),
    (softarm.MagneticField([0.0, 1e200, 0.0]), "MagneticField.field", "1e+200 T"),
    (softarm.MagneticField([0.0, 0.1, 0.0], gradient=np.diag([1e20, -1e20, 0.0])),
     "MagneticField.gradient", "1e+20 T/m"),
]


@pytest.mark.parametrize("method", ["auto", "numeric"])
@pytest.mark.parametrize(("load", "name", "size"), HUGE, ids=[f"{n} {s}" for _, n, s in HUGE])
def test_every_load_too_large_is_a_value_error_on_every_route(load, name, size, method):
    """softarm 0.2: NaN poses with residual 0 (chamber, tendon), a ZeroDivisionError
    (elastica), a tip at 8e196 m (axial), or no check (tendon tension, magnets)."""
    pattern = rf"^{re.escape(name)}: a load of {re.escape(size)} is not representable on " \
              r"this arm: it exceeds 1e\+12 times the bending scale \(EI/L² = 0\.16 N, EI/L " \
              r"= 0\.04 N m\)"
    with pytest.raises(ValueError, match=pattern):
        softarm.solve(MAGNET, load, method=method, s=5)


@pytest.mark.parametrize(("call", "name"), [
    (lambda: softarm.analytic.elastica(ARM, [0.0, 0.0, 1e200], s=5), "elastica"),
    (lambda: softarm.analytic.axial_force(ARM, [1e200, 0.0, 0.0], s=5), "axial_force"),
    (lambda: softarm.analytic.shear_force(ARM, [0.0, 0.0, 1e200], s=5), "shear_force"),
    (lambda: softarm.analytic.tip_moment(ARM, [1e200, 1e200, 0.0], s=5), "tip_moment"),
    (lambda: softarm.analytic.linear(ARM, moment=[0.0, 1e200, 0.0], s=5), "linear"),
    (lambda: softarm.analytic.actuated(ARM, softarm.Chamber(1e160, 1e-5, Straight(0.0, 0.0))),
     "actuated"),
    (lambda: softarm.analytic.exact_closed_form(ARM, softarm.TipLoad(force=[0, 0, 1e200])),
     "exact_closed_form"),
])
def test_closed_forms_called_directly_check_the_size_too(call, name):
    with pytest.raises(ValueError, match=rf"^{name}: TipLoad\.(force|moment): a load of 1e\+200"
                                         r"|^actuated: Chamber\.pressure: a load of 1e\+160"):
        call()


def test_largest_accepted_loads_give_finite_closed_forms():
    """Just below the limit (1e11 times the bending scale) every closed form answers with
    finite numbers or refuses with an error: never NaN or inf."""
    force, moment = 1e11 * EI / L**2, 1e11 * EI / L
    loads = [softarm.TipLoad(moment=[0.0, moment, 0.0]),
             softarm.TipLoad(moment=[moment, moment, 0.0]),
             softarm.TipLoad(force=[force, 0.0, 0.0]),
             softarm.Chamber(force / 1e-5, 1e-5, Straight(0.0, 0.005)),
             softarm.Tendon(force, Straight(0.0, 0.005))]
    for load in loads:
        try:
            eq = softarm.solve(ARM, load, method="analytic", s=5, stability=False)
        except (ValueError, ConvergenceError):
            continue
        assert np.isfinite(eq.poses).all() and np.isfinite(eq.strains).all(), load


def test_a_closed_form_that_computes_nan_raises(monkeypatch):
    """The last check of every closed form (``analytic._common.build``)."""
    from softarm.analytic import moment

    real = moment._constant_strain

    def broken(arm, moment_, s):
        poses, strains, stresses = real(arm, moment_, s)
        poses = np.array(poses)
        poses[..., -1, 0, 3] = np.nan
        return poses, strains, stresses

    monkeypatch.setattr(moment, "_constant_strain", broken)
    arm = softarm.Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EI, EIy=EI, EIz=2 * EI)
    with pytest.raises(ConvergenceError, match=r"analytic\.tip_moment\.principal computed "
                                               r"non-finite values"):
        softarm.analytic.tip_moment(arm, [0.0, 0.01, 0.0], s=5)
