"""Typed details of a result, by kind: a catalogue search, a GP solve, a robust optimum,
the comparison with a reference design.

Each kind is a record with named fields (:class:`Details` holds the ones a result has);
``result.json`` writes them under ``"extra"`` with the keys earlier releases wrote
(``extra.catalogue.items``, ``extra.gp_timing``, ``extra.risk_label``...), so scripts
reading result files see the same keys and values. These are plain records: they import
nothing from the layers above.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Any


def _fields_json(record: Any, omit_none: tuple[str, ...] = ()) -> dict[str, Any]:
    """The record's fields as a dict, in declaration order; those of ``omit_none`` only
    when set (a key that older files have only in some cases)."""
    out: dict[str, Any] = {}
    for f in fields(record):
        value = getattr(record, f.name)
        if value is None and f.name in omit_none:
            continue
        out[f.name] = asdict(value) if hasattr(value, "__dataclass_fields__") else value
    return out


@dataclass
class CatalogueCombination:
    """One combination of catalogue items solved by the enumeration."""

    items: dict[str, float]
    status: str
    objective: float


@dataclass
class MINLPDetails:
    """What a MINLP back-end did with a catalogue problem (method ``"minlp"``).

    Attributes
    ----------
    solver, algorithm, status
        The back-end (``"bonmin"``), its algorithm and its return status.
    binaries, groups
        One-hot binaries of the encoding, and the catalogue variables of each group.
    seconds
        Time of the encoding and the MINLP solve.
    items, objective_scaled
        The items it chose and its objective (the NLP's scaled one); None when it found
        no integer-feasible point.
    """

    solver: str
    algorithm: str
    status: str
    binaries: int
    groups: list[list[str]]
    seconds: float
    items: dict[str, float] | None = None
    objective_scaled: float | None = None

    def to_json(self) -> dict[str, Any]:
        return _fields_json(self, ("items", "objective_scaled"))


@dataclass
class CatalogueDetails:
    """How the exact catalogue optimum was found (:func:`optdesign.studies.catalogue.
    solve_catalogue`).

    Attributes
    ----------
    method
        ``"enumerate"``, ``"bnb"`` or ``"minlp"`` (a MINLP back-end picked the items).
    combinations
        Number of item combinations.
    variables
        The catalogue values of each discrete variable.
    relaxation_bound, relaxation_status, relaxation_design
        The continuous relaxation (every catalogue range at once): its optimum (None when
        it failed), status and design - a lower bound of the catalogue optimum.
    starts_per_node
        Multistart of each node's NLP.
    enumerated
        Every combination and its solve (enumeration only).
    nodes, pruned, infeasible, leaves
        Branch-and-bound counts (branch and bound only).
    seeded
        Nodes solved for the first incumbents (a front's neighbouring optima).
    warm_fallbacks
        Warm nodes that fell back to the full multistart.
    implied_infeasible
        Boxes proved infeasible with no NLP (:class:`~optdesign.studies.catalogue_bnb.
        InfeasibleBoxes`).
    minlp
        What the MINLP back-end did (method ``"minlp"`` only).
    nlp_solves
        NLP solves spent.
    items
        The items chosen (None: no feasible combination).
    gap_to_relaxation_rel
        (optimum - relaxation bound) / |relaxation bound| (None without a bound).
    """

    method: str
    combinations: int
    variables: dict[str, list[float]]
    relaxation_bound: float | None
    relaxation_status: str
    relaxation_design: dict[str, float | None]
    starts_per_node: int
    enumerated: list[CatalogueCombination] | None = None
    nodes: int | None = None
    pruned: int | None = None
    infeasible: int | None = None
    leaves: int | None = None
    seeded: int | None = None
    warm_fallbacks: int | None = None
    implied_infeasible: int | None = None
    minlp: MINLPDetails | None = None
    nlp_solves: int = 0
    items: dict[str, float] | None = None
    gap_to_relaxation_rel: float | None = None
    #: The boxes the search proved infeasible, with the epsilon limits of each proof
    #: (:class:`~optdesign.studies.catalogue_bnb.InfeasibleBoxes`): the neighbouring
    #: items of the optimum read them before solving. In memory only (not in result.json).
    infeasible_boxes: list[tuple[dict[str, tuple[float, float]], dict[str, float]]] = field(
        default_factory=list, repr=False
    )

    def to_json(self) -> dict[str, Any]:
        out = _fields_json(
            self,
            (
                "enumerated",
                "nodes",
                "pruned",
                "infeasible",
                "leaves",
                "seeded",
                "warm_fallbacks",
                "implied_infeasible",
                "minlp",
                "items",
                "gap_to_relaxation_rel",
            ),
        )
        if self.enumerated is not None:
            out["enumerated"] = [asdict(row) for row in self.enumerated]
        if self.minlp is not None:
            out["minlp"] = self.minlp.to_json()
        out.pop("infeasible_boxes")
        return out


@dataclass
class GPTiming:
    """Where a GP solve spent its time (seconds; None: not measured)."""

    build_s: float | None = None
    compile_s: float | None = None
    solver_s: float | None = None
    total_s: float | None = None
    certificate_s: float | None = None
    trace_s: float | None = None

    def to_json(self) -> dict[str, Any]:
        return _fields_json(self, tuple(f.name for f in fields(self)))


@dataclass
class GPDual:
    """The GP's dual: whether the dual bound's minimisation converged, and the multipliers
    of the active rows (row label -> multiplier)."""

    dual_bound_converged: bool
    multipliers: dict[str, float] = field(default_factory=dict)


@dataclass
class GPRows:
    """Sizes of the geometric program: objective rows, constraint rows, rows before the
    pruning of dominated ones."""

    objective: int
    constraints: int
    before_pruning: int


@dataclass
class ExactNLP:
    """The exact NLP (exact Hertz) solved from the GP design, for the GP's model gap."""

    status: str
    objective: float
    design: dict[str, float | None]
    wall_time_s: float
    starts: int


@dataclass
class GPDetails:
    """A GP solve: its dual, timing and size, and the exact NLP compared with it."""

    dual: GPDual | None = None
    timing: GPTiming | None = None
    rows: GPRows | None = None
    nlp_exact: ExactNLP | None = None
    #: (GP optimum - exact NLP optimum) / |exact NLP optimum| (NaN: the NLP failed).
    gap_gp_nlp_rel: float | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.dual is not None:
            out["gp_dual"] = asdict(self.dual)
        if self.timing is not None:
            out["gp_timing"] = self.timing.to_json()
        if self.rows is not None:
            out["gp_rows"] = asdict(self.rows)
        if self.nlp_exact is not None:
            out["nlp_exact"] = asdict(self.nlp_exact)
        if self.gap_gp_nlp_rel is not None:
            out["gap_gp_nlp_rel"] = self.gap_gp_nlp_rel
        return out


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
        out = _fields_json(self, ("saa_check", "nominal_optimum"))
        if self.nominal_optimum is not None:
            out["nominal_optimum"] = self.nominal_optimum.to_json()
        return out


@dataclass
class ReferenceComparison:
    """A reference design (the file's ``[reference]``) against the optimum, on the NumPy
    path of the same models (:func:`optdesign.studies.reference.compare_reference`).

    Attributes
    ----------
    label
        The reference's name.
    design
        Its free variables.
    quantities
        Per quantity (ripple, backlash, ratio band...): (reference, optimum).
    reference_violation, reference_violated
        The reference's largest relative violation and the requirements it violates.
    optimum_violation
        The optimum's largest relative violation.
    optimum_design
        The optimum's free variables.
    """

    label: str
    design: dict[str, float]
    quantities: dict[str, tuple[float, float]]
    reference_violation: float
    reference_violated: list[str]
    optimum_violation: float
    optimum_design: dict[str, float] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class Details:
    """The details a result has beyond the common fields, each typed (None: not that kind).

    Attributes
    ----------
    catalogue, gp, robust
        The catalogue search, the GP solve, the robust optimum.
    reference
        The comparison with the file's reference design.
    fallback
        Why an epsilon point was solved again by Ipopt ("" when it was not).
    """

    catalogue: CatalogueDetails | None = None
    gp: GPDetails | None = None
    robust: RobustDetails | None = None
    reference: ReferenceComparison | None = None
    fallback: str = ""

    def to_json(self) -> dict[str, Any]:
        """The ``"extra"`` object of ``result.json`` (the keys earlier releases wrote)."""
        out: dict[str, Any] = {}
        if self.gp is not None:
            out.update(self.gp.to_json())
        if self.robust is not None:
            out.update(self.robust.to_json())
        if self.catalogue is not None:
            out["catalogue"] = self.catalogue.to_json()
        if self.fallback:
            out["fallback"] = self.fallback
        if self.reference is not None:
            out["reference"] = self.reference.to_json()
        return out
