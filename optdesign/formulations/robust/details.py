"""The robust formulation's typed record (``result.details["robust"]``): the risk
measure, its samples and the nominal optimum it started from.

``result.json`` writes its fields at the top of ``"extra"`` (``risk_label``,
``saa_samples``...), the keys earlier releases wrote.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from optdesign.solvers.details import fields_json


@dataclass
class NominalOptimum:
    """The nominal optimum a robust solve started from."""

    status: str
    objective: str
    value: float
    design: dict[str, float]

    def to_json(self) -> dict[str, Any]:
        # Older files key the value by the objective's name.
        return {"status": self.status, self.objective: self.value, "design": self.design}


@dataclass
class RobustDetails:
    """A robust (sample-average) optimum.

    Attributes
    ----------
    risk_label
        What the objective measures (``"CVaR_0.9(backlash)"``...).
    saa_samples, saa_seed
        The fixed scatter samples of the SAA.
    build_time_s
        Time to build the formulation.
    constrain_samples
        Whether the requirements hold at every sample.
    saa_check
        The statistic recomputed on the NumPy path from the same samples (None: no design).
    nominal_optimum
        The nominal optimum it started from (``formulation="robust"``).
    """

    risk_label: str
    saa_samples: int
    saa_seed: int
    build_time_s: float
    constrain_samples: bool
    saa_check: float | None = None
    nominal_optimum: NominalOptimum | None = None

    def to_json(self) -> dict[str, Any]:
        out = fields_json(self, ("saa_check", "nominal_optimum"))
        if self.nominal_optimum is not None:
            out["nominal_optimum"] = self.nominal_optimum.to_json()
        return out

    def extra(self) -> dict[str, Any]:
        """Its keys in ``result.json``'s ``"extra"`` object (at its top level)."""
        return self.to_json()
