"""Pareto fronts of a design problem.

- :mod:`.template`: what every front method does, written once (:class:`FrontMethod`);
- :mod:`.methods`: the methods as its subclasses (:class:`EpsilonConstraint`,
  :class:`WeightedSum`, :class:`NSGA2`; :mod:`.catalogue_front`: :class:`CatalogueEpsilon`),
  :func:`make_method` (a method from its name, for the API and the command line) and
  :func:`compute_front`;
- :mod:`.chains` and :mod:`.tasks`: the epsilon method's task graph (anchors, chains);
- :mod:`.eps_solver`: every solve of a front on one formulation;
- :mod:`.records`: typed records as stored; :mod:`.front`: the :class:`Front`;
- :mod:`.metrics`: hypervolume, spacing, spread (the CSV and JSON files of a front are
  the reports', :mod:`optdesign.reports.front_files`);
- :mod:`.costs`: what each limit costs at a point, from the point's own solve.
"""

from optdesign.studies.pareto.front import Front, FrontPoint, common_hypervolumes, make_front
from optdesign.studies.pareto.methods import (
    METHODS,
    NSGA2,
    EpsilonConstraint,
    FrontMethod,
    RunOptions,
    WeightedSum,
    compute_front,
    make_method,
)
from optdesign.studies.pareto.records import PointRecord


def __getattr__(name: str):
    # imported when named: see optdesign.studies.pareto.methods
    if name == "CatalogueEpsilon":
        from optdesign.studies.pareto.catalogue_front import CatalogueEpsilon

        return CatalogueEpsilon
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "METHODS",
    "NSGA2",
    "CatalogueEpsilon",
    "EpsilonConstraint",
    "Front",
    "FrontMethod",
    "FrontPoint",
    "PointRecord",
    "RunOptions",
    "WeightedSum",
    "common_hypervolumes",
    "compute_front",
    "make_front",
    "make_method",
]
