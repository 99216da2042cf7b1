"""The results of a simulation: the arm's :class:`State` at one time and its
:class:`Trajectory` over many, with the :class:`Energy` budget."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import along_the_arm, penalty_energy, resultant

__all__ = ["Energy", "State", "Trajectory"]


class AlongTheArm:
    """What a state, a trajectory and a saved trajectory share: ``positions`` (..., S, 3)."""

    positions: np.ndarray

    @property
    def tip_position(self) -> np.ndarray:
        """p(L), shape (B..., [T,] 3) (m, spatial)."""
        return self.positions[..., -1, :]


@dataclass(frozen=True, eq=False)
class Energy:
    """The energy budget of a trajectory (J), each of shape (B..., T).

    Attributes
    ----------
    kinetic : ndarray
        ∫ ½ (μ |q|² + ω · ρJ ω) ds, translation and rotation of the sections.
    elastic : ndarray
        ∫ ½ (ε - ε⁰) · K (ε - ε⁰) ds, the strain energy.
    gravity : ndarray
        -∫ μ g · p ds, the potential of gravity (zero without :class:`~softarm.Gravity`).
    dissipated : ndarray
        ∫₀ᵗ ∫ ε̇ · B ε̇ ds dt, the work of the damping so far (cumulative; trapezoidal rule
        in time).
    """

    kinetic: np.ndarray
    elastic: np.ndarray
    gravity: np.ndarray
    dissipated: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """kinetic + elastic + gravity + dissipated: constant for a free arm under gravity
        (to the time step's error), damped or not."""
        return self.kinetic + self.elastic + self.gravity + self.dissipated


@dataclass(frozen=True, eq=False)
class State(AlongTheArm):
    """The arm at one time: what :meth:`Simulator.step` returns and what a simulation may
    start from (``initial=state``: the same arm, stations, time step and scheme).

    Attributes (S stations, the batch axes B... of the loads first)
    ----------
    time : float
        t in s.
    s : ndarray, shape (S,)
        Stations in m.
    positions : ndarray, shape (B..., S, 3)
        Centreline p (m, spatial).
    rotations : ndarray, shape (B..., S, 3, 3)
        Material frames R (columns e1, e2, e3 in the spatial frame).
    velocities, angular_velocities : ndarray, shape (B..., S, 3)
        ṗ (m/s) and the sections' angular velocity (rad/s), spatial components.
    strains : ndarray, shape (B..., S, 6)
        ε - ε⁰ = (γ; κ), material frame.
    stresses : ndarray, shape (B..., S, 6)
        The internal wrench (n; m) (N, N m), material frame, elastic plus viscous part.
    error : ndarray, shape (B...)
        The distance between the step's predicted (extrapolated) and solved centreline,
        relative to L: the size of the time step's correction, an indicator of its local
        error (0 for a state that was not stepped to).
    iterations : ndarray of int, shape (B...)
        Newton iterations of the step.
    tendon_lengths : ndarray, shape (B..., tendons), or None
        Each tendon's length along its path (m), in the order of the actuators.
    """

    time: float
    s: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    strains: np.ndarray
    stresses: np.ndarray
    error: np.ndarray
    iterations: np.ndarray
    tendon_lengths: np.ndarray | None = None
    _arrays: tuple = ()  # the kernel's state (nodes, previous nodes, history, energy)
    _signature: tuple = ()  # what the state is valid for (arm, grid, Δt, scheme, batch)
    _fresh: bool = False  # at rest with no step taken yet (its first step: backward Euler)


class Trajectories(AlongTheArm):
    """What a trajectory and a saved one share: the batch shape of (B..., T, S, 3), and the
    contact's gaps, forces and stored energy (from ``contact``, the law the steps used, and
    ``contact_radii``; None without contact)."""

    s: np.ndarray
    contact: object
    contact_radii: np.ndarray | None

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.positions.shape[:-3]

    @property
    def gaps(self) -> np.ndarray:
        """(B..., T, S): the distance from the arm's surface to the nearest obstacle, m (inf
        without a Contact)."""
        return self._contact_state()[0]

    @property
    def contact_forces(self) -> np.ndarray:
        """(B..., T, S, 3): the obstacles' normal force per length on the arm, N/m, spatial
        (Coulomb friction, which acted in the steps, is not included; docs/contact.md)."""
        return self._contact_state()[1]

    @property
    def contact_wrench(self) -> np.ndarray:
        """(B..., T, 6): the total normal contact force (N) and its moment about the origin
        (N m), integrated over the stations (:func:`softarm.contact.resultant`)."""
        return resultant(self.s, self.positions, self.contact_forces)

    @property
    def contact_energy(self) -> np.ndarray:
        """(B..., T): the energy the contact's penalty stores, ∫ Φ(g) ds over the stations
        (J; zero without a Contact): what :class:`Energy`'s total leaves out while the arm
        presses on an obstacle (docs/contact.md)."""
        if self.contact is None:
            return np.zeros(self.positions.shape[:-2])
        k = np.asarray(self.contact.stiffness)
        k = k.reshape(k.shape + (1,) * (self.positions.ndim - 1 - k.ndim)) if k.ndim else k
        per_length = penalty_energy(self.gaps, self.contact.distance, k)
        ds = np.diff(self.s)
        return (0.5 * (per_length[..., 1:] + per_length[..., :-1]) * ds).sum(-1)

    def _contact_state(self):
        return along_the_arm(self.contact, self.contact_radii, self.positions, inner=1)


@dataclass(frozen=True, eq=False)
class Trajectory(Trajectories):
    """An arm's motion: T times from the initial state on (T = steps + 1), S stations.

    Attributes (the batch axes B... of the loads first)
    ----------
    times : ndarray, shape (T,)
        t in s.
    s : ndarray, shape (S,)
        Stations in m.
    positions : ndarray, shape (B..., T, S, 3)
    rotations : ndarray, shape (B..., T, S, 3, 3)
    velocities, angular_velocities : ndarray, shape (B..., T, S, 3)
        Spatial components (m/s, rad/s).
    strains, stresses : ndarray, shape (B..., T, S, 6)
        Material frame, as :class:`State`'s.
    energy : Energy
        Kinetic, elastic, gravity and dissipated energy, shape (B..., T) each.
    errors : ndarray, shape (B..., T)
        Each step's predictor-corrector distance relative to L (:attr:`State.error`).
    iterations : ndarray of int, shape (B..., T)
    tendon_lengths : ndarray, shape (B..., T, tendons), or None
        Each tendon's length (m), in the order of the actuators.
    final : State
        The last state (to continue from: ``simulate(..., initial=trajectory.final)``).
    failed : ndarray of bool, shape (B...)
        The cases whose step could not be solved (``Simulator.run(..., failures="keep")``):
        their values from the failed step on are NaN (``Simulator.failures`` says when).
    contact : Contact or None
        The contact law the steps used (:class:`softarm.Contact`, its distance and
        stiffness set; docs/contact.md), for :attr:`gaps`, :attr:`contact_forces` and
        :attr:`contact_wrench`.
    contact_radii : ndarray, shape (S,), or None
        The arm's surface radius at each station (m).
    """

    times: np.ndarray
    s: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    strains: np.ndarray
    stresses: np.ndarray
    energy: Energy
    errors: np.ndarray
    iterations: np.ndarray
    tendon_lengths: np.ndarray | None
    final: State
    failed: np.ndarray | None = None
    contact: object = None
    contact_radii: np.ndarray | None = None

    def show(self, path=None, *, arm=None, browser: bool = True, **options):
        """Write the motion's page (:func:`softarm.view.trajectory_figure`: the arm moving
        with a time slider, play at real time or other rates, the tip's path, the energy;
        ``arm`` draws it as a tube of its radius; ``options`` as there) to a self-contained
        HTML file, ``path`` or a new temporary file, open it in the web browser unless
        ``browser`` is False, and return its path. Needs plotly (``softarm[view]``)."""
        from ..view import show_page, write_trajectory_html

        return show_page(lambda where: write_trajectory_html(self, where, arm=arm, **options),
                         path, browser)
