"""Sweep designs: key paths, the four designs, [sweep] parameter tables and their errors.

Needs no extra package (the designs and the case reader are numpy and scipy only)."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import softarm
from softarm.case import CaseError, parse_case
from softarm.sweep import Design, Parameter

STIFF = {"EA": 1e6, "GAy": 1e6, "GAz": 1e6, "GJ": 1.0, "EIy": 1.0, "EIz": 1.0}
SILICONE = {"E": 1.5e6, "nu": 0.49, "density": 1070.0}


def two_segment_case(sweep: dict) -> dict:
    """The issue's example: two segments, gravity and a tip force (load 2)."""
    return {
        "segment": [
            {"length": 0.2, "section": {"kind": "circle", "radius": 0.012},
             "material": dict(SILICONE)},
            {"length": 0.1, "section": {"kind": "circle", "radius": 0.008},
             "material": dict(SILICONE)},
        ],
        "load": [{"kind": "gravity"}, {"kind": "tip", "force": [0.0, 0.0, -1.0]}],
        "sweep": sweep,
    }


def test_the_issue_example_parses():
    case = parse_case(two_segment_case({"design": "grid", "parameter": [
        {"path": "load[2].force.magnitude", "start": 0.0, "stop": 1.5, "steps": 25},
        {"path": "segment[1].section.radius", "values": [0.014, 0.016, 0.018, 0.020]}]}))
    assert case.sweep is None
    design = case.design
    assert design.kind == "grid" and design.shape == (25, 4) and design.size == 100
    values = design.values()
    # the Cartesian product, the first parameter slowest (as nested loops)
    expected = [(f, r) for f in np.linspace(0.0, 1.5, 25) for r in (0.014, 0.016, 0.018, 0.02)]
    np.testing.assert_array_equal(values, expected)
    np.testing.assert_array_equal(design.values(37, 41), expected[37:41])


def test_list_design_zips_the_values():
    design = Design((Parameter("arm.length", values=(1.0, 2.0, 3.0)),
                     Parameter("load[1].force.z", values=(0.1, 0.2, 0.3))), "list")
    np.testing.assert_array_equal(design.values(), [[1.0, 0.1], [2.0, 0.2], [3.0, 0.3]])
    with pytest.raises(ValueError, match="same number of values"):
        Design((Parameter("arm.length", values=(1.0, 2.0)),
                Parameter("load[1].force.z", values=(0.1,))), "list")


def test_latin_hypercube_has_one_sample_per_stratum():
    """Latin hypercube property (McKay, Beckman & Conover 1979): with n samples each of the n
    equal slices of every parameter's range holds exactly one sample; same seed, same design."""
    n = 50
    design = Design((Parameter("arm.length", start=0.2, stop=0.4),
                     Parameter("load[1].force.y", start=-1.0, stop=1.0)),
                    "latin-hypercube", samples=n, seed=7)
    values = design.values()
    assert values.shape == (n, 2)
    for j, (low, high) in enumerate([(0.2, 0.4), (-1.0, 1.0)]):
        strata = np.floor((values[:, j] - low) / (high - low) * n).astype(int)
        assert sorted(strata) == list(range(n))
    again = Design(design.parameters, "latin-hypercube", samples=n, seed=7).values()
    np.testing.assert_array_equal(values, again)
    other = Design(design.parameters, "latin-hypercube", samples=n, seed=8).values()
    assert not np.array_equal(values, other)


def test_sobol_points_are_a_net():
    """The first 2^m points of a (scrambled) Sobol sequence are a (0, m, 1)-net in each
    coordinate: one point in each of the 2^m equal slices (Sobol 1967; Owen scrambling keeps
    it). A slice count that is not a power of 2 is accepted too (no warning)."""
    m = 6
    design = Design((Parameter("arm.length", start=1.0, stop=2.0),
                     Parameter("load[1].moment.y", start=0.0, stop=4.0),
                     Parameter("load[1].moment.z", start=-1.0, stop=1.0)),
                    "sobol", samples=2 ** m, seed=3)
    values = design.values()
    for j, (low, high) in enumerate([(1.0, 2.0), (0.0, 4.0), (-1.0, 1.0)]):
        slices = np.floor((values[:, j] - low) / (high - low) * 2 ** m).astype(int)
        assert sorted(slices) == list(range(2 ** m))
    odd = Design(design.parameters, "sobol", samples=10, seed=3).values()
    np.testing.assert_array_equal(odd, values[:10])  # a prefix of the same sequence


