"""One validation layer for the public entry points, shared by the Python API and the CLI.

``od.load``, ``od.solve``, ``od.pareto``, ``od.bench`` and the :class:`~optdesign.
DesignProblem` methods a user calls check every argument here, before any work: its type
(``True`` is not an integer, nor is ``2.5``; NumPy integers are), its range (the caps
below, the same as the command line's), a known name (formulation, solver, objective,
method, suite, configuration: with the nearest valid one) and the options that exclude
each other. A refusal is an :class:`ArgumentError` (an :class:`~optdesign.errors.
InputError`) naming the argument: ``starts: 0 is outside 1..10000``.

The command line derives its argparse types from the same checks
(:func:`optdesign.cli.checked`) and renames the argument to its option
(``argument --starts: 0 is outside 1..10000``), so one check gives one message on
both paths. The checks of one argument that know no registry are
:mod:`optdesign.argument_checks` (re-exported here); the known names are looked up when a
check runs, so that nothing here imports a solver library.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

# The checks of one argument, re-exported: the CLI and the API call them as validation.X.
from optdesign.argument_checks import (  # noqa: F401
    DEFAULT_FRONT_POINTS,
    MAX_GENERATIONS,
    MAX_NAME,
    MAX_POINTS,
    MAX_POP,
    MAX_SECONDS,
    MAX_SEED,
    MAX_STARTS,
    MAX_WORKERS,
    ArgumentError,
    agree,
    choice,
    flag,
    function,
    generations,
    integer,
    is_integer,
    is_number,
    name,
    names,
    nearest,
    number,
    odds,
    path,
    points,
    pop_size,
    scheduler,
    seconds,
    seed,
    shown,
    starts,
    text,
    unit,
    workers,
)
from optdesign.errors import InputError
from optdesign.solvers.registry import FRONT_SOLVERS, solver_hints, solver_names


def formulation(argument: str, value: Any) -> str:
    """``auto`` or a registered formulation."""
    from optdesign.formulations.registry import formulation_names

    return choice(argument, value, ["auto", *formulation_names()], "formulation")


def solver(argument: str, value: Any) -> str | None:
    """A registered solver back-end (NLP or GP); None: the formulation's default."""
    return None if value is None else choice(argument, value, solver_names(), "solver")


def method(argument: str, value: Any) -> str:
    """A Pareto-front method."""
    from optdesign.studies.pareto.methods import METHODS

    return choice(argument, value, list(METHODS), "method")


def suite(argument: str, value: Any) -> str | None:
    """A benchmark suite (None: the default)."""
    from optdesign.studies.bench.instances import SUITES

    return choice(argument, value, SUITES, "suite", optional=True)


# --- the entry points -------------------------------------------------------------------
Check = Callable[[str, Any], Any]


def _checked(checks: Mapping[str, Check], arguments: Mapping[str, Any]) -> dict[str, Any]:
    """Each argument through its check, in the order of ``checks``."""
    return {key: check(key, arguments[key]) for key, check in checks.items()}


def _optional_text(argument: str, value: Any) -> str | None:
    return text(argument, value, optional=True)


def _optional_path(argument: str, value: Any):
    return path(argument, value, optional=True)


def _optional_out(argument: str, value: Any):
    return None if value is None else path(argument, out_path(argument, value))


def _optional_function(argument: str, value: Any):
    return function(argument, value, optional=True)


def solve_arguments(**arguments: Any) -> dict[str, Any]:
    """The checked arguments of :func:`optdesign.solve`: ``formulation``, ``objective``
    (a string; the problem's names are checked by :func:`objective_of` once it is
    loaded), ``starts``, ``seed``, ``workers``, ``solver``, ``options``, ``ranges``,
    ``agree``, ``diagnose``, ``sensitivities``, ``contact_models``, ``time_limit``,
    ``target_odds``; ``unknown`` (the keywords the caller gave beyond these) is refused
    with the nearest valid name."""
    unknown = arguments.pop("unknown", None) or {}
    for key in unknown:
        raise ArgumentError(
            str(key),
            f"unknown argument of solve() ({nearest(str(key), SOLVE_ARGUMENTS)}"
            f"known: {', '.join(SOLVE_ARGUMENTS)})",
        )
    checked = _checked(
        {
            "formulation": formulation,
            "objective": _optional_text,
            "starts": starts,
            "seed": seed,
            "workers": workers,
            "solver": solver,
            "ranges": flag,
            "agree": agree,
            "diagnose": flag,
            "sensitivities": flag,
            "contact_models": flag,
            "time_limit": seconds,
            "target_odds": odds,
        },
        arguments,
    )
    checked["options"] = solver_options("options", arguments["options"], checked["solver"])
    return checked


