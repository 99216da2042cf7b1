"""The shared drawing geometry (softarm.geometry): tube, outlines, cube limits, tip frame and
load arrows, checked against hand-built references. numpy only: no plotting library needed."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

import softarm
from softarm import geometry
from softarm.lie import se3, so3


def two_segments():
    soft = softarm.Material(1.0e6, poisson_ratio=0.5, density=1100.0)
    return softarm.SegmentedArm([softarm.Arm(0.25, softarm.Circle(0.015), soft),
                                 softarm.Arm(0.15, softarm.Tube(0.01, 0.005), soft)])


def test_radius_per_segment_and_unknown_section():
    # the base segment is a 15 mm rod, the tip one a tube of 10 mm outer radius; at the joint
    # s = 0.25 the tip-side segment's radius is used
    np.testing.assert_array_equal(
        geometry.station_radii(two_segments(), [0.0, 0.2, 0.25, 0.3, 0.4]),
        [0.015, 0.015, 0.01, 0.01, 0.01])
    stiff = softarm.Arm.from_stiffness(1.0, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    assert geometry.station_radii(stiff, [0.0, 1.0]) is None


def test_tube_points_lie_at_the_radius_around_a_bent_axis():
    # an arc of curvature 2 1/m about e3, with a twisted frame: every surface point is at
    # distance r from its own centreline point and in the plane normal to e1 there
    s = np.linspace(0.0, 1.0, 7)
    poses = se3.exp(s[:, None] * [1.0, 0, 0, 0.7, 0, 2.0])
    radii = np.linspace(0.05, 0.02, 7)
    surface = geometry.tube_surface(poses, radii, sides=12)
    assert surface.shape == (3, 7, 13)
    offset = np.moveaxis(surface, 0, -1) - poses[:, None, :3, 3]
    np.testing.assert_allclose(np.linalg.norm(offset, axis=-1), radii[:, None] + 0 * offset[..., 0])
    np.testing.assert_allclose(np.einsum("nkx,nx->nk", offset, poses[:, :3, 0]), 0.0,
                               atol=1e-15)
    np.testing.assert_allclose(surface[:, :, 0], surface[:, :, -1], atol=1e-15)  # closed


def test_tube_mesh_covers_the_surface_with_triangles():
    s = np.linspace(0.0, 1.0, 5)
    poses = se3.exp(s[:, None] * [1.0, 0, 0, 0, 1.0, 0])
    vertices, triangles = geometry.tube_mesh(poses, np.full(5, 0.1), sides=6)
    assert vertices.shape == (30, 3) and triangles.shape == (2 * 4 * 6, 3)
    surface = geometry.tube_surface(poses, np.full(5, 0.1), sides=6)
    np.testing.assert_allclose(vertices[6 * 2 + 3], surface[:, 2, 3])  # station 2, φ = π
    # every triangle joins two neighbouring stations and neighbouring angles (with the seam)
    station, angle = np.divmod(triangles, 6)
    assert np.all(np.ptp(station, axis=1) == 1)
    gaps = np.sort(angle, axis=1)
    assert np.all((np.ptp(angle, axis=1) <= 1) | ((gaps[:, 0] == 0) & (gaps[:, -1] == 5)))
    # the triangles tile the side of the tube: total area → 2π r L as the mesh refines
    fine_v, fine_t = geometry.tube_mesh(se3.exp(np.linspace(0, 1, 200)[:, None]
                                                * [1.0, 0, 0, 0, 1.0, 0]),
                                        np.full(200, 0.1), sides=256)
    corner = fine_v[fine_t]
    area = 0.5 * np.linalg.norm(np.cross(corner[:, 1] - corner[:, 0],
                                         corner[:, 2] - corner[:, 0]), axis=-1).sum()
    np.testing.assert_allclose(area, 2 * np.pi * 0.1 * 1.0, rtol=1e-3)


def test_tube_rings_bound_the_mesh_and_keep_the_joint_sharp():
    arm = two_segments()  # joint at s = 0.25 m: 15 mm rod, then 10 mm tube
    s = np.linspace(0.0, 0.4, 401)  # 1 mm apart: the joint is station 250
    index, radii = geometry.tube_rings(arm, s, rings=40)
    # every 10th station (ceil(400 / 40)), the ends, and the joint twice: once with each
    # segment's radius, so that the drawn step is a flat annulus
    expected = np.concatenate([np.arange(0, 251, 10), [250], np.arange(260, 401, 10)])
    np.testing.assert_array_equal(index, expected)
    np.testing.assert_array_equal(radii, np.where(np.arange(expected.size) <= 25, 0.015, 0.01))
    # a coarse solution keeps all its stations; a joint between stations gets no extra ring
    coarse = np.linspace(0.0, 0.4, 9)  # 0.05 m apart: the joint is station 5
    index, radii = geometry.tube_rings(arm, coarse, rings=40)
    np.testing.assert_array_equal(index, [0, 1, 2, 3, 4, 5, 5, 6, 7, 8])
    odd = np.linspace(0.0, 0.4, 12)
    index, radii = geometry.tube_rings(arm, odd, rings=40)
    np.testing.assert_array_equal(index, np.arange(12))
    np.testing.assert_array_equal(radii, np.where(odd < 0.25, 0.015, 0.01))
    # every 3rd of 102 stations (ceil(101 / 50)), the last one off the stride, and the first
    # station past the joint (s = 0.25 m lies between stations 63 and 64)
    index, _ = geometry.tube_rings(arm, np.linspace(0.0, 0.4, 102), rings=50)
    np.testing.assert_array_equal(index, sorted([*range(0, 102, 3), 64, 101]))
    stiff = softarm.Arm.from_stiffness(1.0, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    assert geometry.tube_rings(stiff, [0.0, 1.0]) is None


def test_silhouette_of_a_straight_arm_is_a_rectangle():
    points = np.stack([np.linspace(0.0, 2.0, 5), np.zeros(5)], -1)
    outline = geometry.silhouette(points, np.full(5, 0.1))
    np.testing.assert_allclose(outline[:5], np.stack([points[:, 0], np.full(5, 0.1)], -1))
    np.testing.assert_allclose(outline[5:], np.stack([points[::-1, 0], np.full(5, -0.1)], -1))


def test_cube_limits_hold_every_point_with_equal_sides():
    points = np.array([[0.0, -1.0, 0.0], [4.0, 1.0, 0.5]])
    centre, half = geometry.cube_limits(points, margin=1.0)
    np.testing.assert_allclose(centre, [2.0, 0.0, 0.25])
    assert half == 2.0  # half the largest extent, 4 m along x


def test_tip_frame_is_the_tip_rotation():
    R = so3.exp(np.array([0.3, -0.2, 1.1]))
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = R, [1.0, 2.0, 3.0]
    frame = geometry.tip_frame(np.stack([np.eye(4), pose]), 0.5)
    np.testing.assert_allclose(frame[:, 0], np.tile([1.0, 2.0, 3.0], (3, 1)))
    np.testing.assert_allclose(frame[:, 1] - frame[:, 0], 0.5 * R.T)  # rows: e1, e2, e3


def test_load_arrows_dead_follower_and_distributed():
    arm = two_segments()
    s = np.linspace(0.0, 0.4, 41)
    poses = se3.exp(s[:, None] * [1.0, 0, 0, 0, 3.0, 0])  # bent about e2
    loads = [softarm.TipLoad(force=[0.0, 0.0, -1.0]),
             softarm.TipLoad(force=[0.0, 1.0, 0.0], follower=True),
             softarm.TipLoad(moment=[0.0, 0.0, 0.0]),  # zero: no arrow
             softarm.PointLoad(0.1, force=[1.0, 0.0, 0.0]),
             softarm.DistributedForce([0.0, 0.0, -2.0], span=(0.1, 0.3)),
             softarm.Gravity()]
    arrows = geometry.load_arrows(loads, poses, s, arm, count=4)
    assert [a.unit for a in arrows] == ["N", "N", "N", "N/m", "m/s²"]
    dead, follower, point, distributed, gravity = arrows
    np.testing.assert_allclose(dead.origins, poses[-1:, :3, 3])
    np.testing.assert_allclose(dead.vectors, [[0.0, 0.0, -1.0]])
    # follower: material e2 component, drawn along the tip's e2 in space
    np.testing.assert_allclose(follower.vectors, [poses[-1, :3, 1]])
    np.testing.assert_allclose(point.origins, poses[10:11, :3, 3])  # s = 0.1 is station 10
    assert distributed.origins.shape == (4, 3)
    np.testing.assert_allclose(distributed.origins, poses[[14, 18, 22, 26], :3, 3])
    np.testing.assert_allclose(gravity.vectors, np.tile([0.0, 0.0, -9.81], (4, 1)))


def test_geometry_imports_no_plotting_library():
    code = ("import sys, softarm.geometry; "
            "print(any(m.split('.')[0] in ('matplotlib', 'plotly') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
