"""The exceptions of the cosdem package.

Every error cosdem raises is a :class:`CosdemError`; each kind is also the built-in exception
a Python user would catch for it. The message is the CLI's: the file (or ``job dict``), the key
path and the reason, with line and column where the input was a TOML file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional, Union


class CosdemError(Exception):
    """Base class of every cosdem error."""


class JobError(CosdemError, ValueError):
    """A job (file or dict) or an assembly spec that cannot be read or is invalid: an unknown
    key, a wrong type, a value out of range, a set the mesh does not have."""


class RunError(CosdemError, RuntimeError):
    """A run that could not start (its directory holds another run, a worker cannot be
    reached, ...) or stopped on an error. ``run_dir`` is the run directory holding the steps
    finished before the error, or ``None`` when nothing was written."""

    def __init__(self, message: str, run_dir: Optional[Union[str, Path]] = None) -> None:
        super().__init__(message)
        self.run_dir: Optional[Path] = Path(run_dir) if run_dir is not None else None


class ResultsError(CosdemError, LookupError):
    """A directory that is not a run directory, or a step, Gauss point or snapshot the run did
    not save; the message names the ones it did."""
