"""The model's limits, checked once for every route (docs/solver.md, "The model's limits").

An equilibrium of the Cosserat rod is only a state of an arm while each cross-section keeps
the centreline on its positive side: the axial stretch v₁ = e1 · v (material frame, v the
linear strain, 1 in the unloaded arm) must stay > 0. At v₁ = 0 the centreline's tangent
p' = R v lies in the section's plane, and beyond it the arm is inside out. The equations
themselves stay smooth there (a shooting solver or a closed form passes through v₁ = 0
without noticing), so every route asks: the closed forms in ``analytic._common.build``, the
numerical solver where its kernel returns (``statics.solver``), continuation where it
records its points.

:func:`check_finite` is the last line of a closed form: a formula that overflows for an
accepted input must not hand NaN or inf to the user as an answer.
"""

from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from .errors import ConvergenceError, InadmissibleStateError

__all__ = ["all_finite", "batch_part", "check_finite", "check_stretch", "distinct",
           "inside_out", "load_case", "stretched", "tendon_limit"]


#: While a part of a larger batch is solved (statics.solver solves a batch in parts), the
#: whole batch's shape and the part's first case: messages name a case of the whole batch
_PART: contextvars.ContextVar = contextvars.ContextVar("softarm_batch_part", default=None)


@contextlib.contextmanager
def batch_part(shape: tuple, first: int, size: int):
    """Within the block, :func:`load_case` of the part (a batch of shape (size,)) names its
    cases in the whole batch of shape ``shape``, of which the part starts at case ``first``
    (another batch solved meanwhile, e.g. a diagnosis's, keeps its own numbers)."""
    token = _PART.set((tuple(shape), int(first), int(size)))
    try:
        yield
    finally:
        _PART.reset(token)


def load_case(flat: int, shape: tuple) -> str:
    """" for load case (i, j)" of the case at C-order position ``flat`` of a batch of shape
    ``shape`` (of the whole batch, within :func:`batch_part`); "" for a single case."""
    if not shape:
        return ""
    part = _PART.get()
    if part is not None and tuple(shape) == (part[2],):
        shape, flat = part[0], part[1] + int(flat)
    return f" for load case {tuple(int(i) for i in np.unravel_index(int(flat), shape))}"


def _residual_of(residual, flat: int) -> float:
    residual = np.asarray(residual, dtype=np.float64)
    return float(residual.reshape(-1)[flat if residual.size > 1 else 0])


def all_finite(array) -> bool:
    """Whether every value of ``array`` is finite: one pass over its distinct values, no
    temporary (a NaN or an inf anywhere makes the sum NaN or inf; a sum that overflows is
    checked element by element)."""
    with np.errstate(over="ignore", invalid="ignore"):
        if math.isfinite(float(np.sum(distinct(array)))):
            return True
    return bool(np.isfinite(array).all())


def distinct(array: np.ndarray) -> np.ndarray:
    """A view of ``array`` without its repeats: along an axis of stride 0 (a field constant
    along the arm, a ``np.broadcast_to`` view, as the closed forms give) only index 0. The
    same values, and a pass over them costs what the data costs, not the broadcast shape."""
    return array[tuple(slice(0, 1) if stride == 0 else slice(None)
                       for stride in array.strides)]


def stretched(strains: np.ndarray) -> bool:
    """Whether the axial stretch v₁ = 1 + ε₁ of ``strains`` (…, 6) is > 0 everywhere: one
    reduction over its distinct values (a control loop's call checks its answer with it: a
    few microseconds)."""
    axial = (distinct(strains) if 0 in strains.strides else strains)[..., 0]
    return bool(axial.size == 0 or np.minimum.reduce(axial, axis=None) > -1.0)


def inside_out(strains) -> np.ndarray:
    """(B..., N) True where the axial stretch v₁ = 1 + ε₁ of ``strains`` (B..., N, 6), ε - f⁰
    (material; f⁰'s stretch is 1), is not > 0 (NaN included)."""
    return ~(np.asarray(strains)[..., 0] > -1.0)


