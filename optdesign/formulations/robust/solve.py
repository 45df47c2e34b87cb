"""Robust design study: nominal optimum vs robust (SAA) optimum, judged by an independent
Monte Carlo.

- :func:`solve_robust`: the robust NLP of :mod:`optdesign.formulations.robust.program` solved by
  Ipopt from the nominal optimum and scrambled-Sobol starts; the best point is checked on
  the NumPy path (nominal requirements, :func:`optdesign.formulations.nlp.solve.finish`) and its
  sample-average statistic recomputed there on the same fixed samples.
- :func:`monte_carlo`: the objective of a design under freshly drawn scatter (its own seed,
  many samples), vectorised over the population of perturbed designs on the NumPy path of
  the same expressions; also the share of samples that violate a requirement.
- :func:`compare_nominal_robust`: both optima, the same Monte Carlo samples for both
  (common random numbers: the difference is not blurred by sampling noise), a table.

The comparison's table: ``python benchmarks/robust_compare.py FILE``; the robust optimum
alone: ``optdesign solve FILE --formulation robust``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign.display.tables import format_table
from optdesign.formulations.nlp.solution import has_multipliers
from optdesign.formulations.nlp.solve import (
    continuous_only,
    finish,
    solve_nlp,
    solver_options,
    start_points,
)
from optdesign.formulations.robust.details import NominalOptimum, RobustDetails
from optdesign.formulations.robust.program import (
    Samples,
    build_robust_nlp,
    draw_samples,
    perturb,
    risk_label,
    sampled_objective,
    tolerances_of,
)
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.evaluation import relative_violation, term_values
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.problem.request import SolveRequest
from optdesign.runtime.inherited_map import map_inherited
from optdesign.solvers.multistart import multistart
from optdesign.solvers.registry import make_solver
from optdesign.solvers.result import Globality, Result
from optdesign.tolerances import FEASIBILITY_TOL

#: Default independent Monte Carlo: sample count and seed (different from the SAA seed).
MC_SAMPLES = 20_000
MC_SEED = 20_251_121


def empirical_cvar(values: np.ndarray, alpha: float) -> float:
    """CVaR_alpha of equally weighted samples (Rockafellar-Uryasev), the statistic the SAA
    NLP minimises: min_c c + mean(max(v - c, 0)) / (1 - alpha), attained at the
    alpha-quantile (inverted CDF)."""
    v = np.asarray(values, dtype=float)
    c = float(np.quantile(v, alpha, method="inverted_cdf"))
    return c + float(np.mean(np.maximum(v - c, 0.0))) / (1.0 - alpha)


def risk_value(values: np.ndarray, risk: str, alpha: float, k: float) -> float:
    """The risk measure of ``values`` as the SAA NLP defines it (population std)."""
    v = np.asarray(values, dtype=float)
    if risk == "cvar":
        return empirical_cvar(v, alpha)
    return float(v.mean() + k * v.std())


def sample_values(
    problem: DesignProblem,
    design: Mapping[str, float],
    samples: Samples,
    objective: str,
    chunk: int = 4000,
) -> tuple[np.ndarray, np.ndarray]:
    """Objective and requirement violation of ``design`` under every sample (NumPy path).

    The perturbed designs are a population (one row per sample) evaluated in chunks of
    ``chunk`` through :func:`sampled_objective`, i.e. the same expressions as the solver.

    Returns
    -------
    (values, violation)
        Objective per sample; largest relative violation of a requirement per sample
        (0: the perturbed design meets every requirement).
    """
    full = {**problem.fixed_values, **design}
    out_v, out_viol = [], []
    for start in range(0, samples.n, chunk):
        idx = slice(start, min(start + chunk, samples.n))
        pop = idx.stop - idx.start
        # every value a column, so each expression is (pop, grid) or (pop, 1)
        columns = {name: np.full((pop, 1), float(value)) for name, value in full.items()}
        d = perturb(columns, samples, idx)
        fit = None
        if samples.fit is not None:
            fit = [samples.fit[idx, j : j + 1] for j in range(samples.fit.shape[1])]
        with np.errstate(invalid="ignore", divide="ignore"):
            term, ex = sampled_objective(problem, d, objective, fit)
            val = term_values(term, pop, len(problem.phi))
            worst = np.zeros(pop)
            for block in ex.constraints:
                c = np.asarray(block.expr, dtype=float).reshape(pop, -1)
                viol = relative_violation(c, block.lower, block.upper)
                worst = np.maximum(worst, np.nan_to_num(viol.max(axis=-1), nan=np.inf))
        out_v.append(val)
        out_viol.append(worst)
    return np.concatenate(out_v), np.concatenate(out_viol)


@dataclass
class MonteCarloSummary:
    """Statistics of one design's objective under the independent Monte Carlo."""

    n: int
    seed: int
    mean: float
    std: float
    quantile: float
    q: float
    cvar: float
    alpha: float
    risk: float
    p_violation: float
    values: np.ndarray = field(repr=False)


