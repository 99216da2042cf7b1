"""Geometry of a drawn equilibrium, shared by every front end (matplotlib pictures, the HTML
viewer, the live app): the tube of the arm's real radius, its planar outlines, cube axis limits
with equal scaling, the tip frame, arrows for the loads, and the obstacles of a contact with
the arrows of its forces.

numpy only: no plotting library is imported here. Positions are in m, in the spatial frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Arrow",
    "contact_arrows",
    "contact_scale",
    "contacts",
    "cube_limits",
    "grid_mesh",
    "load_arrows",
    "obstacle_outline",
    "obstacle_surface",
    "silhouette",
    "station_radii",
    "sweep_axis",
    "tip_frame",
    "tube_mesh",
    "tube_rings",
    "tube_surface",
]


def station_radii(arm, s) -> np.ndarray | None:
    """Tube radius (m) at each station ``s`` (m), shape (N,), or None if a segment's cross-section
    is not known (an arm given by its stiffnesses only). At a joint the tip-side segment's
    radius is used."""
    radii = [segment.radius for segment in arm.segments]
    if any(r is None for r in radii):
        return None
    bounds = np.asarray(arm.boundaries[1:-1], dtype=float)
    index = np.searchsorted(bounds, np.asarray(s, dtype=float), side="right")
    return np.asarray(radii, dtype=float)[index]


def tube_rings(arm, s, rings: int = 48) -> tuple[np.ndarray, np.ndarray] | None:
    """The stations and radii of the rings of a drawn tube: (index (M,), radii (M,) in m), or
    None if a segment's cross-section is not known.

    At most about ``rings`` rings spread evenly over the stations ``s`` (every k-th station,
    always the first and last), so that a fine solution does not make a heavy drawing; a
    joint between segments of different radii gets two rings at its station, one of each
    radius, so that the step is drawn flat and sharp (an annulus) whatever the spacing.
    The rings in order, ``poses[index]`` and ``radii`` give :func:`tube_mesh` its input.
    """
    s = np.asarray(s, dtype=float)
    per = [segment.radius for segment in arm.segments]
    if any(r is None for r in per):
        return None
    n = s.size
    stride = max(1, -(-(n - 1) // max(int(rings), 1)))  # ceil((n - 1) / rings)
    keep = np.zeros(n, dtype=bool)
    keep[::stride] = True
    keep[-1] = True
    bounds = np.asarray(arm.boundaries[1:-1], dtype=float)
    joints = np.searchsorted(s, bounds)  # the station at (or just after) each joint
    keep[joints[joints < n]] = True
    index = np.flatnonzero(keep)
    radii = np.asarray(per, dtype=float)[np.searchsorted(bounds, s[index], side="right")]
    # at a joint station, a first ring of the base-side radius
    base_side = np.asarray(per, dtype=float)[np.searchsorted(bounds, s[index], side="left")]
    step = np.flatnonzero((base_side != radii) & (index > 0))
    index = np.insert(index, step, index[step])
    radii = np.insert(radii, step, base_side[step])
    return index, radii


def tube_surface(poses, radii, sides: int = 24) -> np.ndarray:
    """Surface points of the tube p(s) + r(s) (cos φ e2(s) + sin φ e3(s)), φ in [0, 2π].

    ``poses`` (N, 4, 4), ``radii`` (N,) in m. Returns shape (3, N, sides + 1): the x, y and z
    grids (the first and last columns coincide, closing the tube).
    """
    poses = np.asarray(poses, dtype=float)
    radii = np.asarray(radii, dtype=float)
    phi = np.linspace(0.0, 2.0 * np.pi, sides + 1)
    e2, e3 = poses[:, :3, 1], poses[:, :3, 2]
    ring = np.cos(phi)[None, :, None] * e2[:, None, :] + np.sin(phi)[None, :, None] * e3[:, None]
    points = poses[:, None, :3, 3] + radii[:, None, None] * ring
    return np.moveaxis(points, -1, 0)


def tube_mesh(poses, radii, sides: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """The tube as a triangle mesh: vertices (N·sides, 3), ring by ring (vertex ``n·sides + j``
    at station n, angle φ_j = 2πj/sides, as in :func:`tube_surface`), and triangles
    (2·(N-1)·sides, 3) of vertex indices, wrapping around each ring. Open at both ends."""
    points = tube_surface(poses, radii, sides)[:, :, :-1]  # drop the repeated seam column
    n = points.shape[1]
    vertices = np.moveaxis(points, 0, -1).reshape(-1, 3)
    ring = np.arange(n - 1)[:, None] * sides
    j = np.arange(sides)[None, :]
    a, b = ring + j, ring + (j + 1) % sides  # this ring: φ_j, φ_j+1
    c, d = a + sides, b + sides  # the next ring
    triangles = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)], axis=1)
    return vertices, triangles.reshape(-1, 3)


def silhouette(points2, radii) -> np.ndarray:
    """Outline of a tube of radius r around a planar polyline (N, 2), shape (2N, 2)."""
    points2 = np.asarray(points2, dtype=float)
    radii = np.asarray(radii, dtype=float)
    tangent = np.gradient(points2, axis=0)
    length = np.linalg.norm(tangent, axis=-1, keepdims=True)
    # Where the arm points straight out of the plane the outline is a disc; any unit normal
    # is as good as another there.
    safe = np.where(length > 0, length, 1.0)
    normal = np.where(length > 0, np.stack([-tangent[:, 1], tangent[:, 0]], -1) / safe,
                      np.array([0.0, 1.0]))
    offset = radii[:, None] * normal
    return np.concatenate([points2 + offset, (points2 - offset)[::-1]])


def cube_limits(points, margin: float = 1.1) -> tuple[np.ndarray, float]:
    """(centre (3,), half side) of a cube holding ``points`` (..., 3) with equal scaling on x, y
    and z; ``margin`` enlarges it (1.1: 10 %)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    low, high = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (low + high)
    half = 0.5 * margin * max(float(np.max(high - low)), 1e-9)
    return centre, half


