"""The template of every front method, written once: the checks and refusals, the store,
its identity, the seeds, the anchors' check and the wrap-up into a :class:`Front`.

A method is a small subclass of :class:`FrontMethod`: its settings (a dataclass), what it
refuses (:attr:`FrontMethod.designs`, :meth:`FrontMethod.check_settings`), the identity
of its store (:meth:`FrontMethod.identity`) and its step (:meth:`FrontMethod.trace`),
which gets a :class:`FrontRun` - the problem, the objectives, the store, its key, the
starts and seed, and :meth:`FrontRun.tasks` to run tasks through the checkpointed runner -
and returns its records (:class:`Traced`). :meth:`FrontMethod.run` does the rest, the
same for every method.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from optdesign.errors import InputError
from optdesign.formulations.nlp.solve import planned_starts
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.runtime.runner import run_tasks
from optdesign.studies.pareto.chains import check_anchor
from optdesign.studies.pareto.front import Front, FrontPoint, anchors_of, make_front
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.pareto.run_setup import (
    RunOptions,
    check_objectives,
    record_check,
    run_key,
    store_path,
)

_COUNTS = {2: "two", 3: "three"}


def has_catalogue(problem: DesignProblem) -> bool:
    """Some free variable takes catalogue values (a front must stay on them)."""
    return any(v.discrete for v in problem.free)


def leaves_catalogue(what: str) -> str:
    """The one refusal of a method whose points would leave the catalogue."""
    return f"{what} would leave the catalogue: with catalogue variables use epsilon or nsga2"


@dataclass
class FrontRun:
    """One run of a front method as the template set it up: what the method's step needs.

    Attributes
    ----------
    problem, objectives
        What the front trades (the objectives checked).
    run
        Where and how the tasks run (workers, scheduler, resume, progress, time limit).
    store, key
        The run's store and its identity (:func:`~optdesign.studies.pareto.run_setup.
        run_key`; None and empty for a method that stores nothing).
    starts, seed
        The anchors' multistart and seed (the method's, else the problem file's).
    check
        Why a stored record cannot be trusted (None: it can), for a resume.
    """

    problem: DesignProblem
    objectives: list[str]
    run: RunOptions
    store: Path | None
    key: dict[str, Any]
    starts: int
    seed: int
    check: Callable[[Mapping[str, Any]], str | None] | None

    def tasks(self, tasks: Sequence[Mapping[str, Any]], fn: Callable, **kw: Any) -> dict:
        """Run ``tasks`` through ``fn`` with the run's store, key, check, workers and
        resume (:func:`optdesign.runtime.runner.run_tasks`; ``kw`` overrides)."""
        settings: dict[str, Any] = {
            "workers": self.run.workers,
            "scheduler": self.run.scheduler,
            "resume": self.run.resume,
            "progress": False,
            "key": self.key,
            "on_record": self.run.on_record,
            "check": self.check,
            **kw,
        }
        return run_tasks(tasks, fn, self.store, **settings)


@dataclass
class Traced:
    """What a method's step returns: the front's records in order, the anchors (each
    checked by the template), the solves spent and notes for the reader."""

    records: list[PointRecord]
    anchors: dict[str, PointRecord] = field(default_factory=dict)
    n_solves: int = 0
    notes: list[str] = field(default_factory=list)


def smooth_refusal(method: Any, problem: DesignProblem, objectives: Sequence[str]) -> str:
    """Why front ``method`` (an object) cannot trace ``objectives``: one of them has no
    smooth form and the method solves NLPs (``""``: it can; NSGA-II reads the NumPy
    path's values)."""
    if not getattr(method, "smooth", True):
        return ""
    who = f"the front method {getattr(method, 'name', type(method).__name__)!r} (it solves NLPs)"
    return smooth_form_refusal(problem, objectives, who)


class FrontMethod:
    """Base of the front methods (see the module docstring); subclasses are dataclasses
    with a ``name`` field (the method's and its store's name)."""

    name: str
    #: Which problems it takes: ``"continuous"`` (refuses catalogue variables, whose
    #: points would leave the catalogue), ``"catalogue"`` (needs them) or ``"any"``.
    designs: ClassVar[str] = "continuous"
    #: Objective counts it traces.
    n_objectives: ClassVar[tuple[int, ...]] = (2, 3)
    #: Whether it stops at a run's time limit (no point begins after it).
    honours_time_limit: ClassVar[bool] = False
    #: Whether its records go to a resumable store (``{name}.jsonl``).
    stored: ClassVar[bool] = True
    #: What the method is, in messages.
    what: ClassVar[str] = "a front"
    #: Most starts of an anchor by default (None: the problem file's).
    max_default_starts: ClassVar[int | None] = None
    #: Whether it solves NLPs, which need each objective's smooth form (False: it reads
    #: the NumPy path's values only, as NSGA-II does).
    smooth: ClassVar[bool] = True

    # --- what a method says --------------------------------------------------------------
    def check_settings(self) -> None:
        """Refuse settings the method cannot run with (InputError naming the field)."""

    def identity(
        self, starts: int, seed: int, objectives: Sequence[str]
    ) -> tuple[str, dict[str, Any]]:
        """The back-end and the method's settings that identify its store."""
        raise NotImplementedError

    def settings(self, starts: int, seed: int, objectives: Sequence[str]) -> dict[str, Any]:
        """The settings written with the front (``Front.settings``)."""
        return {}

    def trace(self, ctx: FrontRun) -> Traced:
        """The method's step: its records, from the run the template set up."""
        raise NotImplementedError

    # --- the template --------------------------------------------------------------------
    def refuse(self, problem: DesignProblem, objectives: Sequence[str]) -> list[str]:
        """The checked objectives; refuse a problem or settings the method cannot take."""
        objectives = check_objectives(problem, objectives)
        refusal = smooth_refusal(self, problem, objectives)
        if refusal:
            raise InputError("objectives", refusal)
        if len(objectives) not in self.n_objectives:
            counts = " or ".join(_COUNTS[n] for n in self.n_objectives)
            raise InputError("objectives", f"{self.what} takes {counts} objectives")
        if self.designs == "continuous" and has_catalogue(problem):
            raise InputError(
                "method",
                leaves_catalogue(f"{type(self).__name__} {self.name!r}")
                + " (the name 'epsilon' picks CatalogueEpsilon there)",
            )
        if self.designs == "catalogue" and not has_catalogue(problem):
            raise InputError("method", f"{self.name}: no variable takes catalogue values")
        self.check_settings()
        return objectives

    def starts_and_seed(self, problem: DesignProblem) -> tuple[int, int]:
        """The method's ``starts`` and ``seed``, else the problem file's."""
        starts = getattr(self, "starts", None)
        if starts is None:
            starts = planned_starts(problem)
            if self.max_default_starts is not None:
                starts = min(starts, self.max_default_starts)
        seed = getattr(self, "seed", None)
        return starts, (seed if seed is not None else problem.spec.solver.seed)

    def run(self, problem: DesignProblem, objectives: Sequence[str], run: RunOptions) -> Front:
        """The front of ``objectives``: checks, store and identity, the method's step,
        the anchors' check, the front."""
        objectives = self.refuse(problem, objectives)
        t0 = time.perf_counter()
        starts, seed = self.starts_and_seed(problem)
        store, key, check = None, {}, None
        if self.stored:
            back_end, settings = self.identity(starts, seed, objectives)
            store = store_path(run.out, self.name)
            key = run_key(problem, objectives, back_end, **settings)
            check = record_check(problem, objectives)
        ctx = FrontRun(problem, objectives, run, store, key, starts, seed, check)
        traced = self.trace(ctx)
        for k, rec in traced.anchors.items():
            check_anchor(rec, k, problem)
        return make_front(
            [FrontPoint.from_record(r, self.name) for r in traced.records],
            objectives,
            self.name,
            time.perf_counter() - t0,
            problem,
            anchors=anchors_of(traced.anchors),
            store=str(store) if store is not None else "",
            n_solves=traced.n_solves,
            settings=self.settings(starts, seed, objectives),
            notes=traced.notes,
        )
