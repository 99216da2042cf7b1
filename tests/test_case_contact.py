"""Obstacles in case files: ``[[obstacle]]`` and ``[contact]`` tables in, the same tables out
(Case.to_dict, result files, contact_to_dict), and bad input named by table index and key."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import softarm
from softarm import cli, io
from softarm._schema import contact_to_dict, loads_to_dict
from softarm.case import CaseError, CaseTypeError, load_case, parse_case, solve_case

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

TABLE = """
name = "on the table"
[arm]
length = 0.5
section = { kind = "circle", radius = 0.01 }
material = { E = 1.0e6, nu = 0.5, density = 1000.0 }

[[load]]
kind = "gravity"

[[obstacle]]
kind = "plane"
point = [0.0, 0.0, -0.05]
normal = [0.0, 0.0, 2.0]          # any length: stored unit

[[obstacle]]
kind = "sphere"
center = [0.3, 0.3, 0.0]          # out of reach: no force
radius = 0.05

[[obstacle]]
kind = "capsule"
a = [0.0, -0.3, 0.2]
b = [0.1, -0.3, 0.2]
radius = 0.02

[contact]
friction = 0.3

[solve]
stations = 51
"""

ARM = softarm.Arm(0.5, softarm.Circle(0.01),
                  softarm.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1000.0))


def _by_hand():
    return softarm.Contact([softarm.Plane((0, 0, -0.05), (0, 0, 1)),
                            softarm.Sphere((0.3, 0.3, 0.0), 0.05),
                            softarm.Capsule((0, -0.3, 0.2), (0.1, -0.3, 0.2), 0.02)],
                           friction=0.3)


def assert_same_contact(a, b):
    assert isinstance(a, softarm.Contact) and isinstance(b, softarm.Contact)
    assert [o.kind for o in a.obstacles] == [o.kind for o in b.obstacles]
    for x, y in zip(a.obstacles, b.obstacles, strict=True):
        assert x.to_case() == y.to_case()
    for name in ("friction", "distance", "radius", "stiffness"):
        assert getattr(a, name) == getattr(b, name), name


@pytest.fixture(scope="module")
def table_case():
    return parse_case(tomllib.loads(TABLE), "table.toml")


@pytest.fixture(scope="module")
def table_eq(table_case):
    return solve_case(table_case)


def test_obstacles_make_one_contact_after_the_loads(table_case):
    kinds = [load.kind for load in table_case.loads]
    assert kinds == ["gravity", "contact"]
    assert_same_contact(table_case.loads[-1], _by_hand())
    np.testing.assert_array_equal(table_case.loads[-1].obstacles[0].normal, [0.0, 0.0, 1.0])


@pytest.mark.slow
def test_the_case_solves_as_the_contact_built_by_hand(table_case, table_eq):
    direct = softarm.solve(ARM, [softarm.Gravity(), _by_hand()], s=51, tol=1e-8)
    np.testing.assert_allclose(table_eq.poses, direct.poses, rtol=0, atol=1e-12)
    # the arm lies on the table: its tip rests on the plane z = -0.05 + r = -0.04 (within δ)
    assert table_eq.tip_position[2] == pytest.approx(-0.04, abs=2 * 5e-6)
    # the table carries part of the weight, μ g L = π r² ρ g L = 1.541 N in all
    weight = np.pi * 0.01**2 * 1000.0 * 9.81 * 0.5
    assert 0.3 * weight < table_eq.contact_wrench[2] < weight


def test_to_dict_round_trip_gives_the_same_contact_and_solve(table_case, table_eq):
    data = table_case.to_dict()
    assert data["obstacle"][0] == {"kind": "plane", "point": [0.0, 0.0, -0.05],
                                   "normal": [0.0, 0.0, 2.0]}
    again = parse_case(data, "again")
    assert_same_contact(again.loads[-1], table_case.loads[-1])
    np.testing.assert_array_equal(solve_case(again).poses, table_eq.poses)


def test_the_solved_loads_written_back_reproduce_the_contact_law(table_eq):
    """contact_to_dict of eq.loads carries the stiffness the solver chose: read back, the
    same Contact, and solved with that stiffness fixed, the same shape."""
    solved = table_eq.loads[-1]
    assert solved.stiffness is not None and solved.distance == pytest.approx(5e-6)
    tables = contact_to_dict(table_eq.loads)
    assert [t["kind"] for t in tables["obstacle"]] == ["plane", "sphere", "capsule"]
    assert tables["contact"] == {"friction": 0.3, "distance": solved.distance,
                                 "stiffness": solved.stiffness}
    assert [t["kind"] for t in loads_to_dict(table_eq.loads)] == ["gravity"]
    data = {**softarm.case.arm_to_dict(ARM), "load": loads_to_dict(table_eq.loads), **tables,
            "solve": {"stations": 51}}
    case = parse_case(data, "written")
    assert_same_contact(case.loads[-1], solved)
    again = solve_case(case)
    np.testing.assert_allclose(again.positions, table_eq.positions, rtol=0, atol=1e-8)
    np.testing.assert_allclose(again.contact_forces, table_eq.contact_forces, rtol=1e-5,
                               atol=1e-6 * np.abs(table_eq.contact_forces).max())


def test_contact_to_dict_without_contact_and_defaults():
    assert contact_to_dict([softarm.Gravity()]) == {}
    plain = softarm.Contact(softarm.Sphere((0, 0, 0), 0.1))
    assert contact_to_dict([plain]) == {"obstacle": [{"kind": "sphere",
                                                      "center": [0.0, 0.0, 0.0],
                                                      "radius": 0.1}]}
    with pytest.raises(ValueError, match=r"at most one softarm\.Contact .*, got 2"):
        contact_to_dict([plain, plain])


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
@pytest.mark.parametrize("with_case", [True, False])
def test_result_files_keep_the_obstacles_and_the_contact_forces(tmp_path, table_case,
                                                                table_eq, suffix, with_case):
    path = tmp_path / f"result{suffix}"
    io.save_result(table_eq, path, table_case if with_case else None)
    saved = io.load_saved(path)
    contact = saved.result.loads[-1]
    assert_same_contact(contact, table_eq.loads[-1])  # the law used, whatever the case says
    np.testing.assert_array_equal(saved.result.contact_forces, table_eq.contact_forces)
    # the solver's total, not a sum on the saved stations (which may miss a narrow zone)
    np.testing.assert_array_equal(saved.result.contact_wrench, table_eq.contact_wrench)
    assert np.count_nonzero(np.linalg.norm(table_eq.contact_forces, axis=-1)) > 5


def test_a_bad_contact_entry_in_a_result_file_is_named(tmp_path, table_eq):
    import json

    path = tmp_path / "result.json"
    io.save_result(table_eq, path)
    document = json.loads(path.read_text())
    document["contact"] = {"stiffness": -1.0, "distance": 1e-5}
    path.write_text(json.dumps(document))
    with pytest.raises(CaseError, match=r"result.json: not a softarm result file \('contact'"
                       r" Contact.stiffness must be a positive"):
        io.load_saved(path)
    document = json.loads(io.save_result(table_eq, path).read_text())
    document["contact_wrench"] = [1.0, 2.0]
    path.write_text(json.dumps(document))
    with pytest.raises(CaseError, match=r"result.json: not a softarm result file "
                       r"\('contact_wrench': 2 numbers for the batch shape \(\)\)"):
        io.load_saved(path)


@pytest.mark.slow  # (~9 s)
def test_a_sweep_counts_the_load_tables_only(tmp_path):
    text = TABLE.replace("[solve]", """[[load]]
