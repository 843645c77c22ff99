"""`Solver`: a job's solver driven one step at a time from a Python loop."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._arrays import array, arrays
from ._job import Job
from ._run import Run

PathLike = Union[str, "os.PathLike[str]"]


class Solver:
    """A job's mesh, material and Newton settings, loaded by the script step by step.

    As FEMxDEM scripts do: set prescribed displacements, pressures, tractions and gravity on
    the mesh's named sets, then :meth:`step`; read :meth:`reactions`, :meth:`displacement`,
    :meth:`gauss_fields`; repeat. None of the job's own loading (``[loading]`` loads,
    ``[[stage]]``) is applied. Each :meth:`step` is one ``[[stage]]`` of a job file
    (``docs/reference/job-file.md``) made of what the script set since the last step, with the
    same rule: what was set stays in force until the script changes it (a prescribed dof is
    held where it is, a pressure stays). A converged step is committed, as in ``cosdem run``;
    a step that cannot be solved raises :class:`cosdem.RunError` and leaves the solver where it
    was (the script may try an easier step).

    ``out``: a run directory written as the solver goes (the CLI's files: ``curve.csv``, VTK,
    ``summary.json``); ``workers``: remote workers as for :meth:`cosdem.Job.run`, else the
    job's, else in-process. Use it as a context manager (or call :meth:`finish`) to mark the
    run directory finished.
    """

    def __init__(
        self,
        job: Job,
        out: Optional[PathLike] = None,
        workers: Optional[Union[str, Sequence[str]]] = None,
        *,
        overwrite: bool = False,
        snapshots: bool = True,
        token_file: Optional[PathLike] = None,
        max_memory: Optional[int] = None,
    ) -> None:
        self._native = _native.Solver(
            job._native,
            out=_path(out),
            workers=_workers(workers),
            overwrite=overwrite,
            snapshots=snapshots,
            token_file=_path(token_file),
            max_memory=max_memory,
        )
        self._pending: Dict[str, Dict[Tuple, Dict[str, Any]]] = {}

    @classmethod
    def resume(
        cls,
        checkpoint: PathLike,
        job: Optional[Job] = None,
        out: Optional[PathLike] = None,
        workers: Optional[Union[str, Sequence[str]]] = None,
        *,
        newton_changed: bool = False,
        snapshots: bool = True,
        token_file: Optional[PathLike] = None,
        max_memory: Optional[int] = None,
    ) -> "Solver":
        """Goes on from a :meth:`checkpoint`: its steps, the script's loading so far, the
        assemblies' states and the job it ran (``job``: give the job again instead, e.g. with
        other ``[output]`` settings; another mesh, material or loading is refused); the next
        steps are those the solver would have taken had it not stopped, bit for bit.
        ``out``: the run directory to go on writing (cut back to the checkpoint's step)."""
        solver = cls.__new__(cls)
        solver._native = _native.Solver.resume(
            os.fspath(checkpoint),
            job._native if job is not None else None,
            out=_path(out),
            workers=_workers(workers),
            newton_changed=newton_changed,
            snapshots=snapshots,
            token_file=_path(token_file),
            max_memory=max_memory,
        )
        solver._pending = {}
        return solver

    # The loading of the next step.

    def _set(self, kind: str, key: Tuple, entry: Dict[str, Any]) -> None:
        self._pending.setdefault(kind, {})[key] = entry

    def prescribe(self, set: str, component: str, value: Optional[float] = None, *,
                  increment: Optional[float] = None) -> None:
        """Prescribes ``component`` (``ux``, ``uy``, ``w``) of node set ``set`` for the next
        step: ``value`` reached at its end, or ``increment`` from where the nodes are (``0``
        holds them). It stays held afterwards until changed or :meth:`free`-d."""
        if (value is None) == (increment is None):
            raise ValueError("prescribe: give one of value and increment")
        entry: Dict[str, Any] = {"set": set, "component": component}
        entry["value" if value is not None else "increment"] = float(value if value is not None else increment)
        self._set("prescribed", (set, component), entry)

    def free(self, set: str, component: str) -> None:
        """Releases ``component`` of ``set`` prescribed earlier (from the next step on)."""
        self._set("prescribed", (set, component), {"set": set, "component": component, "free": True})

    def pressure(self, set: str, value: float = 0.0, ramp: str = "constant") -> None:
        """A pressure (Pa, positive pushes into the body) on edge set ``set``: full from the
        next step on (``ramp="constant"``), reached over it (``"linear"``), or taken away over
        it (``"remove"``)."""
        self._set("pressure", (set,), {"set": set, "value": float(value), "ramp": ramp})

    def traction(self, set: str, value: Sequence[float], ramp: str = "constant") -> None:
        """A traction vector ``[t_x, t_y]`` (Pa) on edge set ``set``, with ``pressure``'s ramps."""
        self._set("traction", (set,), {"set": set, "value": [float(v) for v in value], "ramp": ramp})

    def gravity(self, acceleration: Sequence[float], density: Optional[float] = None,
                ramp: str = "constant") -> None:
        """Self-weight: ``acceleration`` ``[g_x, g_y]`` (m/s^2) on the bulk density
        (``density`` kg/m^3, else the material's), with ``pressure``'s ramps."""
        entry: Dict[str, Any] = {"acceleration": [float(a) for a in acceleration], "ramp": ramp}
        if density is not None:
            entry["density"] = float(density)
        self._set("gravity", (), entry)

    def step(self, steps: int = 1, *, increment: Optional[float] = None, name: str = "") -> List[Dict[str, Any]]:
        """Solves the next step: what was set since the last one, in ``steps`` load steps
        (cut as any step when Newton fails). ``increment``: shorthand for
        ``prescribe(load_set, "uy", increment=increment)``, the job's ``[loading] load_set``
        (``top`` by default) moved vertically by that much (m, negative downwards). Returns
        each committed step: ``step``, ``load_factor``, ``iterations``, ``cuts``,
        ``dem_steps``. The GIL is released while it runs. A failure raises
        :class:`cosdem.RunError` with the solver back where it was and the pending settings
        kept; a bad setting (an unknown set, a wrong component) raises :class:`cosdem.JobError`
        before anything moves."""
        if increment is not None:
            self.prescribe(self._native.load_set, "uy", increment=increment)
        stage: Dict[str, Any] = {"steps": int(steps)}
        if name:
            stage["name"] = name
        for kind, entries in self._pending.items():
            if kind == "gravity":
                stage["gravity"] = entries[()]
            else:
                stage[kind] = list(entries.values())
        reports = self._native.step(stage)
        self._pending = {}
        return reports

    # What the script reads.

    def reactions(self, set: str, moment: bool = False) -> np.ndarray:
        """The reaction ``[R_x, R_y]`` (N per metre of thickness) of node set ``set`` at the
        last committed step: the force holding its prescribed dofs (``moment=True``: also the
        couple ``R_w``, N m/m). An unknown set raises :class:`cosdem.JobError` naming the
        known ones."""
        r = np.array(self._native.reactions(set))
        return r if moment else r[:2]

    def displacement(self, set: str, component: str) -> np.ndarray:
        """``component`` (``ux``, ``uy`` in m; ``w`` in rad) at each node of ``set`` (ascending
        node numbers) at the last committed step."""
        return array(self._native.displacement(set, component))

    def gauss_fields(self) -> Dict[str, np.ndarray]:
        """The Gauss-point fields of the last committed step, as :meth:`cosdem.Run.gauss`
        reads them from a run directory."""
        return arrays(self._native.gauss_fields())

    @property
    def steps(self) -> int:
        """Committed load steps so far."""
        return self._native.steps

    @property
    def stages(self) -> int:
        """The script's steps (stages) so far."""
        return self._native.stages

    @property
    def run(self) -> Optional[Run]:
        """The run directory being written, as a :class:`cosdem.Run` (``None`` without ``out``)."""
        d = self._native.dir
        return Run(d) if d is not None else None

    def checkpoint(self, path: PathLike) -> None:
        """Writes the solver's state, the assemblies' and the script's loading so far to
        ``path`` (:meth:`resume` goes on from it)."""
        self._native.checkpoint(os.fspath(path))

    def finish(self) -> None:
        """Marks the run directory finished and lets the workers go; the solver cannot step
        afterwards."""
        self._native.finish()

    def __enter__(self) -> "Solver":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.finish()


def _path(p: Optional[PathLike]) -> Optional[str]:
    return os.fspath(p) if p is not None else None


def _workers(workers: Optional[Union[str, Sequence[str]]]) -> Optional[List[str]]:
    if workers is None:
        return None
    if isinstance(workers, str):
        return [w for w in workers.split(",") if w]
    return list(workers)