def tip_frame(poses, length: float) -> np.ndarray:
    """The tip's material frame as three segments of ``length`` (m) from the tip along e1, e2
    and e3: shape (3, 2, 3) = (axis, [start, end], xyz)."""
    tip = np.asarray(poses, dtype=float)[-1]
    start = tip[:3, 3]
    return np.stack([np.stack([start, start + length * tip[:3, k]]) for k in range(3)])


@dataclass(frozen=True)
class Arrow:
    """Arrows of one vector field of one load: ``origins`` and spatial ``vectors`` (k, 3), in
    the load's ``unit``; ``moment``: the vectors are moments (drawn differently from forces);
    ``key``: (index of the load in the loads, field name), stable when the values change."""

    label: str
    origins: np.ndarray
    vectors: np.ndarray
    unit: str
    moment: bool = False
    key: tuple = ()


def _at(poses, s, where):
    """Poses interpolated at arc lengths ``where`` (nearest station; for drawing only)."""
    index = np.clip(np.searchsorted(s, where), 0, len(s) - 1)
    return poses[index]


def _span(load, arm) -> tuple[float, float]:
    span = getattr(load, "span", None)
    if span is not None:
        return float(span[0]), float(span[1])
    segment = getattr(load, "segment", None)
    bounds = arm.boundaries
    if segment is not None and segment + 1 < len(bounds):
        return float(bounds[segment]), float(bounds[segment + 1])
    return 0.0, float(arm.length)


def load_arrows(loads, poses, s, arm, count: int = 6) -> list[Arrow]:
    """Arrows for the (unbatched) ``loads`` acting on the drawn equilibrium (``poses`` (N, 4, 4)
    at stations ``s`` (N,)): tip and point wrenches at their station, distributed loads and
    gravity as ``count`` arrows along their span. Follower components are turned into the
    spatial frame with the material frame where they act. Zero vectors give no arrow."""
    poses = np.asarray(poses, dtype=float)
    s = np.asarray(s, dtype=float)
    arrows = []
    for index, load in enumerate(loads):
        kind = getattr(load, "kind", type(load).__name__)
        follower = bool(getattr(load, "follower", False))
        if kind == "tip":
            where = np.array([s[-1]])
        elif kind == "point":
            where = np.array([float(load.s)])
        else:
            s0, s1 = _span(load, arm)
            where = np.linspace(s0, s1, count + 2)[1:-1] if kind != "gravity" else \
                np.linspace(0.0, float(arm.length), count + 2)[1:-1]
        at = _at(poses, s, where)
        for name, unit in load.vectors:
            vector = np.asarray(getattr(load, name), dtype=float)
            if vector.ndim != 1 or not np.any(vector != 0):
                continue
            vectors = at[:, :3, :3] @ vector if follower else \
                np.broadcast_to(vector, at[:, :3, 3].shape)
            label = load.describe() if len(load.vectors) == 1 else \
                f"{'follower ' if follower else ''}{kind} {name}"
            arrows.append(Arrow(label, at[:, :3, 3].copy(), np.array(vectors), unit,
                                moment="moment" in name, key=(index, name)))
    return arrows


