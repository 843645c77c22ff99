"""`Job.run` and `open_run`: the CLI's run, directory rules and results, from Python."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import cosdem


def dem_job(fixture_job, steps: int = 2, **output) -> cosdem.Job:
    """The one-element DEM job (four hexagonal assemblies of about 100 discs), with `steps`
    load steps and the `[output]` keys given."""
    tables = cosdem.Job.from_toml(fixture_job("dem-one-element")).to_dict()
    tables["loading"]["steps"] = steps
    if output:
        tables["output"] = output
    return cosdem.Job(tables)


def same_files(a: Path, b: Path, skip=("summary.json", "provenance.json", "cosdem.log", ".cosdem.lock")):
    """The files of run directory `a` that differ from `b`'s or are missing there (plots are
    the CLI's alone; the summary and provenance hold times and the command)."""
    differ = []
    for f in sorted(p for p in a.rglob("*") if p.is_file()):
        rel = f.relative_to(a)
        if rel.name in skip or rel.parts[0] == "plots":
            continue
        other = b / rel
        if not other.exists() or other.read_bytes() != f.read_bytes():
            differ.append(str(rel))
    return differ


def test_a_run_is_bit_identical_to_the_clis(fixture_job, tmp_path, cli):
    """The same DEM job run by `cosdem run` and by `Job.run`: every result file (curve, VTK,
    fields, snapshots, checkpoint) the same bytes."""
    path = tmp_path / "job.toml"
    path.write_text(dem_job(fixture_job, steps=3, snapshots=[[0, 1]]).text)
    subprocess.run([cli, "run", path, "--out", tmp_path / "cli", "--quiet"], check=True, capture_output=True)
    run = cosdem.Job.from_toml(path).run(tmp_path / "py", progress=False)
    assert run.status == "finished"
    assert same_files(tmp_path / "cli", run.dir) == []
    assert same_files(run.dir, tmp_path / "cli") == []
    assert (run.dir / "job.toml").read_text() == path.read_text()


def test_results_are_the_files_as_arrays(fixture_job, tmp_path):
    job = dem_job(fixture_job, steps=2, snapshots=[[0, 1]])
    run = job.run(tmp_path / "r", progress=False)
    s = run.summary
    assert s["status"] == "finished" and s["steps"] == 2
    assert s["metrics"]["peak_load"] > 0  # the README's example reads it
    curve = run.curve
    np.testing.assert_array_equal(curve["step"], [1.0, 2.0])
    assert curve["displacement"][-1] == pytest.approx(0.004, rel=1e-12)
    frame = run.curve_frame()
    assert list(frame.columns) == list(curve) and len(frame) == 2
    assert run.saved_steps == [1, 2]
    g = run.gauss()
    assert g["position"].shape == (4, 2) and g["stress"].shape == (4, 4)
    np.testing.assert_array_equal(g["element"], [0, 0, 0, 0])
    np.testing.assert_array_equal(g["point"], [0, 1, 2, 3])
    # compressed vertically at 100 kPa lateral: every point in compression, s_yy the larger
    assert np.all(g["stress"][:, 1] < g["stress"][:, 0]) and np.all(g["stress"][:, 0] < 0)
    g["stress"][0, 0] = 0.0  # arrays are writable (no copy behind them)
    m = run.mesh(2)
    assert m["points"].shape == (8, 2) and m["offsets"].tolist() == [8]
    assert m["connectivity"].shape == (8,) and m["point_data"]["displacement"].shape == (8, 3)
    assert run.snapshot_points() == [(0, 1)]
    assert run.snapshot_steps(0, 1)[-1] == 2
    p = run.snapshot(0, 1)
    n = len(p["radius"])
    assert n == cosdem.Assembly(job).disc_count
    assert p["position"].shape == (n, 2) and p["contacts"].shape[1] == 2
    assert len(p["normal_force"]) == len(p["contacts"]) and np.all(p["contacts"] < n)


