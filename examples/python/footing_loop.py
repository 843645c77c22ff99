"""A strip footing pushed into the ground step by step from Python, as FEMxDEM scripts load
theirs: the footing example's mesh and DEM material (`examples/footing.toml`), its loading
written as a loop instead of `[[stage]]` tables.

The base is held, the far side on rollers, the centre line a symmetry axis; a 20 kPa
surcharge is put on the ground and the footing; then the rigid rough footing is pushed down
`--increment` per step. After each step the script reads the settlement and the force on the
footing (twice the half model's reaction: the whole footing, per metre), and stops when the
force has fallen `--drop` below its peak (the bearing capacity is passed) or after `--steps`.

    python examples/python/footing_loop.py --out runs/footing-py
    python examples/python/footing_loop.py --side 0.05 --steps 2      # a quick look
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cosdem

HERE = Path(__file__).resolve().parent


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--job", type=Path, default=HERE.parent / "footing.toml")
    p.add_argument("--side", type=float, help="side of the assemblies (m); default: the job's")
    p.add_argument("--steps", type=int, default=15, help="footing steps at most")
    p.add_argument("--increment", type=float, default=2e-3, help="footing push per step (m)")
    p.add_argument("--drop", type=float, default=0.2, help="stop when the force is this far below its peak")
    p.add_argument("--out", type=Path, help="run directory written as the loop goes")
    args = p.parse_args(argv)

    tables = cosdem.Job.from_toml(args.job).to_dict()
    tables.pop("stage", None)  # the loading is this script's
    tables["mesh"]["file"] = str(args.job.parent / tables["mesh"]["file"])
    if args.side is not None:
        tables["material"]["assembly"]["packing"]["side"] = args.side
    job = cosdem.Job(tables)

    history = []
    with cosdem.Solver(job, out=args.out, overwrite=True) as s:
        s.prescribe("base", "ux", 0.0)
        s.prescribe("base", "uy", 0.0)
        s.prescribe("side", "ux", 0.0)
        s.prescribe("axis", "ux", 0.0)
        s.prescribe("axis", "w", 0.0)
        s.pressure("surface", 2e4)
        s.pressure("footing", 2e4)
        s.step(name="surcharge")
        start = s.displacement("footing", "uy").mean()
        print(f"surcharge: footing settles {-start:.3e} m")

        s.prescribe("footing", "ux", increment=0.0)  # rough: no sideways slip
        for k in range(1, args.steps + 1):
            s.prescribe("footing", "uy", increment=-args.increment)  # rigid: all nodes together
            s.step(name=f"push {k}")
            settlement = start - s.displacement("footing", "uy").mean()
            force = -2.0 * s.reactions("footing")[1]
            history.append((settlement, force))
            print(f"step {k}: settlement {settlement:.4e} m, force {force:.4e} N/m")
            peak = max(f for _, f in history)
            if force < (1.0 - args.drop) * peak:
                print(f"force {args.drop:.0%} below its peak: bearing capacity passed")
                break
    settlement, peak = max(history, key=lambda h: h[1])
    print(f"peak force {peak:.4e} N/m at {settlement:.4e} m settlement")
    return history


if __name__ == "__main__":
    main()
