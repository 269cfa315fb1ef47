"""irpol.dataset — large sweeps on Dask distributed (docs/design.md §2.7).

A sweep spec (TOML) names a scene template and a grid of values for dotted keys of it (renders),
or a folder tree of measurement files (fits). Each item runs as one Dask task, on a LocalCluster
or an existing scheduler; its outputs are written atomically to ``out/items/<i>/`` and recorded
in ``out/manifest.jsonl`` with their SHA-256. Renders at instants of a scene with ``[thermal]``
share its thermal runs: one more task per distinct run solves it once into
``out/thermal/<key>.bin``, and the renders read it. A rerun skips the finished items; a failed
item is retried once and then recorded with its error while the others go on.

    python -m irpol.dataset SPEC.toml [--scheduler ADDRESS] [--workers N]
"""

from .spec import Item, Spec, SpecError, load_spec
from .runner import RunSummary, run

__all__ = ["Item", "Spec", "SpecError", "load_spec", "RunSummary", "run"]
