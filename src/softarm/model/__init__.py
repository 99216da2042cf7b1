"""The arm model: materials, cross-sections, uniform and segmented arms (SI units)."""

from .arm import Arm, SegmentedArm
from .material import Material
from .sections import Circle, Rectangle, Rigidities, Section, StiffnessMatrix, Tube

__all__ = [
    "Arm",
    "Circle",
    "Material",
    "Rectangle",
    "Rigidities",
    "Section",
    "SegmentedArm",
    "StiffnessMatrix",
    "Tube",
]
