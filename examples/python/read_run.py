"""Reading a run into pandas: the load-displacement curve, the Gauss-point fields of the last
saved step, and the particles of a watched Gauss point.

    python examples/python/read_run.py runs/quick          # a finished (or running) run
    python examples/python/read_run.py --run examples/quick.toml --out runs/quick-py

With `--run JOB`, the job is run first (in-process workers, as `cosdem run JOB`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import cosdem


def gauss_frame(run: cosdem.Run, step=None) -> pd.DataFrame:
    """One row per Gauss point: position, element, point, and each field's components
    (`stress_0` .. `stress_3` for `[s_xx, s_yy, s_xy, s_yx]`)."""
    g = run.gauss(step)
    columns = {"x": g["position"][:, 0], "y": g["position"][:, 1]}
    for name, values in g.items():
        if name == "position":
            continue
        if values.ndim == 1:
            columns[name] = values
        else:
            for c in range(values.shape[1]):
                columns[f"{name}_{c}"] = values[:, c]
    return pd.DataFrame(columns)


def main(argv=None) -> pd.DataFrame:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dir", nargs="?", type=Path, help="a run directory")
    p.add_argument("--run", type=Path, help="run this job first")
    p.add_argument("--out", type=Path, help="run directory of --run (default: the job's)")
    p.add_argument("--max-steps", type=int, help="with --run: stop after this many steps")
    args = p.parse_args(argv)
    if args.run is not None:
        run = cosdem.Job.from_toml(args.run).run(args.out, max_steps=args.max_steps, overwrite=True)
    elif args.dir is not None:
        run = cosdem.open_run(args.dir)
    else:
        p.error("give a run directory or --run JOB")

    curve = run.curve_frame()
    print(f"{run.dir}: {run.status}, {len(curve)} steps")
    print(curve[["step", "displacement", "load", "iterations"]].tail().to_string(index=False))
    peak = curve["load"].abs().idxmax()
    print(f"peak load {curve['load'][peak]:.4e} N at {curve['displacement'][peak]:.4e} m")

    gauss = gauss_frame(run)
    mean = -0.5 * (gauss["stress_0"] + gauss["stress_1"])
    print(f"{len(gauss)} Gauss points at step {run.saved_steps[-1]}: mean stress "
          f"{mean.min():.4e} .. {mean.max():.4e} Pa (compression positive)")

    for element, point in run.snapshot_points()[:1]:
        s = run.snapshot(element, point)
        forces = pd.Series(s["normal_force"])
        print(f"element {element} point {point}: {len(s['radius'])} discs, {len(forces)} contacts, "
              f"mean normal force {forces.mean():.4e} N, max {forces.max():.4e} N")
        assert np.all(s["contacts"] < len(s["radius"]))
    return curve


if __name__ == "__main__":
    main()