#: The keyword arguments of :func:`optdesign.solve` (the nearest one names a misspelling).
SOLVE_ARGUMENTS = (
    "formulation",
    "objective",
    "starts",
    "seed",
    "workers",
    "solver",
    "options",
    "ranges",
    "agree",
    "diagnose",
    "sensitivities",
    "contact_models",
    "time_limit",
    "target_odds",
)


def vary_path(path: str) -> None:
    """A sweep parameter's dotted path has no empty name (InputError ``vary``), the check
    :func:`optdesign.sweep` makes, for the command line's ``--vary`` before its range."""
    from optdesign.studies.sweep_grid import check_path_names

    check_path_names(path)


def solver_options(argument: str, options: Any, solver: str) -> dict[str, Any] | None:
    """Options of a solver back-end (None: the registry's default for an NLP): a mapping
    with string keys, checked as the back-end declares (Ipopt's by Ipopt itself, the
    check the problem file's ``[solver] ipopt`` gets)."""
    if options is None:
        solver_hints(solver).check_options({}, argument)  # what it takes from elsewhere
        return None
    if not isinstance(options, Mapping):
        raise ArgumentError(argument, f"expected a dict of solver options, got {shown(options)}")
    for key in options:
        if not isinstance(key, str):
            raise ArgumentError(argument, f"option names are strings, got {shown(key)}")
    solver_hints(solver).check_options(options, argument)
    return dict(options)


def objective_of(problem: Any, objective: str | None, argument: str = "objective") -> None:
    """``objective`` (None: the problem's first) is one the problem declares."""
    if objective is not None:
        choice(argument, objective, problem.objectives, "objective")


#: Options of :func:`optdesign.pareto` that say where and how a front runs (any method).
RUN_OPTIONS = (
    "out",
    "workers",
    "scheduler",
    "resume",
    "overwrite",
    "progress",
    "files",
    "on_record",
    "time_limit",
)


def _pareto_options() -> dict[str, tuple[Check, tuple[str, ...]]]:
    """The options of :func:`optdesign.pareto`: name -> (check, the methods that use it;
    empty: every method)."""
    eps = ("epsilon", "uniform")

    def retries(a: str, v: Any) -> int:
        return integer(a, v, 0, MAX_STARTS)

    return {
        "out": (_optional_out, ()),
        "workers": (workers, ()),
        "scheduler": (scheduler, ()),
        "resume": (flag, ()),
        "overwrite": (flag, ()),
        "progress": (flag, ()),
        "files": (flag, ()),
        "on_record": (_optional_function, ()),
        "time_limit": (seconds, ()),  # refused by front_time_limit where not applied
        "starts": (starts, (*eps, "weighted_sum")),
        "seed": (seed, ()),
        "agree": (agree, eps),
        "solver": (lambda a, v: choice(a, v, FRONT_SOLVERS.choices, "front solver"), eps),
        "spacing": (lambda a, v: choice(a, v, ("arc", "uniform"), "spacing"), ("epsilon",)),
        "eps_values": (_eps_values, eps),
        "retry_starts": (retries, eps),
        "extra_starts": (retries, eps),
        "deterministic": (flag, eps),
        "pop_size": (pop_size, ("nsga2",)),
        "generations": (generations, ("nsga2",)),
        "name": (name, ("epsilon", "weighted_sum", "nsga2")),
    }


def _eps_values(argument: str, value: Any) -> list[float] | None:
    if value is None:
        return None
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Iterable):
        raise ArgumentError(argument, f"expected a list of numbers, got {shown(value)}")
    values = list(value)
    if not 1 <= len(values) <= MAX_POINTS:
        raise ArgumentError(argument, f"give 1..{MAX_POINTS} values, got {len(values)}")
    for v in values:
        if not is_number(v) or not math.isfinite(float(v)):
            raise ArgumentError(argument, f"{shown(v)} is not a finite number")
    return [float(v) for v in values]


