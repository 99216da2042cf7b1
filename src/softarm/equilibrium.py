"""Equilibrium: the one result type of every route (closed forms and the numerical solver)."""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from .contact import along_the_arm, balance, resultant

__all__ = ["Equilibrium", "Stability"]


def _read_only_throughout(array: np.ndarray) -> bool:
    """Neither ``array`` nor any array or buffer it views can be written through."""
    base = array
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return False
        base = base.base
    if base is None:
        return True
    try:
        return memoryview(base).readonly
    except TypeError:  # an object that exposes no buffer: it cannot be checked
        return False


def _frozen(array) -> np.ndarray:
    """``array`` itself if it is a read-only float64 ndarray throughout, else a frozen copy."""
    if type(array) is np.ndarray and array.dtype == np.float64 and _read_only_throughout(array):
        return array
    array = np.array(array, dtype=np.float64)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Stability:
    """The stability verdict of an equilibrium (docs/stability.md), per load case.

    Attributes
    ----------
    index : int or ndarray of int, shape (B...)
        The Morse index: the number of independent directions in which the equilibrium is
        unstable (conjugate points of the backward sweep on [0, L), counted with their
        multiplicity). 0: no unstable direction. -1: a conjugate point at the clamp itself
        (a critical equilibrium, neither stable nor unstable to first order).
    conservative : bool or ndarray of bool, shape (B...)
        False for follower loads and dead couples (nonconservative in 3D, Ziegler) and for
        a tip held with friction (docs/contact.md, "Friction"): the static test then
        cannot prove stability (an odd index still proves divergence).
    stable : bool or ndarray of bool, shape (B...)
        ``index == 0 and conservative``.
    """

    index: int | np.ndarray
    conservative: bool | np.ndarray
    stable: bool | np.ndarray

    @classmethod
    def of(cls, index, conservative, shape=None) -> Stability:
        """The verdict of batch shape ``shape`` (default: index's own) from the indices and
        the conservative flags (plain Python scalars for shape ())."""
        if shape == () and np.size(index) == 1 and np.size(conservative) == 1:
            # one case (the common call of a closed form): scalars, no array work
            i, c = int(np.ravel(index)[0]), bool(np.ravel(conservative)[0])
            return cls(i, c, i == 0 and c)
        index = np.asarray(index, dtype=np.int64)
        shape = index.shape if shape is None else tuple(shape)
        index = index.reshape(shape)
        conservative = np.asarray(conservative, dtype=bool)
        conservative = (conservative.reshape(shape) if conservative.size == index.size
                        else np.broadcast_to(conservative, shape)).copy()
        stable = (index == 0) & conservative
        if shape == ():
            return cls(int(index), bool(conservative), bool(stable))
        index = index.copy()
        for array in (index, conservative, stable):
            array.setflags(write=False)
        return cls(index, conservative, stable)

    def describe(self) -> str:
        """The verdict of one (unbatched) case in words, e.g. "stable (Morse index 0)"."""
        index = int(self.index)
        if index < 0:
            return "critical (a conjugate point at the clamp: neither stable nor unstable)"
        if not self.conservative:
            odd = ", odd: unstable by divergence" if index % 2 else ""
            return (f"not decided: follower loads, dead couples and friction are not "
                    f"conservative (Morse index {index}{odd})")
        if index == 0:
            return "stable (Morse index 0)"
        return (f"UNSTABLE (Morse index {index}: a real arm would move away; solve with "
                "branch = \"stable\")")

    @property
    def unstable(self):
        """Proven unstable: index > 0 (for a nonconservative load only an odd index is a
        proof, a divergence; an even one is reported but proves nothing)."""
        if isinstance(self.index, int):  # one case: Python scalars
            return self.index > 0 and (self.conservative or self.index % 2 == 1)
        index = np.asarray(self.index)
        out = (index > 0) & (np.asarray(self.conservative) | (index % 2 == 1))
        return out if out.shape else bool(out)


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """A static equilibrium of an arm under its loads, sampled at stations s.

    Arrays are read-only. With a batch of loads of batch shape B, every array gains the
    leading axes B; the station axis is the last batch axis.

    Ownership: an array given as a read-only float64 ``numpy.ndarray`` that views no writable
    memory (it and every array or buffer it is a view of are read-only) is taken as it is, with
    no copy; any other input (a writable array, a read-only view of a writable one, another
    dtype, a list, an ndarray subclass) is copied once and the copy frozen, so later writes to
    the caller's array never reach the result. Producers (the closed forms, the solver) create
    fresh arrays, make them read-only and hand them over without a copy; a field that is
    constant along the arm may be a read-only ``np.broadcast_to`` view of a frozen (B..., 1, 6)
    or (B..., 6) array, which costs no memory. Treat the arrays as read-only views: they may
    share memory with each other (never with a writable caller's array) and may have zero
    strides.

    Attributes
    ----------
    s : ndarray, shape (N,)
        Arc-length stations in m, increasing in [0, L].
    poses : ndarray, shape (B..., N, 4, 4)
        H(s) = [[R, p], [0, 1]]: the material frame R (columns e1, e2, e3 in the spatial frame)
        and the centreline position p (m).
    strains : ndarray, shape (B..., N, 6)
        ε = f - f⁰ = (γ; κ) in the material frame (dimensionless; 1/m).
    stresses : ndarray, shape (B..., N, 6)
        σ = K ε = (n; m), internal force (N) and moment (N m) in the material frame, exerted
        on the part [0, s] by the part [s, L].
    arm : Arm or SegmentedArm
    loads : tuple
        The loads as given.
    method : str
        The solution used, e.g. ``"analytic.tip_moment"``, ``"numeric.shooting"`` or
        ``"numeric.tip_contact"`` (a free tip held exactly on an obstacle, docs/contact.md).
    exact : bool
        True only if the result solves the full Cosserat model (eq. 20) for these loads (to
        the solver's tolerance for numerical results).
    residual : float or ndarray, shape (B...)
        Boundary-condition residual, N and N m (0 for closed forms).
    error_estimate : float or ndarray, shape (B...)
        Estimated position error at the tip in m (0 for exact closed forms, NaN where the
        closed form is an approximation of unknown error).
    tip_compliance : ndarray, shape (B..., 6, 6), or None
        With ``solve(..., jacobians=True)``: the tip's (δp; δθ) per unit extra *dead* tip
        wrench (δF; δM), all spatial components, δR(L) = δθ~ R(L) (m/N, m/(N m), 1/N,
        1/(N m)). None otherwise.
    compliance : ndarray, shape (B..., N, 6, 6), or None
        The same map to every station's (δp(s); δθ(s)), spatial components.
    base_wrench : ndarray, shape (B..., 6), or None
        The total wrench (N; N m) the base carries, spatial components: the load the rod
        puts on the clamp (the clamp's reaction on the rod is its negative: an arm hanging
        under its weight W gives (0, 0, -W) with gravity along -z) plus what the actuators
        pull or push on the base (tendons' motors, the chambers' fluid). The rod's own share
        is ``forces_spatial[..., 0, :]`` and ``moments_spatial[..., 0, :]``. Numerical route
        only (None from closed forms).
    actuation_jacobian : ndarray, shape (B..., 6, n), or None
        With ``solve(..., jacobians=True)`` and actuators: the tip's (δp; δθ) (spatial,
        δR(L) = δθ~ R(L)) per unit change of each actuation input, in the order of the loads:
        each tendon's tension (per N), each chamber's pressure (per Pa), each component of
        each magnetic field's B0 (per T). Exact (implicit function theorem on the shooting
        problem, one tangent column per input), not finite differences.
    station_actuation_jacobian : ndarray, shape (B..., N, 6, n), or None
        The same for every station's (δp(s); δθ(s)).
    tendon_tensions, tendon_lengths, tendon_length_changes : ndarray, shape (B..., T), or None
        Per :class:`~softarm.Tendon`, in the order given: its tension (N), its length from
        the base to its anchor (m), and that length less the unloaded arm's (m; negative
        when pulled in: what a motor encoder measures). None without tendons.
    tendon_length_jacobian : ndarray, shape (B..., T, n), or None
        With ``solve(..., jacobians=True)`` and tendons: each tendon's length (m) per unit
        change of each actuation input (columns as in ``actuation_jacobian``). Exact (the
        implicit function theorem, like ``actuation_jacobian``). For tension inputs of a
        conservative system it is symmetric and negative semi-definite (the Hessian of the
        potential's complementary energy): more tension, a shorter tendon.
    tendon_slack : ndarray of bool, shape (B..., T), or None
        Per tendon: True where it carries no tension (τ = 0): a displacement-controlled
        tendon given more length than its path needs, or a tension-controlled one at 0 N.
        None without tendons.
    """

    s: np.ndarray
    poses: np.ndarray
    strains: np.ndarray
    stresses: np.ndarray
    arm: object
    loads: tuple
    method: str
    exact: bool
    residual: float | np.ndarray = 0.0
    error_estimate: float | np.ndarray = 0.0
    tip_compliance: np.ndarray | None = None
    compliance: np.ndarray | None = None
    base_wrench: np.ndarray | None = None
    actuation_jacobian: np.ndarray | None = None
    station_actuation_jacobian: np.ndarray | None = None
    tendon_tensions: np.ndarray | None = None
    tendon_lengths: np.ndarray | None = None
    tendon_length_changes: np.ndarray | None = None
    tendon_length_jacobian: np.ndarray | None = None
    tendon_slack: np.ndarray | None = None
    stability: Stability | None = None
    #: the solver's total contact wrench (B..., 6), integrated on its own fine stations
    #: (:attr:`contact_wrench`), or None
    contact_resultant: np.ndarray | None = None

    def __post_init__(self):
        for name in ("s", "poses", "strains", "stresses"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        n = self.s.shape[-1]
        if self.poses.shape[-3:] != (n, 4, 4) or self.strains.shape[-2:] != (n, 6) or \
                self.stresses.shape[-2:] != (n, 6):
            raise ValueError(
                f"Equilibrium arrays disagree: s {self.s.shape}, poses {self.poses.shape}, "
                f"strains {self.strains.shape}, stresses {self.stresses.shape}"
            )
        object.__setattr__(self, "loads", tuple(self.loads))

    def _with_stability(self, stability: Stability | None) -> Equilibrium:
        """This equilibrium with its stability verdict: a copy sharing the (frozen) arrays,
        not checked again (``dataclasses.replace`` re-runs every check: a tenth of a
        closed-form solve)."""
        new = copy.copy(self)
        object.__setattr__(new, "stability", stability)
        return new

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Leading batch axes B (empty for a single load case)."""
        return self.poses.shape[:-3]

    @property
    def positions(self) -> np.ndarray:
        """Centreline positions p(s) in m, spatial frame, shape (B..., N, 3)."""
        return self.poses[..., :3, 3]

    @property
    def rotations(self) -> np.ndarray:
        """Material frames R(s), shape (B..., N, 3, 3)."""
        return self.poses[..., :3, :3]

    @property
    def tip(self) -> np.ndarray:
        """Pose at the last station, shape (B..., 4, 4)."""
        return self.poses[..., -1, :, :]

    @property
    def tip_position(self) -> np.ndarray:
        """Position of the last station in m, shape (B..., 3)."""
        return self.poses[..., -1, :3, 3]

    @property
    def forces_spatial(self) -> np.ndarray:
        """Internal force R n in the spatial frame (N), shape (B..., N, 3)."""
        return np.einsum("...ij,...j->...i", self.rotations, self.stresses[..., :3])

    @property
    def moments_spatial(self) -> np.ndarray:
        """Internal moment R m in the spatial frame about the centreline point (N m)."""
        return np.einsum("...ij,...j->...i", self.rotations, self.stresses[..., 3:])

    def _contact(self):
        """The Contact among the loads (with the stiffness the solver used), or None."""
        return next((load for load in self.loads if getattr(load, "kind", "") == "contact"),
                    None)

    @property
    def gaps(self) -> np.ndarray:
        """(B..., N): the distance from the arm's surface to the nearest obstacle at each
        station, m (inf without a :class:`~softarm.Contact`)."""
        return self._contact_state()[0]

    @property
    def contact_forces(self) -> np.ndarray:
        """(B..., N, 3): the obstacles' force per unit length on the arm at each station,
        N/m, spatial (zero without a :class:`~softarm.Contact`, and wherever the gap is at
        least the contact distance)."""
        return self._contact_state()[1]

    @property
    def contact_wrench(self) -> np.ndarray:
        """(B..., 6): the total contact force (N) and its moment about the spatial origin
        (N m) on the arm, from the global balance (:func:`softarm.contact.balance`: the base
        wrench less the other loads), exact however narrow a contact zone. ``softarm.solve``
        computes it on stations of its own (at least 2001); an Equilibrium without it (a
        ForwardSolver's, a file's of an older version) takes the balance on its own stations
        where they run from base to tip through every cut of the loads, else integrates
        :attr:`contact_forces` over them, which is right only where they resolve every
        contact zone (docs/contact.md). ValueError where its stations do not span the arm
        (a ForwardSolver's default, the tip alone): no total can be formed."""
        if self.contact_resultant is not None:
            return self.contact_resultant
        if self._contact() is None:
            return np.zeros((*self.batch_shape, 6))
        s, length = self.s, float(self.arm.length)
        if s[0] != 0.0 or abs(s[-1] - length) > 1e-12 * length:
            raise ValueError(
                f"Equilibrium.contact_wrench: its stations must run from the base to the "
                f"tip (s from 0 to L = {length:.6g} m) to form the total, got "
                f"{s.size} from {s[0]:.6g} to {s[-1]:.6g} m; solve with s=... or "
                "ForwardSolver(..., s=None) for 101 stations")
        cuts = {float(c) for load in self.loads for c in load.cuts(self.arm)} | \
            {float(b) for b in self.arm.boundaries}
        if self.base_wrench is not None and all(
                np.min(np.abs(s - c)) <= 1e-12 * length for c in cuts):
            return balance(self.arm, self.loads, s, self.poses, self.base_wrench)
        return resultant(s, self.positions, self.contact_forces)

    def _contact_state(self) -> tuple[np.ndarray, np.ndarray]:
        contact = self._contact()
        radii = None if contact is None else contact.station_radii(self.arm, self.s)
        return along_the_arm(contact, radii, self.positions)

    def show(self, path=None, *, browser: bool = True, **options):
        """Write an interactive 3D view (:func:`softarm.view.figure`, ``options`` as there) to
        a self-contained HTML file, ``path`` or a new temporary file, open it in the web
        browser unless ``browser`` is False, and return its path. Needs plotly
        (``pip install "softarm[view]"``)."""
        from .view import show_page, write_html

        return show_page(lambda where: write_html(self, where, **options), path, browser)

    def _repr_html_(self) -> str | None:
        """Jupyter's rich display: the interactive 3D view (:func:`softarm.view.notebook_html`:
        the first display of a kernel session embeds plotly.js, about 4.8 MB, later ones use
        it from the page; see :data:`softarm.view.NOTEBOOK_PLOTLYJS`); None (the plain repr)
        without plotly or for a batch with more than one axis."""
        try:
            from .view import notebook_html
        except ImportError:  # pragma: no cover - plotly missing
            return None
        if len(self.batch_shape) > 1:
            return None
        try:
            return notebook_html(self)
        except ImportError:
            return None

    def __repr__(self) -> str:
        tip = np.array2string(self.tip_position, precision=6) if not self.batch_shape else \
            f"batch {self.batch_shape}"
        return (f"Equilibrium(method={self.method!r}, exact={self.exact}, stations={self.s.size}, "
                f"tip_position={tip})")