@dataclass(frozen=True)
class ActuatorPath:
    """The drawn path of one actuator (a tendon or a chamber's centroid): ``points`` (k, 3)
    in the spatial frame, p(s) + R(s) r(s) at the stations on its span."""

    label: str
    kind: str
    points: np.ndarray
    key: int = 0


def actuator_paths(loads, poses, s) -> list[ActuatorPath]:
    """The paths of the loads that run along a routing (tendons, chambers) on the drawn
    equilibrium (``poses`` (N, 4, 4) at stations ``s`` (N,))."""
    poses = np.asarray(poses, dtype=float)
    s = np.asarray(s, dtype=float)
    paths = []
    for index, load in enumerate(loads):
        routing = getattr(load, "routing", None)
        if routing is None:
            continue
        s0, s1 = load.path_span(float(s[-1]))
        on = (s >= s0 - 1e-12) & (s <= s1 + 1e-12)
        r = routing.position(s[on])
        points = poses[on, :3, 3] + np.einsum("nij,nj->ni", poses[on, :3, :3], r)
        paths.append(ActuatorPath(load.describe(), load.kind, points, index))
    return paths


def sweep_axis(steps: int, sweep=None, values=None, label=None) -> tuple[np.ndarray, str]:
    """The parameter values (shape (steps,)) and axis label of a sweep result's batch axis:
    ``values``/``label`` as given, else the sweep's (a :class:`softarm.sweep.Sweep`), else the
    step index. ValueError if ``values`` has the wrong shape."""
    if values is None:
        values = sweep.values if sweep is not None else np.arange(steps)
    values = np.asarray(values, dtype=float)
    if values.shape != (steps,):
        raise ValueError(f"values must have shape ({steps},), got {values.shape}")
    if label is None:
        label = sweep.label if sweep is not None else "step"
    return values, label


# --------------------------------------------------------------------------------------------
# Obstacles and contact forces (softarm.Contact)
# --------------------------------------------------------------------------------------------


def contacts(loads) -> list:
    """The :class:`softarm.Contact` loads among ``loads`` (found by their kind)."""
    return [load for load in loads if getattr(load, "kind", "") == "contact"]


