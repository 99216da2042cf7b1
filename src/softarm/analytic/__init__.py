"""Closed-form equilibria (Grazioso, Di Gironimo & Siciliano, RoboSoft 2018), corrected.

Each function returns a :class:`~softarm.Equilibrium` whose ``exact`` flag says whether it
solves the full Cosserat model for its loads. See docs/closed-forms.md for the formulas, the
corrections to the paper and the domains of exactness.
"""

from .actuation import actuated
from .elastica import elastica
from .exact import exact_closed_form
from .force import axial_force, shear_force
from .linear import linear
from .moment import tip_moment

__all__ = [
    "actuated",
    "axial_force",
    "elastica",
    "exact_closed_form",
    "linear",
    "shear_force",
    "tip_moment",
]