def pareto_arguments(
    objectives: Any, points_: Any, method_: Any, options: Mapping[str, Any]
) -> tuple[list[str], int, Any, dict[str, Any]]:
    """The checked arguments of :func:`optdesign.pareto` (the objectives' names are
    checked by :func:`front_objectives` once the problem is loaded)."""
    objectives = front_objectives(None, objectives)
    n = points("points", points_)
    if isinstance(method_, str) or not hasattr(method_, "run"):
        method_ = method("method", method_)
    else:  # a method object carries its own settings
        extra = sorted(set(options) - set(RUN_OPTIONS))
        if extra:
            raise ArgumentError(extra[0], "goes into the method object, not pareto()")
    table = _pareto_options()
    checked: dict[str, Any] = {}
    for key, value in options.items():
        if key not in table:
            raise ArgumentError(
                key,
                f"unknown option of pareto() ({nearest(key, [*table, 'points', 'method'])}"
                f"known: {', '.join(table)})",
            )
        check, methods = table[key]
        if methods and isinstance(method_, str) and method_ not in methods:
            raise ArgumentError(
                key, f"not an option of method {method_!r} (it is one of {', '.join(methods)})"
            )
        checked[key] = check(key, value)
    run_folder(checked.get("out"), checked.get("resume", False), checked.get("overwrite", False))
    return objectives, n, method_, checked


def run_folder(out: Any, resume: bool, overwrite: bool) -> None:
    """A stored run is continued (``resume``) or started afresh (``overwrite``), not
    both; continuing needs the folder of the run."""
    if resume and overwrite:
        raise ArgumentError("overwrite", "excludes {resume} (start over, or continue)", ("resume",))
    if resume and out is None:
        raise ArgumentError("resume", "give the {out} folder of the run to resume", ("out",))
    if out is not None:
        folder("out", out)


def out_path(argument: str, value: Any):
    """An output folder's path, as the command line's ``--out`` reads it: an empty word
    names no folder (``Path("")`` is the working folder, which would receive every file)."""
    from pathlib import Path

    if isinstance(value, str) and not value.strip():
        raise ArgumentError(argument, "an empty path names no folder: give the folder to write")
    return Path(value)


def folder(argument: str, out: Any) -> None:
    """``out`` can be (or become) a folder: the nearest part of the path that exists is
    a folder (a file there would fail only when the first result is written, after the
    work); an empty text is refused (:func:`out_path`)."""
    from pathlib import Path

    out_path(argument, out)
    part = Path(out)
    while not os.path.lexists(part) and part != part.parent:
        part = part.parent
    if os.path.lexists(part) and not part.is_dir():
        where = "is" if part == Path(out) else f"is under {part}, which is"
        raise ArgumentError(argument, f"{shown(str(out))} {where} a file, not a folder")


def report_arguments(subject: Any, path_: Any) -> tuple[Any, list[Any], Any]:
    """The checked arguments of :func:`optdesign.report`: (problem, fronts or [],
    the page's path). ``subject`` is a :class:`~optdesign.Result` with a design, a
    :class:`~optdesign.Front` with points, a list of fronts of one problem (drawn
    together, as ``optdesign pareto --method all`` does) or a :class:`~optdesign.Sweep`; ``path_`` the page's file,
    or a folder to write ``report.html`` in (as the command line's ``--out``)."""
    from optdesign.solvers.result import Result
    from optdesign.studies.pareto.front import Front
    from optdesign.studies.sweep import Sweep

    target = path("path", path_)
    if target.is_dir():
        target = target / "report.html"
    elif os.path.lexists(target) and not os.path.islink(target) and not target.is_file():
        raise ArgumentError("path", f"{shown(str(target))} is not a regular file")
    folder("path", target.parent)
    items = list(subject) if isinstance(subject, list | tuple) else [subject]
    if isinstance(subject, Sweep):
        if not any(p.design for p in subject.points):
            raise ArgumentError("result", "the sweep has no point with a design to report")
        return subject.problem, [], target
    if isinstance(subject, Result):
        problem = subject.problem_object
        if problem is None:
            raise ArgumentError("result", "carries no problem (a result made by od.solve does)")
        if not subject.design:
            raise ArgumentError("result", f"has no design to report (status {subject.status})")
        return problem, [], target
    if not items or not all(isinstance(f, Front) for f in items):
        raise ArgumentError(
            "result",
            f"expected a Result (od.solve), a Front (od.pareto) or a Sweep (od.sweep), "
            f"got {shown(subject)}",
        )
    problem = items[0].problem_object
    if problem is None or any(f.problem_object is not problem for f in items):
        raise ArgumentError("result", "the fronts carry no problem, or not the same one")
    if not any(f.points for f in items):
        raise ArgumentError("result", "the front has no point to report")
    return problem, items, target


