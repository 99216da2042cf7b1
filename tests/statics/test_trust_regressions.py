"""Issue 12 ("Trust: no silently wrong answer, ever"): each reproducer as a named regression test.

Reference numbers come from an independent computation, never from softarm's solver:

* ``REF``: scipy ``solve_bvp`` on the static Cosserat rod with extension and shear
  (tests/_reference_rod.py), continued from the unloaded arm in load steps ≤ 0.02, collocation
  tolerance 1e-6 on the way and 1e-9 at λ = 1. Recompute them with

      PYTHONPATH=tests python tests/reference_scripts/trust_references.py

  (a case's name as an argument runs only that case; about 5-10 s a case). The tips agree with
  a second run at collocation tolerance 1e-4/1e-5 and other load steps to 5e-7 m.
* closed forms (linear beam, axial extension), written in the test;
* statics: global balance of every part [s, L] (tests/_equilibrium_checks.py) and the
  boundary condition at the tip.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pytest
from _equilibrium_checks import balance_errors, fine_stations, potential_energy
from _reference_rod import solve_reference

import softarm
import softarm.case
import softarm.io
import softarm.statics

# scipy solve_bvp continuation, tests/reference_scripts/trust_references.py (see docstring)
REF = {
    "gravity_1m_nu049": {"tip": [0.08923565860838809, 0.0, -0.9678516588349809],
                         "energy": -1.4269597967280658},
    "gravity_1m_nu05": {"tip": [0.08923294546342976, 0.0, -0.9678571187699188],
                        "energy": -1.4269712646094008},
    "gravity_0.6m": {"tip": [0.12994720928394746, 0.0, -0.5522399559095039],
                     "energy": -0.4230370802062591},
    "gravity_0.8m": {"tip": [0.10317976207835754, 0.0, -0.7615735326945323],
                     "energy": -0.8565626952041896},
    "tip_k25": {"tip": [0.2827049971203076, 0.0, -0.8835421018010339],
                "energy": -0.22564911199333826},
    "oblique_compressive": {"tip": [0.2465260500621968, 0.0, -0.8161208842990143],
                            "energy": 0.025085800278510373},
    "demo_case_1": {"tip": [0.06987614720493994, 0.30916057142271425, 0.06654100938921852]},
    "demo_case_17": {"tip": [0.0947290154352822, 0.06145294391869268, 0.30230047696789425]},
    "point_tol": {"tip": [0.6545387727708166, -0.2734535926758917, -0.6614372203245873]},
    "tip_station": {"tip": [0.16569600047910477, 0.01334841549123189, -0.38919421184303066]},
}

#: tip agreement with the solve_bvp references, m: they agree with each other (collocation
#: tolerances 1e-4 ... 1e-9) to 5e-7 m on these ≤ 1 m arms; the solver's tol is 1e-8 L
REF_ATOL = 2e-6
#: balance of every part [s, L], relative to the case's own load scale (see test_invariants)
BALANCE_RTOL = 1e-6

DEMO = Path(softarm.__file__).parent / "data" / "demo.toml"


def silicone_arm(length=1.0, nu=0.49):
    """The issue's arm: 10 mm radius silicone, E 1.5 MPa, ρ 1070 kg/m³."""
    return softarm.Arm(length, softarm.Circle(0.01),
                       softarm.Material(youngs_modulus=1.5e6, poisson_ratio=nu, density=1070.0))


def steel_post():
    """A stiff steel arm: 0.2 m long, radius 50 mm, EI/L² = 2.5e7 N (softarm 0.1 dropped loads
    below about 1e-13 EI/L² ... here 1e-6 N)."""
    return softarm.Arm(0.2, softarm.Circle(0.05),
                       softarm.Material(youngs_modulus=200e9, poisson_ratio=0.3, density=7850.0))


def assert_balanced(eq):
    force_err, moment_err, force_scale, moment_scale = balance_errors(eq)
    assert force_err <= BALANCE_RTOL * force_scale, (force_err, force_scale)
    assert moment_err <= BALANCE_RTOL * moment_scale, (moment_err, moment_scale)


# ---------------------------------------------------------------------------------------------
# 1. wrong branch from a cold solve


