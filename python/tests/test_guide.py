"""The guide's (`docs/guide/python.md`) job and assembly snippets run as written."""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def blocks():
    text = (ROOT / "docs" / "guide" / "python.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_job_and_assembly_snippets_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    python = blocks()
    jobs = next(b for b in python if "cosdem.Job(tables)" in b)
    assembly = next(b for b in python if "cosdem.Assembly(job)" in b)
    scope: dict = {}
    exec(jobs, scope)
    exec(assembly, scope)
    r = scope["r"]
    assert r.stress.shape == (2, 2) and r.tangent.shape == (6, 6) and r.stress[0, 0] < 0
    assert os.getcwd() == str(ROOT)
