"""Checks of the method-of-lines swinging-arm reference (tests/_mol_rod.py) and its data file."""

import numpy as np
import pytest
from _mol_rod import energy, linear_frequencies, load_reference, simulate, swinging_arm

from softarm.validation._timoshenko import cantilever_bending


def test_small_amplitude_limit_is_the_timoshenko_cantilever():
    # the semi-discrete rod's lowest two bending frequencies converge at O(h²) to the roots
    # of Huang's frequency equation; Richardson of 20/40 cells lands within 1e-5 relative
    rod = swinging_arm()
    exact = cantilever_bending(rod.length, rod.EI, rod.GA, rod.rhoA, rod.rhoI)
    coarse, fine = linear_frequencies(rod, 20), linear_frequencies(rod, 40)
    ratio = np.abs(coarse - exact) / np.abs(fine - exact)
    assert np.all((ratio > 3.8) & (ratio < 4.2))  # second order
    np.testing.assert_allclose((4 * fine - coarse) / 3, exact, rtol=1e-5)


@pytest.mark.slow
def test_undamped_swing_conserves_the_discrete_energy():
    # T + V is exactly conserved by the semi-discrete system (module docstring); the change
    # over 0.3 s is the time integration's alone and shrinks with rtol
    rod = swinging_arm()
    drifts = []
    for rtol in (1e-5, 1e-8):
        run = simulate(rod, 10, duration=0.3, rtol=rtol, t_eval=np.linspace(0, 0.3, 31))
        e = energy(rod, 10, run.y)
        drifts.append(np.max(np.abs(e - e[0])))
    swing_energy = rod.rhoA * rod.length * rod.gravity * 0.1  # order of the exchanged energy
    assert drifts[1] < 1e-9 * swing_energy < drifts[0]


def test_damped_swing_dissipates():
    rod = swinging_arm(tau=0.01)
    run = simulate(rod, 10, duration=0.3, rtol=1e-6, t_eval=np.linspace(0, 0.3, 31))
    e = energy(rod, 10, run.y)
    assert np.all(np.diff(e) < 1e-12)
    assert e[-1] < -1e-3


@pytest.mark.parametrize("case", ["undamped", "damped"])
def test_reference_file_matches_a_coarse_run(case):
    # the stored trajectory against a fresh 40-cell run: their gap is the 40-cell
    # discretisation error, measured at 1.2e-4 m (undamped) in the convergence study
    t, tip = load_reference(case)
    assert t.shape == (151,) and np.allclose(t, np.arange(151) * 0.01)
    assert tip[0] == pytest.approx([0.5, 0.0])
    rod = swinging_arm(0.0 if case == "undamped" else 0.01)
    run = simulate(rod, 40, duration=0.3, rtol=1e-7, t_eval=t[:31],
                   method="DOP853" if case == "undamped" else "Radau")
    gap = np.max(np.abs(run.tip_xz - tip[:31]))
    assert 1e-7 < gap < 3e-4
