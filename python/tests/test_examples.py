"""`examples/python/`: each example's first steps, at a small size."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def example(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / "python" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_calibration_finds_a_sand_like_friction_angle(tmp_path):
    """The biaxial example's assembly cut to about 100 discs, 10 steps of 2e-3 (2 % axial
    strain: past the peak of a dense disc packing). A dense assembly of discs with contact
    friction 0.5 and rolling resistance mobilises 25-50 degrees (the biaxial tests of disc
    assemblies in the literature); a broken stress control or a sign error gives far less."""
    plot = tmp_path / "phi.png"
    peak = example("calibrate").main(["--side", "0.05", "--steps", "10", "--increment", "2e-3", "--plot", str(plot)])
    assert 25.0 < peak < 50.0
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert plot.stat().st_size > 0


def test_reading_a_run_into_pandas(tmp_path):
    """The quick example's first two steps, read into DataFrames."""
    curve = example("read_run").main(["--run", str(EXAMPLES / "quick.toml"), "--out", str(tmp_path / "q"), "--max-steps", "2"])
    assert list(curve["step"]) == [1.0, 2.0]
    assert (curve["load"] > 0).all()


def test_a_footing_loop(tmp_path):
    """The footing example's loading as a Python loop, its first two pushes at about 70 discs
    per assembly: the rigid footing settles by the pushes exactly (its nodes are prescribed),
    and the force on it grows as it is pushed (a footing before its bearing capacity)."""
    history = example("footing_loop").main(["--side", "0.05", "--steps", "2", "--out", str(tmp_path / "f")])
    assert [round(s, 12) for s, _ in history] == [2e-3, 4e-3]
    assert 0 < history[0][1] < history[1][1]
    import cosdem

    assert cosdem.open_run(tmp_path / "f").status == "finished"