kind = "tip"
force = [0.0, 0.0, -0.1]

[sweep]
load = 2
start = 0.0
stop = 0.2
steps = 3

[solve]""")
    case = parse_case(tomllib.loads(text), "sweep.toml")
    assert [load.kind for load in case.loads] == ["gravity", "tip", "contact"]
    assert case.sweep.load == 1
    eq = solve_case(case)
    # pressed harder, the arm carries more on the table
    assert np.all(np.diff(eq.contact_wrench[:, 2]) > 0)
    # each step's contact law is the one softarm.solve of the batch chooses for it
    batch = softarm.solve(ARM, case.batched_loads, s=51, tol=1e-8)
    np.testing.assert_array_equal(eq.loads[-1].stiffness, batch.loads[-1].stiffness)
    np.testing.assert_allclose(eq.positions, batch.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq.contact_forces, batch.contact_forces, rtol=0, atol=1e-9)


BASE = """
[arm]
length = 0.5
section = { kind = "circle", radius = 0.01 }
material = { E = 1.0e6, nu = 0.5, density = 1000.0 }
[[obstacle]]
kind = "plane"
point = [0, 0, -0.05]
normal = [0, 0, 1]
"""

BAD = {
    "unknown kind": ('[[obstacle]]\nkind = "cube"\ncenter = [0, 0, 0]\n',
                     "obstacle[2].kind: unknown value 'cube'; expected one of 'plane', "
                     "'sphere', 'capsule'"),
    "missing radius": ('[[obstacle]]\nkind = "sphere"\ncenter = [0, 0, 0]\n',
                       "obstacle[2].radius: missing (a number in m)"),
    "missing normal": ('[[obstacle]]\nkind = "plane"\npoint = [0, 0, 0]\n',
                       "obstacle[2].normal: missing"),
    "zero normal": ('[[obstacle]]\nkind = "plane"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\n',
                    "obstacle[2].normal: must be a non-zero vector, got [0.0, 0.0, 0.0]"),
    "negative radius": ('[[obstacle]]\nkind = "capsule"\na = [0, 0, 0]\nb = [1, 0, 0]\n'
                        'radius = -0.1\n',
                        "obstacle[2].radius: must be a positive finite radius in m, got -0.1"),
    "nan point": ('[[obstacle]]\nkind = "sphere"\ncenter = [0, nan, 0]\nradius = 0.1\n',
                  "obstacle[2].center: must be a list of 3 finite numbers in m"),
    "nan radius": ('[[obstacle]]\nkind = "sphere"\ncenter = [0, 0, 0]\nradius = nan\n',
                   "obstacle[2].radius: must be a finite number in m, got nan"),
    "misspelled key": ('[[obstacle]]\nkind = "sphere"\ncentre = [0, 0, 0]\nradius = 0.1\n',
                       "obstacle[2].centre: unknown key; did you mean 'center'?"),
    "negative friction": ("[contact]\nfriction = -0.2\n",
                          "contact.friction: must be a finite number >= 0"),
    "unknown contact key": ("[contact]\nmu = 0.2\n", "contact.mu: unknown key"),
    "zero distance": ("[contact]\ndistance = 0.0\n",
                      "contact.distance: must be a positive finite number in m or None, "
                      "got 0.0"),
    "a contact load": ('[[load]]\nkind = "contact"\n',
                       "load[1].kind: contact is given by [[obstacle]] tables"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_obstacles_name_the_table_and_key(tmp_path, name):
    text, message = BAD[name]
    path = tmp_path / "case.toml"
    path.write_text(BASE + text)
    with pytest.raises(CaseError) as caught:
        load_case(path)
    assert str(caught.value).startswith(f"{path}: {message}")


def test_a_wrong_type_is_a_type_error(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(BASE.replace("point = [0, 0, -0.05]", 'point = [0, 0, "low"]'))
    with pytest.raises(CaseTypeError, match=r"obstacle\[1\].point: must be a list of 3"):
        load_case(path)


def test_contact_without_obstacles_and_an_arm_without_radius(tmp_path):
    with pytest.raises(CaseError, match=r"case: contact: a \[contact\] table needs one or "
                       r"more \[\[obstacle\]\] tables"):
        parse_case({**softarm.case.arm_to_dict(ARM), "contact": {"friction": 0.1}}, "case")
    stiff = softarm.Arm.from_stiffness(1.0, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    data = {**softarm.case.arm_to_dict(stiff),
            "obstacle": [{"kind": "sphere", "center": [0, 0, -1], "radius": 0.5}]}
    with pytest.raises(CaseError, match="case: contact: radius is required for an arm given "
                       "by its stiffnesses"):
        parse_case(data, "case")
    case = parse_case({**data, "contact": {"radius": 0.01}}, "case")
    assert case.loads[-1].radius == 0.01


def test_the_command_line_names_a_bad_obstacle_in_one_line_and_exits_2(tmp_path, capsys):
    case = tmp_path / "case.toml"
    case.write_text(BASE + '[[obstacle]]\nkind = "sphere"\ncenter = [0, 0, 0]\nradius = -1\n')
    code = cli.main(["solve", str(case), "-o", str(tmp_path / "out.csv"),
                     "--plot", str(tmp_path / "out.png")])
    _, err = capsys.readouterr()
    assert code == 2
    assert err == (f"softarm: error: {case}: obstacle[2].radius: must be a positive finite "
                   "radius in m, got -1.0\n")
    assert err.count("\n") == 1 and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]


def test_the_command_line_solves_a_case_with_obstacles(tmp_path, capsys):
    case = tmp_path / "table.toml"
    case.write_text(TABLE)
    out = tmp_path / "table.npz"
    code = cli.main(["solve", str(case), "-o", str(out)])
    stdout, err = capsys.readouterr()
    assert code == 0, err
    assert "contact with 3 obstacles (plane, sphere, capsule), μ = 0.3" in stdout
    back = io.load_result(out)
    assert back.tip_position[2] == pytest.approx(-0.04, abs=1e-5)


def test_every_obstacle_kind_has_a_case_table():
    """The reader's tables and the obstacles' own to_case agree, for every kind."""
    from softarm._schema import OBSTACLES
    from softarm.contact import OBSTACLE_KINDS

    assert set(OBSTACLES) == set(OBSTACLE_KINDS)
    for obstacle in _by_hand().obstacles:
        assert OBSTACLES[obstacle.kind].write(obstacle) == obstacle.to_case()


@pytest.mark.slow  # (~13 s)
def test_a_stable_branch_sweep_solves_every_step_with_one_contact_law():
    """branch = "stable" solves step by step, each with its own penalty stiffness: each step
    equals its own softarm.solve."""
    text = TABLE.replace("[solve]", """[[load]]
kind = "tip"
force = [0.0, 0.0, -0.1]

[sweep]
load = 2
start = 0.0
stop = 0.4
steps = 3

[solve]
branch = "stable\"""")
    case = parse_case(tomllib.loads(text), "stable.toml")
    eq = solve_case(case)
    law = eq.loads[-1]
    assert law.stiffness is not None
    for k, force in enumerate(case.batched_loads[1].force):
        alone = softarm.solve(ARM, [softarm.Gravity(), softarm.TipLoad(force=force),
                                    _by_hand()], s=51, tol=1e-8)
        assert alone.loads[-1].stiffness == np.broadcast_to(law.stiffness, (3,))[k]
        np.testing.assert_allclose(eq.positions[k], alone.positions, rtol=0, atol=1e-12)
    assert np.all(np.diff(eq.contact_wrench[:, 2]) > 0)