@pytest.mark.parametrize("nu, key", [(0.49, "gravity_1m_nu049"), (0.5, "gravity_1m_nu05")])
def test_r1_gravity_cold_solve_gives_the_hanging_arm(nu, key):
    """The 1 m arm under its weight (qL³/EI ≈ 280) hangs below the clamp.

    The issue's solve_bvp number (0.0892357, 0, -0.9678517) m is reproduced by ours with
    ν = 0.49 (Cowper factor 6(1+ν)/(7+6ν)); ν = 0.5 gives (0.0892329, 0, -0.9678571) m.
    The wrong branch of softarm 0.1: tip (0.124, 0, -0.259) m, energy +0.89 J.
    """
    arm = silicone_arm(nu=nu)
    loads = [softarm.Gravity()]
    eq = softarm.solve(arm, loads, s=fine_stations(arm, loads))
    np.testing.assert_allclose(eq.tip_position, REF[key]["tip"], rtol=0, atol=REF_ATOL)
    assert np.max(eq.positions[:, 2]) <= 1e-9  # never above the clamp
    # potential energy: the reference's own, the hanging branch (-1.43 J, not +0.89 J)
    assert potential_energy(eq) == pytest.approx(REF[key]["energy"], abs=1e-5)
    assert_balanced(eq)


def test_r1_issue_number_for_the_hanging_arm():
    """Our reference reproduces the issue's solve_bvp tip to its 7 printed digits."""
    np.testing.assert_allclose(REF["gravity_1m_nu049"]["tip"], [0.0892357, 0.0, -0.9678517],
                               rtol=0, atol=6e-8)


@pytest.mark.parametrize("length", [0.6, 0.8])
def test_r1_gravity_other_lengths(length):
    """The issue: wrong for 17 of 24 lengths from 0.55 m up."""
    arm = silicone_arm(length)
    eq = softarm.solve(arm, softarm.Gravity())
    np.testing.assert_allclose(eq.tip_position, REF[f"gravity_{length}m"]["tip"], rtol=0,
                               atol=REF_ATOL)


def test_r1_dead_tip_force_k25_numeric_route():
    """A dead transverse tip force with k = PL²/EI = 25: numeric = elastica = solve_bvp."""
    arm = silicone_arm()
    EI = float(arm.stiffness[4, 4])
    tip = softarm.TipLoad(force=(0.0, 0.0, -25.0 * EI))
    closed = softarm.solve(arm, tip)
    numeric = softarm.solve(arm, tip, method="numeric")
    np.testing.assert_allclose(closed.tip_position, REF["tip_k25"]["tip"], rtol=0,
                               atol=REF_ATOL)
    np.testing.assert_allclose(numeric.tip_position, REF["tip_k25"]["tip"], rtol=0,
                               atol=REF_ATOL)
    # a negligible distributed load (tip moves < 1e-9 m) sends the case to the solver
    nudged = softarm.solve(arm, [tip, softarm.DistributedForce((0.0, 0.0, -1e-12))])
    np.testing.assert_allclose(nudged.tip_position, REF["tip_k25"]["tip"], rtol=0,
                               atol=REF_ATOL)


def test_r1_oblique_compressive_force_bends_with_the_transverse_force():
    """F = (-4, 0, -1.5) EI/L², k ≈ 4.3: the arm bends towards -z (softarm 0.1: tip z +0.77)."""
    arm = silicone_arm()
    EI = float(arm.stiffness[4, 4])
    tip = softarm.TipLoad(force=np.array([-4.0, 0.0, -1.5]) * EI)
    numeric = softarm.solve(arm, tip, method="numeric")
    assert numeric.tip_position[2] < 0.0
    np.testing.assert_allclose(numeric.tip_position, REF["oblique_compressive"]["tip"],
                               rtol=0, atol=REF_ATOL)
    np.testing.assert_allclose(softarm.solve(arm, tip).tip_position,
                               REF["oblique_compressive"]["tip"], rtol=0, atol=REF_ATOL)


# ---------------------------------------------------------------------------------------------
# 2. batched ≠ looped


def demo_forces():
    """200 random tip forces up to 4 N (k up to ~30 on the tip segment), seed 2."""
    rng = np.random.default_rng(2)
    F = rng.normal(size=(200, 3))
    F *= (rng.uniform(0.0, 4.0, size=200) / np.linalg.norm(F, axis=1))[:, None]
    return F


