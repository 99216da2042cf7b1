"""Obstacles and contact forces in the pictures (matplotlib), the browser view's figure, the
live app's updates and the shared geometry (softarm.geometry)."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm import geometry

ARM = softarm.Arm(0.5, softarm.Circle(0.01),
                  softarm.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1000.0))
OBSTACLES = [softarm.Plane((0, 0, -0.05), (0, 0, 1)), softarm.Sphere((0.3, 0.3, 0.0), 0.05),
             softarm.Capsule((0.0, -0.3, 0.2), (0.1, -0.3, 0.2), 0.02)]


@pytest.fixture(scope="module")
def table():
    return softarm.solve(ARM, [softarm.Gravity(), softarm.Contact(OBSTACLES)], s=51)


@pytest.mark.parametrize("obstacle", OBSTACLES, ids=lambda o: o.kind)
def test_obstacle_surfaces_lie_on_the_obstacles(obstacle):
    """Every point of a drawn surface is on the obstacle's surface: its own signed distance
    (contact.py) is zero there; the mesh uses every vertex."""
    surface = geometry.obstacle_surface(obstacle, np.array([0.2, 0.0, 0.0]), 0.3)
    distance, _ = obstacle.distance(np.moveaxis(surface, 0, -1))
    np.testing.assert_allclose(distance, 0.0, atol=1e-15)
    vertices, triangles = geometry.grid_mesh(surface)
    assert vertices.shape == (surface.shape[1] * surface.shape[2], 3)
    assert set(np.unique(triangles)) == set(range(len(vertices)))


def test_a_plane_is_drawn_as_the_square_about_the_scene():
    plane = softarm.Plane((0, 0, -0.05), (0, 1, 1))
    surface = geometry.obstacle_surface(plane, np.array([0.2, 0.0, 0.0]), 0.3)
    corners = np.moveaxis(surface, 0, -1).reshape(-1, 3)
    middle = corners.mean(axis=0)
    # the centre's projection onto the plane, and a square of side 0.6
    np.testing.assert_allclose(middle, [0.2, -0.025, -0.025], atol=1e-15)
    sides = np.linalg.norm(corners[[1, 3, 2, 0]] - corners[[0, 1, 3, 2]], axis=-1)
    np.testing.assert_allclose(sides, 0.6, rtol=1e-14)


def test_outlines_in_the_side_views():
    capsule = softarm.Capsule((0, 0, 0), (1, 0, 0), 0.1)
    outline = geometry.obstacle_outline(capsule, (0, 2), np.zeros(3), 1.0)
    np.testing.assert_allclose(outline.min(axis=0), [-0.1, -0.1], atol=1e-15)
    np.testing.assert_allclose(outline.max(axis=0), [1.1, 0.1], atol=1e-15)
    table = softarm.Plane((0, 0, -0.05), (0, 0, 1))
    # seen edge-on from y: its line z = -0.05; seen from above it covers the view: nothing
    np.testing.assert_allclose(geometry.obstacle_outline(table, (0, 2), np.zeros(3), 0.3),
                               [[0.3, -0.05], [-0.3, -0.05]], atol=1e-15)
    assert geometry.obstacle_outline(table, (0, 1), np.zeros(3), 0.3) is None


def test_contact_arrows_are_the_nonzero_contact_forces(table):
    arrows = geometry.contact_arrows(table)
    on = np.linalg.norm(table.contact_forces, axis=-1) > 0
    assert 5 < on.sum() < table.s.size
    np.testing.assert_array_equal(arrows.origins, table.positions[on])
    np.testing.assert_array_equal(arrows.vectors, table.contact_forces[on])
    assert geometry.contact_arrows(softarm.solve(ARM, softarm.Gravity(), s=11)) is None
    scale = geometry.contact_scale([arrows], 0.5)
    assert scale * np.max(np.linalg.norm(arrows.vectors, axis=-1)) == pytest.approx(0.075)


def test_the_picture_draws_the_obstacles_and_the_contact_forces(table, tmp_path):
    pytest.importorskip("matplotlib")
    from softarm import plot

    fig = plot.plot_equilibrium(table, path=tmp_path / "table.png")
    ax3, xz, xy = fig.axes
    gids = {ax: [a.get_gid() for a in ax.get_children() if a.get_gid()] for ax in fig.axes}
    assert gids[ax3] == ["obstacle 1 plane", "obstacle 2 sphere", "obstacle 3 capsule",
                         "contact forces"]
    # the plane is seen edge-on in the x–z view only; spheres and capsules in both
    assert gids[xz] == ["obstacle 1 plane", "obstacle 2 sphere", "obstacle 3 capsule",
                        "contact forces"]
    assert gids[xy] == ["obstacle 2 sphere", "obstacle 3 capsule", "contact forces"]
    # the x–z view's arrows: one per station in contact, from the centreline, 0.15 L the
    # largest
    quiver = next(a for a in xz.get_children() if a.get_gid() == "contact forces")
    on = np.linalg.norm(table.contact_forces, axis=-1) > 0
    np.testing.assert_allclose(quiver.get_offsets(), table.positions[on][:, [0, 2]])
    assert np.max(np.hypot(quiver.U, quiver.V)) == pytest.approx(0.075)
    # the table's line at z = -0.05 in the x–z view
    line = next(a for a in xz.get_children() if a.get_gid() == "obstacle 1 plane")
    np.testing.assert_allclose(line.get_ydata(), -0.05)
    # the 3D limits hold the capsule at z = 0.2 + 0.02 and y = -0.3 - 0.02
    assert ax3.get_zlim()[1] > 0.22 and ax3.get_ylim()[0] < -0.32
    assert "contact force per length (magenta) up to" in fig.texts[-1].get_text()
    assert (tmp_path / "table.png").stat().st_size > 10_000


@pytest.mark.slow  # (2.5 s)
def test_a_trajectory_picture_draws_the_obstacles_forces_and_contact_energy(tmp_path):
    """Issue 39: a motion's picture draws the obstacles in its side view, the contact forces
    at its last time, and the penalty's stored energy, with a total that holds it (the
    energy Energy.total leaves out while the arm presses on an obstacle)."""
    pytest.importorskip("matplotlib")
    from softarm import plot

    pin = softarm.Capsule((0.3, -0.1, -0.04), (0.3, 0.1, -0.04), 0.01)
    path = softarm.simulate(ARM, [softarm.Gravity(), softarm.Contact([OBSTACLES[0], pin])],
                            duration=0.11, dt=1e-3, stations=51)  # (on the table at the end)
    fig = plot.plot_trajectory(path, path=tmp_path / "drop.png")
    side, energy = fig.axes[0], fig.axes[2]  # (fig.axes[1]: the tip; [3]: the colour bar)
    gids = [a.get_gid() for a in side.get_children() if a.get_gid()]
    assert gids == ["obstacle 1 plane", "obstacle 2 capsule", "contact forces"]
    table = next(a for a in side.get_children() if a.get_gid() == "obstacle 1 plane")
    np.testing.assert_allclose(table.get_ydata(), -0.05)  # the x–z view: z = -0.05
    quiver = next(a for a in side.get_children() if a.get_gid() == "contact forces")
    on = np.linalg.norm(path.contact_forces[-1], axis=-1) > 0
    np.testing.assert_allclose(quiver.get_offsets(), path.positions[-1][on][:, [0, 2]])
    lines = {a.get_gid(): a for a in energy.get_lines()}
    stored = path.contact_energy
    assert stored.max() > 0.0
    np.testing.assert_allclose(lines["energy contact"].get_ydata(), stored - stored[0])
    e = path.energy
    total = e.total - e.total[0] + stored - stored[0]
    np.testing.assert_allclose(lines["energy total"].get_ydata(), total)
    assert (tmp_path / "drop.png").stat().st_size > 10_000
    # the browser page: the obstacles (after the moving traces, outside the frames) and the
    # contact energy among the curves, the total holding it
    pytest.importorskip("plotly")
    from softarm import view

    page = view.trajectory_figure(path, arm=ARM)
    names = [trace.get("name") for trace in page["data"]]
    assert names[-2:] == ["obstacle 1: plane", "obstacle 2: capsule"]
    assert all(len(frame["traces"]) < len(names) - 2 for frame in page["frames"])
    curves = {trace["name"]: np.asarray(trace["y"]) for trace in page["energy"]["data"]
              if trace.get("name")}
    np.testing.assert_allclose(curves["contact"], stored)
    np.testing.assert_allclose(curves["total"], e.kinetic + e.elastic + e.gravity
                               + e.dissipated + stored)


@pytest.mark.slow
def test_a_sweep_picture_draws_the_obstacles(tmp_path):
    pytest.importorskip("matplotlib")
    from softarm import plot

    force = np.array([0.0, 0.2])[:, None] * [0.0, 0.0, -1.0]
    sweep = softarm.solve(ARM, [softarm.Gravity(), softarm.TipLoad(force=force),
                                softarm.Contact(OBSTACLES[0])], s=31)
    fig = plot.plot_sweep(sweep)
    assert [a.get_gid() for a in fig.axes[0].get_children() if a.get_gid()] == \
        ["obstacle 1 plane"]


def test_the_view_draws_the_obstacles_and_the_contact_forces(table):
    pytest.importorskip("plotly")
    from softarm import view

    fig = view.figure(table)
    names = [trace.get("name") for trace in fig["data"]]
    assert names[-4:] == ["obstacle 1: plane", "obstacle 2: sphere", "obstacle 3: capsule",
                          "axis cube"]
    sphere = fig["data"][names.index("obstacle 2: sphere")]
    points = np.stack([sphere["x"], sphere["y"], sphere["z"]], -1)
    np.testing.assert_allclose(np.linalg.norm(points - [0.3, 0.3, 0.0], axis=-1), 0.05)
    shafts, cones = (fig["data"][k] for k, name in enumerate(names)
                     if name == "contact forces")
    on = np.linalg.norm(table.contact_forces, axis=-1) > 0
    starts = np.stack([shafts[axis][0::3] for axis in "xyz"], -1)
    ends = np.stack([shafts[axis][1::3] for axis in "xyz"], -1)
    np.testing.assert_allclose(starts, table.positions[on])
    forces = table.contact_forces[on]
    scale = 0.15 * 0.5 / np.max(np.linalg.norm(forces, axis=-1))  # largest: 0.15 L
    np.testing.assert_allclose(ends - starts, scale * forces, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(np.stack([cones[axis] for axis in "xyz"], -1), ends)
    # the cube holds the obstacles near the arm
    z_range = fig["layout"]["scene"]["zaxis"]["range"]
    assert z_range[1] > 0.22


@pytest.mark.slow
def test_a_sweep_view_keeps_the_obstacles_out_of_its_frames():
    pytest.importorskip("plotly")
    from softarm import view

    force = np.array([0.0, 0.2])[:, None] * [0.0, 0.0, -1.0]
    sweep = softarm.solve(ARM, [softarm.Gravity(), softarm.TipLoad(force=force),
                                softarm.Contact(OBSTACLES[0])], s=31)
    fig = view.figure(sweep)
    names = [trace.get("name") for trace in fig["data"]]
    frames = fig["frames"]
    assert names.index("obstacle 1: plane") not in frames[0]["traces"]
    shafts = names.index("contact forces")
    assert shafts in frames[0]["traces"]
    # each frame's arrows are its own step's forces, on one scale for the whole sweep
    lengths = []
    for k, frame in enumerate(frames):
        data = frame["data"][frame["traces"].index(shafts)]
        starts = np.stack([data[a][0::3] for a in "xyz"], -1)
        ends = np.stack([data[a][1::3] for a in "xyz"], -1)
        on = np.linalg.norm(sweep.contact_forces[k], axis=-1) > 0
        np.testing.assert_allclose(starts, sweep.positions[k][on])
        lengths.append(np.linalg.norm(ends - starts, axis=-1).max())
        ratio = np.linalg.norm(ends - starts, axis=-1) / np.linalg.norm(
            sweep.contact_forces[k][on], axis=-1)
        np.testing.assert_allclose(ratio, ratio[0], rtol=1e-6)
    assert max(lengths) == pytest.approx(0.075)
    assert lengths[0] < lengths[1]


@pytest.mark.slow
def test_the_app_draws_the_solved_contact_forces():
    pytest.importorskip("plotly")
    from softarm import app
    from softarm.case import parse_case

    data = {**softarm.case.arm_to_dict(ARM), "load": [{"kind": "gravity"}],
            "obstacle": [OBSTACLES[0].to_case()], "solve": {"stations": 51}}
    live = app.LiveCase(parse_case(data, "app"))
    body = live.solve()
    contact = live.result.loads[-1]
    assert contact.stiffness is not None  # the solver's law, not the case's (None)
    fig = live.figure()
    names = [trace.get("name") for trace in fig["data"]]
    shafts = body["data"][names.index("contact forces")]
    starts = np.stack([shafts[a][0::3] for a in "xyz"], -1)
    on = np.linalg.norm(live.result.contact_forces, axis=-1) > 0
    assert on.sum() > 5
    np.testing.assert_allclose(starts, live.result.positions[on])
