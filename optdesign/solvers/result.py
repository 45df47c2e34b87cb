"""One result schema for every solver (after Pyomo's contrib.solver results).

``termination`` says why the solver stopped, ``solution_status`` what the returned point
is; ``status`` is the one word users and scripts read ("optimal", "feasible",
"infeasible", "failed", "max_iterations", "time_limit"). Bounds and certificates are
typed fields, not dictionary entries.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from enum import Enum, StrEnum
from typing import Any, ClassVar

from optdesign.models.impossibility import Impossibility
from optdesign.solvers.details import Details
from optdesign.solvers.solved_point import SolvedPoint, in_key_order


class TerminationCondition(StrEnum):
    """Why the solver stopped."""

    CONVERGED = "converged"
    ACCEPTABLE = "acceptable"
    MAX_ITERATIONS = "max_iterations"
    MAX_TIME = "max_time"
    INFEASIBLE = "infeasible"
    UNBOUNDED = "unbounded"
    NUMERICAL_ERROR = "numerical_error"
    ERROR = "error"
    INTERRUPTED = "interrupted"
    UNKNOWN = "unknown"


class SolutionStatus(StrEnum):
    """What the returned point is."""

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    INFEASIBLE = "infeasible"
    NO_SOLUTION = "no_solution"


@dataclass
class ConstraintReport:
    """One constraint row at the returned point, in the problem's units.

    ``amount`` is the violation (> 0 violated) in the constraint's unit.
    """

    name: str
    value: float
    lower: float | None
    upper: float | None
    amount: float = 0.0
    unit: str = ""

    def describe(self) -> str:
        bound = []
        if self.lower is not None:
            bound.append(f">= {self.lower:.6g}")
        if self.upper is not None:
            bound.append(f"<= {self.upper:.6g}")
        limits = " and ".join(bound) or "must be a number"  # a row without bounds: NaN
        text = f"{self.name} = {self.value:.6g} {self.unit} ({limits})".replace("  ", " ")
        if 0 < self.amount < float("inf"):
            text += f", violated by {self.amount:.3g} {self.unit}".rstrip()
        return text


def percent(p: float) -> str:
    """A probability as summaries write it: ``"0.4 %"``, ``"< 0.1 %"``, ``"12 %"``."""
    if p < 1e-3:
        return "< 0.1 %"
    return f"{100 * p:.2g} %" if p < 0.1 else f"{100 * p:.0f} %"


@dataclass(frozen=True)
class Odds:
    """What the counted starts of a search say about the optima not seen
    (:func:`optdesign.search.odds.odds`: Boender and Rinnooy Kan's estimates).

    Attributes
    ----------
    starts, optima
        The counted starts (independent draws that converged) and the distinct local
        optima they reached.
    expected_optima
        The posterior mean of the number of local optima (inf: fewer than ``optima + 3``
        counted starts).
    p_better
        The estimated probability that an optimum better than the best seen exists: the
        expected share of the starts' distribution held by regions not reached yet (1.0
        while the posterior is improper).
    p_better_any
        The cautious figure: the best optimum any of them with equal chance, whatever the
        size of its region.
    """

    starts: int
    optima: int
    expected_optima: float
    p_better: float
    p_better_any: float

    @property
    def expected_unseen(self) -> float:
        """The expected number of local optima not seen yet."""
        return self.expected_optima - self.optima

    def text(self) -> str:
        """``"3 local optima seen in 24 starts; estimated probability that a better one
        exists: 2.2 %"``."""
        s = "" if self.starts == 1 else "s"
        seen = f"{self.optima} local optim{'um' if self.optima == 1 else 'a'} seen in "
        seen += f"{self.starts} counted start{s}"
        if self.optima == 0:
            return seen
        if self.p_better >= 1.0:
            return seen + "; too few starts to estimate the odds of a better one"
        return seen + f"; estimated probability that a better one exists: {percent(self.p_better)}"


@dataclass
class Globality:
    """What is known of whether an optimum is the global one, in words that say exactly
    what was checked.

    Attributes
    ----------
    proved
        True only where a certificate covers the whole problem (a convex program's dual
        bound).
    basis
        What the claim rests on: ``"a geometric program: convex; dual bound within
        1e-9"``, ``"the global search stopped at its cap of 32 starts"``, ...
    odds
        The global search's odds (:class:`Odds`), when a search ran.
    """

    proved: bool = False
    basis: str = ""
    odds: Odds | None = None

    def text(self) -> str:
        """``"proved (a geometric program: ...)"`` or ``"not proved; 1 local optimum seen
        in 8 counted starts; estimated probability that a better one exists: 3.6 %"``."""
        if self.proved:
            return f"proved ({self.basis})" if self.basis else "proved"
        parts = ["not proved"]
        if self.odds is not None:
            parts.append(self.odds.text())
        if self.basis:
            parts.append(self.basis)
        return "; ".join(parts)