def test_unsaved_steps_and_points_name_the_saved_ones(fixture_job, tmp_path):
    run = dem_job(fixture_job, snapshots=[[0, 1]]).run(tmp_path / "r", progress=False)
    with pytest.raises(cosdem.ResultsError, match=r"step 5 has no .*saved steps: 1, 2"):
        run.gauss(5)
    with pytest.raises(LookupError, match=r"step 7 has no"):
        run.mesh(7)
    with pytest.raises(cosdem.ResultsError, match=r"element 0, Gauss point 3.*snapshot points: "):
        run.snapshot(0, 3, 2)
    with pytest.raises(cosdem.ResultsError, match="not a run directory"):
        cosdem.open_run(tmp_path)


def test_an_existing_directory_follows_the_clis_rules(fixture_job, tmp_path):
    """A directory holding a run is refused; `overwrite` starts again (the old one kept as
    `.old-1`); `max_steps` stops cleanly and `resume` goes on to the same curve."""
    job = dem_job(fixture_job, steps=4)
    straight = job.run(tmp_path / "straight", progress=False)
    with pytest.raises(cosdem.RunError, match="overwrite|resume") as caught:
        job.run(tmp_path / "straight", progress=False)
    assert isinstance(caught.value, RuntimeError)
    again = job.run(tmp_path / "straight", progress=False, overwrite=True)
    assert again.status == "finished" and (tmp_path / "straight.old-1").is_dir()
    stopped = job.run(tmp_path / "parts", progress=False, max_steps=2)
    assert stopped.status == "stopped" and len(stopped.curve["step"]) == 2
    resumed = job.run(tmp_path / "parts", progress=False, resume=True)
    assert resumed.status == "finished"
    assert (resumed.dir / "curve.csv").read_bytes() == (straight.dir / "curve.csv").read_bytes()
    with pytest.raises(ValueError, match="resume=True and overwrite=True"):
        job.run(tmp_path / "x", resume=True, overwrite=True)
    with pytest.raises(ValueError, match="max_steps=0"):
        job.run(tmp_path / "x", max_steps=0)


def test_a_failed_run_keeps_its_steps(fixture_job, tmp_path):
    """A step that cannot be solved (Newton allowed one iteration, no cuts) raises RunError
    naming the run directory, where the summary says `failed`."""
    tables = dem_job(fixture_job, steps=2).to_dict()
    tables["newton"]["max_iterations"] = 1
    tables["newton"]["min_increment_fraction"] = 1.0
    with pytest.raises(cosdem.RunError) as caught:
        cosdem.Job(tables).run(tmp_path / "r", progress=False)
    assert caught.value.run_dir == tmp_path / "r"
    assert cosdem.open_run(tmp_path / "r").status.startswith("failed")


# Python's own Ctrl-C handler, as an interactive Python has it: a process started in the
# background of a non-interactive shell (as CI may start the tests) inherits SIGINT ignored, and
# Python then leaves it ignored.
CHILD = textwrap.dedent(
    """
    import signal, sys, cosdem
    signal.signal(signal.SIGINT, signal.default_int_handler)
    job = cosdem.Job.from_toml(sys.argv[1])
    try:
        job.run(sys.argv[2], progress=False)
    except KeyboardInterrupt:
        print("KeyboardInterrupt", flush=True)
        sys.exit(3)
    """
)


