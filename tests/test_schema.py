"""The case-file schema (softarm._schema): every table kind read and written by the same keys,
and the model's own errors reported at the key path."""

from __future__ import annotations

import re

import pytest

from softarm import (
    Arm,
    Circle,
    DistributedForce,
    Material,
    PointLoad,
    Rectangle,
    Section,
    SegmentedArm,
    TipLoad,
    Tube,
)
from softarm._schema import SECTIONS, arm_to_dict, loads_to_dict, solve_to_dict, sweep_to_dict
from softarm.case import CaseError, CaseTypeError, SolveOptions, parse_case
from softarm.sweep import Sweep

SILICONE = Material(1.0e6, poisson_ratio=0.45, density=1100.0)
STIFF = {"EA": 1e6, "GAy": 1e6, "GAz": 1e6, "GJ": 1.0, "EIy": 1.0, "EIz": 1.0}

# One model object of every section kind the schema knows, built in Python (not read).
SECTION_OBJECTS = {
    "circle": Circle(0.012),
    "tube": Tube(0.012, 0.005),
    "rectangle": Rectangle(0.02, 0.01),
    "general": Section(1e-4, 1e-9, 2e-9, 2.5e-9, 0.9, 0.8),
}


def test_every_section_kind_has_an_object_here():
    """A new section kind in the schema must be added to the round trip below."""
    assert sorted(SECTIONS) == sorted(SECTION_OBJECTS)


@pytest.mark.parametrize("kind", sorted(SECTION_OBJECTS))
def test_section_round_trip(kind):
    arm = Arm(0.3, SECTION_OBJECTS[kind], SILICONE, curvature=(0.0, 1.5, -0.5))
    case = parse_case({**arm_to_dict(arm), "load": []})
    assert case.arm == arm
    assert case.arm.rigidities == arm.rigidities


@pytest.mark.parametrize("material", [
    Material(2.0e6, poisson_ratio=0.3),
    Material(2.0e6, shear_modulus=7.0e5, density=950.0),
    Material(2.0e6, poisson_ratio=-0.2, density=1.0),
], ids=["nu", "G and density", "negative nu"])
def test_material_round_trip(material):
    """The file's E, nu, G are the model's youngs_modulus, poisson_ratio, shear_modulus; the
    one not given stays absent (the model needs exactly one)."""
    arm = Arm(0.3, Circle(0.01), material)
    table = arm_to_dict(arm)["arm"]["material"]
    assert ("nu" in table) == (material.poisson_ratio is not None)
    assert ("G" in table) == (material.shear_modulus is not None)
    assert parse_case({**arm_to_dict(arm)}).arm.material == material


def test_segmented_stiffness_and_mass_round_trip():
    arm = SegmentedArm([
        Arm.from_stiffness(0.2, 1e6, 2e6, 3e6, 0.5, 0.25, 0.125, mass_per_length=0.05),
        Arm(0.1, Rectangle(0.01, 0.02), SILICONE, curvature=(0.1, 0.0, 0.0)),
    ])
    case = parse_case({**arm_to_dict(arm)})
    assert case.arm == arm


def test_solve_and_sweep_round_trip():
    loads = (TipLoad(force=[0.0, 3.0, 4.0]), PointLoad(0.1, moment=[0.0, 0.0, 1.0]),
             DistributedForce([0.0, 0.0, -1.0], span=(0.05, 0.2), follower=True))
    options = SolveOptions("numeric", 7, 1e-6)
    for sweep in (Sweep(0, "tip", "force", "magnitude", (0.0, 0.5, 2.0), "payload"),
                  Sweep(1, "point", "moment", "x", (1.0, -1.0))):
        data = {"name": "trip", **arm_to_dict(Arm(0.3, Circle(0.01), SILICONE)),
                "load": loads_to_dict(loads), "solve": solve_to_dict(options),
                "sweep": sweep_to_dict(sweep)}
        case = parse_case(data)
        assert case.solve == options and case.sweep == sweep


def test_solve_options_check_their_own_values():
    """The rules of [solve] live in SolveOptions; the reader reports them at the key path."""
    with pytest.raises(ValueError, match=r"^SolveOptions\.stations must be an integer >= 2, "
                                         r"got 1$"):
        SolveOptions(stations=1)
    with pytest.raises(ValueError, match=r"^SolveOptions\.tol must be .*\[1e-13, 0\.1\]"):
        SolveOptions(tol=0.5)
    with pytest.raises(TypeError, match=r"^SolveOptions\.tol must be a real number"):
        SolveOptions(tol="1e-8")


def _segment(**changes) -> dict:
    table = {"length": 0.2, "section": {"kind": "circle", "radius": 0.01},
             "material": {"E": 1e6, "nu": 0.3}}
    table.update(changes)
    return table