def test_r2_demo_arm_batched_equals_looped_in_any_order():
    """softarm 0.1: 7 of these 200 cases took their neighbour's branch (0.57 m off)."""
    arm = softarm.load_case(DEMO).arm
    L = arm.length
    F = demo_forces()
    looped = np.full((F.shape[0], 3), np.nan)
    folds = []
    for i, f in enumerate(F):
        try:
            looped[i] = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=f)],
                                      method="numeric").tip_position
        except softarm.ConvergenceError as error:
            folds.append((i, error))
    for i, error in folds:  # acceptable only where the reference cannot continue either
        assert error.load_factor is not None and 0.0 < error.load_factor < 1.0, error
        ref = solve_reference(arm, [softarm.Gravity(), softarm.TipLoad(force=F[i])],
                              lam_step=0.02, tol=1e-5)
        assert not ref.complete, f"case {i}: the reference reaches λ = 1, the solver {error}"
    ok = np.flatnonzero(np.isfinite(looped[:, 0]))
    assert ok.size >= 150  # not vacuous (the reference confirmed every fold above)
    rng = np.random.default_rng(12)
    for order in (ok, ok[::-1], rng.permutation(ok)):
        batched = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=F[order])],
                                method="numeric")
        np.testing.assert_allclose(batched.tip_position, looped[order], rtol=0, atol=1e-6 * L)
    for i in (1, 17):
        np.testing.assert_allclose(looped[i], REF[f"demo_case_{i}"]["tip"], rtol=0,
                                   atol=REF_ATOL)


def test_r2_neighbour_does_not_change_the_answer():
    """Case 17 alone, after case 1, after its own negative: the same tip (solve_bvp's)."""
    arm = softarm.load_case(DEMO).arm
    F = demo_forces()
    for batch in ([F[17]], [F[1], F[17]], [-F[17], F[17]], [F[17], F[17] * 0.0, F[17]]):
        eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=np.array(batch))],
                           method="numeric")
        for row in range(len(batch)):
            if np.array_equal(batch[row], F[17]):
                np.testing.assert_allclose(eq.tip_position[row], REF["demo_case_17"]["tip"],
                                           rtol=0, atol=REF_ATOL)


# ---------------------------------------------------------------------------------------------
# 3. the branch depends on tol


@pytest.mark.parametrize("tol", [1e-6, 1e-8, 1e-10])
def test_r3_point_load_branch_does_not_depend_on_tol(tol):
    """softarm 0.1: tips 0.98 m apart at tol 1e-6 and 1e-8 for this point load."""
    arm = silicone_arm()
    load = softarm.PointLoad(0.88, force=[0.1639, -0.1041, -0.2518])
    eq = softarm.solve(arm, load, tol=tol)
    np.testing.assert_allclose(eq.tip_position, REF["point_tol"]["tip"], rtol=0,
                               atol=max(10 * tol * arm.length, REF_ATOL))


# ---------------------------------------------------------------------------------------------
# 4. small loads dropped


def linear_tip_deflection(arm, P):
    """Timoshenko cantilever, small load: δ = PL³/(3 EI) + PL/(k G A) (closed form)."""
    K = arm.stiffness
    return P * arm.length**3 / (3.0 * K[4, 4]) + P * arm.length / K[2, 2]


def test_r4_micro_newton_tip_load_on_a_steel_arm_is_the_linear_beam():
    """1e-6 N on a stiff steel post: δ = 3.1e-15 m (softarm 0.1: 0, the unloaded arm)."""
    arm = steel_post()
    P = 1e-6
    eq = softarm.solve(arm, softarm.TipLoad(force=(0.0, 0.0, P)), method="numeric")
    # geometric nonlinearity is O(k²) = O(1e-17) relative: the linear beam to 1e-3
    assert eq.tip_position[2] == pytest.approx(linear_tip_deflection(arm, P), rel=1e-3)
    # the base reaction balances the load (spatial force and moment at s = 0)
    np.testing.assert_allclose(eq.forces_spatial[0], [0.0, 0.0, P], rtol=0, atol=1e-3 * P)
    np.testing.assert_allclose(eq.moments_spatial[0], [0.0, -P * arm.length, 0.0], rtol=0,
                               atol=1e-3 * P * arm.length)


