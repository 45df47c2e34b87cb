"""The public API: what ``import optdesign`` offers a script or a notebook.

::

    import optdesign as od

    problem = od.load("problems/cs_min_backlash.toml")   # a file, a dict, or a problem
    result = od.solve(problem)                             # formulation="auto"
    print(result.summary()); result.to_frame(); result.plot()
    front = od.pareto(problem, ["ripple", "backlash"], points=30)
    report = od.bench(problems=[problem], solvers=["ipopt", "slsqp"])

Every function takes keyword arguments and returns typed results; none prints, none
changes the matplotlib back-end. Every argument is checked before any work, by the checks
the command line uses (:mod:`optdesign.validation`): a refusal is an
:class:`~optdesign.errors.InputError` naming the argument, with the command line's
message (``starts: 0 is outside 1..10000``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from optdesign import validation
from optdesign.errors import InputError
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.load import load
from optdesign.problem.request import SolveRequest
from optdesign.solvers.result import Result

__all__ = [
    "bench",
    "bench_configurations",
    "load",
    "pareto",
    "report",
    "simulate",
    "solve",
    "sweep",
]


def solve(
    problem: DesignProblem | str | Path | Mapping[str, Any],
    formulation: str = "auto",
    *,
    objective: str | None = None,
    starts: int | None = None,
    seed: int | None = None,
    workers: int = 1,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    ranges: bool = True,
    agree: int | None = None,
    diagnose: bool = True,
    sensitivities: bool = True,
    contact_models: bool = False,
    time_limit: float | None = None,
    target_odds: float | None = None,
    **unknown: Any,
) -> Result:
    """The optimal design of ``problem``, with its evidence.

    Parameters
    ----------
    problem
        A :class:`DesignProblem`, a problem-file path or a problem dict.
    formulation
        ``"auto"`` (catalogue when a variable takes catalogue values, robust when the
        problem has tolerances, GP when it is a geometric program in ``objective``, a
        formulation of your own that applies (:func:`optdesign.register_formulation`),
        else NLP), or one of ``"nlp"``, ``"gp"``, ``"catalogue"``, ``"robust"`` or a
        registered name (:func:`optdesign.formulation_names`); one that does not apply
        to the problem is refused with the reason, before any work.
    objective
        Objective to minimise (default: the problem's first).
    starts, seed
        Multistart size (1..10000) and Sobol seed (0..2**32-1) (default: the problem's
        ``[solver]``).
    workers
        Local processes for the starts (1..256); on a catalogue problem, for each
        node's starts (the same search, node for node, as one worker).
    solver, options
        Registered solver back-end (:func:`optdesign.solver_names`; None: the
        formulation's default, :func:`optdesign.solvers.registry.default_solver` - Ipopt
        for an NLP, Clarabel for a GP) and its options (checked as the back-end declares
        before the solve: Ipopt's by Ipopt). A GP formulation given an NLP back-end
        solves the GP with the default GP back-end and says so in a note.
    ranges
        Also compute the range of each variable over the optimal set (NLP optima).
    agree
        NLP multistart: stop once this many starts agree on the best value (default: the
        problem's ``[solver] agree``, 3); 0 runs every start.
    diagnose
        When no feasible design is found: the best point's violated requirements and
        the smallest relaxation of each conflicting requirement (``result.diagnosis``),
        for every formulation. A problem with no free variable is not optimised: its
        fixed design is checked (formulation ``"fixed"``).
    sensitivities
        Also what each requirement costs at the optimum (``result.sensitivities``, from
        the solver's multipliers).
    contact_models
        Also the worst-case backlash of the optimum under each pin contact model
        (``duan2017``, ``conforming``, ``palmgren``, ``huth``; ``n/a`` with the reason
        where a model lacks its inputs, e.g. Huth's without ``[materials.lug]``), as a
        note of the result: the spread of the models a designer should read beside the
        file's choice.
    time_limit
        Wall-clock seconds for the NLP multistart (at most a day; None: no limit): no
        start begins after it, an Ipopt solve stops at it, and the result says so (a
        note; the starts cut or not begun counted in ``result.multistart.failed``); the
        diagnosis and the ranges are then skipped, with a note.
    target_odds
        NLP global search: go on past the stopping rule until the estimated probability
        that a better local optimum exists is below this, in (0, 0.5] (None: Boender and
        Rinnooy Kan's rule alone; see docs/optimisation.md,
        "The global search").

    Any other keyword is refused with an :class:`~optdesign.errors.InputError` naming the
    nearest valid argument.

    Returns
    -------
    Result
        Status, objective, design, every objective at the design, active and violated
        constraints, the independent check, the multistart record, bounds/certificates,
        and for a result with no feasible design its diagnosis.

    Notes
    -----
    The arguments, checked, travel down as one :class:`optdesign.SolveRequest`: the
    record a formulation's ``applies`` and ``solve`` receive.
    """
    from optdesign.studies.solve import solve as run

    checked = validation.solve_arguments(
        formulation=formulation,
        objective=objective,
        starts=starts,
        seed=seed,
        workers=workers,
        solver=solver,
        options=options,
        ranges=ranges,
        agree=agree,
        diagnose=diagnose,
        sensitivities=sensitivities,
        contact_models=contact_models,
        time_limit=time_limit,
        target_odds=target_odds,
        unknown=unknown,
    )
    problem = load(problem)
    request = validation.solve_request(problem, checked)
    result = run(problem, request)
    if request.contact_models and result.design:
        from optdesign.studies.contact_spread import contact_model_spread

        line = contact_model_spread(problem, result.design)
        result.notes.append(line or "backlash by pin contact model: no sized pin or no backlash")
    return result


def pareto(
    problem: DesignProblem | str | Path | Mapping[str, Any],
    objectives: Sequence[str] | str,
    points: int = validation.DEFAULT_FRONT_POINTS,
    method: str | Any = "epsilon",
    **options: Any,
):
    """The Pareto front of two or three objectives of ``problem``.

    ``objectives``: a list of names, or one string ``"ripple,backlash"`` (the command
    line's form). ``points``: 2..10000. ``method``: ``"epsilon"`` (epsilon-constraint
    between exact anchors, evenly spread along the front; default), ``"uniform"``
    (epsilon evenly spaced), ``"weighted_sum"`` or ``"nsga2"``, or a method object.
    Options (all keywords; an option the method does not use is refused): ``out``
    (folder of the resumable store, and of the files ``optdesign pareto`` writes:
    ``front.csv``, ``front.json``, ``front.png``, ``report.html``; default: a new
    temporary folder ``optdesign-pareto-*`` with the store alone, kept, named by
    ``Front.store``), ``files`` (False: the store alone in ``out``), ``workers``,
    ``scheduler`` (Dask), ``resume``, ``overwrite`` (start afresh over a stored run),
    ``progress``,
    ``starts``, ``seed``,
    ``solver``, ``agree``, ``spacing``, ``eps_values``, ``retry_starts``,
    ``extra_starts``, ``deterministic``, ``time_limit`` (wall-clock seconds of a
    continuous epsilon front, refused by any other method: no point begins after it, the
    points running finish; the front says how many were left out and a resume in
    ``out`` computes them), NSGA-II's ``pop_size`` and ``generations``. ``optdesign
    pareto`` runs each of its methods through this function.

    Returns
    -------
    Front
        The non-dominated points with their designs, the rejected points, the metrics
        (hypervolume, spacing, spread); ``.summary()``, ``.to_frame()``, ``.plot()``.
    """
    from optdesign.studies.pareto import compute_front
    from optdesign.studies.pareto.front import Front

    objectives, points, method, options = validation.pareto_arguments(
        objectives, points, method, options
    )
    problem = load(problem)
    validation.front_objectives(problem, objectives)
    validation.method_for(problem, method, objectives=objectives)
    validation.front_time_limit(problem, [method], options.get("time_limit"))
    files = options.pop("files", True)
    front = compute_front(problem, objectives, points, method, **options)
    if files and options.get("out") is not None and isinstance(front, Front):
        _, notes = front_outputs([front], problem, options["out"], objectives, points)
        front.notes.extend(notes)
    return front


def front_outputs(
    fronts: Sequence[Any],
    problem: DesignProblem,
    out: str | Path,
    objectives: Sequence[str],
    points: int,
    plot: bool = True,
    report: bool = True,
    figures: Any = None,
) -> tuple[list[Path], list[str]]:
    """The files ``optdesign pareto`` writes of the fronts of one problem in folder
    ``out`` (``front.csv``, ``front.json``, ``front.png``, ``report.html``:
    :func:`optdesign.reports.front_files.write_front_outputs`); the files written and
    the notes of the outputs that could not be drawn.

    Several methods' fronts first get their hypervolumes against one reference point
    (comparable, in ``front.json`` and the summary): a computation of the study, done
    here so that the report only writes what the fronts hold. ``figures``: a started
    :class:`optdesign.plots.figure_process.FigureProcess` that draws front.png while
    the page is made (None: drawn in process).
    """
    import time

    from optdesign.reports.front_files import write_front_outputs
    from optdesign.studies.pareto import common_hypervolumes

    if len(fronts) > 1:
        common_hypervolumes(fronts)
    return write_front_outputs(
        fronts,
        problem,
        Path(out),
        objectives=objectives,
        points=points,
        created=time.strftime("%Y-%m-%d %H:%M:%S"),
        plot=plot,
        report=report,
        figures=figures,
    )


def bench(
    problems: Sequence[DesignProblem | str | Path | Mapping[str, Any]] | None = None,
    *,
    suite: str | None = None,
    solvers: Sequence[str] | str | None = None,
    out: str | Path | None = None,
    workers: int = 1,
    resume: bool = False,
    overwrite: bool = False,
    time_limit: float = 1.0,
    hard_timeout: float | None = None,
    progress: bool = False,
    scheduler: str | None = None,
    update_readme: str | Path | None = None,
):
    """Benchmark solver configurations on problems (yours) or on a seeded suite.

    ``problems``: problems to run every configuration on; ``suite``: ``"quick"`` or
    ``"default"`` (instance families of the registered mechanisms; the default when no
    problems are given). ``solvers``: names of configurations (default: all). Runs
    stream to ``out`` (a new temporary folder by default) and can be resumed
    (``resume``) or started afresh (``overwrite``). ``time_limit``: soft wall-time limit
    of each solver call (s, at most a day); ``hard_timeout``: a run is killed after it
    (default ``time_limit + 3``; above ``time_limit``). ``scheduler``: address of a Dask
    scheduler (``tcp://HOST:PORT``) or its ``distributed.Client``.
    ``update_readme``: a text file whose generated block (between the markers of
    ``benchmarks/README.md``) gets the summary; checked before any run. ``optdesign
    bench`` runs through this function.

    Returns
    -------
    BenchReport
        Every run's row (``.rows``: :class:`~optdesign.studies.bench.BenchRow`, read by
        attribute: ``row.config``, ``row.success``, ``row.gap``), per-configuration
        statistics, performance profiles, the summary table; ``.summary()``,
        ``.to_frame()``, ``.plot()``.
    """
    from optdesign.studies.bench import run_bench

    args = validation.bench_arguments(
        problems=problems,
        suite=suite,
        solvers=solvers,
        out=out,
        workers=workers,
        resume=resume,
        overwrite=overwrite,
        time_limit=time_limit,
        hard_timeout=hard_timeout,
        progress=progress,
        scheduler=scheduler,
    )
    readme = validation.readme_file("update_readme", update_readme)
    loaded = None if args["problems"] is None else [load(p) for p in args["problems"]]
    report = run_bench(
        suite=args["suite"],
        problems=loaded,
        configs=args["solvers"],
        out=args["out"],
        workers=args["workers"],
        scheduler=args["scheduler"],
        resume=args["resume"],
        overwrite=args["overwrite"],
        time_limit=args["time_limit"],
        hard_timeout=args["hard_timeout"],
        progress=args["progress"],
    )
    if readme is not None:
        from optdesign.studies.bench.report import update_readme as paste

        try:
            pasted = paste(readme, report.summary())
        except validation.ArgumentError:
            raise
        except InputError as exc:  # the file gone or changed during the runs
            raise validation.ArgumentError("update_readme", exc.reason) from None
        if not pasted:  # its markers gone during the runs
            raise validation.ArgumentError(
                "update_readme", f"{readme} has no generated-block markers"
            )
    return report


def bench_configurations(hidden: bool = False) -> list[tuple[str, str, str]]:
    """The benchmark's configurations ``(name, kind, description)``, the names
    :func:`bench` takes as ``solvers`` (a registered solver back-end is one too, by its
    name); ``hidden``: also the ones kept for the tests."""
    from optdesign.studies.bench import default_configs, get_config

    return [
        (name, (c := get_config(name)).kind, c.description)
        for name in default_configs(include_hidden=hidden)
    ]


def report(result: Any, path: str | Path) -> Path:
    """Write the interactive ``report.html`` of a result or a front made in Python - the
    page the command line writes for ``optdesign solve`` / ``optdesign pareto``.

    Parameters
    ----------
    result
        A :class:`Result` with a design (:func:`solve`), a :class:`Front` with points
        (:func:`pareto`), a list of fronts of one problem (drawn together), or a
        :class:`Sweep` (:func:`sweep`: its design chart and table, hover a point for its
        design; the command line's ``sweep.html``).
    path
        The page's file; or an existing folder, to write ``report.html`` in it. Written
        as the command line writes it: atomically, through a new file (a link planted at
        ``path`` is replaced, never followed; a failed write leaves the old file).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    InputError
        Naming ``result`` or ``path`` and the reason (no design, not a folder...).
    """
    from optdesign.reports.html import front_report, solve_report
    from optdesign.storage import atomic_write_text
    from optdesign.studies.sweep import Sweep

    problem, fronts, target = validation.report_arguments(result, path)
    if isinstance(result, Sweep):
        from optdesign.reports.sweep_html import sweep_report

        page = sweep_report(result)
    else:
        page = front_report(problem, fronts) if fronts else solve_report(result)
    return atomic_write_text(target, page)


def sweep(
    problem: DesignProblem | str | Path | Mapping[str, Any],
    vary: Mapping[str, Any],
    *,
    linked: Mapping[str, str] | None = None,
    objective: str | None = None,
    check_every: int = 10,
    starts: int | None = None,
    seed: int | None = None,
    out: str | Path | None = None,
    resume: bool = False,
    overwrite: bool = False,
    progress: bool = False,
    sensitivities: bool = False,
    workers: int = 1,
    scheduler: str | None = None,
    files: bool = True,
):
    """How the optimum of ``problem`` moves when one or two parameters change.

    ``vary``: ``{path: (start, stop, count)}`` for one or two parameters, e.g.
    ``{"requirements.hinge_moment": ("200 N*m", "1000 N*m", 20)}``; a path is
    ``requirements.NAME`` (``requirements.mean_ratio.min`` inside a band), a number of
    the motion, the load or the loop (``motion.rise_time``, ``load.inertia``,
    ``loop.bandwidth``), ``variables.NAME.lower`` / ``.upper`` (a free variable's bound)
    or ``variables.NAME``
    (a fixed variable); start and stop are quantities of the parameter's dimension
    (a bare number only for a plain number), count 2..1000, at most 2 500 points in all
    (the product of the counts). ``linked``: ``{path: swept path}``, parameters that
    move with a swept one, set to its value at every point (paths as above, of the same
    dimension), e.g. ``{"loop.bandwidth":
    "requirements.bandwidth_min"}``: the loop's gains placed for the bandwidth that is
    required. Every point gets the global search a cold solve of it
    runs (``starts``, ``seed``: that search's, default the file's; the same seed at every
    point), then polish rounds warm-start each point from
    its neighbours' designs until no point improves (:mod:`optdesign.studies.sweep`).
    ``check_every`` is accepted and ignored (it set the interval of the multistart
    checks of an older method; every point is searched now). The points go to
    ``out/sweep.jsonl`` as they finish (a new temporary folder by default), and with
    ``out`` given the files ``optdesign sweep`` writes (``sweep.csv``, ``sweep.json``,
    ``sweep.png``, ``sweep.html``; ``files=False``: the store alone); ``resume``
    continues a stored sweep, ``overwrite`` starts afresh over one. ``workers`` (local
    processes) or ``scheduler`` (a Dask scheduler's address): the points of each round
    side by side (the records are the same for any number).
    ``sensitivities``: also each point's log-sensitivities to every binding requirement
    (``point.sensitivities``, :attr:`optdesign.Result.sensitivities`).

    Returns
    -------
    Sweep
        The points (parameters, status, objective, design, binding set, the jumps and
        what found each optimum, what fails at an infeasible point); ``.summary()``,
        ``.to_frame()`` (columns ``"name [unit]"``), ``.plot()`` (the design chart).

    Notes
    -----
    The arguments, checked, travel down as one :class:`optdesign.SolveRequest` (how each
    point is solved; a point a formulation solves receives it) and one
    :class:`~optdesign.runtime.run_options.RunOptions` (where and how the points run).
    """
    from optdesign.runtime.run_options import RunOptions
    from optdesign.studies.sweep import run_sweep

    starts = validation.starts("starts", starts)
    seed = validation.seed("seed", seed)
    check_every = validation.integer("check_every", check_every, 1, 10_000)
    resume = validation.flag("resume", resume)
    overwrite = validation.flag("overwrite", overwrite)
    progress = validation.flag("progress", progress)
    files = validation.flag("files", files)
    sensitivities = validation.flag("sensitivities", sensitivities)
    workers = validation.workers("workers", workers)
    scheduler = validation.scheduler("scheduler", scheduler)
    validation.run_folder(out, resume, overwrite)
    problem = load(problem)
    validation.objective_of(problem, objective)
    # A sweep's points show no ranges of the optimal set; an infeasible point is
    # diagnosed (what to relax: it has no design to show).
    request = SolveRequest.for_problem(
        problem,
        objective,
        starts=starts,
        seed=seed,
        sensitivities=sensitivities,
        ranges=False,
        diagnose=True,
    )
    run = RunOptions(
        out=out,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        overwrite=overwrite,
        progress=progress,
    )
    swept = run_sweep(problem, vary, request, linked=linked, check_every=check_every, run=run)
    if out is not None and files:
        from optdesign.reports.sweep_files import write_sweep_outputs

        _, notes, _ = write_sweep_outputs(swept, Path(out))
        swept.notes.extend(notes)
    return swept


def simulate(
    result: Any,
    reference: str = "step",
    *,
    design: Mapping[str, float] | None = None,
    amplitude: Any = "1 deg",
    angle: Any = None,
    horizon: Any = None,
    frequency: Any = "5 Hz",
    samples: int = 2001,
    csv: str | Path | None = None,
    plant: str | None = None,
    periods: int = 1,
    period: Any = None,
) -> Any:
    """The time response of a solved design in its position loop (docs/loop.md): the
    drive at the grid angle nearest ``angle``, or following the fin along the stroke,
    with its elastic backlash, friction and the motor's limits
    (:func:`optdesign.models.loop_simulation.simulate`).

    Parameters
    ----------
    result
        A :class:`Result` of :func:`solve` with a design, of a problem with ``[loop]``;
        or a :class:`DesignProblem` with ``design``.
    design
        With a problem: the design (every free variable, internal units: mm, rad).
    reference
        ``"step"`` (of ``amplitude`` at t = 0), ``"sine"`` (``amplitude`` at
        ``frequency``) or ``"duty"`` (``requirements.duty_cycle``'s deflection history
        and hinge moments, over ``periods`` periods).
    amplitude, angle, horizon, frequency
        Quantities (``"1 deg"``, ``"0 deg"``, ``"0.5 s"``, ``"5 Hz"``) or numbers in rad,
        rad, s, Hz; ``angle`` None: the middle of the stroke; ``horizon`` None: 0.5 s (a
        duty run lasts its periods and takes none).
    samples
        Output samples (2 to 10^6).
    csv
        A file to write the samples to, one column per quantity with its unit.
    plant
        ``"angle"`` (the plant of the grid angle, held; a step's and a sine's default) or
        ``"path"`` (following the fin along the stroke; the duty cycle's only plant).
    periods, period
        The duty cycle's periods (>= 1) and its length (a time, or a number in s;
        default ``requirements.duty_period``), at most 600 s in all.

    Returns
    -------
    DesignSimulation
        The angle simulated and the model's record (internal units: rad, s, N*mm).

    Raises
    ------
    InputError
        Naming the argument and the reason (no design, no ``[loop]``, an angle outside
        the stroke, a horizon beyond 600 s ...).
    """
    from optdesign.problem.loop_time import simulate_design, simulation_csv
    from optdesign.storage import atomic_write_text

    if isinstance(result, DesignProblem):
        if design is None:
            raise InputError("design", "a problem needs the design to simulate")
        problem, values = result, {**result.fixed_values, **design}
        missing = [v.name for v in problem.free if v.name not in values]
        if missing:
            raise InputError("design", f"gives no value for {', '.join(missing)}")
    else:
        problem = getattr(result, "problem_object", None)
        if problem is None or not getattr(result, "design", None):
            raise InputError("result", "a result of od.solve with a design (and its problem)")
        values = result.design
    sim = simulate_design(
        problem,
        values,
        reference,
        amplitude,
        angle,
        horizon,
        frequency,
        samples,
        plant=plant,
        periods=periods,
        period=period,
    )
    if csv is not None:
        atomic_write_text(Path(csv), simulation_csv(sim))
    return sim
