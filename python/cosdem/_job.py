"""`Job`: a cosdem job read from a TOML file or given as a dict, and run."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Dict, Mapping, Optional, Sequence, Union

from . import _native
from ._run import Run

PathLike = Union[str, "os.PathLike[str]"]


class Job:
    """A validated cosdem job: the TOML job file's schema, defaults and error messages.

    ``Job(tables)`` takes the file's tables as a dict (``{"title": ..., "mesh": {...},
    "material": {...}, "loading": {...}}``; arrays of tables such as ``[[loading.pressure]]``
    as lists of dicts; a ``None`` value leaves its key out). An unknown key, a wrong type or an
    invalid value raises :class:`cosdem.JobError` naming the key path
    (``job dict: at key `mesh.nz`: unknown field `nz` ...``).
    """

    _native: Any

    def __init__(self, tables: Mapping[str, Any]) -> None:
        if not isinstance(tables, Mapping):
            raise TypeError(f"Job(tables): a dict of the job's tables, not {type(tables).__name__}")
        self._native = _native.Job.from_dict(dict(tables))

    @classmethod
    def from_toml(cls, path: PathLike) -> "Job":
        """Reads and validates a job file. Relative paths in it (``mesh.file``, a packing
        ``file``) are relative to the file. Errors name the file, line and column."""
        job = cls.__new__(cls)
        job._native = _native.Job.from_toml(os.fspath(path))
        return job

    @property
    def title(self) -> str:
        """The job's ``title``."""
        return self._native.title

    @property
    def file(self) -> Optional[Path]:
        """The job file, or ``None`` for a job given as a dict."""
        f = self._native.file
        return Path(f) if f is not None else None

    @property
    def text(self) -> str:
        """The job as TOML text (what the run directory keeps as ``job.toml``)."""
        return self._native.text

    @property
    def is_dem(self) -> bool:
        """Whether the material is DEM assemblies (``[material] kind = "dem"``)."""
        return self._native.is_dem

    def to_dict(self) -> Dict[str, Any]:
        """The job's tables as written (defaults are not filled in): ``Job(job.to_dict())``
        is the same job."""
        return self._native.to_dict()

    def default_dir(self) -> Path:
        """Where :meth:`run` writes without ``out``: the job's ``[output] dir``, else
        ``runs/<job file stem>`` (``runs/job`` for a job given as a dict)."""
        return Path(self._native.default_dir())

    def run(
        self,
        out: Optional[PathLike] = None,
        workers: Optional[Union[str, Sequence[str]]] = None,
        progress: bool = True,
        *,
        overwrite: bool = False,
        resume: bool = False,
        newton_changed: bool = False,
        max_steps: Optional[int] = None,
        token_file: Optional[PathLike] = None,
        max_memory: Optional[int] = None,
        create_timeout: Optional[float] = None,
    ) -> Run:
        """Runs the job as ``cosdem run`` does and returns the :class:`Run`.

        ``out``: the run directory (default :meth:`default_dir`). A directory holding a
        previous run is refused unless ``overwrite=True`` (the old one is renamed
        ``OUT.old-N`` once the setup succeeds) or ``resume=True`` (the run goes on from its
        checkpoint; ``newton_changed=True`` lets the job's ``[newton]`` differ from it).
        ``workers``: remote workers (``"host:port,host:port"``, a list, or ``dns:NAME:PORT``;
        default the job's ``[workers]``, else in-process); ``token_file``: their shared token
        (else ``COSDEM_TOKEN``). ``max_steps``: stop cleanly after that many committed steps
        (resumable). ``max_memory``: refuse a job estimated above that many bytes (default
        80 % of the machine's). ``create_timeout``: seconds a worker may take to build its
        assemblies. ``progress``: the CLI's progress bar on a terminal.

        The GIL is released while the run goes; the results are written as it goes, so
        :func:`cosdem.open_run` can read them from another thread or process. Ctrl-C stops the
        run after its current step (checkpoint written, ``status`` ``interrupted``, resumable
        with ``resume=True``) and is raised again as ``KeyboardInterrupt``. A step that
        cannot be solved raises :class:`cosdem.RunError` whose ``run_dir`` holds the finished
        steps.
        """
        out_dir = Path(out) if out is not None else self.default_dir()
        if isinstance(workers, str):
            workers = [w for w in workers.split(",") if w]
        self._native.run(
            os.fspath(out_dir),
            workers=list(workers) if workers is not None else None,
            progress=progress,
            overwrite=overwrite,
            resume=resume,
            newton_changed=newton_changed,
            max_steps=max_steps,
            token_file=os.fspath(token_file) if token_file is not None else None,
            max_memory=max_memory,
            create_timeout=create_timeout,
        )
        return Run(out_dir)

    def __repr__(self) -> str:
        return repr(self._native)