def test_r4_tiny_load_batched_with_a_huge_one():
    """1e-7 N transverse beside 1e6 N axial tension, one batch: each case its own answer."""
    arm = steel_post()
    EA = float(arm.stiffness[0, 0])
    force = np.array([[0.0, 0.0, 1e-7], [1e6, 0.0, 0.0]])
    eq = softarm.solve(arm, softarm.TipLoad(force=force), method="numeric")
    assert eq.tip_position[0, 2] == pytest.approx(linear_tip_deflection(arm, 1e-7), rel=1e-3)
    np.testing.assert_allclose(eq.forces_spatial[0, 0], [0.0, 0.0, 1e-7], rtol=0, atol=1e-10)
    np.testing.assert_allclose(eq.moments_spatial[0, 0], [0.0, -1e-7 * arm.length, 0.0],
                               rtol=0, atol=1e-10 * arm.length)
    # axial tension of a straight rod: x(L) = L (1 + F/EA), exact for n = EA γ
    np.testing.assert_allclose(eq.tip_position[1], [arm.length * (1.0 + 1e6 / EA), 0.0, 0.0],
                               rtol=0, atol=1e-8 * arm.length)


# ---------------------------------------------------------------------------------------------
# 5. tip station copied


def tip_station_case():
    arm = silicone_arm(0.45)
    loads = [softarm.Gravity(), softarm.PointLoad(0.09, force=[0.0, 0.0, -0.05]),
             softarm.TipLoad(force=[0.0, 0.02, -0.03])]
    return arm, loads


@pytest.mark.parametrize("s", [[0.0, 0.225, 0.45], None, 7])
def test_r5_station_at_L_holds_the_tip_state(s):
    """L = 0.45, a point load at 0.09: softarm 0.1 copied the previous station into s = L."""
    arm, loads = tip_station_case()
    eq = softarm.solve(arm, loads, s=s)
    assert eq.s[-1] == arm.length
    np.testing.assert_allclose(eq.tip_position, REF["tip_station"]["tip"], rtol=0,
                               atol=REF_ATOL)
    # the tip boundary condition: n(L) = R(L)ᵀ F_tip (material), m(L) = 0, to BALANCE_RTOL of
    # the case's load scale (weight 0.34 N + point 0.05 N + tip 0.036 N)
    F_tip = np.array([0.0, 0.02, -0.03])
    scale = arm.linear_density * 9.81 * arm.length + 0.05 + np.linalg.norm(F_tip)
    np.testing.assert_allclose(eq.stresses[-1, :3], eq.rotations[-1].T @ F_tip, rtol=0,
                               atol=BALANCE_RTOL * scale)
    np.testing.assert_allclose(eq.stresses[-1, 3:], 0.0, rtol=0,
                               atol=BALANCE_RTOL * scale * arm.length)


def test_r5_every_station_its_own_state_and_balance():
    arm, loads = tip_station_case()
    fine = softarm.solve(arm, loads, s=fine_stations(arm, loads))
    assert_balanced(fine)
    coarse = softarm.solve(arm, loads, s=[0.0, 0.09, 0.225, 0.45])
    for row, s in enumerate(coarse.s):
        i = int(np.argmin(np.abs(fine.s - s)))
        assert fine.s[i] == s
        np.testing.assert_allclose(coarse.poses[row], fine.poses[i], rtol=0, atol=1e-7)


def test_r5_csv_row_at_L(tmp_path):
    arm, loads = tip_station_case()
    eq = softarm.solve(arm, loads)
    path = softarm.io.save_result(eq, tmp_path / "tip.csv")
    back = softarm.io.load_result(path)
    assert back.s[-1] == pytest.approx(arm.length, abs=1e-12)
    np.testing.assert_allclose(back.positions[-1], REF["tip_station"]["tip"], rtol=0,
                               atol=REF_ATOL)


# ---------------------------------------------------------------------------------------------
# 6. overflow accepted


def test_r6_overflowing_tip_force_is_a_value_error():
    """|F| L²/EI = 8.5e309 overflows: ValueError naming the force, not the unloaded arm."""
    arm = silicone_arm()
    with pytest.raises(ValueError, match=r"(?i)force"):
        softarm.solve(arm, softarm.TipLoad(force=[-1e308, 0.0, 0.0]))
    with pytest.raises(ValueError, match=r"(?i)force"):
        softarm.solve(arm, softarm.TipLoad(force=[[0.0, 0.0, 1.0], [-1e308, 0.0, 0.0]]),
                      method="numeric")
    with pytest.raises(ValueError, match=r"(?i)force"):
        softarm.statics.Solver(arm).solve(softarm.TipLoad(force=[-1e308, 0.0, 0.0]))