def _across(direction) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors that make a right-handed orthonormal frame with the unit
    ``direction`` (3,)."""
    d = np.asarray(direction, dtype=float)
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    u = np.cross(d, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(d, u)


def obstacle_surface(obstacle, centre, half: float, sides: int = 24) -> np.ndarray:
    """A drawable surface of ``obstacle`` (a :class:`softarm.Plane`, ``Sphere`` or ``Capsule``,
    m, spatial), shape (3, rows, columns): the x, y and z grids, as :func:`tube_surface`.

    A plane is drawn as the square of side 2 ``half`` on it centred where ``centre`` (3,)
    projects onto it (the drawn scene's cube: planes are infinite); a sphere as a grid of
    meridians and parallels; a capsule as its cylinder and end caps, one surface of
    revolution about its axis."""
    if obstacle.kind == "plane":
        n = obstacle.normal
        u, v = _across(n)
        middle = centre - ((centre - obstacle.point) @ n) * n
        t = np.linspace(-half, half, 2)
        return np.moveaxis(middle + t[:, None, None] * u + t[None, :, None] * v, -1, 0)
    phi = np.linspace(0.0, 2.0 * np.pi, sides + 1)
    if obstacle.kind == "sphere":
        polar = np.linspace(0.0, np.pi, sides // 2 + 1)
        axis, (u, v) = np.array([0.0, 0.0, 1.0]), (np.eye(3)[0], np.eye(3)[1])
        along, across = -np.cos(polar), np.sin(polar)
        base = obstacle.center
    else:  # a capsule: a profile (along the axis, distance from it) turned about the axis
        span = obstacle.b - obstacle.a
        length = float(np.linalg.norm(span))
        axis = span / length
        u, v = _across(axis)
        cap = np.linspace(-0.5 * np.pi, 0.0, sides // 4 + 1)
        along = np.concatenate([np.sin(cap), length / obstacle.radius + np.sin(-cap[::-1])])
        across = np.concatenate([np.cos(cap), np.cos(cap[::-1])])
        base = obstacle.a
    r = obstacle.radius
    ring = np.cos(phi)[None, :, None] * u + np.sin(phi)[None, :, None] * v
    points = base + r * (along[:, None, None] * axis + across[:, None, None] * ring)
    return np.moveaxis(points, -1, 0)


def grid_mesh(surface) -> tuple[np.ndarray, np.ndarray]:
    """A surface grid (3, rows, columns) as a triangle mesh: vertices (rows·columns, 3) and
    triangles (2·(rows-1)·(columns-1), 3) of vertex indices."""
    rows, columns = surface.shape[1:]
    vertices = np.moveaxis(np.asarray(surface, dtype=float), 0, -1).reshape(-1, 3)
    a = (np.arange(rows - 1)[:, None] * columns + np.arange(columns - 1)[None, :]).ravel()
    b, c, d = a + 1, a + columns, a + columns + 1
    return vertices, np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)])


def obstacle_outline(obstacle, axes: tuple[int, int], centre, half: float,
                     sides: int = 48) -> np.ndarray | None:
    """The outline of ``obstacle`` seen along the third axis in the side view of the
    spatial ``axes`` (i, j): (k, 2) points, a closed polygon (a sphere's circle, a capsule's
    stadium), or None where the view shows no edge of it (a plane not seen edge-on, whose
    projection covers the whole view). A plane seen edge-on is its line across the view's
    square of side 2 ``half`` about ``centre`` (two points)."""
    i, j = axes
    if obstacle.kind == "plane":
        n = obstacle.normal[[i, j]]
        if abs(np.linalg.norm(n) - 1.0) > 1e-9:  # the normal has a component along the view
            return None
        direction = np.array([-n[1], n[0]])
        middle = np.asarray(centre, dtype=float)[[i, j]]
        middle = middle - ((middle - obstacle.point[[i, j]]) @ n) * n
        return middle + np.array([-half, half])[:, None] * direction
    phi = np.linspace(0.0, 2.0 * np.pi, sides + 1)
    circle = np.stack([np.cos(phi), np.sin(phi)], -1) * obstacle.radius
    if obstacle.kind == "sphere":
        return obstacle.center[[i, j]] + circle
    a, b = obstacle.a[[i, j]], obstacle.b[[i, j]]
    span = b - a
    if not np.linalg.norm(span) > 0.0:  # seen along its axis: a circle
        return a + circle
    direction = span / np.linalg.norm(span)
    side = np.arctan2(direction[1], direction[0])
    half_turn = np.linspace(-0.5 * np.pi, 0.5 * np.pi, sides // 2 + 1)
    ends = [b + obstacle.radius * np.stack([np.cos(side + half_turn),
                                            np.sin(side + half_turn)], -1),
            a + obstacle.radius * np.stack([np.cos(side + np.pi + half_turn),
                                            np.sin(side + np.pi + half_turn)], -1)]
    return np.concatenate([*ends, ends[0][:1]])


def contact_arrows(result) -> Arrow | None:
    """The contact forces of an unbatched equilibrium as arrows, or None without a contact:
    per length (N/m, spatial) at the stations where they are nonzero
    (``result.contact_forces``), or, for a tip held on an obstacle without a penalty
    (statics/tip_contact.py: no stiffness, a nonzero ``contact_wrench``), the obstacle's
    reaction (N) at the tip."""
    found = contacts(result.loads)
    if not found:
        return None
    positions = np.asarray(result.poses, dtype=float)[:, :3, 3]
    resultant = getattr(result, "contact_resultant", None)
    if not np.any(found[0].stiffness) and resultant is not None and np.any(resultant[:3]):
        return Arrow("contact force at the tip", positions[-1:],
                     np.asarray(resultant, dtype=float)[None, :3], "N", key=("contact", "force"))
    forces = np.asarray(result.contact_forces, dtype=float)
    on = np.linalg.norm(forces, axis=-1) > 0.0
    return Arrow("contact force per length", positions[on], forces[on], "N/m",
                 key=("contact", "force"))


def contact_scale(arrows, length: float) -> float:
    """m per N/m for contact arrows (:func:`contact_arrows`, one per drawn case): the
    largest force per length is drawn 0.15 L long (0 without a force)."""
    largest = max((float(np.max(np.linalg.norm(a.vectors, axis=-1), initial=0.0))
                   for a in arrows if a is not None), default=0.0)
    return 0.15 * length / largest if largest > 0 else 0.0