@dataclass
class MultistartInfo:
    """How a multistart went.

    ``optima`` (the distinct local optima's values, best first), ``counted`` (the starts
    the odds count: independent draws that converged), ``odds`` and ``stop`` (why the
    search stopped: ``"odds"``, ``"agree"``, ``"all starts run"``, ``"time limit"``, ``"no
    feasible start"``) are filled by the global search (:mod:`optdesign.search`); a plain
    multistart over a given list of starts leaves them empty.
    """

    n_starts: int
    n_converged: int
    n_at_best: int
    tolerance: float
    objectives: list[float] = field(default_factory=list)
    seed: int = 0
    workers: int = 1
    n_planned: int | None = None
    stopped_early: bool = False
    #: How each start ended, in start order: "converged" or why not ("restoration
    #: failed", "iteration limit", "time limit", "not assembling", "locally
    #: infeasible", ...: :func:`optdesign.solvers.multistart.start_outcome`).
    outcomes: list[str] = field(default_factory=list)
    #: The starts that did not converge, counted by reason (most frequent first).
    failed: dict[str, int] = field(default_factory=dict)
    optima: list[float] = field(default_factory=list)
    counted: int = 0
    odds: Odds | None = None
    stop: str = ""
    #: Starts solved on a stand-in of the problem (its grid thinned) whose local optima
    #: were solved again on the problem itself: how many were (0: the starts solved the
    #: problem itself), and the stand-in's grid angles against the problem's.
    polished: int = 0
    search_points: int = 0
    grid_points: int = 0

    def failure_text(self) -> str:
        """``"5 failed: 3 restoration failed, 2 iteration limit"``; "" when none failed."""
        n = sum(self.failed.values())
        if not n:
            return ""
        return f"{n} failed: " + ", ".join(f"{k} {why}" for why, k in self.failed.items())


@dataclass
class Certificate:
    """A proof of optimality: a lower bound from duality (e.g. a GP's dual function).

    ``gap_rel`` = (objective - lower_bound)/|objective|.
    """

    kind: str
    lower_bound: float
    objective: float
    gap_rel: float


@dataclass
class Relaxation:
    """The smallest change of one requirement that makes the problem feasible, in the
    requirement rows' own (internal) quantity; reports show it as the user wrote it
    (:func:`optdesign.display.limits.relaxation_limits`).

    Attributes
    ----------
    name
        The requirement (constraint block) name.
    upper
        True when its upper limit must rise, False when its lower limit must fall.
    written, needed
        The row limit as written and the one that makes the problem feasible (None:
        relaxing this requirement alone gave no feasible design).
    lower_row, upper_row
        Both row bounds as written (for showing a band ``|x| <= a`` as its magnitude).
    solves
        Solves spent on it.
    at
        Where it holds when not at the diagnosis' basis (other catalogue items), else "".
    """

    name: str
    upper: bool
    written: float
    needed: float | None
    lower_row: float | None = None
    upper_row: float | None = None
    solves: int = 0
    at: str = ""


@dataclass
class Diagnosis:
    """Why no feasible design was found: the smallest relaxation of each conflicting
    requirement, what they were computed on, or why there are none.

    Attributes
    ----------
    relaxations
        One record per requirement in the conflict (empty when none was computed).
    basis
        What the relaxations rest on, in words (``"the NLP"``, ``"the catalogue items
        d = 6 mm, p = 2 mm"``, ``"the fixed design"``).
    note
        Why no relaxation is given, or what a reader must know about them (empty if
        nothing).
    together
        When no requirement relaxed alone gives a feasible design: the set to relax
        together and the limit each needs (empty otherwise).
    physical
        The conditions of the physics the best point violates (the linkage passes a
        dead point inside the stroke, or does not assemble): no relaxation of a
        requirement is proposed for them; the stroke or the bounds must change.
    impossible
        Closed-form proofs, found before any solve, that no design within the bounds
        meets the requirements they name (the mechanism's necessary conditions,
        :class:`~optdesign.models.impossibility.Impossibility`); empty otherwise.
    """

    relaxations: list[Relaxation] = field(default_factory=list)
    basis: str = ""
    note: str = ""
    together: list[Relaxation] = field(default_factory=list)
    physical: list[str] = field(default_factory=list)
    impossible: list[Impossibility] = field(default_factory=list)