SWEEP_CASE = """\
name = "overflow"
[arm]
length = 1.0
stiffness = { EA = 1.0e6, GAy = 1.0e6, GAz = 1.0e6, GJ = 1.0, EIy = 1.0, EIz = 1.0 }

[[load]]
kind = "tip"
force = [0.0, 0.0, 1e300]

[sweep]
load = 1
field = "force"
component = "magnitude"
start = 0.5
stop = 1.0
steps = 2
"""


def test_r6_sweep_direction_that_overflows_python(tmp_path):
    """|(0, 0, 1e300)| is finite but its square is not: softarm 0.1 swept a zero force. The
    direction is +z whatever its length: the sweep equals the one along (0, 0, 1)."""
    path = tmp_path / "overflow.toml"
    path.write_text(SWEEP_CASE)
    unit = tmp_path / "unit.toml"
    unit.write_text(SWEEP_CASE.replace("1e300", "1.0"))
    swept = softarm.case.solve_case(softarm.load_case(path))
    reference = softarm.case.solve_case(softarm.load_case(unit))
    np.testing.assert_allclose(swept.tip_position, reference.tip_position, rtol=0, atol=1e-12)
    assert swept.tip_position[1, 2] > 0.3  # k = 1 along +z: w/L = 0.30 (Mattiasson 1981)


