"""Lie-group toolkit: SO(3) and SE(3) maps on batched float64 arrays.

Use as ``from softarm.lie import so3, se3``. Twists are ordered linear part first, h = (u; ω).
"""

from . import se3, so3

__all__ = ["se3", "so3"]
