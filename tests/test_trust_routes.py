"""Issue 42 ("Trust, round 4"): the solver's route counts every force, out-of-range inputs
are refused up front, and a limit reached is said.

- the route: a field gradient pulling a magnetised arm (kL = 32 by its pull) goes to
  multiple shooting and is solved, its tip against a collocation solution (scipy's
  solve_bvp) of the planar extensible, shearable rod under the magnetic force density
  G (R m) and torque (R m) × B(p), continued in the load factor as the solver's path is;
  the route's force on the arm's magnets against the hand bound Σ|G_ij| (|m| L + |dipole|);
- out-of-range inputs (a contact band or penalty no step resolves, a curvature no step count
  resolves), refused with the limits by hand, also from a case file; a strongly curved arm
  under an end moment against the circle;
- pulls beyond EA: the bar's tip at L (1 + F/EA), a lateral pull against linear tension
  theory; past T* = EA GA/(EA - GA) the failure says so, and the closed form's index counts
  the tensile modes the hand linearisation gives;
- a branch that stops before its end says why (its points against linear tension theory);
  critical_load in contact returns None after two solves; a ball of radius 1e6 m as a floor:
  its gaps against 50-digit arithmetic, the arm on it as on the plane less the sag.
"""
from __future__ import annotations

import math
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest
from _planar_elastica import linear_tension_deflection
from scipy.integrate import solve_bvp

import softarm as sa
from softarm.loads import largest_force

EA = GA = 1e6
EI = 1.0


def _magnetic_reference(g: float, b: float) -> np.ndarray:
    """Tip (x, z) of the planar rod (L = 1, EI, EA, GA above) clamped at the origin along x,
    magnetised (1, 0, 0) A m²/m along its axis, in B(x) = (0, 0, b) + diag(g, -g/2, -g/2) x.

    Unknowns along s: x, z, the tangent's angle θ (towards +z), the internal force (N_x,
    N_z) and moment M_y, spatial. With t = (cos θ, 0, sin θ), d3 = (-sin θ, 0, cos θ):
    p' = (1 + n·t/EA) t + (n·d3/GA) d3, θ' = -M_y/EI (a rotation about y by -θ),
    n' = -G t (the force ∇(m·B) = Gᵀ t, G symmetric), M_y' = -(p' × n)_y - (t × B(p))_y.
    The free tip: n = 0, M_y = 0. Continued from the unloaded arm in λ (b and g scaled)."""

    def rhs(lam):
        def f(s, y):
            x, z, th, nx, nz, m = y
            c, sn = np.cos(th), np.sin(th)
            n1, n3 = nx * c + nz * sn, -nx * sn + nz * c
            v1, v3 = 1.0 + n1 / EA, n3 / GA
            px, pz = v1 * c - v3 * sn, v1 * sn + v3 * c
            G = lam * g
            torque = G * x * sn - (lam * b - 0.5 * G * z) * c  # (t × B)_y
            return np.vstack([px, pz, -m / EI, -G * c, 0.5 * G * sn,
                              -(pz * nx - px * nz) - torque])
        return f

    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3], yb[4], yb[5]])

    s = np.linspace(0.0, 1.0, 201)
    y = np.zeros((6, s.size))
    y[0] = s
    for lam in (0.1, 0.3, 0.6, 1.0):
        sol = solve_bvp(rhs(lam), bc, s, y, tol=1e-9, max_nodes=200000)
        assert sol.success, sol.message
        s, y = sol.x, sol.y
    return y[:2, -1]


def test_a_field_gradient_pulling_a_magnetised_arm_is_solved():
    # g M L³/EI = 1000: the arm is pulled along its axis by the force g per length, the
    # tension g L at the clamp (kL = 32); B0 bends it. Single shooting failed here with a
    # false fold after 12-45 s: the route did not count the magnets' force.
    g, b = 1000.0, 2.0
    arm = sa.Arm.from_stiffness(1.0, EA=EA, GAy=GA, GAz=GA, GJ=1.0, EIy=EI, EIz=EI,
                                magnetization=(1.0, 0.0, 0.0))
    field = sa.MagneticField([0.0, 0.0, b], gradient=np.diag([g, -g / 2, -g / 2]))
    eq = sa.solve(arm, field, method="numeric", tol=1e-10, s=3)
    x, z = _magnetic_reference(g, b)
    assert eq.tip_position == pytest.approx([x, 0.0, z], abs=1e-8)
    assert z > 1e-3  # (B0 does bend it: the comparison is not of a straight rod)