def monte_carlo(
    problem: DesignProblem,
    design: Mapping[str, float],
    n: int = MC_SAMPLES,
    seed: int = MC_SEED,
    objective: str | None = None,
    q: float = 0.95,
    risk: str | None = None,
    alpha: float | None = None,
    k: float | None = None,
    samples: Samples | None = None,
) -> MonteCarloSummary:
    """Independent Monte Carlo of ``design`` under the problem's tolerances.

    Parameters
    ----------
    n, seed
        Fresh draws (use a seed other than the SAA one); ignored if ``samples`` given.
    q
        Quantile level reported (e.g. 0.95).
    risk, alpha, k
        The risk measure also reported (default: the file's).
    """
    tol = tolerances_of(problem)
    objective = objective or problem.objective_names[0]
    risk = risk or tol.risk
    alpha = tol.alpha if alpha is None else alpha
    k = tol.k if k is None else k
    samples = samples if samples is not None else draw_samples(problem, n, seed, tol)
    values, viol = sample_values(problem, design, samples, objective)
    return MonteCarloSummary(
        n=samples.n,
        seed=samples.seed,
        mean=float(values.mean()),
        std=float(values.std()),
        quantile=float(np.quantile(values, q)),
        q=q,
        cvar=empirical_cvar(values, alpha),
        alpha=alpha,
        risk=risk_value(values, risk, alpha, k),
        p_violation=float(np.mean(viol > FEASIBILITY_TOL)),
        values=values,
    )


def solve_robust(
    problem: DesignProblem,
    x0: np.ndarray | None = None,
    starts: int = 1,
    seed: int = 0,
    objective: str | None = None,
    samples: Samples | None = None,
    risk: str | None = None,
    alpha: float | None = None,
    k: float | None = None,
    constrain_samples: bool = False,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    workers: int = 1,
    sensitivities: bool = False,
) -> Result:
    """Robust optimum of ``problem`` (SAA of the ``[tolerances]``), multistart NLP.

    Parameters
    ----------
    x0
        First start, e.g. the nominal optimum (default: the declared start).
    starts, seed
        Number of starts; the others are scrambled-Sobol points (``seed``).
    samples
        Fixed scatter samples (default: the file's ``tolerances.samples`` and ``seed``).
    solver, options
        Registered NLP back-end (None: the registry's default) and its options.
    sensitivities
        Also what each requirement costs at the optimum (``result.sensitivities``, from
        the multipliers of the sample-average NLP: :mod:`optdesign.formulations.robust.sensitivities`).

    Returns
    -------
    Result
        ``objective``: the risk measure (SAA); ``objectives``: nominal objective values
        (NumPy check); ``details.robust``: ``risk_label``, ``saa_check`` (the statistic
        recomputed on the NumPy path from the same samples), ``saa_samples``, ``saa_seed``.
    """
    tol = tolerances_of(problem)
    objective = objective or problem.objective_names[0]
    risk = risk or tol.risk
    alpha = tol.alpha if alpha is None else alpha
    k = tol.k if k is None else k
    samples = samples if samples is not None else draw_samples(problem, tol.samples, tol.seed, tol)
    pts = start_points(problem, starts, seed, x0)
    t0 = time.perf_counter()
    nlp = build_robust_nlp(problem, objective, samples, risk, alpha, k, constrain_samples)
    merged = {**solver_options(problem, solver), **(options or {})}
    solve = make_solver(nlp, solver, merged).solve
    build_s = time.perf_counter() - t0
    result = multistart(solve, pts, workers=workers, seed=seed, parallel_map=map_inherited)
    label = risk_label(risk, alpha, k, objective)
    result.formulation = "robust-saa"
    # Per-sample rows are the formulation's own; report the nominal requirements only.
    result.active = [r for r in result.active if "[s" not in r.name and "cvar" not in r.name]
    result = finish(problem, result, objective)
    details = result.details["robust"] = RobustDetails(
        risk_label=label,
        saa_samples=samples.n,
        saa_seed=samples.seed,
        build_time_s=build_s,
        constrain_samples=constrain_samples,
    )
    result.notes.append(
        f"objective = {label} over {samples.n} fixed samples (seed {samples.seed}); "
        "'objectives' below are the nominal design's"
    )
    result.objective_name = label
    if result.design:
        free = {v.name: result.design[v.name] for v in problem.free}
        values, _ = sample_values(problem, free, samples, objective)
        details.saa_check = risk_value(values, risk, alpha, k)
    if sensitivities and result.success and has_multipliers(result, solver):
        _attach_sensitivities(problem, result, nlp, samples, objective)
    return result


