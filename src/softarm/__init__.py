"""softarm: static equilibrium of soft robotic arms and slender elastic rods.

Cosserat rods on SE(3) (Grazioso, Di Gironimo & Siciliano, RoboSoft 2018): closed forms where
they exist (:mod:`softarm.analytic`) and a geometrically exact solver for any load.
"""

__version__ = "0.1.0"  # first, so that submodules may import it

from . import analytic, sweep
from .case import Case, CaseError, load_case
from .dispatch import solve
from .equilibrium import Equilibrium
from .errors import ApproximationWarning, ConvergenceError
from .loads import DistributedForce, DistributedMoment, Gravity, Load, PointLoad, TipLoad
from .model import Arm, Circle, Material, Rectangle, Rigidities, Section, SegmentedArm, Tube
from .sweep import open_sweep

__all__ = [
    "ApproximationWarning",
    "Arm",
    "Case",
    "CaseError",
    "Circle",
    "ConvergenceError",
    "DistributedForce",
    "DistributedMoment",
    "Equilibrium",
    "Gravity",
    "Load",
    "Material",
    "PointLoad",
    "Rectangle",
    "Rigidities",
    "Section",
    "SegmentedArm",
    "TipLoad",
    "Tube",
    "__version__",
    "analytic",
    "load_case",
    "open_sweep",
    "solve",
    "sweep",
]
