"""Multiple shooting (issue 31): the stiff route's verdicts, its agreement with single
shooting where both work, equilibrium at every station, its errors. The references of the
stiff regime itself (linear tension theory, the separatrix of a hard pull, hanging arms
against solve_bvp) are in test_stiff_tension.py and test_stiff_hanging.py."""

import time

import numpy as np
import pytest

import softarm
from softarm import Arm, Circle, DistributedForce, Gravity, Material, TipLoad
from softarm.statics.solver import Solver

ROD = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
NUDGE = DistributedForce([0.0, 0.0, 0.0])  # (keeps a tip-load case on the numerical route)


def pull(F, lateral=1e-3):
    return [TipLoad(force=[F, 0.0, lateral * F]), NUDGE]


@pytest.mark.parametrize(("P", "index"), [(5.0, 2), (30.0, 4)])
def test_the_verdict_of_a_compressed_column_is_the_same_on_both_routes(P, index):
    # the straight column under P L²/EI = 5 and 30 has lost stability at (2n - 1)² π²/4 in
    # each of its two bending planes: once (2.47) and twice (2.47, 22.2)
    assert sum(2 for n in (1, 2, 3) if (2 * n - 1) ** 2 * np.pi ** 2 / 4 < P) == index
    for shooting in ("single", "multiple"):
        eq = Solver(ROD, s=5, shooting=shooting).solve([TipLoad(force=[-P, 0.0, 0.0]), NUDGE])
        assert int(eq.stability.index) == index


@pytest.mark.parametrize("F", [1e3, 1e6])
def test_a_rod_in_strong_tension_is_stable(F):
    eq = softarm.solve(ROD, pull(F))
    assert eq.stability.stable
    assert int(eq.stability.index) == 0


@pytest.mark.parametrize("F", [100.0, 150.0])
def test_both_routes_agree_where_single_shooting_still_works(F):
    # kL = 10 and 12: single shooting's growth e^{kL} still leaves it 1e-8 L; the intervals
    # of the multiple-shooting route cut the arm in 2 and 3
    loads = [TipLoad(force=[0.5 * F, 0.0, F]), NUDGE]
    single = Solver(ROD, s=11, shooting="single").solve(loads)
    multiple = Solver(ROD, s=11, shooting="multiple").solve(loads)
    assert np.abs(single.positions - multiple.positions).max() < 1e-9
    assert np.abs(single.stresses - multiple.stresses).max() < 1e-6 * F


def test_a_hanging_hose_carries_the_weight_below_every_station():
    # a 3 m silicone hose (qL³/EI = 7.6e3, kL = 87): n(s) = ∫_s^L f = -q (L - s) e_z at
    # every station (n' = -f, n(L) = 0), spatial, from the material stresses rotated by R(s)
    L, q = 3.0, 1070.0 * np.pi * 1e-4 * 9.81
    arm = Arm(L, Circle(0.01), Material(1.5e6, poisson_ratio=0.49, density=1070.0))
    eq = softarm.solve(arm, [Gravity([0.0, 0.0, -9.81])], s=31)
    n = np.einsum("sij,sj->si", eq.poses[:, :3, :3], eq.stresses[:, :3])
    expected = np.zeros_like(n)
    expected[:, 2] = -q * (L - eq.s)
    assert np.abs(n - expected).max() < 1e-9 * q * L
    assert eq.error_estimate <= 1e-8 * L


def test_a_chained_solver_gives_the_unchained_answer_of_a_stiff_case():
    solver = Solver(ROD, s=5)
    solver.solve(pull(1.0))
    chained = solver.solve(pull(1e5))
    alone = softarm.solve(ROD, pull(1e5), s=5)
    assert np.abs(chained.positions - alone.positions).max() < 1e-12
    again = solver.solve(pull(2.0))  # from the unloaded arm again, as after a reset
    assert np.abs(again.positions - softarm.solve(ROD, pull(2.0), s=5).positions).max() < 1e-9


def test_a_stiff_failure_is_fast_and_says_what_was_reached():
    solver = Solver(ROD, s=5, max_shootings=3)
    start = time.process_time()
    with pytest.raises(softarm.ConvergenceError, match="max_shootings=3") as caught:
        solver.solve(pull(1e6))
    assert time.process_time() - start < 2.0
    assert caught.value.load_factor < 1.0


def test_the_shooting_route_is_checked():
    with pytest.raises(ValueError, match="shooting must be 'auto', 'single' or 'multiple', "
                                         "got 'double'"):
        Solver(ROD, shooting="double")


def test_jacobians_of_a_stiff_case_say_they_are_not_there_yet():
    with pytest.raises(NotImplementedError, match=r"jacobians=True on a stiff case \(kL = 1e\+03"):
        softarm.solve(ROD, pull(1e6), jacobians=True)
