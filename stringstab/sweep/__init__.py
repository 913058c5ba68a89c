"""The paper's studies as sweeps on Dask: a TOML spec, one task per point, results that survive.

* :mod:`~stringstab.sweep.spec` — :func:`load_spec`: base settings, axes (crossed or zipped,
  lists or ranges), seeds and what each point computes, checked on load;
* :mod:`~stringstab.sweep.tasks` — :func:`run_point`: one point, calling the library
  (train + evaluate, region map, certified share, probe);
* :mod:`~stringstab.sweep.cluster` — :func:`dask_client`: a local cluster on 127.0.0.1 or a
  remote scheduler, closed by the ``with`` block that opened it;
* :mod:`~stringstab.sweep.runner` — :func:`run_sweep`: tasks submitted, records written
  atomically as they finish, finished points skipped on a re-run;
* :mod:`~stringstab.sweep.report` — the table of all points and the paper's Tables 3 and 5 and
  Figs 4 and 5 from it, beside :mod:`~stringstab.sweep.paper`'s numbers.

Dask (the ``dask`` extra) is imported only when a sweep runs.
"""

from __future__ import annotations

from .cluster import dask_client
from .records import read_records
from .report import sweep_table, write_outputs
from .runner import run_sweep
from .spec import KINDS, STUDIES, Point, SweepSpec, load_spec, parse_spec
from .tasks import run_point

__all__ = [
    "KINDS",
    "STUDIES",
    "Point",
    "SweepSpec",
    "dask_client",
    "load_spec",
    "parse_spec",
    "read_records",
    "run_point",
    "run_sweep",
    "sweep_table",
    "write_outputs",
]