@pytest.mark.parametrize(("parameter", "message"), [
    ({"path": "load[3].force.x", "values": [1.0]}, "there are 2 [[load]] tables"),
    ({"path": "load[2].forse.x", "values": [1.0]}, "did you mean 'force'"),
    ({"path": "load[2].force", "values": [1.0]}, "name a component"),
    ({"path": "load[2].force.w", "values": [1.0]}, "unknown component 'w'"),
    ({"path": "load[2].follower", "values": [1.0]}, "unknown key 'follower'"),
    ({"path": "segment[3].length", "values": [1.0]}, "there are 2 [[segment]] tables"),
    ({"path": "arm.length", "values": [1.0]}, "has [[segment]] tables, not [arm]"),
    ({"path": "segment[1].stiffness.EA", "values": [1.0]}, "not stiffness"),
    ({"path": "segment[1].section.width", "values": [1.0]}, "unknown key 'width'"),
    ({"path": "load[2].force.x", "values": []}, "empty"),
    ({"path": "load[2].force.x", "start": 1.0, "stop": 1.0, "steps": 3}, "empty range"),
    ({"path": "load[2].force.x", "start": 0.0, "stop": 1.0, "steps": 1}, "steps"),
    ({"path": "load[2].force.x", "start": 0.0, "stop": 1.0}, "steps"),
    ({"path": "force.x", "values": [1.0]}, "key path"),
    ({"values": [1.0]}, "path: missing"),
])
def test_bad_parameters_name_the_key_path(parameter, message):
    data = two_segment_case({"design": "grid", "parameter": [parameter]})
    with pytest.raises(CaseError, match=r"sweep\.parameter\[1\]") as info:
        parse_case(data, "case.toml")
    assert message in str(info.value)
    assert str(info.value).startswith("case.toml: ")


@pytest.mark.parametrize(("sweep", "message"), [
    ({"design": "sobol", "parameter": [{"path": "load[2].force.x", "start": 0, "stop": 1}]},
     "needs samples"),
    ({"design": "sobol", "samples": 8,
      "parameter": [{"path": "load[2].force.x", "values": [0.0, 1.0]}]}, "start and stop only"),
    ({"design": "grid", "samples": 8,
      "parameter": [{"path": "load[2].force.x", "values": [0.0, 1.0]}]}, "samples is for"),
    ({"design": "grid", "parameter": [{"path": "load[2].force.x", "values": [0.0]},
                                      {"path": "load[2].force.x", "values": [1.0]}]},
     "given twice"),
    ({"design": "cube", "parameter": [{"path": "load[2].force.x", "values": [0.0]}]},
     "unknown value 'cube'"),
    ({"design": "grid"}, "sweep.parameter: missing"),
])
def test_bad_designs_are_case_errors(sweep, message):
    with pytest.raises(CaseError, match="sweep") as info:
        parse_case(two_segment_case(sweep), "case.toml")
    assert message in str(info.value)


def test_a_value_that_makes_the_arm_invalid_is_an_error_before_any_solve():
    """The radius -0.01 m is rejected by Circle itself; the message names the key path and
    the value, and nothing is solved (the map is never called)."""
    case = parse_case(two_segment_case({"design": "grid", "parameter": [
        {"path": "load[2].force.magnitude", "values": [0.0, 1.0]},
        {"path": "segment[1].section.radius", "values": [0.014, -0.01]}]}), "case.toml")
    calls = []

    def recording_map(function, tasks):
        calls.append(function)
        return map(function, tasks)

    pytest.importorskip("xarray", reason="softarm.sweep.run needs pip install "
                        "'softarm[sweep]'")
    with pytest.raises(ValueError, match=r"segment\[1\]\.section\.radius = -0\.01") as info:
        softarm.sweep.run(case, map=recording_map)
    assert "must be" in str(info.value) and calls == []


def test_one_parameter_sweeps_become_list_designs():
    """A one-parameter [sweep] keeps its Sweep (softarm solve) and maps onto the same key
    path for softarm sweep."""
    data = two_segment_case({"load": 2, "component": "y", "values": [0.5, 1.0]})
    case = parse_case(data)
    assert case.design is None and case.sweep.values == (0.5, 1.0)
    design = softarm.sweep.design_of(case)
    assert design.kind == "list" and design.paths == ("load[2].force.y",)
    np.testing.assert_array_equal(design.values(), [[0.5], [1.0]])


def test_design_to_dict_reads_back():
    design = Design((Parameter("arm.length", start=1.0, stop=2.0),
                     Parameter("arm.section.radius", start=0.01, stop=0.02)),
                    "latin-hypercube", samples=9, seed=4)
    data = {"arm": {"length": 1.0, "section": {"kind": "circle", "radius": 0.01},
                    "material": dict(SILICONE)}, "load": [{"kind": "gravity"}],
            "sweep": design.to_dict()}
    assert parse_case(data).design == design
    assert math.prod(design.shape) == 9