def test_ctrl_c_stops_cleanly_and_the_run_resumes(fixture_job, tmp_path):
    """SIGINT while a run goes: the run stops after its step with the checkpoint written
    (status `interrupted`), KeyboardInterrupt reaches the script, and `resume=True` finishes
    with the curve of an uninterrupted run."""
    # 600 steps of about 7 ms: seconds of slack for a busy machine to see the first rows and
    # signal the run before it ends (checked: the child must still be running when signalled).
    steps = 600
    job = dem_job(fixture_job, steps=steps)
    path = tmp_path / "job.toml"
    path.write_text(job.text)
    out = tmp_path / "r"
    child = subprocess.Popen([sys.executable, "-c", CHILD, path, out], stdout=subprocess.PIPE, text=True)
    curve = out / "curve.csv"
    deadline = time.monotonic() + 120
    while True:
        running = child.poll() is None
        if curve.exists() and len(curve.read_text().splitlines()) >= 4:
            break
        assert running, "the run ended before it could be interrupted"
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert running and child.poll() is None, "the run ended before it could be interrupted"
    child.send_signal(signal.SIGINT)
    stdout, _ = child.communicate(timeout=120)
    assert child.returncode == 3 and "KeyboardInterrupt" in stdout
    run = cosdem.open_run(out)
    assert run.status.startswith("interrupted")
    done = len(run.curve["step"])
    assert 3 <= done < steps
    resumed = job.run(out, progress=False, resume=True)
    assert resumed.status == "finished"
    straight = job.run(tmp_path / "straight", progress=False)
    assert (resumed.dir / "curve.csv").read_bytes() == (straight.dir / "curve.csv").read_bytes()


def test_the_gil_is_released_and_a_run_reads_while_it_goes(fixture_job, tmp_path):
    """While a run goes in one thread, the main thread runs Python and reads the run
    directory: it sees a partial curve (the results are written as the run goes) and the run
    does not hold the GIL (the main thread's reads happen during the run, not after)."""
    import threading

    job = dem_job(fixture_job, steps=150)
    out = tmp_path / "r"
    thread = threading.Thread(target=lambda: job.run(out, progress=False))
    thread.start()
    seen = set()
    while thread.is_alive():
        if (out / "summary.json").exists():
            try:
                seen.add(len(cosdem.open_run(out).curve["step"]))
            except cosdem.ResultsError:
                pass  # the directory is being set up
        time.sleep(0.002)
    thread.join()
    assert cosdem.open_run(out).status == "finished"
    partial = {n for n in seen if 0 < n < 150}
    assert len(partial) >= 2, sorted(seen)  # seen during the run, at two different steps at least


def free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_remote_workers_give_the_in_process_bytes(fixture_job, tmp_path, worker_binary):
    """Two `cosdem-worker` processes on this host, named as `workers=`: the run's results are
    the in-process run's, byte for byte (the assemblies are split between the workers), and a
    stepped `Solver` on them gives the in-process solver's reactions to the bit."""
    job = dem_job(fixture_job, steps=2)
    local = job.run(tmp_path / "local", progress=False)
    ports = [free_port(), free_port()]
    workers = [subprocess.Popen([worker_binary, "listen", "--listen", f"127.0.0.1:{p}"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for p in ports]
    try:
        for p in ports:
            deadline = time.monotonic() + 60
            while subprocess.run([worker_binary, "health", "--addr", f"127.0.0.1:{p}", "--timeout", "1"],
                                 capture_output=True).returncode != 0:
                assert time.monotonic() < deadline, f"worker on port {p} did not come up"
                time.sleep(0.1)
        addresses = [f"127.0.0.1:{p}" for p in ports]
        remote = job.run(tmp_path / "remote", workers=",".join(addresses), progress=False)
        # a stepped solver too: the same reactions from remote and in-process assemblies
        reactions = []
        for where in (addresses, None):
            s = cosdem.Solver(job, workers=where)
            s.prescribe("bottom", "uy", 0.0)
            s.prescribe("bottom", "ux", 0.0)
            s.prescribe("top", "ux", 0.0)
            s.pressure("left", 1e5)
            s.pressure("right", 1e5)
            s.step(increment=-1e-3)
            reactions.append(s.reactions("top", moment=True))
            s.finish()
        np.testing.assert_array_equal(reactions[0], reactions[1])
    finally:
        for w in workers:
            w.terminate()
            w.wait(timeout=30)
    assert remote.summary["workers"] == 2
    assert same_files(local.dir, remote.dir) == []