def test_the_route_counts_a_fields_force_on_the_magnets_and_no_actuator():
    m, d, L = np.array([0.3, -0.4, 0.0]), np.array([0.0, 2.0, 0.0]), 0.5
    arm = sa.Arm.from_stiffness(L, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                magnetization=tuple(m), tip_magnet=tuple(d))
    G = np.array([[1.0, 2.0, 0.0], [2.0, -3.0, 0.5], [0.0, 0.5, 2.0]])
    bound = np.abs(G).sum() * (np.linalg.norm(m) * L + np.linalg.norm(d))
    assert largest_force(arm, [sa.MagneticField([0.0, 0.0, 1.0], gradient=G)]) == \
        pytest.approx(bound, rel=1e-15)
    # a uniform field only turns the magnets; the gradients of a batch, case by case
    assert largest_force(arm, [sa.MagneticField([0.0, 0.0, 1.0])]) == 0.0
    batch = sa.MagneticField([0.0, 0.0, 1.0], gradient=np.stack([G, 2 * G, 0 * G]))
    assert largest_force(arm, [batch]) == pytest.approx([bound, 2 * bound, 0.0], rel=1e-15)
    # forces add up; a tendon and a chamber are internal
    tendon = sa.Tendon(1e4, sa.routing.Straight(0.0, 0.01))
    chamber = sa.Chamber(1e6, 1e-4, sa.routing.Straight(0.01, 0.0))
    tip = sa.TipLoad(force=[3.0, -4.0, 0.0])
    push = sa.DistributedForce([0.0, 0.0, -2.0], span=(0.1, 0.3))
    assert largest_force(arm, [tip, tendon, chamber, push]) == pytest.approx(7.0 + 0.4)


# ---------------------------------------------------------------------------------------------
# out-of-range inputs, refused before any solve (docs/solver.md, "Out-of-range inputs")


def _table_arm():
    return sa.Arm(0.5, sa.Circle(0.01), sa.Material(youngs_modulus=1e6, poisson_ratio=0.5,
                                                    density=1000.0))


def _table(**options):
    return sa.Contact(sa.Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0)), **options)


def test_a_contact_band_or_penalty_the_steps_cannot_resolve_is_refused():
    # δ >= L / 2^30 (a band crossed tangentially spans √(2δL) along the arm, a step L/2^15)
    # and k <= EI (2^15 / L)⁴ (a foundation bends the arm on (EI/k)^¼): by hand
    arm = _table_arm()
    L, EI = 0.5, 1e6 * math.pi * 0.01**4 / 4
    least, most = L / 2.0**30, EI * (2.0**15 / L) ** 4
    with pytest.raises(ValueError, match=rf"Contact\.distance must be at least L / 32768² = "
                                         rf"{re.escape(f'{least:.3g}')} m .* got 1e-30 m"):
        sa.solve(arm, [sa.Gravity(), _table(distance=1e-30)])
    with pytest.raises(ValueError, match=rf"Contact\.stiffness must be at most .* = "
                                         rf"{re.escape(f'{most:.3g}')} N/m² .* got 1e\+300 N/m²"):
        sa.solve(arm, [sa.Gravity(), _table(stiffness=1e300)])
    _table(distance=1.001 * least).check(arm)  # (just inside: accepted)
    _table(stiffness=0.999 * most).check(arm)


