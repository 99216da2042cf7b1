"""No silent coercion (issue 11): strings, bools, None and complex numbers where a number is
expected are a TypeError naming the parameter, in the API and in case files alike; numpy
scalars of any float width are accepted everywhere; float32 stations are accepted within
float32 rounding of L; a nearly rigid base pose is re-orthonormalised on every route; an empty
batch gives an empty result on every route.

References: the exact circle of a pure principal tip moment (Grazioso et al. 2018, eqs. 37-38,
as in tests/analytic/test_moment.py), float32 rounding from numpy's own casts, and the nearest
rotation of a matrix (polar decomposition, computed here with scipy.linalg.polar).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.linalg

import softarm
from softarm import (
    Arm,
    Circle,
    DistributedForce,
    Gravity,
    Material,
    PointLoad,
    TipLoad,
    _validate,
    analytic,
)
from softarm.case import CaseError, CaseTypeError, parse_case

SILICONE = Material(1.5e6, poisson_ratio=0.49, density=1070.0)
ARM = Arm(0.3, Circle(0.01), SILICONE)
UNIT = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)


# --- strings, bools, None, complex --------------------------------------------------------------

@pytest.mark.parametrize(("build", "name"), [
    (lambda: TipLoad(force=[0, 0, "1"]), "TipLoad.force"),
    (lambda: TipLoad(force=[True, False, True]), "TipLoad.force"),
    (lambda: TipLoad(force=[1.0, True, 0.0]), "TipLoad.force"),  # a bool among floats
    (lambda: TipLoad(force=[0, 0, 1j]), "TipLoad.force"),
    (lambda: TipLoad(force=np.array([0, 0, 1], dtype=complex)), "TipLoad.force"),
    (lambda: TipLoad(moment=[0, None, 0]), "TipLoad.moment"),
    (lambda: TipLoad(force=None), "TipLoad.force"),
    (lambda: TipLoad(force=[[0, 0, 1], [0, 0, "2"]]), "TipLoad.force"),
    (lambda: PointLoad(s="0.1", force=[0, 0, 1]), "PointLoad.s"),
    (lambda: PointLoad(s=True, force=[0, 0, 1]), "PointLoad.s"),
    (lambda: Gravity([0, 0, "-9.81"]), "Gravity.acceleration"),
    (lambda: DistributedForce(np.array(["0", "0", "1"])), "DistributedForce.force"),
    (lambda: Circle("0.01"), "Circle.radius"),
    (lambda: Circle(True), "Circle.radius"),
    (lambda: Circle(0.01 + 0j), "Circle.radius"),
    (lambda: Arm(None, Circle(0.01), SILICONE), "Arm.length"),
    (lambda: Material(1e6, poisson_ratio="0.3"), "Material.poisson_ratio"),
    (lambda: Material("1e6", poisson_ratio=0.3), "Material.youngs_modulus"),
    (lambda: softarm.solve(UNIT, TipLoad(moment=[0, 1, 0]), tol="1e-8"), "tol"),
    (lambda: softarm.solve(UNIT, TipLoad(moment=[0, 1, 0]), max_load_step="2"), "max_load_step"),
    (lambda: softarm.solve(UNIT, TipLoad(moment=[0, 1, 0]), max_load_step=True), "max_load_step"),
    (lambda: softarm.solve(UNIT, TipLoad(moment=[0, 1, 0]), max_iterations=30.0),
     "max_iterations"),
    (lambda: softarm.solve(UNIT, TipLoad(moment=[0, 1, 0]), s=["0", "1"]), "s"),
])
def test_non_numbers_are_a_type_error_naming_the_parameter(build, name):
    with pytest.raises(TypeError, match=rf"^{name.replace('.', '[.]')} must be"):
        build()


@pytest.mark.parametrize(("text", "key"), [
    ('force = [0, 0, "1"]', "load[1].force"),
    ("force = [0, true, 0]", "load[1].force"),
    ('moment = "0, 1, 0"', "load[1].moment"),
])
def test_case_files_type_errors_too(text, key):
    data = {"arm": {"length": 1.0, "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6, "GJ": 1.0,
                                                  "EIy": 1.0, "EIz": 1.0}},
            "load": [{"kind": "tip"}]}
    name, value = (part.strip() for part in text.split("=", 1))
    data["load"][0][name] = eval(value.replace("true", "True"))  # a TOML value as tomllib reads
    with pytest.raises(TypeError, match=re.escape(f"{key}: must be a list of 3 ")):
        parse_case(data)
    with pytest.raises(CaseError):  # still a CaseError: the command prints one line, exit 2
        parse_case(data)
    assert issubclass(CaseTypeError, TypeError) and issubclass(CaseTypeError, CaseError)


def test_case_file_string_for_a_number():
    data = {"arm": {"length": "1.0", "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6,
                                                    "GJ": 1.0, "EIy": 1.0, "EIz": 1.0}}}
    with pytest.raises(TypeError, match=r"arm\.length: must be a number in m, got '1\.0'"):
        parse_case(data)


# --- numpy scalars of any width ------------------------------------------------------------------

@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64, np.longdouble])
def test_numpy_float_scalars_of_any_width(dtype):
    nu = dtype(0.25)  # exactly representable in every width (and 2048 too, even in float16)
    material = Material(youngs_modulus=dtype(2048), poisson_ratio=nu, density=dtype(1000))
    assert type(material.poisson_ratio) is float and material.poisson_ratio == 0.25
    assert material.G == 2048 / 2.5  # G = E/2(1 + ν), in float64
    circle = Circle(dtype(0.5))
    assert type(circle.radius) is float
    assert circle.area == np.pi * 0.25  # π r², float64 (no float16/32 arithmetic)
    force = TipLoad(force=np.array([0, 0, 1.5], dtype=dtype)).force
    assert force.dtype == np.float64 and force.tolist() == [0.0, 0.0, 1.5]


def test_poisson_ratio_float32_is_the_float32_value():
    nu = np.float32(0.3)
    material = Material(1.5e6, poisson_ratio=nu)
    assert material.nu == float(nu) and material.G == 1.5e6 / (2.0 * (1.0 + float(nu)))


def test_max_step_float32_through_solve():
    loads = [Gravity(), TipLoad(force=[0.0, 0.0, -0.2])]  # no closed form: the solver
    a = softarm.solve(ARM, loads, max_load_step=np.float32(0.5))
    b = softarm.solve(ARM, loads, max_load_step=0.5)
    assert a.method == "numeric.shooting"
    np.testing.assert_array_equal(a.poses, b.poses)
    c = softarm.solve(ARM, loads, max_iterations=np.int16(30), tol=np.float32(1e-8))
    np.testing.assert_allclose(c.tip_position, b.tip_position, rtol=0, atol=1e-8 * 0.3)


def test_float32_stations_within_float32_rounding_of_L():
    L = 0.3
    s32 = np.linspace(0.0, L, 11, dtype=np.float32)
    assert float(s32[-1]) > L  # float32(0.3) = 0.30000001192...: beyond L by its rounding
    arm = Arm.from_stiffness(L, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    tau = 2.0
    for method in ("auto", "numeric"):
        eq = softarm.solve(arm, TipLoad(moment=[0.0, tau, 0.0]), s=s32, method=method, tol=1e-10)
        assert eq.s[-1] == L and eq.s.dtype == np.float64
        np.testing.assert_array_equal(eq.s[:-1], s32[:-1].astype(np.float64))
        # the circle of eqs. 37-38: p(s) = (sin(sκ)/κ, 0, -(1 - cos sκ)/κ), κ = τ/EIy
        s = eq.s
        circle = np.stack([np.sin(s * tau) / tau, 0 * s, -(1 - np.cos(s * tau)) / tau], -1)
        np.testing.assert_allclose(eq.positions, circle, rtol=0, atol=1e-9)
    beyond = s32.copy()
    beyond[-1] = np.float32(L * (1 + 1e-5))
    with pytest.raises(ValueError, match=r"s must lie in \[0, L\]"):
        softarm.solve(arm, TipLoad(moment=[0.0, tau, 0.0]), s=beyond)
    # float64 stations keep the float64 tolerance
    with pytest.raises(ValueError, match=r"s must lie in \[0, L\]"):
        softarm.solve(arm, TipLoad(moment=[0.0, tau, 0.0]), s=[0.0, float(s32[-1])])


# --- base pose ----------------------------------------------------------------------------------

def _nearly_rigid(rng, error: float) -> np.ndarray:
    R = scipy.linalg.expm(np.cross(np.eye(3), [0.3, -0.2, 0.5]))
    H = np.eye(4)
    H[:3, :3] = R + error * rng.normal(size=(3, 3))
    H[:3, 3] = [0.1, -0.2, 0.3]
    return H


def test_nearly_rigid_base_is_reorthonormalised_the_same_on_both_routes(rng):
    H = _nearly_rigid(rng, 1e-7)
    nearest, _ = scipy.linalg.polar(H[:3, :3])  # the nearest rotation (independent of softarm)
    moment = TipLoad(moment=[0.0, 2.0, 0.0], follower=True)
    routes = {m: softarm.solve(UNIT, moment, base=H, method=m, tol=1e-10)
              for m in ("auto", "numeric")}
    assert routes["auto"].method.startswith("analytic")
    for eq in routes.values():
        base = eq.poses[0]
        np.testing.assert_allclose(base[:3, :3], nearest, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(base[:3, 3], H[:3, 3])
        R = eq.rotations
        np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3),
                                   R.shape), rtol=0, atol=1e-12)
    np.testing.assert_allclose(routes["auto"].poses[0], routes["numeric"].poses[0], rtol=0,
                               atol=1e-15)
    np.testing.assert_allclose(routes["auto"].poses, routes["numeric"].poses, rtol=0, atol=1e-8)


def test_base_far_from_rigid_is_rejected_on_both_routes(rng):
    H = _nearly_rigid(rng, 1e-3)
    for method in ("auto", "numeric"):
        with pytest.raises(ValueError, match=r"^base must be a rigid transform"):
            softarm.solve(UNIT, TipLoad(moment=[0.0, 2.0, 0.0]), base=H, method=method)


# --- empty batches ------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", [(0,), (2, 0)])
def test_empty_batch_gives_an_empty_result_on_every_route(shape):
    none = np.zeros((*shape, 3))
    results = {
        "tip_moment": analytic.tip_moment(UNIT, none),
        "axial_force": analytic.axial_force(UNIT, none),
        "shear_force": analytic.shear_force(UNIT, none),
        "linear": analytic.linear(UNIT, none, none),
        "elastica": analytic.elastica(UNIT, none),
        "solve auto": softarm.solve(UNIT, TipLoad(moment=none)),
        "solve numeric": softarm.solve(UNIT, TipLoad(force=none), method="numeric"),
        "solve gravity": softarm.solve(ARM, [Gravity(), TipLoad(force=none)]),
    }
    for name, eq in results.items():
        assert eq.batch_shape == shape, name
        assert eq.poses.shape == (*shape, 101, 4, 4), name
        assert eq.strains.shape == eq.stresses.shape == (*shape, 101, 6), name
        assert eq.tip_position.shape == (*shape, 3), name
        for estimate in (eq.residual, eq.error_estimate):  # a scalar for a closed form
            assert np.broadcast_shapes(np.shape(estimate), shape) == shape, name


# --- the solver itself (the lead wires the _validate helpers into statics/solver.py) -------------

def test_solver_direct_accepts_numpy_scalars_and_nearly_rigid_base(rng):
    from softarm.statics import Solver

    solver = Solver(ARM, max_load_step=np.float32(0.5), base=_nearly_rigid(rng, 1e-7))
    R = solver.base[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-15)


def test_solver_direct_checks_the_allocation(monkeypatch):
    from softarm.statics import Solver

    monkeypatch.setattr(_validate, "memory_limit", lambda: 10**6)
    # 10⁵ stations × 224 B + 640 B, and 3 × 12288 B of work (check_allocation)
    with pytest.raises(ValueError, match=r"100000 stations would need 22\.4 MB"):
        Solver(ARM, s=100_000)
