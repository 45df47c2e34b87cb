"""Pareto fronts of a design problem.

- :mod:`.methods`: the methods as objects (:class:`EpsilonConstraint`,
  :class:`WeightedSum`, :class:`NSGA2`) and :func:`compute_front`;
- :mod:`.chains` and :mod:`.tasks`: the epsilon method's task graph (anchors, chains);
- :mod:`.eps_solver`: every solve of a front on one formulation;
- :mod:`.records`: typed records as stored; :mod:`.front`: the :class:`Front`;
- :mod:`.metrics`: hypervolume, spacing, spread; :mod:`.io`: CSV and JSON files.
"""

from optdesign.studies.pareto.front import Front, FrontPoint, common_hypervolumes, make_front
from optdesign.studies.pareto.io import read_front_csv, write_front_csv, write_front_json
from optdesign.studies.pareto.methods import (
    METHODS,
    NSGA2,
    CatalogueEpsilon,
    EpsilonConstraint,
    RunOptions,
    WeightedSum,
    compute_front,
)
from optdesign.studies.pareto.records import PointRecord

__all__ = [
    "METHODS",
    "NSGA2",
    "CatalogueEpsilon",
    "EpsilonConstraint",
    "Front",
    "FrontPoint",
    "PointRecord",
    "RunOptions",
    "WeightedSum",
    "common_hypervolumes",
    "compute_front",
    "make_front",
    "read_front_csv",
    "write_front_csv",
    "write_front_json",
]
