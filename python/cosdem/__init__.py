"""cosdem: two-scale FEM x DEM for granular materials, from Python.

- :class:`Job` reads a job (a TOML file or a dict of its tables) and runs it into a run
  directory, as ``cosdem run`` does;
- :func:`open_run` reads a run directory back (:class:`Run`): summary, curve, Gauss-point and
  mesh fields, particle snapshots, as numpy arrays;
- :class:`Solver` steps a job's solver from a Python loop (displacements, pressures and
  gravity on named sets between steps);
- :class:`Assembly` drives one DEM assembly through macro deformations (calibration).

Errors are :class:`CosdemError` subclasses carrying the CLI's messages.
"""

from ._native import __version__
from ._errors import CosdemError, JobError, ResultsError, RunError
from ._run import Run, open_run
from ._job import Job
from ._assembly import Assembly, Response
from ._solver import Solver

__all__ = [
    "Assembly",
    "CosdemError",
    "Job",
    "JobError",
    "Response",
    "ResultsError",
    "Run",
    "RunError",
    "Solver",
    "__version__",
    "open_run",
]
