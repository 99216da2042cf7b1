"""Numbers in messages and hostile case files (issue 30).

A number in an error message is the plain Python number with the shortest repr that reads back
to the same float: an out-of-range 0.10000000001 is shown as such (not rounded to 0.1, which
hides why it is out of range), and numpy 2's reprs (``np.float64(-0.5)``) never leak. A case
file nested 10⁵ levels deep is one line and exit code 2, not a RecursionError.

References: the float read back from the message (it must equal the value given) and the
exit-code contract of docs/cli.md.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import softarm
from softarm import app, cli
from softarm._validate import format_value
from softarm.case import CaseError
from softarm.routing import Straight

SILICONE = softarm.Material(1.5e6, poisson_ratio=0.49, density=1070.0)
ARM = softarm.Arm(0.3, softarm.Circle(0.01), SILICONE)


@pytest.mark.parametrize("value", [0.10000000001, np.float64(-0.5), np.float32(0.1), 1e-300,
                                   np.nextafter(0.3, 1.0), -0.0, 5e-324])
def test_format_value_reads_back_to_the_same_float(value):
    text = format_value(value)
    assert float(text) == float(value) and "np." not in text


def test_format_value_of_containers_and_arrays():
    assert format_value((np.float64(0.1), np.int64(3), None, np.bool_(True))) == \
        "(0.1, 3, None, True)"
    assert format_value(np.array([0.0, 0.30000000001])) == "[0.0, 0.30000000001]"
    assert format_value(np.str_("numeric")) == "'numeric'"
    nested: list = []
    for _ in range(10**5):  # bounded work on a hostile input: no RecursionError
        nested = [nested]
    assert format_value(nested).startswith("[[[[") and len(format_value(nested)) <= 80


def _message(make) -> str:
    with pytest.raises((ValueError, TypeError)) as info:
        make()
    return str(info.value)


# Each maker gets a numpy scalar or an array, as a numpy user passes them; the value shown must
# be the one given, as a plain number.
NUMPY_INPUTS = {
    "radius": (lambda: softarm.Circle(np.float64(-0.5)), "got -0.5"),
    "youngs_modulus": (lambda: softarm.Material(np.float64(-1.0), poisson_ratio=0.3),
                       "got -1.0"),
    "tension": (lambda: softarm.Tendon(np.array([1.0, -0.5]), Straight(0.0, 0.008)),
                "got -0.5"),
    "stations": (lambda: softarm.solve(ARM, [], s=np.array([0.0, 0.30000000001])),
                 "got [0.0, 0.30000000001]"),
    "span": (lambda: softarm.DistributedForce([0, 0, 1], span=(np.float64(0.2),
                                                                np.float64(0.1))),
             "got (0.2, 0.1)"),
    "chamber_area": (lambda: softarm.Chamber(1.0, area=np.float64(-2e-5),
                                             routing=Straight(0.0, 0.0)), "got -2e-05"),
    "tendon_end": (lambda: softarm.Tendon(1.0, Straight(0.0, 0.0), end=np.float64(-0.1)),
                   "got -0.1"),
    "helix": (lambda: softarm.routing.Helix(np.float64(-0.01), 1.0), "got -0.01"),
    "method": (lambda: softarm.solve(ARM, [], method=np.str_("fast")), "got 'fast'"),
    "mass": (lambda: softarm.Arm(0.3, softarm.Circle(0.01), SILICONE,
                                 mass_per_length=np.float64(-1e-3)), "got -0.001"),
}


@pytest.mark.parametrize("name", NUMPY_INPUTS)
def test_numpy_values_are_shown_as_plain_numbers(name):
    make, shown = NUMPY_INPUTS[name]
    message = _message(make)
    assert shown in message, message
    assert not re.search(r"np\.\w+\(", message), message


def test_an_out_of_range_value_is_shown_with_every_digit(tmp_path):
    """The app's sliders: a value just above the end of its slider is shown with the digits
    that put it there (it was ':g', "got 0.1")."""
    path = tmp_path / "tip.toml"
    path.write_text('[arm]\nlength = 1.0\nstiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, '
                    'GJ = 1.0, EIy = 1.0, EIz = 1.0 }\n[[load]]\nkind = "tip"\n'
                    'force = [0.0, 0.0, -0.05]\n', encoding="utf-8")
    live = app.LiveCase(softarm.load_case(path))
    item = live.by_name["l1.force.z"]
    beyond = float(np.nextafter(item.high, np.inf))
    with pytest.raises(app.BadRequest) as info:
        live.update({item.name: repr(beyond)})
    message = str(info.value)
    shown = re.search(r"got (\S+)", message)[1]
    assert float(shown) == beyond and float(shown) != item.high, message


# ------------------------------------------------------------------------------------------
# Case files nested deeply
# ------------------------------------------------------------------------------------------
DEPTH = 10**5


@pytest.fixture(params=["array", "inline_table"])
def deep_case(request, tmp_path):
    """A case file whose [arm] length is nested 10⁵ levels deep."""
    if request.param == "array":
        value = "[" * DEPTH + "]" * DEPTH
    else:
        value = "{ a = " * DEPTH + "1" + " }" * DEPTH
    path = tmp_path / "deep.toml"
    path.write_text(f"[arm]\nlength = {value}\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("command", [["solve"], ["critical"], ["inverse", "--target", "1", "0",
                                                                "0"]])
def test_a_deeply_nested_case_file_is_one_line_and_exit_2(deep_case, command, capsys):
    code = cli.main([*command, str(deep_case)])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"softarm: error: {deep_case}: tables and arrays nested more than "
                          "100 levels deep"), err


def test_load_case_raises_case_error_at_any_depth(deep_case, tmp_path):
    with pytest.raises(CaseError, match="nested more than 100 levels deep"):
        softarm.load_case(deep_case)
    # shallower than the TOML reader's recursion, deeper than any case: refused the same way
    shallow = tmp_path / "shallow.toml"
    shallow.write_text("[arm]\nlength = " + "[" * 150 + "]" * 150 + "\n", encoding="utf-8")
    with pytest.raises(CaseError, match="nested more than 100 levels deep"):
        softarm.load_case(shallow)
    nested: dict = {"length": 1.0}
    for _ in range(DEPTH):
        nested = {"a": nested}
    with pytest.raises(CaseError, match="nested more than 100 levels deep"):
        softarm.case.parse_case({"arm": nested})


# ------------------------------------------------------------------------------------------
# Issue 42: an empty unit, numpy reprs and a stray space in the dynamics' and the app's words
# ------------------------------------------------------------------------------------------


def test_a_dimensionless_key_reads_without_an_empty_unit(tmp_path):
    """Contact.friction has no unit: the message was 'must be a number in , got 'high''."""
    path = tmp_path / "friction.toml"
    path.write_text('[arm]\nlength = 0.12\nsection = { kind = "circle", radius = 0.01 }\n'
                    'material = { E = 1.0e6, nu = 0.49, density = 1070.0 }\n'
                    '[[obstacle]]\nkind = "sphere"\ncenter = [0.06, 0.0, -0.1]\n'
                    'radius = 0.03\n[contact]\nfriction = "high"\n', encoding="utf-8")
    with pytest.raises(CaseError) as info:
        softarm.load_case(path)
    assert str(info.value) == f"{path}: contact.friction: must be a number, got 'high'"


def test_the_apps_switch_and_a_unitless_slider_read_without_a_stray_space():
    """A switch given 2 said 'l2.on must be in [0.0, 1.0] , got 2.0' (an empty unit)."""
    switch = app.Input("l2.on", "tendon on", "", 0.0, 1.0, 1.0, load=1)
    slider = app.Input("l1.ratio", "ratio", "", 0.0, 1.0, 0.5, load=0, field="ratio",
                       component=-1)
    by_name = {item.name: item for item in (switch, slider)}
    for query, message in (({"l2.on": "2"}, "l2.on must be 0 (off) or 1 (on), got 2.0"),
                           ({"l2.on": "0.5"}, "l2.on must be 0 (off) or 1 (on), got 0.5"),
                           ({"l1.ratio": "2"}, "l1.ratio must be in [0.0, 1.0], got 2.0")):
        with pytest.raises(app.BadRequest) as info:
            app._updated(by_name, {}, query)
        assert str(info.value) == message


def _moving_base(fails_from: float, how: str):
    def base(t):
        pose = np.eye(4)
        pose[0, 3] = 0.01 * t
        if t >= fails_from:
            if how == "raises":
                raise ZeroDivisionError("boom")
            pose[0, 0] = 2.0  # not a rotation
        return pose
    return base


@pytest.mark.parametrize(("how", "message"), [
    ("raises", "base(0.005) raised ZeroDivisionError: boom"),
    ("scaled", "base(0.005) must be a rigid transform [[R, p], [0, 0, 0, 1]] with R a proper "
               "rotation"),
])
def test_a_base_functions_fault_names_its_time_as_a_plain_number(how, message):
    """The time was shown as 'base(np.float64(0.005))'."""
    sim = softarm.Simulator(ARM, [], [softarm.Gravity()], dt=1e-3, stations=5,
                            base=_moving_base(0.005, how))
    with pytest.raises(ValueError) as info:
        sim.run(10)
    assert str(info.value).startswith(message), str(info.value)
    assert not re.search(r"np\.\w+\(", str(info.value))
