"""`scripts/`: the analysis scripts the problem pages quote, run on small runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cosdem

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def test_shear_band_reads_a_run_and_its_platens(fixture_job, tmp_path):
    """`scripts/shear-band` on the elastic panel (2 x 2 Q8 between rough platens, 1 cm of
    shortening in 4 steps, every step saved). The panel has no band; what is checked is that
    the script reads the run end to end and that its platens line, the figure the shear-band
    page quotes for the band's slip, gives the job's own kinematics: the 1 cm of shortening
    (both platens' prescribed u_y, printed to the micrometre) and no sideways offset (rough
    platens hold u_x = 0 exactly). A wrong node set (not the top and bottom edges) or a wrong
    component would give neither."""
    tables = cosdem.Job.from_toml(fixture_job("elastic-panel")).to_dict()
    tables["output"] = {"vtk_every": 1}
    out = tmp_path / "panel"
    cosdem.Job(tables).run(str(out), progress=False)
    done = subprocess.run(
        [sys.executable, str(SCRIPTS / "shear-band"), str(out), "--from", "1"],
        capture_output=True,
        text=True,
        check=True,
    )
    line = next(s for s in done.stdout.splitlines() if s.startswith("platens at step 4"))
    assert "shortening 10.000 mm" in line, done.stdout
    assert line.endswith("the bottom's 0.000 mm") or line.endswith("the bottom's -0.000 mm"), line
    assert "inclination:" in done.stdout and "thickness (FWHM):" in done.stdout
