"""`Assembly`: one DEM assembly driven from Python (calibration)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, Mapping, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._arrays import array
from ._job import Job


@dataclass
class Response:
    """The homogenized answer of one trial solve.

    ``stress``: the Cauchy stress as a 2x2 array ``[[s_xx, s_xy], [s_yx, s_yy]]`` (Pa,
    tension positive; ``s_xy`` and ``s_yx`` as the Voigt entries of the same names);
    ``couple_stress``: ``[m_x, m_y]`` (N); ``voigt``: ``[s_xx, s_yy, s_xy, s_yx, m_x, m_y]``;
    ``tangent``: 6x6, ``tangent[i, j] = d voigt[i] / d e[j]`` with the strain in the same
    order (``[e_xx, e_yy, e_xy, e_yx, k_x, k_y]``, ``e_xy = u_y,x - w``); ``diagnostics``:
    DEM steps, residual, contacts, sliding fraction, micro-structure descriptors.
    """

    stress: np.ndarray
    couple_stress: np.ndarray
    voigt: np.ndarray
    tangent: np.ndarray
    diagnostics: Dict[str, Any]


class Assembly:
    """One DEM assembly of a job's ``[material.assembly]`` (or of a dict of its keys), driven
    through macro deformations as a Gauss point is: :meth:`solve` a trial, then
    :meth:`commit` or :meth:`rollback`. The laboratory paths of ``cosdem rve`` are Python
    loops over these three. Building packs the assembly (the GIL is released)."""

    def __init__(self, job_or_spec: Union[Job, Mapping[str, Any]]) -> None:
        if isinstance(job_or_spec, Job):
            self._native = _native.Assembly(job_or_spec._native)
        elif isinstance(job_or_spec, Mapping):
            self._native = _native.Assembly(dict(job_or_spec))
        else:
            raise TypeError(
                f"Assembly(job_or_spec): a cosdem.Job or a dict, not {type(job_or_spec).__name__}"
            )

    @property
    def disc_count(self) -> int:
        """Discs in the assembly."""
        return self._native.disc_count

    @property
    def area(self) -> float:
        """Reference area of the periodic cell (m^2 per metre of thickness)."""
        return self._native.area

    def solve(
        self,
        F: Union[Sequence[Sequence[float]], np.ndarray],
        w: float = 0.0,
        kappa: Union[Sequence[float], np.ndarray] = (0.0, 0.0),
    ) -> Response:
        """Trial solve, from the committed state, for the deformation gradient ``F`` (2x2,
        ``F[a, b] = delta_ab + du_a/dx_b``, total from the reference state), the
        micro-rotation ``w`` (rad) and the curvature ``kappa`` (``[w_x, w_y]``, 1/m). A
        non-finite value or ``det(F) <= 0`` raises ``ValueError`` naming the field. The GIL
        is released during the relaxation."""
        f = np.asarray(F, dtype=float)
        if f.shape != (2, 2):
            raise ValueError(f"F must be 2x2, not of shape {f.shape}")
        k = np.asarray(kappa, dtype=float)
        if k.shape != (2,):
            raise ValueError(f"kappa must have 2 components, not shape {k.shape}")
        voigt, tangent, diagnostics = self._native.solve(f.tolist(), float(w), k.tolist())
        v = array(voigt)
        stress = np.array([[v[0], v[2]], [v[3], v[1]]])
        return Response(stress, v[4:6].copy(), v, array(tangent), diagnostics)

    def commit(self) -> None:
        """Accepts the last trial: the next solve starts from it."""
        self._native.commit()

    def rollback(self) -> None:
        """Drops the last trial: the next solve starts from the committed state again."""
        self._native.rollback()

    def particles(self) -> Tuple[np.ndarray, np.ndarray]:
        """The committed state's disc centres ``(n, 2)`` and radii ``(n,)``."""
        positions, radii = self._native.particles()
        return array(positions), array(radii)