# (case data, key path, the model's constructor that must give the same message)
MODEL_RULES = {
    "radius": ({"segment": [_segment(), _segment(section={"kind": "circle", "radius": -0.01})]},
               "segment[2].section.radius", lambda: Circle(-0.01)),
    "radius too large": ({"arm": _segment(section={"kind": "circle", "radius": 1e100})},
                         "arm.section.radius", lambda: Circle(1e100)),
    "tube radii": ({"arm": _segment(section={"kind": "tube", "outer_radius": 0.01,
                                             "inner_radius": 0.02})},
                   "arm.section.inner_radius", lambda: Tube(0.01, 0.02)),
    "rectangle": ({"arm": _segment(section={"kind": "rectangle", "width": 0.0, "height": 1.0})},
                  "arm.section.width", lambda: Rectangle(0.0, 1.0)),
    "shear factor": ({"arm": _segment(section={"kind": "general", "area": 1e-4, "Iy": 1e-9,
                                               "Iz": 1e-9, "J": 2e-9,
                                               "shear_factor_z": 1.5})},
                     "arm.section.shear_factor_z",
                     lambda: Section(1e-4, 1e-9, 1e-9, 2e-9, shear_factor_z=1.5)),
    "E": ({"arm": _segment(material={"E": float("inf"), "nu": 0.3})}, "arm.material.E",
          lambda: Material(float("inf"), poisson_ratio=0.3)),
    "density": ({"arm": _segment(material={"E": 1e6, "nu": 0.3, "density": -1.0})},
                "arm.material.density", lambda: Material(1e6, poisson_ratio=0.3, density=-1.0)),
    "length": ({"arm": _segment(length=1e-300)}, "arm.length",
               lambda: Arm(1e-300, Circle(0.01), Material(1e6, poisson_ratio=0.3))),
    "mass": ({"arm": _segment(mass_per_length=-0.1)}, "arm.mass_per_length",
             lambda: Arm(0.2, Circle(0.01), Material(1e6, poisson_ratio=0.3),
                         mass_per_length=-0.1)),
    "stiffness": ({"segment": [{"length": 1.0, "stiffness": {**STIFF, "GJ": -1.0}}]},
                  "segment[1].stiffness.GJ", lambda: Arm.from_stiffness(1.0, **{**STIFF,
                                                                               "GJ": -1.0})),
    "point load": ({"arm": _segment(), "load": [{"kind": "tip"}, {"kind": "point", "s": 0.3}]},
                   "load[2].s", lambda: PointLoad(0.3).check(Arm(0.2, Circle(0.01),
                                                                 SILICONE))),
    "span": ({"arm": _segment(), "load": [{"kind": "distributed", "force": [0, 0, 1],
                                           "span": [0.3, 0.1]}]},
             "load[1].span", lambda: DistributedForce([0, 0, 1], span=(0.3, 0.1))),
}


@pytest.mark.parametrize("name", sorted(MODEL_RULES))
def test_the_model_error_at_its_key_path(name):
    """The reader does not re-check the model's rules: it reports the model's own message
    (without the class prefix) at the key path."""
    data, path, build = MODEL_RULES[name]
    with pytest.raises((TypeError, ValueError)) as model:
        build()
    # "Tube.inner_radius must be smaller than Tube.outer_radius, ...": the key path replaces
    # the first name, the file's key name the others
    model_text = re.sub(r"\b[A-Z][A-Za-z]*\.(?=[a-z_])", "",
                        re.sub(r"^\w+\.\w+ ", "", str(model.value)))
    with pytest.raises(CaseError) as info:
        parse_case(data, "case.toml")
    assert str(info.value) == f"case.toml: {path}: {model_text}"


def test_renamed_keys_in_a_model_message():
    """Material's poisson_ratio and shear_modulus are the file's nu and G: the message says so,
    also when the rule is on a key that is not in the file (nu computed from G)."""
    data = {"arm": _segment(material={"E": 1e6, "nu": 0.7})}
    with pytest.raises(CaseError, match=re.escape(
            "case.toml: arm.material.nu: must lie in (-1, 0.5], got nu=0.7")):
        parse_case(data, "case.toml")
    data = {"arm": _segment(material={"E": 1e6, "G": 1e5})}
    with pytest.raises(CaseError, match=re.escape(
            "case.toml: arm.material: nu must lie in (-1, 0.5], got G=100000.0 (ν = E/2G - 1 "
            "= 4.0)")):
        parse_case(data, "case.toml")
    data = {"arm": _segment(material={"E": 1e6})}
    with pytest.raises(CaseError, match=re.escape(
            "case.toml: arm.material: needs exactly one of nu and G, got nu=None, G=None")):
        parse_case(data, "case.toml")


def test_a_type_error_of_the_model_stays_a_type_error():
    data = {"arm": _segment(section={"kind": "circle", "radius": "0.01"})}
    with pytest.raises(CaseTypeError, match=r"arm\.section\.radius: must be a number in m"):
        parse_case(data, "case.toml")


def test_a_missing_table_is_reported_after_an_earlier_key_fault():
    """The model checks in the file's order, so does the reader: a bad length first, then the
    missing section."""
    with pytest.raises(CaseError, match=r"^case\.toml: arm\.length: must be a positive"):
        parse_case({"arm": {"length": -1.0}}, "case.toml")
    with pytest.raises(CaseError, match=r"^case\.toml: arm\.section: missing"):
        parse_case({"arm": {"length": 1.0}}, "case.toml")
    with pytest.raises(CaseError, match=r"^case\.toml: arm\.material: missing"):
        parse_case({"arm": {"length": 1.0, "section": {"kind": "circle", "radius": 0.01}}},
                   "case.toml")
