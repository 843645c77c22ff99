"""`cosdem.Job`: the job file's schema, defaults and messages, from a file or a dict."""

from __future__ import annotations

import subprocess

import pytest

import cosdem


def test_a_dict_is_the_job_of_its_file(fixture_job, tmp_path):
    """`Job(d)` with the tables of a file reads the same job: the same text round trip and
    the same run (curve bytes)."""
    from_file = cosdem.Job.from_toml(fixture_job("elastic-panel"))
    tables = from_file.to_dict()
    from_dict = cosdem.Job(tables)
    assert from_dict.to_dict() == tables
    assert from_file.title == from_dict.title
    a = from_file.run(tmp_path / "a", progress=False)
    b = from_dict.run(tmp_path / "b", progress=False)
    assert (a.dir / "curve.csv").read_bytes() == (b.dir / "curve.csv").read_bytes()


def test_unknown_keys_and_wrong_types_name_the_key_path(fixture_job):
    tables = cosdem.Job.from_toml(fixture_job("elastic-panel")).to_dict()
    tables["mesh"]["nz"] = 3
    with pytest.raises(cosdem.JobError, match=r"at key `mesh\.nz`: unknown field `nz`"):
        cosdem.Job(tables)
    del tables["mesh"]["nz"]
    tables["mesh"]["nx"] = "two"
    with pytest.raises(cosdem.JobError, match=r"at key `mesh\.nx`.*invalid type"):
        cosdem.Job(tables)
    tables["mesh"]["nx"] = object()
    with pytest.raises(cosdem.JobError, match=r"at key `mesh\.nx`: a object cannot be a job value"):
        cosdem.Job(tables)


def test_job_errors_are_value_errors_with_the_clis_message(fixture_job, tmp_path, cli):
    """A TOML file's error is the CLI's, with its line and column; a JobError is a
    ValueError."""
    text = fixture_job("elastic-panel").read_text().replace("nx = 2", "nx = 2\nnz = 3")
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(ValueError) as caught:
        cosdem.Job.from_toml(bad)
    message = str(caught.value)
    line = 1 + text.splitlines().index("nz = 3")
    assert f"line {line}, column 1" in message and "nz" in message
    shown = subprocess.run([cli, "run", bad, "--out", tmp_path / "r"], capture_output=True, text=True)
    assert shown.returncode != 0
    assert message.splitlines()[0] in shown.stderr


def test_validation_names_the_field_and_an_unknown_set(fixture_job, tmp_path):
    tables = cosdem.Job.from_toml(fixture_job("elastic-panel")).to_dict()
    tables["mesh"]["nx"] = 0
    with pytest.raises(cosdem.JobError, match=r"mesh\.nx"):
        cosdem.Job(tables)
    tables = cosdem.Job.from_toml(fixture_job("elastic-panel-confined")).to_dict()
    tables["loading"]["pressure"][0]["set"] = "nowhere"
    # The sets are the mesh's: known once it is built, at the start of the run.
    with pytest.raises(cosdem.JobError, match=r"unknown edge set `nowhere` \(known: bottom, left, right, top\)"):
        cosdem.Job(tables).run(tmp_path / "r", progress=False)
    assert not (tmp_path / "r").exists()


def test_values_from_numpy_and_paths_are_accepted(fixture_job, tmp_path):
    import numpy as np

    tables = cosdem.Job.from_toml(fixture_job("elastic-panel")).to_dict()
    tables["mesh"]["nx"] = np.int64(tables["mesh"]["nx"])
    tables["mesh"]["lx"] = np.float64(tables["mesh"]["lx"])
    tables["mesh"]["origin"] = np.zeros(2)
    tables["output"] = {"dir": tmp_path / "here", "checkpoint_every": None}
    job = cosdem.Job(tables)
    assert job.default_dir() == tmp_path / "here"
    assert cosdem.Job.from_toml(fixture_job("elastic-panel")).default_dir().name == "elastic-panel"
    with pytest.raises(TypeError):
        cosdem.Job("mesh = 1")  # type: ignore[arg-type]