@pytest.mark.slow
def test_r6_sweep_direction_that_overflows_cli(tmp_path):
    path = tmp_path / "overflow.toml"
    path.write_text(SWEEP_CASE)
    unit = tmp_path / "unit.toml"
    unit.write_text(SWEEP_CASE.replace("1e300", "1.0"))
    tables = []
    for case in (path, unit):
        out = tmp_path / f"{case.stem}.csv"
        run = subprocess.run([sys.executable, "-m", "softarm", "solve", str(case), "-o",
                              str(out)], capture_output=True, text=True, timeout=600)
        # nothing on stderr but the progress bar, which a slow first run shows (a subprocess
        # that compiles a kernel variant the suite has not cached yet)
        said = [line for line in run.stderr.splitlines()
                if line.strip() and not line.startswith("solving [")]
        assert run.returncode == 0 and not said, (run.returncode, run.stderr)
        tables.append(np.genfromtxt(out, delimiter=",", skip_header=1))
    np.testing.assert_allclose(tables[0], tables[1], rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# 7. hang on non-finite or subnormal derived quantities

_GUARD_S = 120  # a guard against the old 3-4 minute spin, never an assertion of speed

_R7 = {
    # ρ A = 1e308 × π = inf kg/m: the linear density overflows
    "linear_density": (
        "arm = softarm.Arm(1.0, softarm.Circle(1.0), softarm.Material(youngs_modulus=1.5e6, "
        "poisson_ratio=0.49, density=1e308))\n"
        "softarm.solve(arm, softarm.Gravity())",
        "(?i)density|mass"),
    # EIy = 1e-310 N m² is subnormal
    "subnormal_EI": (
        "arm = softarm.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1e-310, "
        "EIz=1.0)\n"
        "softarm.solve(arm, softarm.TipLoad(force=(0.0, 0.0, 1e-3)))",
        "(?i)EIy|stiffness|rigidit"),
}


@pytest.mark.parametrize("name", sorted(_R7))
@pytest.mark.slow
def test_r7_non_finite_or_subnormal_derived_quantity_is_a_value_error(name):
    code, pattern = _R7[name]
    script = textwrap.dedent("""\
        import json, softarm
        try:
        {body}
            print(json.dumps({{"raised": None}}))
        except Exception as error:
            print(json.dumps({{"raised": type(error).__name__,
                               "value_error": isinstance(error, ValueError),
                               "message": str(error)}}))
        """).format(body=textwrap.indent(code, "    "))
    try:
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             timeout=_GUARD_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{name}: still running after {_GUARD_S} s (the reproducer's hang)")
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["raised"] is not None, f"{name}: no exception"
    assert result["value_error"], result
    assert re.search(pattern, result["message"]), result


# ---------------------------------------------------------------------------------------------
# 8. crash at import without a writable cache


def _read_only_copy(root: Path) -> Path:
    """softarm copied under root, read-only, where no __pycache__ can be created.

    Directories are 0555 and files 0444 (enough for a normal user); as root (which ignores
    permissions) a regular file named __pycache__ in every package directory blocks numba's
    in-tree cache and Python's bytecode cache alike.
    """
    src = Path(softarm.__file__).parent
    dest = root / "site" / "softarm"
    shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    dirs = [d for d in dest.rglob("*") if d.is_dir()] + [dest]
    for d in dirs:
        (d / "__pycache__").write_text("")
    for path in dest.rglob("*"):
        if path.is_file():
            path.chmod(stat.S_IRUSR | stat.S_IRGRP | stat.S_IROTH)
    for d in dirs:
        d.chmod(0o555)
    return dest.parent


R8_SCRIPT = r"""
import json, sys, warnings
warnings.simplefilter("always")
with warnings.catch_warnings(record=True) as at_import:
    import softarm
import numba.core.registry as registry
compiled = []
for name, module in list(sys.modules.items()):
    if name == "softarm" or name.startswith("softarm."):
        for attr in vars(module).values():
            if isinstance(attr, registry.CPUDispatcher) and attr.signatures:
                compiled.append(f"{name}.{attr.__name__}")
closed = softarm.analytic.tip_moment(
    softarm.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0),
    moment=[0.0, 1.0, 0.0])
with warnings.catch_warnings(record=True) as at_solve:
    arm = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    eq = softarm.solve(arm, softarm.TipLoad(force=[0.0, 0.0, 1.0]), method="analytic")
print(json.dumps({
    "file": softarm.__file__,
    "compiled_at_import": compiled,
    "import_warnings": [str(w.message) for w in at_import],
    "solve_warnings": [str(w.message) for w in at_solve],
    "closed_tip": closed.tip_position.tolist(),
    "tip": eq.tip_position.tolist(),
}))
"""


@pytest.mark.slow  # (~15 s: compiles the closed forms in memory, without numba's cache)
def test_r8_import_and_solve_without_a_writable_cache(tmp_path):
    """Where neither the package's folder nor any cache folder can be written, softarm
    imports (compiling nothing), warns once, naming NUMBA_CACHE_DIR, and solves, compiling
    in memory. The solve is the closed-form elastica: its kernels are cached through the same
    softarm._jit as the shooting solver's (a numeric solve here cost 70 s of CI's slow run:
    the whole solver and its verdict compiled in memory, for the same check)."""
    root = Path(tempfile.mkdtemp(prefix="softarm-ro-"))
    try:
        site = _read_only_copy(root)
        blocker = root / "blocker"       # a file: nothing can be created below it
        blocker.write_text("")
        locked = root / "locked"          # a read-only directory
        locked.mkdir()
        locked.chmod(0o555)
        root.chmod(0o555)
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("NUMBA", "PYTHON", "XDG"))}
        env.update(PYTHONPATH=str(site), HOME=str(blocker / "home"),
                   XDG_CACHE_HOME=str(blocker / "xdg"), PYTHONDONTWRITEBYTECODE="1",
                   NUMBA_CACHE_DIR=str(locked if os.geteuid() != 0 else blocker / "numba"))
        run = subprocess.run([sys.executable, "-c", R8_SCRIPT], capture_output=True, text=True,
                             env=env, cwd=str(root), timeout=900)
    finally:
        for d in [root, *root.rglob("*")]:
            if d.is_dir() and not d.is_symlink():
                d.chmod(0o755)
        shutil.rmtree(root, ignore_errors=True)
    assert run.returncode == 0, run.stderr[-3000:]
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["file"].startswith(str(site)), out["file"]
    assert out["compiled_at_import"] == []
    # pure bending, M/EI = 1 about +y: a circular arc bending towards -z
    np.testing.assert_allclose(out["closed_tip"], [np.sin(1.0), 0.0, -(1.0 - np.cos(1.0))],
                               atol=1e-9)
    # Mattiasson (1981) Table 1, k = 1: w/L = 0.30172, inextensible; here EA = 1e9 N
    assert out["tip"][2] == pytest.approx(0.30172, abs=2e-5)
    warned = out["import_warnings"] + out["solve_warnings"]
    assert any("NUMBA_CACHE_DIR" in w for w in warned), warned


