"""softarm: static equilibrium of soft robotic arms and slender elastic rods.

Cosserat rods on SE(3) (Grazioso, Di Gironimo & Siciliano, RoboSoft 2018): closed forms where
they exist (:mod:`softarm.analytic`) and a geometrically exact solver for any load.
"""

__version__ = "0.1.0"  # first, so that submodules may import it

from . import analytic, routing, sweep
from .case import Case, CaseError, load_case
from .contact import Capsule, Contact, Plane, Sphere
from .control import ForwardResult, ForwardSolver, InverseResult, InverseSolver, inverse
from .dispatch import solve
from .dynamics import Damping, Energy, Simulator, State, Trajectory, simulate
from .equilibrium import Equilibrium, Stability
from .errors import (
    ApproximationWarning,
    ConvergenceError,
    InadmissibleStateError,
    StabilityWarning,
)
from .loads import (
    Chamber,
    DistributedForce,
    DistributedMoment,
    Gravity,
    Load,
    MagneticField,
    PointLoad,
    Tendon,
    TipLoad,
)
from .model import Arm, Circle, Material, Rectangle, Rigidities, Section, SegmentedArm, Tube
from .stability import Branch, CriticalPoint, continuation, critical_load
from .sweep import open_sweep

#: Submodules loaded on first use as an attribute, so that ``softarm.view.write_trajectory_html``
#: and ``softarm.io.read_trajectory`` work after a plain ``import softarm`` while
#: ``import softarm`` itself stays light (no plotly, matplotlib or numba: tests/test_package.py).
_ON_FIRST_USE = ("geometry", "io", "plot", "view", "warmup")


def __getattr__(name: str):
    if name in _ON_FIRST_USE:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_ON_FIRST_USE})

__all__ = [
    "ApproximationWarning",
    "Arm",
    "Branch",
    "Capsule",
    "Case",
    "CaseError",
    "Chamber",
    "Circle",
    "Contact",
    "ConvergenceError",
    "CriticalPoint",
    "Damping",
    "DistributedForce",
    "DistributedMoment",
    "Energy",
    "Equilibrium",
    "ForwardResult",
    "ForwardSolver",
    "Gravity",
    "InadmissibleStateError",
    "InverseResult",
    "InverseSolver",
    "Load",
    "MagneticField",
    "Material",
    "Plane",
    "PointLoad",
    "Rectangle",
    "Rigidities",
    "Section",
    "SegmentedArm",
    "Simulator",
    "Sphere",
    "Stability",
    "StabilityWarning",
    "State",
    "Tendon",
    "TipLoad",
    "Trajectory",
    "Tube",
    "__version__",
    "analytic",
    "continuation",
    "critical_load",
    "inverse",
    "load_case",
    "open_sweep",
    "routing",
    "simulate",
    "solve",
    "sweep",
]