@pytest.mark.parametrize(("missing", "options", "extra"), [
    ("xarray", [], "softarm[sweep]"), ("zarr", [], "softarm[sweep]"),
    ("distributed", ["--scheduler", "local"], "softarm[dask]")])
def test_cli_names_the_extra_to_install(tmp_path, monkeypatch, capsys, missing, options, extra):
    from softarm.cli import main

    case = tmp_path / "case.toml"
    case.write_text("[arm]\nlength = 1.0\nstiffness = { EA = 1.0, GAy = 1.0, GAz = 1.0, "
                    "GJ = 1.0, EIy = 1.0, EIz = 1.0 }\n[[load]]\nkind = 'tip'\n"
                    "[sweep]\ndesign = 'grid'\n[[sweep.parameter]]\npath = 'load[1].force.z'\n"
                    "values = [0.0, 1.0]\n")
    monkeypatch.setitem(sys.modules, missing, None)  # import fails as if not installed
    assert main(["sweep", str(case), "-o", str(tmp_path / "out.zarr"), *options]) == 2
    err = capsys.readouterr().err
    assert f"pip install '{extra}'" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "out.zarr").exists()


def test_softarm_solve_points_a_design_to_softarm_sweep(tmp_path, capsys):
    from softarm.cli import main

    case = tmp_path / "case.toml"
    case.write_text("[arm]\nlength = 1.0\nstiffness = { EA = 1.0, GAy = 1.0, GAz = 1.0, "
                    "GJ = 1.0, EIy = 1.0, EIz = 1.0 }\n[[load]]\nkind = 'tip'\n"
                    "[sweep]\n[[sweep.parameter]]\npath = 'arm.length'\nvalues = [1.0, 2.0]\n")
    assert main(["solve", str(case)]) == 2
    err = capsys.readouterr().err
    assert "softarm sweep" in err and len(err.splitlines()) == 1
    assert err.count(str(case)) == 1  # the file named once (it was twice: "case: case: ...")


def test_progress_counts_cases_with_rate_and_eta():
    """The sweep's progress line: cases (not chunks), the rate since the first report and
    the time left at that rate (reference: the counts and times given here)."""
    import io

    from softarm import cli

    stream = io.StringIO()
    progress = cli._Progress(stream, width=10, delay=0.0, label="sweep", unit="cases", rate=True)
    progress.start -= 5.0
    progress(1000, 10000, 0)  # the first report starts the rate clock
    progress.first = (progress.first[0] - 2.0, 1000)  # 2 s ago
    progress.last = 0.0
    progress(5000, 10000, 3)  # 4000 cases in 2 s: 2000 cases/s, 5000 left: 2.5 s
    line = stream.getvalue().split("\r")[-1]
    assert line.startswith("sweep [#####.....] 5000/10000 cases, ")
    rate = float(line.split(", ")[1].split()[0])
    assert 1900 < rate <= 2000  # a little time passes between the two calls
    assert "ETA 0:02" in line or "ETA 0:03" in line
    assert line.endswith("3 failed")


def test_a_pickled_design_leaves_its_samples_behind():
    """Tasks carry the design to every worker: its cached samples (n × d floats) stay home,
    and the unpickled design draws the same points again."""
    import pickle

    design = Design((Parameter("arm.length", start=1.0, stop=2.0),), "sobol", samples=4096)
    values = design.values()
    small = len(pickle.dumps(Design(design.parameters, "sobol", samples=4096)))
    assert len(pickle.dumps(design)) == small < 1000
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(design)).values(), values)


def test_a_stiffness_matrix_arm_has_no_stiffness_table_to_sweep():
    # arm.stiffness.EIy on an arm given by a full stiffness_matrix: one CaseError when the
    # file is read (it passed, and the sweep ended in a KeyError traceback)
    import tomllib

    from softarm.case import CaseError, parse_case

    text = """
[arm]
length = 1.0
stiffness_matrix = [[1e6, 0, 0, 0, 0, 0], [0, 1e6, 0, 0, 0, 0], [0, 0, 1e6, 0, 0, 0],
                    [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1]]
[[load]]
kind = "tip"
force = [0.0, 0.0, 1.0]
[sweep]
design = "grid"
[[sweep.parameter]]
path = "arm.stiffness.EIy"
values = [1.0, 2.0]
"""
    with pytest.raises(CaseError, match=r"arm\.stiffness\.EIy: this arm is given by its "
                                        r"stiffness_matrix, not stiffness"):
        parse_case(tomllib.loads(text), "x.toml")