def _attach_sensitivities(
    problem: DesignProblem, result: Result, nlp, samples: Samples, objective: str
) -> None:
    """What each requirement costs at the robust optimum (a report: never loses it)."""
    from optdesign.formulations.robust.sensitivities import robust_sensitivities

    kind = sampled_objective(problem, problem.design_dict(problem.midpoint()), objective)
    if kind[0].kind not in ("max", "spread"):
        result.notes.append(
            "sensitivities not computed: a one-value objective enters the risk measure "
            "directly (only worst-case and spread objectives are covered)"
        )
        return
    try:
        result.sensitivities = robust_sensitivities(problem, result, nlp, samples, objective)
    except Exception as exc:
        result.notes.append(f"sensitivities not computed: {exc}")


def robust_applies(problem: DesignProblem, request: SolveRequest | None = None) -> bool | str:
    """The ``robust`` formulation's predicate: the problem has tolerances and its
    variables are continuous (else the reason)."""
    if problem.spec.tolerances is None:
        return (
            'robust design needs a [tolerances] section (e.g. R = "0.05 mm", '
            'phi0 = "0.1 deg", fit = "uniform")'
        )
    names = problem.objective_names
    objective = request.objective if request is not None else None
    info = problem.objectives.get(objective or (names[0] if names else ""))
    if info is not None and info.numeric_only:
        return smooth_form_refusal(problem, info.name, "robust design (an NLP per sample)")
    if info is not None and info.bound_rows is not None:
        # each sample would need its own implicit epigraph and the sensitivities their
        # slopes in it: not built; the nominal NLP and the catalogue search pose it
        return (
            f"robust design takes objectives that are expressions of the design; "
            f"{info.name} is a root of the model, bounded by implicit rows (use "
            "formulation='nlp')"
        )
    return continuous_only(problem, "robust design needs continuous variables")


def solve_robust_formulation(problem: DesignProblem, request: SolveRequest) -> Result:
    """``formulation="robust"``: the nominal optimum (multistart), then the robust optimum
    started from it."""
    objective = request.objective
    nominal = solve_nlp(
        problem,
        objective=objective,
        starts=request.starts,
        seed=request.seed,
        workers=request.workers,
        solver=request.solver,
        options=request.options,
    )
    x0 = np.array([nominal.design[v.name] for v in problem.free]) if nominal.design else None
    result = solve_robust(
        problem,
        x0=x0,
        objective=objective,
        solver=request.solver,
        options=request.options,
        sensitivities=True,
    )
    result.details.robust.nominal_optimum = NominalOptimum(
        nominal.status,
        objective,
        nominal.objectives.get(objective, nominal.objective),
        nominal.design,
    )
    result.globality = Globality(
        basis="the robust optimum: a local solve started at the nominal optimum, which the "
        "global search found" + (f" ({nominal.globality.text()})" if nominal.globality else "")
    )
    return result


def paired_bootstrap(
    a: np.ndarray, b: np.ndarray, stat, n_boot: int = 200, seed: int = 0
) -> tuple[float, float]:
    """95 % bootstrap interval of ``stat(b) - stat(a)`` for paired samples (same draws)."""
    rng = np.random.default_rng(seed)
    diffs = np.empty(n_boot)
    for j in range(n_boot):
        idx = rng.integers(0, len(a), len(a))
        diffs[j] = stat(b[idx]) - stat(a[idx])
    lo, hi = np.quantile(diffs, [0.025, 0.975])
    return float(lo), float(hi)