# ---------------------------------------------------------------------------------------------
# a fold is named, never stepped over


def _folding_arm_and_loads():
    """A two-segment precurved silicone arm under gravity, a tip load and a follower
    distributed force (case 145 of the large invariant run): its loading path folds."""
    from softarm import Arm, Circle, Material, SegmentedArm
    arm = SegmentedArm((
        Arm(0.057223175772382645, Circle(0.006442504304126564),
            Material(1412509.6998014837, 0.45838143782569835, density=1166.3554475481694)),
        Arm(0.06618812950420067, Circle(0.003616947541333363),
            Material(3375017.1648721294, 0.46084365394229315, density=1062.677284099753),
            curvature=(0.585028501892152, 19.629228462126353, 3.855973461989754)),
    ))
    loads = [softarm.Gravity([0.5343718257142738, 8.975736710575093, -3.922588081142014]),
             softarm.TipLoad(force=[-0.16034632351717393, -0.2942841125760248,
                                    0.08767939608339592],
                             moment=[-0.0004259798954824446, 5.268703753457297e-05,
                                     5.146484277363034e-05]),
             softarm.DistributedForce([7.498238810500564, 7.297987066688497,
                                       0.7367217597926948], follower=True)]
    return arm, loads


def test_a_fold_is_named_with_its_load_factor():
    """The solve stops at the fold with its load factor. Independent evidence that it is a
    fold (a second method): along the path followed quasi-statically, det ∂r/∂x from the
    shooting primitive at 400 fixed steps falls to zero like √(λ_c - λ), the signature of a
    limit point, and extrapolates to the same λ_c."""
    arm, loads = _folding_arm_and_loads()
    with pytest.raises(softarm.ConvergenceError) as info:
        softarm.solve(arm, loads)
    lam_c = info.value.load_factor
    assert 0.63 < lam_c < 0.65 and f"{lam_c:.6g}" in str(info.value)
    solver = softarm.statics.Solver(arm, tol=1e-8)
    lams = np.array([0.62, 0.63, 0.64])
    dets = []
    for lam in lams:
        scaled = [load.scaled(lam) for load in loads]
        eq = solver.solve(scaled)
        x = eq.stresses[0]  # the base reaction: R(0) = I, material = spatial components
        dets.append(np.linalg.det(solver.shoot(scaled, x, steps=400).jacobian_x))
    # det² linear in λ near a fold: its zero from the last two points
    d2 = np.square(dets)
    assert np.all(np.diff(d2) < 0)
    root = lams[1] - d2[1] * (lams[2] - lams[1]) / (d2[2] - d2[1])
    assert abs(root - lam_c) < 2e-3, (root, lam_c)


def test_a_chained_solve_through_a_vanishing_input_is_no_zero_division():
    """A chained Solver driven from tensions (0, 1/3, 0.2) N through (5.8e-113, 0, 0) N to
    zero (what inverse statics met with extreme scales): the path's turning test took the
    cosine of two tip motions of order 1e-113 m per unit load, whose squared norms' product
    underflowed to 0, and the kernel raised ZeroDivisionError. Now the last equilibrium is
    the unloaded-by-tendons arm's, as a solve from the unloaded arm gives it."""
    from softarm.routing import Straight

    nitinol = softarm.Material(6.0e10, poisson_ratio=0.33, density=6450.0)
    arm = softarm.Arm(0.25, softarm.Circle(0.0006), nitinol, mass_per_length=0.02)
    offsets = [(0.0, 0.008), (0.006928, -0.004), (-0.006928, -0.004)]

    def loads(tensions):
        return [softarm.Gravity([0.0, 0.0, -9.81]),
                *(softarm.Tendon(t, Straight(*o)) for t, o in zip(tensions, offsets, strict=True))]

    solver = softarm.statics.Solver(arm, tol=1e-6)
    for tensions in ((0.0, 1 / 3, 0.2), (5.8e-113, 0.0, 0.0), (0.0, 0.0, 0.0)):
        last = solver.solve(loads(tensions))
    alone = softarm.solve(arm, loads((0.0, 0.0, 0.0)), tol=1e-6, method="numeric")
    np.testing.assert_allclose(last.tip_position, alone.tip_position, rtol=0.0,
                               atol=1e-6 * 0.25)
