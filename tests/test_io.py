"""Result files out and back: columns, round trips, rejected files and atomic writes."""

from __future__ import annotations

import csv
import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import io
from softarm.case import CaseError, load_case
from softarm.lie import se3

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def arc(kappa: float = 3.0, n: int = 11, length: float = 1.0, batch=None):
    """An exact circular arc of curvature κ about material y (pure bending, paper eq. 38)."""
    arm = softarm.Arm.from_stiffness(length, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    s = np.linspace(0.0, length, n)
    kappa = np.asarray(kappa, dtype=float)
    twist = np.array([1.0, 0, 0, 0, 0, 0]) + kappa[..., None] * np.array([0, 0, 0, 0, 1, 0])
    poses = se3.exp(s[:, None] * twist[..., None, :])
    strains = np.broadcast_to((twist - [1, 0, 0, 0, 0, 0])[..., None, :], (*kappa.shape, n, 6))
    moment = np.stack([0 * kappa, kappa, 0 * kappa], axis=-1)
    return softarm.Equilibrium(s, poses, strains, strains, arm,
                               (softarm.TipLoad(moment=moment),), "test.arc", True,
                               np.zeros(kappa.shape) if kappa.shape else 0.0,
                               np.zeros(kappa.shape) if kappa.shape else 0.0)


# ------------------------------------------------------------------------------- result files


def test_columns_of_an_arc(tmp_path):
    """CSV columns against the closed-form arc: x = sin(κs)/κ, z = -(1 - cos κs)/κ, R = Ry(κs)
    (paper eq. 38), rotation vector (0, κs, 0), quaternion (cos κs/2, 0, sin κs/2, 0)."""
    result = arc(2.0)
    path = io.save_result(result, tmp_path / "arc.csv")
    lines = path.read_text().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    assert any("(w, x, y, z)" in line for line in comments)
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert list(rows[0]) == list(io.COLUMNS)
    table = {k: np.array([float(r[k]) for r in rows]) for k in io.COLUMNS}
    s, k = table["s_m"], 2.0
    np.testing.assert_allclose(table["x_m"], np.sin(k * s) / k, atol=1e-15)
    np.testing.assert_allclose(table["z_m"], -(1 - np.cos(k * s)) / k, atol=1e-15)
    np.testing.assert_allclose(table["rotvec_y_rad"], k * s, atol=1e-15)
    np.testing.assert_allclose(table["quat_w"], np.cos(k * s / 2), atol=1e-15)
    np.testing.assert_allclose(table["quat_y"], np.sin(k * s / 2), atol=1e-15)
    np.testing.assert_allclose(table["kappa_2_per_m"], k)
    np.testing.assert_allclose(table["m_2_Nm"], k)
    # as docs/case-files.md says: five comment lines, then the header
    array = np.genfromtxt(path, delimiter=",", names=True, skip_header=5)
    assert array.dtype.names == io.COLUMNS
    np.testing.assert_array_equal(array["x_m"], table["x_m"])


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
@pytest.mark.parametrize("batch", [None, (3, 1, 2)])
def test_round_trip_without_case(tmp_path, suffix, batch):
    kappa = 2.0 if batch is None else np.linspace(0.5, 3.0, 6).reshape(batch)
    result = arc(kappa)
    back = io.load_result(io.save_result(result, tmp_path / f"r{suffix}"))
    atol = 1e-15 if suffix != ".csv" else 1e-14  # CSV rebuilds R from the quaternion
    assert back.batch_shape == result.batch_shape
    np.testing.assert_allclose(back.poses, result.poses, atol=atol, rtol=0)
    np.testing.assert_array_equal(back.strains, result.strains)
    np.testing.assert_array_equal(back.stresses, result.stresses)
    np.testing.assert_array_equal(back.s, result.s)
    assert back.method == result.method and back.exact == result.exact
    np.testing.assert_array_equal(back.residual, result.residual)
    assert back.arm == result.arm
    np.testing.assert_array_equal(back.loads[0].moment, result.loads[0].moment)


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
def test_round_trip_with_sweep_case(tmp_path, suffix):
    case = load_case(EXAMPLES / "fig2_sweep.toml")
    values = np.asarray(case.sweep.values)
    result = arc(values)
    path = io.save_result(result, tmp_path / f"sweep{suffix}", case)
    saved = io.load_saved(path)
    assert saved.version == softarm.__version__
    assert saved.case.name == "fig2_sweep" and saved.case.sweep == case.sweep
    np.testing.assert_array_equal(saved.sweep_values, values)
    assert saved.sweep_label == case.sweep.label
    np.testing.assert_allclose(saved.result.poses, result.poses, atol=1e-14, rtol=0)
    np.testing.assert_array_equal(saved.result.loads[0].moment[:, 1], values)
    if suffix == ".csv":
        header = next(line for line in path.read_text().splitlines() if not line[0] == "#")
        assert header.startswith("tip_moment_tau_Nm,s_m,x_m")
    if suffix == ".json":
        document = json.loads(path.read_text())
        assert document["case"]["sweep"]["stop"] == 5.0
        assert document["softarm_version"] == softarm.__version__


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
def test_the_stability_verdict_round_trips_and_is_drawn(tmp_path, suffix):
    """A straight cantilever compressed by 5 N with EI = 1 N m², L = 1 m: past the first Euler
    load π²EI/4L² = 2.47 N and below the second, 9π²EI/4L² = 22.2 N, in both bending planes
    (EIy = EIz), so the straight state has two unstable directions (Morse index 2). Read back
    from any format, the result carries that verdict and its picture says so, as the picture
    of the solve itself does."""
    arm = softarm.Arm.from_stiffness(1.0, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    with pytest.warns(softarm.StabilityWarning):
        result = softarm.solve(arm, [softarm.TipLoad(force=[-5.0, 0.0, 0.0])], s=11)
    assert (result.stability.index, result.stability.conservative) == (2, True)
    saved = io.load_saved(io.save_result(result, tmp_path / f"r{suffix}"))
    verdict = saved.result.stability
    assert (verdict.index, verdict.conservative, verdict.stable) == (2, True, False)
    from softarm import plot

    def footer(fig):
        return next(t.get_text() for t in fig.texts if t.get_text().startswith("tip at"))

    drawn = footer(plot.plot_result_file(saved))
    assert "; UNSTABLE (Morse index 2" in drawn
    assert drawn == footer(plot.plot_equilibrium(result))


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
def test_a_batch_verdict_round_trips(tmp_path, suffix):
    result = arc(np.array([[0.5, 1.0, 1.5], [2.0, 2.5, 3.0]]))._with_stability(
        softarm.Stability.of([[0, 1, 2], [-1, 0, 3]],
                             [[True, False, True], [True, True, False]]))
    back = io.load_result(io.save_result(result, tmp_path / f"b{suffix}"))
    np.testing.assert_array_equal(back.stability.index, [[0, 1, 2], [-1, 0, 3]])
    np.testing.assert_array_equal(back.stability.stable, [[True, False, False],
                                                          [False, True, False]])


def test_a_file_without_verdict_reads_back_without_one(tmp_path):
    """Files of softarm 0.2 carry no verdict: read back, the result has none (not a made-up
    one); a verdict that is not integers and booleans of the batch shape is refused."""
    path = io.save_result(arc(2.0)._with_stability(softarm.Stability.of(0, True, ())),
                          tmp_path / "r.csv")
    lines = path.read_text().splitlines()
    meta = json.loads(lines[3].removeprefix("# meta: "))
    for value, ok in ((None, True), ({"index": [0], "conservative": True}, False),
                      ({"index": True, "conservative": True}, False),
                      ({"index": 0, "conservative": 1}, False)):
        meta["stability"] = value
        lines[3] = "# meta: " + json.dumps(meta)
        path.write_text("\n".join(lines) + "\n")
        if ok:
            assert io.load_result(path).stability is None
        else:
            with pytest.raises(CaseError, match="'stability'"):
                io.load_result(path)


def test_save_rejects_unknown_format(tmp_path):
    with pytest.raises(ValueError, match=r"unknown output format '\.txt'"):
        io.save_result(arc(), tmp_path / "r.txt")
    assert list(tmp_path.iterdir()) == []


def test_load_rejects_other_files(tmp_path):
    path = tmp_path / "other.csv"
    path.write_text("a,b\n1,2\n")
    with pytest.raises(CaseError, match="not a softarm result"):
        io.load_result(path)
    with pytest.raises(CaseError, match="no such file"):
        io.load_result(tmp_path / "missing.json")


def test_atomic_write_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError), io.write_atomic(target) as stream:
        stream.write("half")
        raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


def test_written_files_get_normal_permissions(tmp_path):
    """An atomic write must not leave the private 0600 mode of its temporary file behind."""
    umask = os.umask(0o022)
    try:
        path = io.save_result(arc(), tmp_path / "r.json")
    finally:
        os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
