"""Batches in threads (``softarm._threads``, Solver's ``threads``): a batch solved from the
unloaded arm is cut into contiguous chunks solved concurrently. Reference: the same batch on
one thread, and each case solved alone. Every case is independent of the others, so the
answers must agree to the bit, stability verdicts, compliances and actuation Jacobians
included, whatever the cut."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm import _threads
from softarm.routing import Straight
from softarm.statics import Solver

_FIELDS = ("poses", "strains", "stresses", "base_wrench", "residual", "error_estimate",
           "tip_compliance", "compliance")


def _tendon_robot():
    nitinol = softarm.Material(6.0e10, poisson_ratio=0.33, density=6450.0)
    arm = softarm.Arm(0.25, softarm.Circle(0.0006), nitinol, mass_per_length=0.02)
    offsets = [(0.0, 0.008), (0.006928, -0.004), (-0.006928, -0.004)]
    return arm, offsets


def _same(a, b, fields) -> None:
    for name in fields:
        x, y = getattr(a, name), getattr(b, name)
        assert np.array_equal(x, y), name
    assert np.array_equal(a.stability.index, b.stability.index)
    assert np.array_equal(a.stability.stable, b.stability.stable)


def test_a_passive_batch_in_threads_equals_it_on_one_thread_and_case_by_case():
    rng = np.random.default_rng(4)
    arm = softarm.Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=0.7, EIy=1.0, EIz=1.3)
    loads = softarm.TipLoad(force=rng.normal(size=(3, 23, 3)) * 1.5,
                            moment=rng.normal(size=(3, 23, 3)) * 0.3)
    one = Solver(arm, s=11, threads=1).solve_from_unloaded(loads, jacobians=True)
    three = Solver(arm, s=11, threads=3).solve_from_unloaded(loads, jacobians=True)
    _same(three, one, _FIELDS)
    alone = Solver(arm, s=11).solve_from_unloaded(
        softarm.TipLoad(force=loads.force[2, 17], moment=loads.moment[2, 17]), jacobians=True)
    assert np.array_equal(three.poses[2, 17], alone.poses)
    assert np.array_equal(three.tip_compliance[2, 17], alone.tip_compliance)


def test_an_actuated_batch_in_threads_equals_it_on_one_thread():
    arm, offsets = _tendon_robot()
    tensions = np.random.default_rng(5).uniform(0.0, 3.0, size=(40, 3))
    loads = [softarm.Gravity([0.0, 0.0, -9.81])] + [
        softarm.Tendon(tensions[:, i], Straight(*o)) for i, o in enumerate(offsets)]
    one = softarm.solve(arm, loads, tol=1e-6, jacobians=True, threads=1)
    two = softarm.solve(arm, loads, tol=1e-6, jacobians=True, threads=2)
    _same(two, one, (*_FIELDS, "tendon_tensions", "tendon_lengths", "actuation_jacobian",
                     "tendon_length_jacobian"))


def test_in_threads_covers_every_element_once_in_contiguous_ranges():
    seen = []

    def work(first, last):
        seen.append((first, last))

    _threads.in_threads(work, 50, 3)
    assert sorted(seen) == [(0, 16), (16, 33), (33, 50)]
    seen.clear()
    _threads.in_threads(work, 2, 8)  # never more threads than elements
    assert sorted(seen) == [(0, 1), (1, 2)]


def test_a_chained_batch_is_one_path_in_one_thread(monkeypatch):
    calls = []
    real = _threads.in_threads

    def spy(work, size, threads):
        calls.append(threads)
        real(work, size, threads)

    monkeypatch.setattr("softarm.statics.solver.in_threads", spy)
    arm = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    loads = softarm.TipLoad(force=np.linspace(0.0, 1.0, 64)[:, None] * [0.0, 0.0, 2.0])
    Solver(arm, s=3, threads=4).solve(loads)
    assert calls == [1]
    calls.clear()
    Solver(arm, s=3, threads=4).solve_from_unloaded(loads)
    assert calls == [4]  # 64 cases: 16 a thread
    calls.clear()
    Solver(arm, s=3, threads=4).solve_from_unloaded(softarm.TipLoad(force=loads.force[:20]))
    assert calls == [1]  # fewer than 2 × 16 cases: one thread


def test_the_default_follows_softarm_num_threads(monkeypatch):
    monkeypatch.setenv(_threads.THREADS_VARIABLE, "3")
    assert _threads.available_threads() == 3
    monkeypatch.setenv(_threads.THREADS_VARIABLE, "0")
    with pytest.raises(ValueError, match="SOFTARM_NUM_THREADS must be a positive integer"):
        _threads.available_threads()


@pytest.mark.parametrize(("threads", "error", "match"), [
    (0, ValueError, "threads must be an integer >= 1, got 0"),
    (1.5, TypeError, "threads must be an integer, got a float"),
    (True, TypeError, "threads must be an integer, got a bool"),
    ("2", TypeError, "threads must be an integer, got a str"),
])
def test_bad_threads_are_refused_by_name(threads, error, match):
    arm = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    with pytest.raises(error, match=match):
        Solver(arm, threads=threads)
    with pytest.raises(error, match=match):
        softarm.solve(arm, softarm.TipLoad([0.0, 0.0, 1.0]), threads=threads)