def check_stretch(strains, s, residual=0.0, stresses=None, what: str = "the equilibrium",
                  load_factor: float | None = None) -> None:
    """:class:`~softarm.InadmissibleStateError` unless the axial stretch v₁ = 1 + ε₁ is > 0
    at every station: ``strains`` (B..., N, 6) are ε - f⁰ (material; f⁰'s stretch is 1),
    ``s`` (N,) the stations (m), ``residual`` a number or (B...), ``stresses`` (B..., N, 6)
    (optional: the message then gives the axial force n₁). The message names the first
    load case (C order) and station where v₁ <= 0; ``load_factor`` goes to the error."""
    strains = np.asarray(strains)
    if stretched(strains):  # (the common case)
        return
    axial = strains[..., 0]
    bad = inside_out(strains)
    flat = int(np.argmax(bad.reshape(-1)))
    batch = axial.shape[:-1]
    case, station = divmod(flat, axial.shape[-1])
    stretch = 1.0 + float(axial.reshape(-1)[flat])
    force = ""
    if stresses is not None:
        n1 = float(np.broadcast_to(stresses, strains.shape)[..., 0].reshape(-1)[flat])
        force = f", axial force n₁ = {n1:.4g} N"
    at = float(np.asarray(s).reshape(-1)[station])
    raise InadmissibleStateError(
        f"{what}{load_case(case, batch)} is outside the rod model: the axial stretch "
        f"v₁ = {stretch:.4g} <= 0 at s = {at:.6g} m{force}. The centreline's tangent "
        "p' = R v turns through the cross-section's plane there (the arm would be inside "
        "out): a compression (or, with a coupled stiffness, a shear) beyond what the arm "
        "can carry; no equilibrium of this model exists", _residual_of(residual, case),
        station=at, load_factor=load_factor)


def check_finite(what: str, array, trailing: int) -> None:
    """ConvergenceError if ``array`` (batch axes, then ``trailing`` object axes: 3 for poses
    (B..., N, 4, 4), 2 for strains (B..., N, 6)) holds NaN or inf: ``what`` (a closed form's
    method) computed no answer for the first such load case."""
    array = np.asarray(array)
    if all_finite(array):
        return
    batch = array.shape[:array.ndim - trailing]
    bad = ~np.isfinite(array.reshape(math.prod(batch), -1)).all(axis=-1)
    raise ConvergenceError(
        f"{what} computed non-finite values{load_case(int(np.argmax(bad)), batch)}: the "
        "inputs are beyond the range where its formulas hold in double precision", math.nan)


def tendon_limit(number: int, description: str, tension: float, case: str,
                 load_factor: float, where: str, residual: float, vanishes: bool,
                 station: float | None = None) -> InadmissibleStateError:
    """The error of a tendon whose path leaves the model as the loads grow: tendon
    ``number`` (0-based, among the tendons in the order given, ``description`` its own
    words, ``tension`` its tension in N in load case ``case`` (text, "" for one case)) at
    ``load_factor`` λ (the loads scaled by λ), at ``where`` (text: "s = ... m");
    ``vanishes``: its path's length |w| -> 0, else its tangent turns backwards through the
    sections (w₁ -> 0)."""
    how = ("its path's length vanishes (|w| -> 0, w = v + u × r + r' the path's tangent)"
           if vanishes else
           "its path turns backwards through the sections (w₁ -> 0, w = v + u × r + r' "
           "the path's tangent: the arm inside out at the tendon)")
    return InadmissibleStateError(
        f"tendon {number} ({description}){case}: {how} at load factor "
        f"λ ≈ {load_factor:.6g}, at {where}. On this arm, with the other loads scaled alike, "
        f"it can carry about {load_factor * tension:.6g} N, not {tension:.6g} N: beyond, the "
        "tendon has no path to pull along and the model has no equilibrium",
        residual, load_factor=float(load_factor), station=station)
