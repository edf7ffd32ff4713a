"""Experiments: scenarios, trials, metrics and reports that reproduce and extend the paper's experiments.

``metrics`` holds the accuracy measures (the SLAM relations metric of Kümmerle et al. 2009 and the
``timestamp x y theta`` pose files it reads and writes).
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.experiments.metrics import read_poses, read_relations, relations_error, write_poses

_EXPORTS = {
    "read_poses": "navlab.experiments.metrics",
    "read_relations": "navlab.experiments.metrics",
    "relations_error": "navlab.experiments.metrics",
    "write_poses": "navlab.experiments.metrics",
}
__all__ = [
    "read_poses",
    "read_relations",
    "relations_error",
    "write_poses",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
