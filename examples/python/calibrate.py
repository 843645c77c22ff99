"""Calibration: the friction angle of a job's DEM assembly from a drained biaxial path,
written as a Python loop over one assembly (what `cosdem rve --path biaxial` does).

The assembly is consolidated to the confining pressure (both normal stresses held by Newton
iterations on F_xx and F_yy with the 2x2 normal block of its tangent), then compressed
vertically in strain steps while F_xx is adjusted to hold s_xx at the confining pressure. The
mobilised friction angle is asin((s1 - s3) / (s1 + s3)) with compression positive; its peak
is the calibration's answer. With matplotlib installed, `--plot FILE` draws the stress ratio
and volumetric strain against the axial strain.

    python examples/python/calibrate.py                      # the biaxial example's assembly
    python examples/python/calibrate.py --side 0.05 --steps 10 --plot phi.png
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import cosdem

HERE = Path(__file__).resolve().parent


def hold(assembly: cosdem.Assembly, F: np.ndarray, components, pressure: float, tolerance: float):
    """Adjusts the normal entries `components` of F (0: F_xx, 1: F_yy) until the matching
    normal stresses are -pressure (Newton with the tangent's normal block). Returns the last
    response (a trial: the caller commits it)."""
    idx = list(components)
    for _ in range(50):
        r = assembly.solve(F)
        residual = np.array([r.voigt[i] + pressure for i in idx])
        if np.max(np.abs(residual)) <= tolerance * pressure:
            return r
        block = r.tangent[np.ix_(idx, idx)]
        step = np.linalg.solve(block, -residual)
        for i, d in zip(idx, step):
            F[i, i] += d
    raise RuntimeError(f"stress control did not converge (residual {residual} Pa)")


def friction_angle(voigt: np.ndarray) -> float:
    s = np.array([[voigt[0], 0.5 * (voigt[2] + voigt[3])], [0.5 * (voigt[2] + voigt[3]), voigt[1]]])
    s3, s1 = sorted(-np.linalg.eigvalsh(s))  # compression positive
    return math.degrees(math.asin((s1 - s3) / (s1 + s3)))


def main(argv=None) -> float:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--job", type=Path, default=HERE.parent / "biaxial.toml")
    p.add_argument("--side", type=float, help="side of the assembly (m); default: the job's")
    p.add_argument("--pressure", type=float, default=1e5, help="confining pressure (Pa)")
    p.add_argument("--steps", type=int, default=100)
    p.add_argument("--increment", type=float, default=1e-3, help="axial strain per step")
    p.add_argument("--tolerance", type=float, default=1e-3, help="stress control, relative")
    p.add_argument("--plot", type=Path, help="draw the path into this file (needs matplotlib)")
    args = p.parse_args(argv)

    spec = cosdem.Job.from_toml(args.job).to_dict()["material"]["assembly"]
    if args.side is not None:
        spec["packing"]["side"] = args.side
    assembly = cosdem.Assembly(spec)
    print(f"{assembly.disc_count} discs, cell {assembly.area:.4e} m^2, confined at {args.pressure:.3g} Pa")

    F = np.eye(2)
    hold(assembly, F, (0, 1), args.pressure, args.tolerance)
    assembly.commit()
    start = F.copy()
    axial, volumetric, angles = [], [], []
    for k in range(1, args.steps + 1):
        F[1, 1] = start[1, 1] - k * args.increment
        r = hold(assembly, F, (0,), args.pressure, args.tolerance)
        assembly.commit()
        axial.append(k * args.increment)
        volumetric.append(np.linalg.det(F) / np.linalg.det(start) - 1.0)
        angles.append(friction_angle(r.voigt))
    peak = int(np.argmax(angles))
    print(f"peak friction angle {angles[peak]:.2f} deg at axial strain {axial[peak]:.3e}; "
          f"final {angles[-1]:.2f} deg, volumetric strain {volumetric[-1]:.3e}")

    if args.plot is not None:
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib is not installed: no plot")
        else:
            fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(5, 6))
            top.plot(axial, angles)
            top.set_ylabel("mobilised friction angle (deg)")
            bottom.plot(axial, volumetric)
            bottom.set_ylabel("volumetric strain")
            bottom.set_xlabel("axial strain")
            fig.savefig(args.plot, dpi=120)
            print(f"plot: {args.plot}")
    return angles[peak]


if __name__ == "__main__":
    main()