def method_for(
    problem: Any, method_: Any, argument: str = "method", objectives: Sequence[str] = ()
) -> None:
    """A front method that keeps the problem's designs valid (a weighted sum of
    continuous NLPs would leave a catalogue) and can pose ``objectives`` (a method that
    solves NLPs needs each one's smooth form)."""
    if method_ == "weighted_sum" or type(method_).__name__ == "WeightedSum":
        from optdesign.studies.pareto.template import has_catalogue, leaves_catalogue

        if has_catalogue(problem):
            raise ArgumentError(argument, leaves_catalogue("weighted_sum"))
    if objectives:
        from optdesign.studies.pareto.methods import make_method
        from optdesign.studies.pareto.template import smooth_refusal

        refusal = smooth_refusal(make_method(problem, method_), problem, objectives)
        if refusal:
            raise ArgumentError("objectives", refusal)


def front_problem(problem: Any) -> None:
    """A problem a front can be traced on (a free variable), whose file's solver options
    its back-ends accept: refused before any work."""
    from optdesign.formulations.nlp.solve import solver_options
    from optdesign.studies.pareto.run_setup import check_front_problem

    check_front_problem(problem)
    solver_options(problem)


def sweep_parameters(
    problem: Any,
    vary: Mapping[str, Any],
    field: str = "vary",
    linked: Mapping[str, str] | None = None,
    linked_field: str = "linked",
) -> None:
    """The parameters of a sweep (``{path: (start, stop, count)}``) of ``problem`` and the
    ones linked to them (``{path: swept path}``): refused, naming ``field`` (or
    ``linked_field``) and the path, before any work."""
    from optdesign.studies.sweep_grid import sweep_axes

    try:
        sweep_axes(problem, vary, linked)
    except InputError as exc:
        head, dot, rest = exc.field.partition(".")
        name = {"vary": field, "linked": linked_field}.get(head)
        raise InputError(name + dot + rest if name else exc.field, exc.reason) from None


def front_store(problem: Any, method: str) -> str | None:
    """The file name of the resumable store of front method ``method`` on ``problem``
    (``"epsilon-catalogue.jsonl"`` for an epsilon front of a catalogue problem), or None
    when the method keeps none (NSGA-II): what a command checks before any front runs."""
    from optdesign.studies.pareto.methods import make_method

    built = make_method(problem, method)
    return f"{built.name}.jsonl" if getattr(built, "stored", False) else None


def front_time_limit(problem: Any, methods: Sequence[Any], time_limit: Any) -> None:
    """A front's time limit (``time_limit``, None: none) is applied by every method in
    ``methods`` (names or method objects), built as the front builds them: only a
    continuous epsilon sweep stops at one."""
    if time_limit is None:
        return
    from optdesign.studies.pareto.methods import check_time_limit, make_method

    for method_ in methods:
        check_time_limit(make_method(problem, method_), time_limit)


def solve_request(problem: Any, checked: Mapping[str, Any]) -> Any:
    """The :class:`~optdesign.problem.request.SolveRequest` of :func:`optdesign.solve`
    on ``problem`` (loaded), from its arguments as :func:`solve_arguments` returned them
    (checked before the problem was loaded): the objective checked among the problem's,
    the request built once."""
    from optdesign.problem.request import SolveRequest

    objective_of(problem, checked["objective"])
    return SolveRequest.for_problem(problem, **checked)


def solve_plan(problem: Any, formulation_: str = "auto", objective: str | None = None) -> str:
    """The formulation :func:`optdesign.solve` will use for ``objective``, after the
    checks that need no solve (a named formulation that does not apply, the file's
    solver options, a combination no formulation honours), so that a caller refuses
    before any work."""
    from optdesign.problem.request import SolveRequest
    from optdesign.studies.solve import plan_solve

    request = SolveRequest.for_problem(problem, objective, formulation=formulation_)
    return plan_solve(problem, request).name