def test_a_case_file_with_an_unresolvable_contact_band_is_one_line_on_stderr(tmp_path):
    case = tmp_path / "band.toml"
    case.write_text("[arm]\nlength = 0.5\nsection = { kind = 'circle', radius = 0.01 }\n"
                    "material = { E = 1.0e6, nu = 0.5, density = 1000.0 }\n"
                    "[[load]]\nkind = 'gravity'\n[[obstacle]]\nkind = 'plane'\n"
                    "point = [0, 0, -0.03]\nnormal = [0, 0, 1]\n[contact]\ndistance = 1e-30\n")
    out = tmp_path / "out.npz"
    run = subprocess.run([sys.executable, "-m", "softarm", "solve", str(case), "-o", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 2, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    assert "distance" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()


def test_a_curvature_no_step_count_resolves_is_refused():
    # 1e12 1/m on 1 m turns the arm by 1e12 rad: more than the 2^15 steps resolve
    with pytest.raises(ValueError, match=r"Arm\.curvature: the unloaded arm turns by 1e\+12 "
                                         r"rad .* more than the 32768 rad"):
        sa.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                              curvature=(0.0, 1e12, 0.0))
    piece = sa.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                  curvature=(0.0, 2e4, 0.0))
    with pytest.raises(ValueError, match=r"SegmentedArm\.segments' curvatures: .* turns by "
                                         r"4e\+04 rad"):
        sa.SegmentedArm([piece, piece])
    # within that range, fewer steps than the turning needs: named
    with pytest.raises(ValueError, match=r"max_steps = 1024 RK4 steps cannot resolve this "
                                         r"arm: it turns by 2e\+04 rad .* max_steps >= 20000"):
        sa.solve(piece, sa.TipLoad(force=[0.0, 0.0, 1.0]), max_steps=1024)


def _arc_tip(kappa: float, L: float) -> np.ndarray:
    """The tip of a circular arc of curvature κ about +y... bending towards -z (the frame's
    rotation about y by κ s: d1 = (cos κs, 0, -sin κs))."""
    return np.array([math.sin(kappa * L), 0.0, -(1.0 - math.cos(kappa * L))]) / kappa


@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_a_strongly_curved_arm_under_an_end_moment_is_a_circle(method):
    # κ⁰ L = 2000 (318 turns), M L/EI = 1: the circle of curvature κ⁰ + M/EI. The numerical
    # path ran on too few steps for the arm's own turning (a false fold at λ = 0) and the
    # closed form's stability sweep overflowed (LinAlgError): both counted only the loads'
    kappa0, M = 2000.0, 1.0
    arm = sa.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                curvature=(0.0, kappa0, 0.0))
    eq = sa.solve(arm, sa.TipLoad(moment=[0.0, M, 0.0]), method=method, tol=1e-6, s=3)
    assert eq.tip_position == pytest.approx(_arc_tip(kappa0 + M, 1.0), abs=1e-6)
    assert eq.stability is not None


# ---------------------------------------------------------------------------------------------
# pulls beyond the axial stiffness (docs/solver.md, "The model's limits")

# a nitinol-like guide wire, r = 0.25 mm, E = 50 GPa, L = 1 m: EA L²/EI = 4 L²/r² = 6.4e7,
# so F L²/EI = 1e8 is a pull of 1.56 EA
WIRE = sa.Arm(1.0, sa.Circle(0.25e-3), sa.Material(youngs_modulus=50e9, poisson_ratio=0.3))


@pytest.mark.parametrize("ratio", [1.56, 10.0])  # F / EA
@pytest.mark.slow
def test_a_pull_beyond_ea_stretches_the_rod_by_f_over_ea(ratio):
    # the linear law σ = K ε holds at any stretch: the bar's tip at L (1 + F/EA) exactly;
    # with GA = EA the straight rod is stable in tension at any pull, and a lateral P =
    # 1e-3 F deflects the tip by linear tension theory, exact for EA = GA to (P/F)³ L
    R = WIRE.rigidities
    EA, EI, L = R.EA, R.EIy, 1.0
    arm = sa.Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=R.GJ, EIy=EI, EIz=EI)
    F = ratio * EA
    zero = sa.DistributedForce([0.0, 0.0, 0.0])  # (off the closed form's route)
    axial = sa.solve(arm, [sa.TipLoad(force=[F, 0.0, 0.0]), zero], method="numeric", s=3)
    assert axial.tip_position == pytest.approx([L * (1.0 + F / EA), 0.0, 0.0], abs=1e-12)
    P = 1e-3 * F
    eq = sa.solve(arm, [sa.TipLoad(force=[F, 0.0, P]), zero], method="numeric", s=3,
                  tol=1e-10)
    assert eq.stability.index == 0
    assert eq.tip_position[2] == pytest.approx(
        linear_tension_deflection(F, P, EI, L, EA), abs=1e-9 * L)
    # x: the stretch F L/EA, less (P/F)² L/2 of the tilted line (to (P/F)⁴ and 1/(kL))
    assert eq.tip_position[0] == pytest.approx(L * (1.0 + F / EA) - 0.5e-6 * L, abs=1e-9)