@dataclass
class RobustComparison:
    """Nominal vs robust optimum under the same independent Monte Carlo."""

    nominal: Result
    robust: Result
    mc_nominal: MonteCarloSummary
    mc_robust: MonteCarloSummary
    objective: str
    risk_label: str
    #: The robust statistic (the SAA's) at the nominal optimum, on the same samples.
    nominal_saa: float = float("nan")

    def table(self) -> str:
        """Readable comparison table."""
        a, b = self.mc_nominal, self.mc_robust
        unit = "deg" if self.objective.startswith("backlash") else ""

        def row(name, x, y, u=unit):
            rel = (y - x) / abs(x) if x else float("nan")
            return [name, f"{x:.6g}", f"{y:.6g}", f"{100 * rel:+.2f} %", u]

        rows = [
            row(
                f"{self.objective} at nominal (fit as required)",
                self.nominal.objectives[self.objective],
                self.robust.objectives[self.objective],
            ),
            row(
                f"SAA {self.risk_label} (S={self.robust.details.robust.saa_samples})",
                self.nominal_saa,
                self.robust.objective,
            ),
            row("MC mean", a.mean, b.mean),
            row("MC std", a.std, b.std),
            row(f"MC {100 * a.q:g} % quantile", a.quantile, b.quantile),
            row(f"MC CVaR_{a.alpha:g}", a.cvar, b.cvar),
            row("MC share violating a requirement", a.p_violation, b.p_violation, ""),
        ]
        lo, hi = paired_bootstrap(
            a.values, b.values, lambda v: float(np.quantile(v, a.q)), seed=a.seed
        )
        clo, chi = paired_bootstrap(
            a.values, b.values, lambda v: empirical_cvar(v, a.alpha), seed=a.seed
        )
        head = (
            f"independent Monte Carlo: {a.n} samples, seed {a.seed} (same draws for both "
            f"designs)\nrobust - nominal, with paired bootstrap 95 % intervals: "
            f"CVaR_{a.alpha:g} {b.cvar - a.cvar:.3g} {unit} [{clo:.3g}, {chi:.3g}]; "
            f"{100 * a.q:g} % quantile {b.quantile - a.quantile:.3g} {unit} [{lo:.3g}, {hi:.3g}]"
        )
        design_rows = [
            [v, f"{self.nominal.design[v]:.6g}", f"{self.robust.design[v]:.6g}"]
            for v in self.robust.design
        ]
        return "\n".join(
            [
                head,
                format_table(["quantity", "nominal opt.", "robust opt.", "change", "unit"], rows),
                "",
                format_table(["variable", "nominal opt.", "robust opt."], design_rows),
            ]
        )


def compare_nominal_robust(
    problem: DesignProblem,
    n_mc: int = MC_SAMPLES,
    mc_seed: int = MC_SEED,
    q: float = 0.95,
    starts: int | None = None,
    robust_starts: int = 1,
    objective: str | None = None,
    samples: Samples | None = None,
    nominal: Result | None = None,
) -> RobustComparison:
    """Nominal optimum (:func:`solve_nlp`) vs robust optimum (started from it), both judged
    by one independent Monte Carlo (``n_mc`` samples, ``mc_seed``)."""
    tol = tolerances_of(problem)
    objective = objective or problem.objective_names[0]
    if mc_seed == tol.seed:
        raise ValueError("mc_seed must differ from the SAA seed (tolerances.seed)")
    nominal = nominal or solve_nlp(problem, starts=starts, objective=objective)
    x_nom = np.array([nominal.design[v.name] for v in problem.free])
    samples = samples if samples is not None else draw_samples(problem, tol.samples, tol.seed, tol)
    robust = solve_robust(
        problem, x0=x_nom, starts=robust_starts, objective=objective, samples=samples
    )
    values, _ = sample_values(
        problem, {v.name: nominal.design[v.name] for v in problem.free}, samples, objective
    )
    nominal_saa = risk_value(values, tol.risk, tol.alpha, tol.k)
    mc = draw_samples(problem, n_mc, mc_seed, tol)
    free = [v.name for v in problem.free]
    mc_nom = monte_carlo(
        problem, {v: nominal.design[v] for v in free}, objective=objective, q=q, samples=mc
    )
    mc_rob = monte_carlo(
        problem, {v: robust.design[v] for v in free}, objective=objective, q=q, samples=mc
    )
    label = robust.details.robust.risk_label
    return RobustComparison(nominal, robust, mc_nom, mc_rob, objective, label, nominal_saa)