@dataclass
class Sensitivity:
    """What one requirement (or active variable bound) costs at an optimum.

    Attributes
    ----------
    name
        ``"requirements.hinge_moment"``, ``"requirements.mean_ratio.min"`` or
        ``"variables.R.upper"``: where the file states it.
    objective
        The objective whose optimum it moves.
    limit, unit
        The requirement's (bound's) value as the user reads it.
    d_objective_d_limit, objective_unit
        d(optimal objective)/d(limit), in ``objective_unit`` per ``unit``.
    log_sensitivity
        % change of the optimal objective per % change of the limit (None when the
        objective is 0).
    """

    name: str
    objective: str
    limit: float
    unit: str
    d_objective_d_limit: float
    objective_unit: str = ""
    log_sensitivity: float | None = None

    def text(self) -> str:
        """One line of what the limit costs, saying which way the limit moves (1.01 x a
        negative limit lowers it; for a variable's bound, whether the box widens)::

            hinge_moment 500 N*m: raising it by 1 % to 505 N*m -> backlash +0.235 %
            variables.gx.lower -150 mm: lowering it by 1 % to -151.5 mm (widens the
                bounds) -> backlash -1.2 %

        A limit at 0 (1 % is no move) or an objective at 0 (no % of it): the derivative
        per unit instead, with the limit raised."""
        what = self.name.removeprefix("requirements.")
        limit = _number(self.limit, self.unit)
        log = self.log_sensitivity
        if log is not None and self.limit != 0 and math.isfinite(self.limit):
            up = self.limit > 0  # 1.01 x the limit: up when positive, down when negative
            to = _number(1.01 * self.limit, self.unit)
            move = f"{'raising' if up else 'lowering'} it by 1 % to {to}"
            return (
                f"{what} {limit}: {move}{_bound_move(self.name, up)} -> "
                f"{self.objective} {log:+.3g} %"
            )
        d = self.d_objective_d_limit
        if not math.isfinite(d):  # a sweep keeps the log-sensitivity only
            return f"{what} {limit}: its cost per {self.unit or 'unit'} is not kept here"
        per = f"{self.objective_unit}/{self.unit}" if self.unit else self.objective_unit
        return (
            f"{what} {limit}: raising it{_bound_move(self.name, True)} -> "
            f"d{self.objective}/d{what} = {d:+.3g} {per}".rstrip()
        )


def _number(value: float, unit: str) -> str:
    return f"{value:.6g} {unit}".rstrip()


def _bound_move(name: str, up: bool) -> str:
    """`` (widens the bounds)`` or `` (narrows the bounds)`` for a variable's bound
    moved up (``up``) or down; "" for a requirement (which way is looser depends on
    what it limits: a stroke's lower end moved down asks for more)."""
    if not name.startswith("variables."):
        return ""
    upper = name.endswith(".upper")
    return " (widens the bounds)" if up == upper else " (narrows the bounds)"


@dataclass
class ItemStep:
    """A catalogue optimum's neighbouring item: one catalogue variable moved one item up
    or down, the other items kept and the continuous part re-solved warm.

    Attributes
    ----------
    variable, item, chosen, unit
        The catalogue variable, the neighbouring item and the chosen one (user's unit).
    status
        The re-solve's status (``"infeasible"``: no design with this item).
    objective, objective_name, objective_unit, change_percent
        The optimum with this item (None when infeasible) and its change from the
        catalogue optimum in %.
    """

    variable: str
    item: float
    chosen: float
    unit: str
    status: str
    objective_name: str
    objective: float | None = None
    objective_unit: str = ""
    change_percent: float | None = None

    def text(self) -> str:
        """``"p 6 mm -> 8 mm: backlash 0.0351 deg (+3.2 %)"`` or ``"... : infeasible"``."""
        unit = f" {self.unit}" if self.unit else ""
        step = f"{self.variable} {self.chosen:g}{unit} -> {self.item:g}{unit}"
        if self.objective is None:
            return f"{step}: {self.status}"
        value = f"{self.objective:.6g} {self.objective_unit}".rstrip()
        change = "" if self.change_percent is None else f" ({self.change_percent:+.3g} %)"
        return f"{step}: {self.objective_name} {value}{change}"


