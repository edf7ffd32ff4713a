"""Experiments: scenarios, trials, metrics and reports that reproduce and extend the paper's experiments.

``metrics`` holds the accuracy measures (the SLAM relations metric of Kümmerle et al. 2009 and the
``timestamp x y theta`` pose files it reads and writes).
"""

from navlab.experiments.metrics import read_poses, read_relations, relations_error, write_poses

__all__ = ["read_poses", "read_relations", "relations_error", "write_poses"]
