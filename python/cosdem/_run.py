"""`Run` and `open_run`: a run directory's results as dicts and numpy arrays."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _native
from ._arrays import array, arrays
from ._errors import ResultsError


class Run:
    """A run directory: finished, stopped, interrupted, failed or still being written.

    Every accessor reads the directory again, so a run that goes on in another thread or
    process shows its new steps. Asking for a step or Gauss point that was not saved raises
    :class:`cosdem.ResultsError` naming the ones that were.
    """

    def __init__(self, dir: Union[str, "os.PathLike[str]"]) -> None:
        self._native = _native.RunDir(os.fspath(dir))

    @property
    def dir(self) -> Path:
        """The run directory."""
        return Path(self._native.dir)

    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json``: ``status``, ``steps``, ``displacement``, the metrics (peak load,
        stiffness, ...), DEM step counts and times."""
        return self._native.summary()

    @property
    def status(self) -> str:
        """``running``, ``finished``, ``stopped``, ``interrupted`` or ``failed: <reason>``."""
        return str(self.summary["status"])

    @property
    def curve(self) -> Dict[str, np.ndarray]:
        """``curve.csv`` as a dict of column name to array (one entry per committed step)."""
        return {name: array(packed) for name, packed in self._native.curve()}

    def curve_frame(self) -> Any:
        """``curve.csv`` as a pandas ``DataFrame`` (needs pandas: ``pip install pandas``)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Run.curve_frame() needs pandas: pip install pandas") from e
        return pd.DataFrame(self.curve)

    @property
    def saved_steps(self) -> List[int]:
        """The steps whose mesh and Gauss-point fields were saved (``[output]
        field_plots_at`` and the last step)."""
        return list(self._native.saved_steps())

    def _step(self, step: Optional[int]) -> int:
        if step is not None:
            return int(step)
        steps = self.saved_steps
        if not steps:
            raise ResultsError(f"{self.dir}: no step has saved fields yet")
        return steps[-1]

    def gauss(self, step: Optional[int] = None) -> Dict[str, np.ndarray]:
        """The Gauss-point fields of ``step`` (default: the last saved one): ``position``
        ``(n, 2)``, ``element`` and ``point`` ``(n,)``, and each field, ``(n,)`` or ``(n,
        components)`` (``stress`` is ``[s_xx, s_yy, s_xy, s_yx]``, ``couple_stress``
        ``[m_x, m_y]``, ``strain``, ``curvature``, and the DEM descriptors of a DEM run)."""
        return arrays(self._native.gauss(self._step(step)))

    def mesh(self, step: Optional[int] = None) -> Dict[str, Any]:
        """The mesh of ``step`` (default: the last saved one): ``points`` ``(n, 2)``, the
        cells as ``connectivity`` and ``offsets`` (each cell's end, as VTK), ``cell_types``
        (VTK codes), ``point_data`` (``displacement`` ``(n, 3)``, ``rotation``, nodal
        ``stress``, ...) and ``cell_data``."""
        return arrays(self._native.mesh(self._step(step)))

    def snapshot_points(self) -> List[Tuple[int, int]]:
        """The ``(element, point)`` Gauss points with particle snapshots (``[output]
        snapshots``)."""
        return [tuple(p) for p in self._native.snapshot_points()]

    def snapshot_steps(self, element: int, point: int) -> List[int]:
        """The steps saved for the snapshots of ``(element, point)``."""
        return list(self._native.snapshot_steps(element, point))

    def snapshot(self, element: int, point: int, step: Optional[int] = None) -> Dict[str, np.ndarray]:
        """The particles of Gauss point ``point`` of ``element`` at ``step`` (default: the
        last saved): ``position`` ``(n, 2)``, ``radius``, ``rotation``, ``fluctuation``
        ``(n, 2)``, ``contacts`` ``(m, 2)`` (disc indices), ``normal_force`` and
        ``tangential_force`` ``(m,)``."""
        if step is None:
            steps = self.snapshot_steps(element, point)
            step = steps[-1]
        return arrays(self._native.snapshot(element, point, int(step)))

    def __repr__(self) -> str:
        return f"cosdem.open_run({str(self.dir)!r})"


def open_run(dir: Union[str, "os.PathLike[str]"]) -> Run:
    """Opens a run directory (finished, stopped or still being written)."""
    return Run(dir)