@dataclass(kw_only=True)
class Result(SolvedPoint):
    """Outcome of one optimisation, whatever the solver: a solved point
    (:class:`~optdesign.solvers.solved_point.SolvedPoint`: status, verified, message,
    design, objectives, wall_time_s, iterations, solver, and the one success rule) with
    what a solve adds. Built by keyword.

    Attributes
    ----------
    objective, formulation
        The objective's value and the formulation that computed it.
    termination, solution_status
        Why the solver stopped and what the point is.
    objective_name
        What ``objective`` measures (an objective, a robust statistic, a weighted sum).
    n_evals
        Evaluation counters of the back-end.
    violated, active, max_violation
        Constraint rows at the point, by name and amount, in their units.
    bound
        A lower bound on the optimum when one is known (a relaxation's optimum, a dual
        bound), for the gap.
    certificate
        A duality certificate of the optimum (GP).
    globality
        What is known of whether the optimum is the global one (:class:`Globality`): a
        proof, or the global search's odds.
    multistart
        How the starts went.
    ranges
        Range of each free variable over the (near-)optimal set, when computed.
    diagnosis
        For a result with no feasible design: the relaxations of the conflicting
        requirements (:class:`Diagnosis`), when computed.
    sensitivities
        What each binding requirement and active bound costs (:class:`Sensitivity`),
        most costly first; empty when not computed.
    item_steps
        A catalogue optimum's neighbouring items (:class:`ItemStep`); empty otherwise.
    notes
        Plain-language remarks for the summary.
    details
        What the formulation adds, by its name (``details["catalogue"]``, or
        ``details.catalogue``: the formulation's own typed record), and a reference
        comparison (:class:`~optdesign.solvers.details.Details`); ``result.json`` writes
        it as ``"extra"``.
    """

    objective: float
    formulation: str
    termination: TerminationCondition = TerminationCondition.UNKNOWN
    solution_status: SolutionStatus = SolutionStatus.NO_SOLUTION
    objective_name: str = ""
    n_evals: dict[str, int] = field(default_factory=dict)
    violated: list[ConstraintReport] = field(default_factory=list)
    active: list[ConstraintReport] = field(default_factory=list)
    max_violation: float = math.nan
    bound: float | None = None
    certificate: Certificate | None = None
    globality: Globality | None = None
    multistart: MultistartInfo | None = None
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    diagnosis: Diagnosis | None = None
    sensitivities: list[Sensitivity] = field(default_factory=list)
    item_steps: list[ItemStep] = field(default_factory=list)
    problem: str = ""
    mechanism: str = ""
    notes: list[str] = field(default_factory=list)
    details: Details = field(default_factory=Details)
    # solver internals kept for warm starts (not written to JSON)
    raw: dict[str, Any] = field(default_factory=dict, repr=False)
    # the DesignProblem solved (for plots and tables; not written to JSON)
    problem_object: Any = field(default=None, repr=False, compare=False)

    #: The key order of :meth:`to_dict`: the one result files have always had.
    KEYS: ClassVar[tuple[str, ...]] = (
        "status",
        "objective",
        "design",
        "solver",
        "formulation",
        "wall_time_s",
        "termination",
        "solution_status",
        "message",
        "objective_name",
        "objectives",
        "iterations",
        "n_evals",
        "violated",
        "active",
        "max_violation",
        "verified",
    )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (enums as strings, NaN as None, no solver internals)."""
        problem, self.problem_object = self.problem_object, None
        try:
            d = asdict(self)
        finally:
            self.problem_object = problem
        d.pop("raw", None)
        d.pop("problem_object", None)
        # The details keep the key and layout result files have always had.
        d = {
            ("extra" if k == "details" else k): (self.details.to_json() if k == "details" else v)
            for k, v in d.items()
        }
        d["termination"] = self.termination.value
        d["solution_status"] = self.solution_status.value
        return clean_json(in_key_order(d, self.KEYS))

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), indent=kw.pop("indent", 2), **kw)

    # Reading a result (tables, frames, figures) lives with the reports and plots; these
    # methods only delegate, so that importing results costs neither pandas nor matplotlib.
    def summary(self) -> str:
        """The plain-text summary the CLI prints."""
        from optdesign.reports.solve_text import result_summary

        return result_summary(self)

    def to_frame(self):
        """A pandas DataFrame: one row per variable (value, bounds) and objective."""
        from optdesign.display.frames import result_frame

        return result_frame(self)

    def plot(self, ax=None):
        """Ratio and backlash over the stroke, optimum against the initial design; returns
        the matplotlib Figure (``ax``: draw the ratio on this axes instead)."""
        from optdesign.plots.solution import plot_result

        return plot_result(self, ax=ax)


def clean_json(obj):
    """A JSON-safe copy: enums as values, non-finite floats as None, NumPy scalars as
    Python numbers."""
    if isinstance(obj, dict):
        return {k: clean_json(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean_json(v) for v in obj]
    if isinstance(obj, Enum):
        return obj.value
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if hasattr(obj, "item") and callable(obj.item):  # numpy scalars
        return clean_json(obj.item())
    return obj