def readme_file(argument: str, path: Any) -> Path | None:
    """A file whose generated block a benchmark's summary replaces (None: none): a
    regular UTF-8 text file with the markers, checked before any run (a FIFO,
    /dev/zero, a folder or a file without the markers is refused at once, not after an
    hour of runs)."""
    if path is None:
        return None
    from optdesign.studies.bench.report import has_readme_markers, read_readme

    path = Path(_optional_path(argument, path))
    try:
        text = read_readme(path, option=argument)
    except ArgumentError:
        raise
    except InputError as exc:
        raise ArgumentError(argument, exc.reason) from None
    if not has_readme_markers(text):
        raise ArgumentError(argument, f"{path} has no generated-block markers")
    return path


def front_objectives(problem: Any, objectives: Any, argument: str = "objectives") -> list[str]:
    """Two or three distinct objective names (of ``problem``, when given)."""
    objectives = names(argument, objectives)
    if len(objectives) not in (2, 3):
        raise ArgumentError(argument, f"give two or three objectives, got {objectives}")
    if len(set(objectives)) != len(objectives):
        raise ArgumentError(argument, f"repeated objective in {objectives}")
    if problem is not None:
        for k in objectives:
            choice(argument, k, problem.objectives, "objective")
    return objectives


def bench_arguments(**arguments: Any) -> dict[str, Any]:
    """The checked arguments of :func:`optdesign.bench`: ``problems`` (a list; loaded by
    the caller), ``suite``, ``solvers``, ``out``, ``workers``, ``resume``,
    ``overwrite``, ``time_limit``, ``hard_timeout``, ``progress``, ``scheduler``."""
    problems = arguments["problems"]
    if problems is not None and (
        isinstance(problems, str | bytes | Mapping | os.PathLike)
        or not isinstance(problems, Iterable)
    ):
        raise ArgumentError(
            "problems",
            f"expected a list of problems (files, dicts or problems), got {shown(problems)}",
        )
    problems = None if problems is None else list(problems)  # a generator is read once
    if problems is not None and not problems:
        raise ArgumentError("problems", "give at least one problem (or None for a suite)")
    if problems is not None and arguments["suite"] is not None:
        raise ArgumentError(
            "suite", "excludes {problems} (run your problems or a suite)", ("problems",)
        )
    checked = _checked(
        {
            "suite": suite,
            "solvers": configs,
            "out": _optional_out,
            "workers": workers,
            "resume": flag,
            "overwrite": flag,
            "time_limit": seconds,
            "hard_timeout": seconds,
            "progress": flag,
            "scheduler": scheduler,
        },
        arguments,
    )
    if checked["time_limit"] is None:
        raise ArgumentError("time_limit", "give a time limit in seconds")
    bench_timeouts(checked["time_limit"], checked["hard_timeout"])
    run_folder(checked["out"], checked["resume"], checked["overwrite"])
    checked["problems"] = problems
    return checked


def bench_timeouts(time_limit: float, hard_timeout: float | None) -> None:
    """A benchmark run's hard timeout (None: ``time_limit + 3``) lies above its soft
    time limit: the hard one kills the run, set-up included, so at or below the soft one
    a run is killed before the soft limit can stop it with its best point."""
    if hard_timeout is not None and not hard_timeout > time_limit:
        raise ArgumentError(
            "hard_timeout",
            f"{hard_timeout:g} s is not above {{time_limit}} ({time_limit:g} s): the hard "
            "timeout kills a run, set-up included, so a run that uses its time would be killed "
            "before the soft limit stops it with its best point; give a larger {hard_timeout} "
            "(default: the time limit + 3 s)",
            ("time_limit", "hard_timeout"),
        )


def configs(argument: str, value: Any) -> list[str] | None:
    """Benchmark configuration names (a list, or comma-separated in one string; None:
    all)."""
    if value is None:
        return None
    items = [s.strip() for item in names(argument, value) for s in item.split(",") if s.strip()]
    if not items:
        raise ArgumentError(argument, "give at least one configuration (or None for all)")
    from optdesign.studies.bench.configs import default_configs

    known = default_configs(include_hidden=True)
    for item in items:
        if item not in known and item not in solver_names("nlp"):
            choice(argument, item, default_configs(), "configuration")
    return items
