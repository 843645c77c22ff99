"""`docs/reference/python.md` against the package: every public name has a section, every
public member of a class a row, and nothing documented is missing from the code."""

from __future__ import annotations

import dataclasses
import inspect
import re
from pathlib import Path

import cosdem

REFERENCE = Path(__file__).resolve().parents[2] / "docs" / "reference" / "python.md"


def sections():
    text = REFERENCE.read_text()
    out = {}
    for block in re.split(r"^### ", text, flags=re.M)[1:]:
        heading, _, body = block.partition("\n")
        members = {re.match(r"\w+", cell).group(0) for cell in re.findall(r"^\| `([^`]+)` \|", body, flags=re.M)}
        out[heading.strip().removeprefix("cosdem.")] = members
    return out


def public_members(obj):
    if dataclasses.is_dataclass(obj):
        return {f.name for f in dataclasses.fields(obj)}
    return {n for n, _ in inspect.getmembers(obj) if not n.startswith("_") and not isinstance(obj, type(cosdem))}


def test_every_public_name_has_a_section():
    assert set(sections()) == set(cosdem.__all__)


def test_every_member_has_a_row():
    documented = sections()
    for name in ["Job", "Run", "Solver", "Assembly", "Response"]:
        cls = getattr(cosdem, name)
        own = {n for n in public_members(cls) if not (inspect.isclass(cls) and issubclass(cls, BaseException))}
        assert documented[name] == own, name


def test_the_run_signature_is_the_documented_one():
    row = next(line for line in REFERENCE.read_text().splitlines() if line.startswith("| `run("))
    listed = re.findall(r"\w+", row.split("`")[1].removeprefix("run"))
    params = [p for p in inspect.signature(cosdem.Job.run).parameters if p != "self"]
    assert listed == params


def test_the_stubs_are_the_extensions():
    """`cosdem/_native.pyi` names every class and member of the extension, and nothing else."""
    import ast

    from cosdem import _native

    stubs = ast.parse((Path(cosdem.__file__).parent / "_native.pyi").read_text())
    for node in stubs.body:
        if isinstance(node, ast.ClassDef):
            stubbed = {n.name for n in node.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")}
            real = {n for n in dir(getattr(_native, node.name)) if not n.startswith("_")}
            assert stubbed == real, node.name
    classes = {n.name for n in stubs.body if isinstance(n, ast.ClassDef)}
    assert classes == {n for n in dir(_native) if isinstance(getattr(_native, n), type)}
