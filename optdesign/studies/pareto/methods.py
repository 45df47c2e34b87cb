"""Front methods as objects holding their settings, behind one :func:`compute_front`.

- :class:`EpsilonConstraint`: exact anchors (multistart, lexicographic tie-break), then
  warm-started chains of ``min B s.t. A <= eps``, evenly spread along the front (arc
  spacing) or in epsilon (``spacing="uniform"``); three objectives on a grid of rows.
- :class:`WeightedSum`: normalised weighted sums (finds only the convex hull).
- :class:`NSGA2`: pymoo's NSGA-II on the NumPy path of the same problem (the baseline).

Every run of the first two goes through :func:`optdesign.runtime.runner.run_tasks`: each
record is written to a JSONL store as it finishes (resumable), on local processes or a
Dask cluster. The store's identity (:func:`run_key`) holds the problem's content, its
formulation, the objectives, the method's settings, the solver with every option and the
optdesign version, and every stored record is checked again before a resume trusts it
(:func:`~optdesign.studies.pareto.records.record_problem`), so a resumed run never mixes
records of another problem, setting or solver option, nor shows a tampered record.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from optdesign.argument_checks import DEFAULT_FRONT_POINTS, ArgumentError
from optdesign.errors import InputError, ProblemError
from optdesign.formulations.catalogue.discrete import CatalogueCoordinates
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.problem.design_problem import DesignProblem
from optdesign.runtime.runner import forks_workers, process_pool
from optdesign.solvers.multistart import improves
from optdesign.solvers.registry import FRONT_SOLVERS
from optdesign.studies.pareto.chains import (
    TwoChains,
    anchor_tasks,
    check_anchor,
    three_objective_tasks,
)
from optdesign.studies.pareto.front import Front
from optdesign.studies.pareto.polish import MAX_ROUNDS, round_tasks
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.pareto.run_setup import (
    RunOptions,
    check_front_problem,
)
from optdesign.studies.pareto.tasks import ANCHOR_SLACK, front_task
from optdesign.studies.pareto.template import (
    FrontMethod,
    FrontRun,
    Traced,
    has_catalogue,
    leaves_catalogue,
)
from optdesign.tolerances import FEASIBILITY_TOL, OBJECTIVE_TIE_TOL


def _common(
    problem: DesignProblem, objectives: Sequence[str], solver: str, **more
) -> dict[str, Any]:
    return {"problem": problem, "objectives": sorted(objectives), "solver": solver, **more}


@dataclass
class EpsilonConstraint(FrontMethod):
    """Epsilon-constraint fronts of two or three objectives.

    Attributes
    ----------
    points
        Points of the sweep (2 objectives), or about that many grid points (3).
    spacing
        ``"arc"`` (default): evenly along the front (L1 arc length in normalised
        objectives, predicted from the neighbour's multiplier); ``"uniform"``: epsilon
        evenly spaced (sparse where the front is steep).
    eps_values
        Explicit epsilon values of the first objective (overrides ``points``, ``spacing``).
    starts, seed
        Multistart of the anchors (default: the problem file's).
    agree
        An anchor's multistart stops once this many starts agree (None: all starts).
    solver
        The sweep's back-end, one of the registry's
        :data:`~optdesign.solvers.registry.FRONT_SOLVERS` choices: its primary (default,
        ``"sqpmethod"``: CasADi's SQP sweep, Ipopt fallback and tie-breaks), ``"slsqp"``
        (SciPy's SLSQP sweep, the same fallback and tie-breaks) or its fallback
        (``"ipopt"`` throughout).
    retry_starts, extra_starts
        Sobol starts for a point that fails, worsens or jumps; at every point.
    deterministic
        True (default): the chains meet in the middle whatever the timing, so the front
        is the same for any number of workers and a resumed run equals an uninterrupted
        one. False: they meet where timing makes them meet (faster with several workers;
        the front may then depend on the workers).
    name
        Name of the method and of its store (``{name}.jsonl``).
    """

    points: int = 50
    spacing: str = "arc"
    eps_values: Sequence[float] | None = None
    starts: int | None = None
    seed: int | None = None
    agree: int | None = 3
    solver: str = FRONT_SOLVERS.primary
    retry_starts: int = 4
    extra_starts: int = 0
    deterministic: bool = True
    name: str = "epsilon"

    honours_time_limit: ClassVar[bool] = True

    @property
    def n_points(self) -> int:
        return len(self.eps_values) if self.eps_values is not None else self.points

    def check_settings(self) -> None:
        if self.spacing not in ("arc", "uniform"):
            raise InputError("spacing", f"{self.spacing!r}: use 'arc' or 'uniform'")
        if self.n_points < 2:
            raise InputError("points", f"a front needs at least 2 points, got {self.n_points}")

    def settings(self, starts: int, seed: int, objectives: Sequence[str]) -> dict[str, Any]:
        mine = {k: v for k, v in asdict(self).items() if k != "name"}
        return {**mine, "starts": starts, "seed": seed}

    def identity(self, starts: int, seed: int, objectives: Sequence[str]) -> tuple[str, dict]:
        return self.solver, {"method": "epsilon", **self.settings(starts, seed, objectives)}

    def trace(self, ctx: FrontRun) -> Traced:
        problem, objectives, run = ctx.problem, ctx.objectives, ctx.run
        n_points = self.n_points
        common = _common(
            problem,
            objectives,
            self.solver,
            retry_starts=self.retry_starts,
            extra_starts=self.extra_starts,
            seed=ctx.seed,
        )
        if run.workers > 1 and run.scheduler is None and forks_workers():
            # Forked workers inherit the formulation built here instead of each building
            # its own; their solvers they build side by side on first use.
            formulation_for(problem, tuple(sorted(objectives)))
        label = f"{self.name}: points" if run.progress else False
        with process_pool(run.workers if run.scheduler is None else 1) as pool:
            # Every phase of the front shares the store, the identity and the workers.
            phase = functools.partial(
                ctx.tasks,
                fn=front_task,
                progress=label,
                pool=pool,
                stop=_deadline_passed if run.time_limit is not None else None,
            )
            anchor_list = anchor_tasks(common, objectives, ctx.starts, ctx.seed, self.agree)
            if len(objectives) == 2:
                split = n_points // 2 if self.deterministic else None
                sweep = TwoChains(
                    objectives, n_points, self.name, common, self.spacing, self.eps_values, split
                )
                done = phase(anchor_list, resume=run.resume, expand=sweep)
                anchors = _anchors(done, objectives, run)
                tasks, single = sweep.tasks, sweep.single
                done, latest = _polish(phase, done, tasks, self.name, common)
            else:
                # Three objectives: the rows need every anchor (the nadir of B), so the
                # anchors run first, then the rows in parallel.
                done = phase(anchor_list, resume=run.resume)
                anchors = _anchors(done, objectives, run)
                for k, rec in anchors.items():
                    check_anchor(rec, k, problem)
                tasks = three_objective_tasks(anchors, objectives, n_points, self.name, common)
                known = {f"anchor-{k}": done[f"anchor-{k}"] for k in objectives}
                # the anchors are in the store already: resume over them
                done = phase(tasks, resume=True, known=known)
                latest, single = {}, False
        recs = [
            PointRecord.from_dict(done[latest.get(t["id"], t["id"])])
            for t in sorted(tasks, key=lambda t: t["index"])
            if t["id"] in done  # a time limit leaves the points not begun out
        ]
        notes = []
        if single:
            notes.append(
                f"{objectives[0]}'s optimum also has the least {objectives[1]} (to a relative "
                f"{OBJECTIVE_TIE_TOL:g}): the front is that one design, not swept"
            )
        elif len(recs) < n_points:
            notes.append(
                f"time limit of {run.time_limit:g} s reached: {n_points - len(recs)} of "
                f"{n_points} points not computed (no point begins after the limit; "
                f"{_resume_hint(run)} computes them)"
            )
        n_solves = sum(r.n_solves for r in recs) + sum(r.n_solves for r in anchors.values())
        return Traced(recs, anchors, n_solves, notes)


def _polish(
    phase: Callable[..., dict],
    done: dict[str, Any],
    tasks: Sequence[Mapping[str, Any]],
    name: str,
    common: Mapping[str, Any],
) -> tuple[dict[str, Any], dict[str, str]]:
    """The polish rounds of a two-objective front (:mod:`optdesign.studies.pareto.
    polish`): the records with the rounds' added, and each point's latest record id."""
    points = sorted((t for t in tasks if t["id"] in done), key=lambda t: t["index"])
    if len(points) < len(tasks):  # a time limit left points out: nothing to polish
        return done, {}
    first = [t["id"] for t in points]
    ids = list(first)
    current = [PointRecord.from_dict(done[i]) for i in ids]
    improved: set[int] | None = None
    for round_no in range(1, MAX_ROUNDS + 1):
        seen_ids = list(done)
        seen = [PointRecord.from_dict(done[i]) for i in seen_ids]
        round_list = round_tasks(current, ids, seen, seen_ids, improved, round_no, name, common)
        if not round_list:
            break
        done = {**done, **phase(round_list, resume=True, known=done)}
        if any(t["id"] not in done for t in round_list):
            break  # the time limit: the points keep what they have
        improved = set()
        for t in round_list:
            i, new = t["index"], PointRecord.from_dict(done[t["id"]])
            if new.success and (
                not current[i].success
                or improves(new.objectives[new.target], current[i].objectives[new.target])
            ):
                improved.add(i)
                current[i], ids[i] = new, t["id"]
        if not improved:
            break
    return done, {a: b for a, b in zip(first, ids, strict=True) if a != b}


def _deadline_passed() -> bool:
    from optdesign.solvers import deadline

    return deadline.passed()


def _resume_hint(run: RunOptions) -> str:
    return "resuming the run in its folder" if run.out is not None else "a run with an out folder"


def _anchors(done, objectives: Sequence[str], run: RunOptions) -> dict[str, PointRecord]:
    """The anchors' records; a time limit that passed before they were all computed is
    said so (a front needs both ends)."""
    missing = [k for k in objectives if f"anchor-{k}" not in done]
    if missing:
        raise InputError(
            "time_limit",
            f"{run.time_limit:g} s passed before the anchors ({', '.join(missing)}) were "
            f"computed: give more time, or {_resume_hint(run)} continues",
        )
    return {k: PointRecord.from_dict(done[f"anchor-{k}"]) for k in objectives}


@dataclass
class WeightedSum(FrontMethod):
    """Weighted sum of the normalised objectives (ideal 0, nadir 1), weights evenly
    spaced. It finds only the convex hull of the front: points in non-convex parts are
    missed whatever the weights."""

    points: int = 50
    starts: int | None = None
    seed: int | None = None
    name: str = "weighted_sum"

    def identity(self, starts: int, seed: int, objectives: Sequence[str]) -> tuple[str, dict]:
        return FRONT_SOLVERS.fallback, {
            "method": "weighted_sum",
            "n": self.points,
            "starts": starts,
            "seed": seed,
        }

    def trace(self, ctx: FrontRun) -> Traced:
        problem, objectives, run = ctx.problem, ctx.objectives, ctx.run
        common = _common(problem, objectives, FRONT_SOLVERS.fallback)
        done = ctx.tasks(anchor_tasks(common, objectives, ctx.starts, ctx.seed, 3), front_task)
        anchors = {k: PointRecord.from_dict(done[f"anchor-{k}"]) for k in objectives}
        for k, rec in anchors.items():
            check_anchor(rec, k, problem)  # the weights are normalised between them
        F = np.array([[r.objectives[k] for k in objectives] for r in anchors.values()])
        ideal, nadir = F.min(axis=0), F.max(axis=0)
        normalise = {k: (float(ideal[j]), float(nadir[j])) for j, k in enumerate(objectives)}
        tasks, prev = [], f"anchor-{objectives[-1]}"
        for i, w in enumerate(_weight_grid(len(objectives), self.points)):
            # Zero weights make ties (the anchors' non-uniqueness); a tiny floor breaks them.
            weights = {k: float(max(wk, 1e-4)) for k, wk in zip(objectives, w, strict=True)}
            tasks.append(
                {
                    **common,
                    "id": f"ws-{i:04d}",
                    "kind": "weighted_sum",
                    "weights": weights,
                    "normalise": normalise,
                    "warm": prev,
                    "after": [prev],
                    "x0": anchors[objectives[-1]].x,
                }
            )
            prev = tasks[-1]["id"]
        done = ctx.tasks(
            tasks,
            front_task,
            workers=1,
            scheduler=None,
            resume=True,
            progress="weighted sum" if run.progress else False,
            known={f"anchor-{objectives[-1]}": done[f"anchor-{objectives[-1]}"]},
        )
        recs = [PointRecord.from_dict(done[t["id"]]) for t in tasks]
        return Traced(recs, anchors, len(recs) + sum(r.n_solves for r in anchors.values()))


def _weight_grid(m: int, n_points: int) -> list[tuple[float, ...]]:
    if m == 2:
        return [(w, 1 - w) for w in np.linspace(0.0, 1.0, n_points)]
    side = max(2, math.ceil((math.sqrt(8 * n_points + 1) - 1) / 2))
    return [
        (i / (side - 1), j / (side - 1), 1 - (i + j) / (side - 1))
        for i in range(side)
        for j in range(side - i)
    ]


@dataclass
class NSGA2(FrontMethod):
    """NSGA-II (pymoo) on the NumPy path of the same problem: its final non-dominated
    feasible population, each point checked with the same independent check."""

    pop_size: int = 100
    generations: int = 500
    seed: int = 0
    name: str = "nsga2"

    designs: ClassVar[str] = "any"  # searched as indices of the catalogue items
    stored: ClassVar[bool] = False
    smooth: ClassVar[bool] = False  # the NumPy path's values, computed when read

    def settings(self, starts: int, seed: int, objectives: Sequence[str]) -> dict[str, Any]:
        return {"pop_size": self.pop_size, "generations": self.generations, "seed": self.seed}

    def trace(self, ctx: FrontRun) -> Traced:
        from pymoo.algorithms.moo.nsga2 import NSGA2 as PymooNSGA2
        from pymoo.optimize import minimize

        problem, objectives = ctx.problem, ctx.objectives
        res = minimize(
            pymoo_problem(problem, objectives),
            PymooNSGA2(pop_size=self.pop_size),
            ("n_gen", self.generations),
            seed=self.seed,
            verbose=False,
        )
        recs = []
        X = np.atleast_2d(res.X) if res.X is not None else np.zeros((0, len(problem.free)))
        if res.X is None and res.pop is not None and len(res.pop):
            # no feasible design: keep the least violating one, for the report to name
            # what it violates (it is rejected as infeasible below)
            cv = np.asarray(res.pop.get("CV"), dtype=float).ravel()
            X = np.atleast_2d(res.pop.get("X")[int(np.argmin(cv))])
        X = CatalogueCoordinates(problem).to_design(X)
        if len(X):
            ev = problem.evaluate(X)
            for j, x in enumerate(X):
                ok = bool(ev.violation[j] <= FEASIBILITY_TOL)
                design = {**problem.fixed_values, **problem.design_dict(x)}
                recs.append(
                    PointRecord(
                        id=f"nsga2-{j:04d}",
                        kind="nsga2",
                        status="feasible" if ok else "infeasible",
                        verified=ok,
                        target="",
                        design={k: float(v) for k, v in design.items()},
                        objectives={k: float(v[j]) for k, v in ev.objectives.items()},
                        wall_time_s=0.0,
                        n_solves=0,
                    )
                )
        return Traced(recs)


def pymoo_problem(problem: DesignProblem, objectives: Sequence[str]):
    """The problem as a vectorised pymoo ``Problem`` (NumPy path, relative violations).

    Catalogue variables are searched as indices of their items
    (:class:`~optdesign.formulations.catalogue.discrete.CatalogueCoordinates`): every design
    evaluated is a catalogue design."""
    from pymoo.core.problem import Problem

    n_con = len(problem.evaluate(problem.start()[None, :]).constraints)
    coords = CatalogueCoordinates(problem)
    lower, upper = (np.array(b, dtype=float) for b in zip(*coords.bounds, strict=True))

    class _Vectorised(Problem):
        def __init__(self):
            super().__init__(
                n_var=len(problem.free),
                n_obj=len(objectives),
                n_ieq_constr=n_con,
                xl=lower,
                xu=upper,
            )

        def _evaluate(self, X, out, *args, **kwargs):
            ev = problem.evaluate(coords.to_design(X))
            out["F"] = np.column_stack(
                [np.nan_to_num(ev.objectives[k], nan=1e6, posinf=1e6) for k in objectives]
            )
            G = []
            for block in ev.constraints.values():
                # G <= 0 feasible: the largest signed relative violation of the block.
                v = np.asarray(block.values, dtype=float).reshape(len(X), -1)
                g = np.full(v.shape, -np.inf)
                if block.lower is not None:
                    g = np.maximum(g, (block.lower - v) / max(1.0, abs(block.lower)))
                if block.upper is not None:
                    g = np.maximum(g, (v - block.upper) / max(1.0, abs(block.upper)))
                g = np.nan_to_num(g.max(axis=1), nan=1e6)
                if block.unchecked is not None:  # not computed: another row already fails
                    g = np.where(block.unchecked, 0.0, g)
                G.append(g)
            out["G"] = np.column_stack(G)

    return _Vectorised()


#: method name -> settings class; ``"uniform"`` is epsilon with uniform spacing.
METHODS: dict[str, Callable[..., Any]] = {
    "epsilon": EpsilonConstraint,
    "uniform": lambda **kw: EpsilonConstraint(spacing="uniform", name="uniform", **kw),
    "weighted_sum": WeightedSum,
    "nsga2": NSGA2,
}

_RUN_FIELDS = (
    "out",
    "workers",
    "scheduler",
    "resume",
    "progress",
    "on_record",
    "overwrite",
    "time_limit",
)


def make_method(
    problem: DesignProblem, method: str | Any = "epsilon", points: int = 50, **settings: Any
) -> Any:
    """The method object of ``method`` (a name of :data:`METHODS` with its ``settings``,
    or a method object, returned as given): the one way the command line and
    :func:`optdesign.pareto` build a front method. On a problem with catalogue variables,
    ``"epsilon"`` and ``"uniform"`` are the catalogue front (:class:`CatalogueEpsilon`,
    every point a catalogue design; it takes ``points``, ``starts`` and ``seed``)."""
    if not isinstance(method, str):
        if settings:
            raise ProblemError(
                f"options {sorted(settings)} go into the method object, not pareto()"
            )
        return method
    if method not in METHODS:
        raise InputError("method", f"unknown method {method!r} (known: {', '.join(METHODS)})")
    if has_catalogue(problem):
        # every point a catalogue design: each one solved by the catalogue search
        if method not in ("epsilon", "uniform", "nsga2"):
            raise InputError("method", leaves_catalogue(method))
        if method != "nsga2":
            from optdesign.studies.pareto.catalogue_front import CatalogueEpsilon

            keep = {k: settings[k] for k in ("starts", "seed") if k in settings}
            return CatalogueEpsilon(points=settings.get("points", points), **keep)
    if method == "nsga2":
        settings.pop("solver", None)
    else:
        settings.setdefault("points", points)
    try:
        return METHODS[method](**settings)
    except TypeError as exc:
        raise InputError("pareto", f"option not understood by {method!r}: {exc}") from None


def check_time_limit(method: Any, time_limit: float | None, field: str = "time_limit") -> None:
    """Refuse a time limit the method (an object, see :func:`make_method`) does not
    apply: only a continuous epsilon sweep stops at one. The one refusal of
    :func:`optdesign.pareto` and ``optdesign pareto``, before any work."""
    if time_limit is None or getattr(method, "honours_time_limit", False):
        return
    what = getattr(method, "what", FrontMethod.what)
    if what == FrontMethod.what:  # a method that does not describe itself: its name
        what = f"the {getattr(method, 'name', type(method).__name__)} method"
    raise ArgumentError(
        field, f"not applied by {what}: only a continuous epsilon sweep stops at a time limit"
    )


def compute_front(
    problem: DesignProblem,
    objectives: Sequence[str],
    points: int = DEFAULT_FRONT_POINTS,
    method: str | Any = "epsilon",
    **options: Any,
) -> Front:
    """The front of ``objectives`` by ``method`` (a name of :data:`METHODS` or a method
    object with ``run(problem, objectives, RunOptions)``, see :func:`make_method`).
    ``options`` holds the run's options (``out``, ``workers``, ``scheduler``, ``resume``,
    ``progress``, ``on_record``, ``overwrite``, ``time_limit``) and the method's settings
    (see the method classes)."""
    check_front_problem(problem)
    run = RunOptions(**{k: options.pop(k) for k in _RUN_FIELDS if k in options})
    if run.workers < 1:
        raise InputError("workers", f"need at least 1 worker, got {run.workers}")
    method = make_method(problem, method, points, **options)
    check_time_limit(method, run.time_limit)
    store_name = getattr(method, "name", None)
    if run.overwrite and run.out is not None and not run.resume and store_name:
        from optdesign import storage

        with storage.lock_folder(run.out):
            storage.discard_store(Path(run.out) / f"{store_name}.jsonl")
    from optdesign.solvers.deadline import deadline

    with deadline(run.time_limit):
        return method.run(problem, objectives, run)


def __getattr__(name: str) -> Any:
    # The catalogue front imports the catalogue search (~50 ms): only a problem with
    # catalogue variables needs it, so it is imported when named.
    if name == "CatalogueEpsilon":
        from optdesign.studies.pareto.catalogue_front import CatalogueEpsilon

        return CatalogueEpsilon
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ANCHOR_SLACK",
    "METHODS",
    "NSGA2",
    "EpsilonConstraint",
    "FrontMethod",
    "RunOptions",
    "WeightedSum",
    "check_front_problem",
    "check_time_limit",
    "compute_front",
    "make_method",
]
