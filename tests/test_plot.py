"""Pictures: valid PNGs of the expected size, equal axes, the tube drawn where it helps."""

from __future__ import annotations

import struct
import subprocess
import sys

import numpy as np
import pytest

import softarm
from softarm.lie import se3

pytest.importorskip("matplotlib")

from softarm import plot


def png_size(path) -> tuple[int, int]:
    """(width, height) from the PNG signature and IHDR chunk (PNG spec, section 11.2.2)."""
    data = path.read_bytes()[:24]
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG file"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


EXPECTED = (round(plot.FIGSIZE[0] * plot.DPI), round(plot.FIGSIZE[1] * plot.DPI))


def helix(radius_known: bool = True, batch=None):
    soft = softarm.Material(1.0e6, poisson_ratio=0.5, density=1100.0)
    if radius_known:
        arm = softarm.SegmentedArm([softarm.Arm(0.25, softarm.Circle(0.015), soft),
                                    softarm.Arm(0.15, softarm.Tube(0.01, 0.005), soft)])
    else:
        arm = softarm.Arm.from_stiffness(0.4, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    s = np.linspace(0.0, 0.4, 41)
    scale = np.ones(()) if batch is None else np.linspace(0.0, 1.0, batch)
    twist = np.array([1.0, 0, 0, 0.5, 3.0, 1.0]) * np.stack(
        [np.ones_like(scale)] + [np.zeros_like(scale)] * 2 + [scale] * 3, axis=-1)
    poses = se3.exp(s[:, None] * twist[..., None, :])
    zeros = np.zeros((*scale.shape, 41, 6))
    force = np.stack([0 * scale, 0 * scale, -scale], axis=-1)
    return softarm.Equilibrium(s, poses, zeros, zeros, arm, (softarm.TipLoad(force=force),),
                               "test", True)


def test_import_softarm_does_not_import_matplotlib():
    code = "import sys, softarm, softarm.io, softarm.cli; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_equilibrium_png(tmp_path):
    path = tmp_path / "one.png"
    fig = plot.plot_equilibrium(helix(), path=path, name="helix")
    assert png_size(path) == EXPECTED
    ax3, xz, xy = fig.axes
    spans = [np.diff(getattr(ax3, f"get_{a}lim")())[0] for a in "xyz"]
    np.testing.assert_allclose(spans, spans[0])  # equal scaling in 3D
    assert xz.get_aspect() == 1.0 and xy.get_aspect() == 1.0
    assert (xz.get_xlabel(), xz.get_ylabel()) == ("x (m)", "z (m)")
    assert (xy.get_xlabel(), xy.get_ylabel()) == ("x (m)", "y (m)")
    assert ax3.get_zlabel() == "z (m)"
    assert "helix" in fig._suptitle.get_text() and "tip force" in fig._suptitle.get_text()
    # the tube: a surface in 3D and a filled outline in each side view
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    assert any(isinstance(c, Poly3DCollection) for c in ax3.collections)
    assert xz.patches and xy.patches


def test_line_only_without_sections(tmp_path):
    fig = plot.plot_equilibrium(helix(radius_known=False), path=tmp_path / "line.png")
    ax3, xz, _ = fig.axes
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    assert not any(isinstance(c, Poly3DCollection) for c in ax3.collections)
    assert not xz.patches


def test_sweep_png(tmp_path):
    path = tmp_path / "sweep.png"
    fig = plot.plot_sweep(helix(batch=5), [0.0, 1.0, 2.0, 3.0, 4.0], label="k (N)", path=path)
    assert png_size(path) == EXPECTED
    bar = fig.axes[-1]
    assert bar.get_ylabel() == "k (N)"
    assert len(fig.axes[1].lines) >= 5


def test_batch_needs_plot_sweep():
    with pytest.raises(ValueError, match="plot_sweep"):
        plot.plot_equilibrium(helix(batch=3))


def test_draw_into_own_figure():
    from matplotlib.figure import Figure

    fig = Figure()
    assert plot.plot_equilibrium(helix(), fig=fig) is fig
    assert len(fig.axes) == 3


def test_describe_loads():
    text = plot.describe_loads([softarm.Gravity(), softarm.TipLoad(force=[0, 0, -1.0],
                                                                   follower=True)])
    assert text == "gravity + follower tip force (0, 0, -1) N"
    assert plot.describe_loads([]) == "no load"