@pytest.mark.slow  # (12-28 s: the path fails among the buckled branches)
def test_a_pull_beyond_the_tensile_limit_of_a_shearable_rod_says_so():
    # GA = 0.34 EA (ν = 0.3): past T* = EA GA/(EA - GA) = 0.517 EA the straight rod in
    # tension is unstable in this model (the shear turns the centreline against its
    # sections); the path with a lateral imperfection fails there, and says why, not "fold"
    R = WIRE.rigidities
    limit = R.EA * R.GAy / (R.EA - R.GAy)
    F = 1.56 * R.EA
    with pytest.raises(sa.ConvergenceError, match=rf"T\* = EA·GA/\(EA − GA\) = "
                                                  rf"{limit:.4g} N") as error:
        sa.solve(WIRE, [sa.TipLoad(force=[F, 0.0, 1e-3 * F]),
                        sa.DistributedForce([0.0, 0.0, 0.0])], method="numeric", s=3)
    assert error.value.load_factor * F * 1.001 >= limit


# ---------------------------------------------------------------------------------------------
# a limit reached is said: continuation and critical_load


@pytest.mark.slow  # (~5 s)
def test_a_branch_that_stops_before_its_end_says_why():
    # a tip pull at F L²/EI = 1000 (kL = 32 at λ = 1): continuation shoots once from the
    # base, which carries the tension only to kL ≈ 20 (λ ≈ 0.38). The branch so far is
    # returned, flagged, with the reason; its points are linear tension theory's
    # (exact for EA = GA to (P/F)³ L = 5e-10 L)
    arm = sa.Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0)
    with pytest.warns(RuntimeWarning, match=r"could not be followed beyond load factor .* "
                                            r"tension up to kL"):
        branch = sa.continuation(arm, [sa.TipLoad(force=[1000.0, 0.0, 1.0])])
    assert not branch.complete and "kL = L √(F/EI) = 19" in branch.reason
    assert 0.3 < branch.lam[-1] < 1.0
    tips = np.asarray(branch.equilibria.tip_position)
    for k in (len(branch.lam) // 2, -1):
        F = 1000.0 * branch.lam[k]
        assert tips[k, 2] == pytest.approx(linear_tension_deflection(F, 1e-3 * F, 1.0, 1.0,
                                                                     1e8), abs=2e-9)
    # the budget of points, likewise; a branch followed to its end is complete
    with pytest.warns(RuntimeWarning, match=r"max_points = 3 points were followed"):
        short = sa.continuation(arm, [sa.TipLoad(force=[10.0, 0.0, 1.0])], max_points=3)
    assert not short.complete and short.lam.size == 3
    whole = sa.continuation(arm, [sa.TipLoad(force=[10.0, 0.0, 1.0])])
    assert whole.complete and whole.reason == "" and whole.lam[-1] == 1.0


def test_a_huge_ball_gives_gaps_to_round_off_of_the_gap():
    # |p - c| - R for a centre 1e6 m away cancelled 1e-10 m of every gap's digits: against
    # the gap computed in 50-digit decimal arithmetic from the same floats
    from decimal import Decimal, getcontext
    getcontext().prec = 50
    big = 1e6
    ball = sa.Sphere((0.0, 0.0, -0.03 - big), big)
    c = [Decimal(float(v)) for v in ball.center]
    for point in ([0.3, 0.1, -0.0299], [0.49, -0.2, -0.0299999], [0.0, 0.0, 0.5]):
        d, n = ball.distance(np.array(point))
        exact = sum((Decimal(v) - w) ** 2 for v, w in zip(point, c, strict=True)).sqrt() \
            - Decimal(big)
        assert float(d) == pytest.approx(float(exact), rel=1e-12, abs=1e-22)
        assert n == pytest.approx((np.array(point) - ball.center)
                                  / np.linalg.norm(np.array(point) - ball.center), abs=1e-15)


@pytest.mark.slow
def test_an_arm_on_a_huge_ball_lies_as_on_the_plane_less_its_sag():
    # a ball of radius 1e6 m as a floor: the arm on the table of docs/contact.md, each
    # station lower by the ball's sag x²/(2R) than on the plane (1.2e-7 m at the tip). It
    # took 131-140 s and widened the band (the rounding of the gaps made the law noisy); now
    # it takes the plane's 1-2 s
    arm = _table_arm()
    big = 1e6
    s = np.linspace(0.0, 0.5, 51)
    plane = sa.solve(arm, [sa.Gravity(), _table()], s=s)
    with warnings.catch_warnings():
        warnings.simplefilter("error", sa.ApproximationWarning)  # (no widened band)
        ball = sa.solve(arm, [sa.Gravity(), sa.Contact(sa.Sphere((0.0, 0.0, -0.03 - big),
                                                                  big))], s=s)
    p, q = np.asarray(plane.positions), np.asarray(ball.positions)
    assert q[:, 2] == pytest.approx(p[:, 2] - q[:, 0] ** 2 / (2 * big), abs=2e-9)
    assert q[:, :2] == pytest.approx(p[:, :2], abs=5e-9)


@pytest.mark.slow
def test_critical_load_in_contact_returns_none_after_two_solves(monkeypatch):
    # the arm on the table under up to 10× its weight is stable (nothing compresses it):
    # None after the solves at λ = 0 and at max_factor (sixteen samples took 17 solves,
    # 28 s of CPU; benchmarks/trust_routes.py)
    from softarm.statics.solver import Solver
    solves = []
    original = Solver.solve_from_unloaded

    def counted(self, loads, **options):
        solves.append(1)
        return original(self, loads, **options)

    monkeypatch.setattr(Solver, "solve_from_unloaded", counted)
    gravity = sa.Gravity()
    point = sa.critical_load(_table_arm(), [gravity, _table()], vary=[gravity],
                             max_factor=10.0)
    assert point is None and len(solves) == 2


@pytest.mark.parametrize("ratio", [0.4, 0.6, 1.0])  # T / EA; T* = 0.515 EA
def test_the_closed_form_index_counts_the_tensile_modes_of_a_shearable_rod(ratio):
    # the straight rod under a dead tension T, GA < EA: a tilted section θ turns the
    # centreline by θ (1 + T/EA - T/GA), and EI θ'' = -T (T/GA - T/EA - 1) θ: each plane
    # has the modes (2n - 1) π/2 < ωL, ω² = T (T/GA - T/EA - 1)/EI (none below T*). The
    # closed form counted compressions only (0 at any tension); the numerical verdict
    # (an independent sweep) counted these
    EA, GA, EI, L = 1e4, 3400.0, 1.0, 1.0
    arm = sa.Arm.from_stiffness(L, EA=EA, GAy=GA, GAz=GA, GJ=1.0, EIy=EI, EIz=EI)
    T = ratio * EA
    omega2 = T * (T / GA - T / EA - 1.0) / EI
    per_plane = sum(1 for n in range(1, 1000)
                    if (2 * n - 1) * math.pi / 2 < math.sqrt(max(omega2, 0.0)) * L)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sa.StabilityWarning)
        closed = sa.solve(arm, sa.TipLoad(force=[T, 0.0, 0.0]), s=3)
        numeric = sa.solve(arm, [sa.TipLoad(force=[T, 0.0, 0.0]),
                                 sa.DistributedForce([0.0, 0.0, 0.0])], method="numeric", s=3)
    assert closed.method == "analytic.axial_force"
    assert closed.stability.index == 2 * per_plane == numeric.stability.index
    assert (per_plane > 0) == (ratio > EA * GA / (EA - GA) / EA)
