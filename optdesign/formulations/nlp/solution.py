"""What an NLP back-end leaves in a result beyond its common fields: the NLP's vector and
its multipliers, read here so that a study (a front's warm starts and costs, a sweep's
sensitivities) never reads a back-end's raw output itself."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from optdesign.errors import InputError
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Result


@dataclass(frozen=True)
class NLPSolution:
    """An NLP back-end's point: the NLP's vector ``z`` (in its scaling) and the
    multipliers of its bounds (``lam_x``) and rows (``lam_g``)."""

    z: np.ndarray
    lam_x: np.ndarray
    lam_g: np.ndarray


def nlp_solution(result: Result) -> NLPSolution | None:
    """The NLP vector and multipliers a back-end left in ``result`` (None: it left no
    multipliers, e.g. a GP's or a derivative-free back-end's result)."""
    raw = result.raw
    if "lam_g" not in raw:
        return None
    return NLPSolution(
        np.asarray(raw["z"], dtype=float),
        np.asarray(raw["lam_x"], dtype=float),
        np.asarray(raw["lam_g"], dtype=float),
    )


def has_multipliers(result: Result, requested: str | None = None) -> bool:
    """Whether ``result`` carries multipliers a sensitivity can read. ``result.solver``
    is the label the run reports (``scipy-slsqp-exact`` for the ``slsqp`` back-end), not
    always a registered name: the requested back-end answers then."""
    if "lam_g" not in result.raw:
        return False
    try:
        return solver_hints(result.solver).multipliers
    except InputError:
        return solver_hints(requested).multipliers
