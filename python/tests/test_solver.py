"""`cosdem.Solver`: a job's solver stepped from a Python loop, against the job file's stages
and closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import cosdem
from test_run import same_files

SETTLEMENT = {"set": "top", "component": "uy", "scale": -1.0}


def elastic(fixture_job) -> cosdem.Job:
    return cosdem.Job.from_toml(fixture_job("elastic-panel"))


def hold_supports(s: cosdem.Solver) -> None:
    s.prescribe("bottom", "ux", 0.0)
    s.prescribe("bottom", "uy", 0.0)
    s.prescribe("top", "ux", 0.0)


def test_a_femxdem_loop_on_the_elastic_panel(fixture_job, tmp_path):
    """The top moved down 1 mm per step between rough platens: `displacement` reads the
    prescribed value back exactly, the top's and the bottom's reactions balance (no other
    load: to rounding of the sums, 1e-9 relative), the force grows linearly with the
    settlement (elastic: each step's force increment equal to 1e-9), and the run directory's
    curve is the settlement against the force."""
    s = cosdem.Solver(elastic(fixture_job), out=tmp_path / "r")
    hold_supports(s)
    forces = []
    for k in range(1, 4):
        (report,) = s.step(increment=-1e-3)
        assert report["step"] == k and report["load_factor"] == 1.0
        np.testing.assert_array_equal(s.displacement("top", "uy"), -1e-3 * k)
        top, bottom = s.reactions("top"), s.reactions("bottom")
        assert top.shape == (2,) and s.reactions("top", moment=True).shape == (3,)
        np.testing.assert_allclose(top + bottom, 0.0, atol=1e-9 * abs(top[1]))
        forces.append(-top[1])
    assert forces[0] > 0
    assert np.diff(forces) == pytest.approx([forces[0], forces[0]], rel=1e-9)
    g = s.gauss_fields()
    assert g["stress"].shape == (16, 4) and np.all(g["stress"][:, 1] < 0)
    s.finish()
    run = cosdem.open_run(tmp_path / "r")
    assert run.status == "finished"
    np.testing.assert_allclose(run.curve["displacement"], [1e-3, 2e-3, 3e-3], rtol=1e-12)
    np.testing.assert_allclose(run.curve["load"], forces, rtol=1e-12)


def test_a_python_loop_is_the_job_files_stages(fixture_job, tmp_path):
    """The DEM fixture loaded in two `[[stage]]`s by `Job.run`, and the same two stages
    written as Solver calls: every result file the same bytes (the loop is the job file's
    stage semantics: what was set stays in force). The job names its curve: a run of stages
    without one has no compression to measure, a solver draws the load set's settlement."""
    tables = cosdem.Job.from_toml(fixture_job("dem-one-element")).to_dict()
    tables["loading"] = {}
    tables["output"] = {"curve": {"control": SETTLEMENT, "load": SETTLEMENT}, "snapshots": [[0, 2]]}
    supports = [
        {"set": "bottom", "component": "uy", "value": 0.0},
        {"set": "bottom", "component": "ux", "value": 0.0},
        {"set": "top", "component": "ux", "value": 0.0},
    ]
    tables["stage"] = [
        {"steps": 2, "prescribed": supports + [{"set": "top", "component": "uy", "value": -2e-3}],
         "pressure": [{"set": "left", "value": 1e5}, {"set": "right", "value": 1e5}]},
        {"steps": 2, "prescribed": [{"set": "top", "component": "uy", "increment": -2e-3}]},
    ]
    job = cosdem.Job(tables)
    ran = job.run(tmp_path / "run", progress=False)

    with cosdem.Solver(job, out=tmp_path / "loop") as s:
        hold_supports(s)
        s.prescribe("top", "uy", -2e-3)
        s.pressure("left", 1e5)
        s.pressure("right", 1e5)
        assert len(s.step(2)) == 2
        assert len(s.step(2, increment=-2e-3)) == 2
        assert (s.steps, s.stages) == (4, 2)
    # A run writes checkpoint.bin after every step; a solver when the script asks.
    skip = ("summary.json", "provenance.json", ".cosdem.lock", "checkpoint.bin")
    assert same_files(ran.dir, tmp_path / "loop", skip) == []
    assert same_files(tmp_path / "loop", ran.dir, skip) == []


def test_a_checkpoint_holds_the_scripts_loading(fixture_job, tmp_path):
    """Two DEM steps, a checkpoint, then two steps with no new settings (the loading held
    where the script left it: the pressures, the supports, the top where it is) and one more
    push; a solver resumed from the checkpoint and given the same calls ends in the same
    state, bit for bit (reactions and every Gauss-point field)."""
    job = cosdem.Job.from_toml(fixture_job("dem-one-element"))

    def first(s):
        hold_supports(s)
        s.pressure("left", 1e5)
        s.pressure("right", 1e5)
        s.step(increment=-1e-3)
        s.step(increment=-1e-3)

    def rest(s):
        s.step()
        s.step()
        s.step(increment=-1e-3)
        return s.reactions("top", moment=True), s.gauss_fields()

    s = cosdem.Solver(job)
    first(s)
    s.checkpoint(tmp_path / "ckp")
    straight = rest(s)
    # the checkpoint alone (it holds the job), and with the job given again
    for resumed in (cosdem.Solver.resume(tmp_path / "ckp"), cosdem.Solver.resume(tmp_path / "ckp", job)):
        assert (resumed.steps, resumed.stages) == (2, 2)
        again = rest(resumed)
        np.testing.assert_array_equal(again[0], straight[0])
        for name, values in straight[1].items():
            np.testing.assert_array_equal(again[1][name], values, err_msg=name)
    # another job's checkpoint is refused, naming the file
    other = cosdem.Job.from_toml(fixture_job("elastic-panel"))
    with pytest.raises(cosdem.CosdemError, match="ckp"):
        cosdem.Solver.resume(tmp_path / "ckp", other)


def test_bad_settings_are_named_and_a_failed_step_changes_nothing(fixture_job):
    s = cosdem.Solver(elastic(fixture_job))
    with pytest.raises(cosdem.JobError, match=r"no node set \"nope\" \(known: all, bottom"):
        s.reactions("nope")
    s.prescribe("nope", "uy", 1e-3)
    with pytest.raises(cosdem.JobError, match=r"stage\[0\]\.prescribed\[0\]\.set = nope"):
        s.step()
    s = cosdem.Solver(elastic(fixture_job))
    s.prescribe("top", "uz", 1e-3)
    with pytest.raises(cosdem.JobError, match=r"uz"):
        s.step()
    with pytest.raises(ValueError, match="one of value and increment"):
        s.prescribe("top", "uy")
    with pytest.raises(cosdem.JobError, match=r"displacement.*ux.*uy|component"):
        s.displacement("top", "uz")

    tables = cosdem.Job.from_toml(fixture_job("dem-one-element")).to_dict()
    tables["newton"]["max_iterations"] = 1
    tables["newton"]["min_increment_fraction"] = 1.0
    s = cosdem.Solver(cosdem.Job(tables))
    hold_supports(s)
    with pytest.raises(cosdem.RunError, match="stage 0"):
        s.step(increment=-2e-3)
    assert (s.steps, s.stages) == (0, 0)
    np.testing.assert_array_equal(s.reactions("top"), [0.0, 0.0])
