"""Studies: the penalty sensitivity sweep and the critical liftoff load, at scale on Dask.

- :func:`run_sweep` (:mod:`.sweep`): penalty at several k-factors (and meshes) against Lagrange;
  cases stored as they finish (:mod:`.store`), resumable; metrics in :mod:`.metrics`.
- :func:`critical_load` (:mod:`.liftoff`): lambda_c of liftoff per method, to a tolerance.
- :func:`open_client` (:mod:`.cluster`): a Dask LocalCluster or an existing scheduler;
  :class:`~.local.LocalExecutor` (:mod:`.local`): cases on worker processes forked from this one.
"""

from .cases import Case, MeshVariant, mesh_variants, parse_k_factors, parse_mesh_options, sweep_cases  # noqa: F401
from .cluster import open_client  # noqa: F401
from .liftoff import critical_load, format_table  # noqa: F401
from .store import CaseStore  # noqa: F401
from .sweep import run_sweep  # noqa: F401
