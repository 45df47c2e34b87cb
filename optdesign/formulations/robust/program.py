"""Robust design: a risk measure of an objective under manufacturing tolerances (SAA NLP).

The tolerances of the problem file's ``[tolerances]`` section (any length or angle
variable as +-band, normal with sigma = band/3 or uniform; pin fits drawn uniformly between
the fit's smallest and largest clearance) are sampled ONCE with a fixed seed, so the
sample-average approximation stays a smooth NLP:

- sample s perturbs the design, ``design_s = design + delta_s`` (CasADi symbols plus
  numbers), and goes through the same :meth:`DesignProblem.expressions` as the nominal
  design; the pin joints get the sampled fit clearance ``c_min + u_s (c_max - c_min)``
  (:func:`sampled_objective`, the only place that departs from the nominal model);
- each sample's objective is an epigraph: ``t_s >= theta_s(phi_k)`` for a ``max`` term
  (worst-case backlash), ``lo_s <= i_s(phi_k) <= hi_s`` for a ``spread`` term (ripple);
- the objective is a risk measure of the per-sample values v_s:

  * ``cvar``: CVaR_alpha after Rockafellar and Uryasev,
    ``VaR + sum_s u_s / ((1 - alpha) S)``, ``u_s >= v_s - VaR``, ``u_s >= 0``
    (alpha = 0 gives the mean; the minimising VaR is the alpha-quantile);
  * ``mean_std``: ``mean(v) + k sqrt(var(v) + eps)`` (population variance).

The requirements are imposed on the nominal design (as in :func:`build_nlp`), and on
every sample too with ``constrain_samples=True``. With zero tolerances every sample is the
nominal design and the robust optimum is the nominal one.

The same sampling and :func:`sampled_objective` serve the NumPy path (vectorised over a
population of perturbed designs) for the independent Monte Carlo check
(:mod:`optdesign.formulations.robust.solve`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.problem.design_problem import DesignProblem, Expressions
from optdesign.problem.objective_refusals import smooth_form_refusal, unavailable_objective
from optdesign.problem.objectives import ObjectiveTerm
from optdesign.problem.spec import Tolerances
from optdesign.programs.nlp import NLP, ConstraintRows, build_nlp, numeric_value, typical

#: Variance guard of the mean + k std measure (in scaled units, objective ~1).
STD_EPS = 1e-12


@dataclass(frozen=True)
class Samples:
    """Fixed draws of the manufacturing scatter.

    Attributes
    ----------
    deltas
        Variable name -> additive deviations, shape (S,), internal units.
    fit
        Fraction of the fit's tolerance band of each pin joint, shape (S, n_pins), in
        [0, 1] (0: smallest clearance, 1: largest); None keeps the requirement's
        ``fit_clearance``.
    seed
        Seed of the draws.
    """

    deltas: dict[str, np.ndarray]
    fit: np.ndarray | None
    seed: int

    @property
    def n(self) -> int:
        if self.deltas:
            return len(next(iter(self.deltas.values())))
        return 0 if self.fit is None else self.fit.shape[0]


def tolerances_of(problem: DesignProblem) -> Tolerances:
    """The problem's ``[tolerances]`` section; raise ProblemError naming it if absent."""
    tol = problem.spec.tolerances
    if tol is None:
        raise ProblemError(
            'tolerances: robust design needs a [tolerances] section (e.g. R = "0.05 mm", '
            'phi0 = "0.1 deg", fit = "uniform")'
        )
    return tol


def pin_count(problem: DesignProblem) -> int:
    """Number of sized pin joints in the clearance chain (each gets its own fit draw)."""
    q = problem.quantities(problem.design_dict(problem.midpoint()))
    return sum(j.pin is not None for j in q.joints)


def draw_samples(
    problem: DesignProblem, n: int, seed: int, tol: Tolerances | None = None
) -> Samples:
    """Draw ``n`` scatter samples of ``problem``'s tolerances with ``numpy`` seed ``seed``.

    Normal tolerances use sigma = band/3, uniform ones [-band, band]; the fit fraction is
    uniform in [0, 1], independently for every pin joint. The draw order is fixed
    (variables in :data:`TOLERANCED` order, then the fits), so the same seed and ``n``
    give the same samples.
    """
    tol = tol if tol is not None else tolerances_of(problem)
    rng = np.random.default_rng(seed)
    deltas: dict[str, np.ndarray] = {}
    per_variable = tol.variables()
    for name in _tolerance_order(problem, per_variable):
        t = per_variable[name]
        if t.distribution == "normal":
            deltas[name] = (t.band / 3.0) * rng.standard_normal(n)
        else:
            deltas[name] = t.band * rng.uniform(-1.0, 1.0, n)
    fit = None
    if tol.fit == "uniform":
        pins = pin_count(problem)
        if pins == 0:
            raise ProblemError("tolerances.fit: the problem has no pin joint to draw a fit for")
        fit = rng.uniform(0.0, 1.0, (n, pins))
    return Samples(deltas, fit, seed)


def perturb(design: Mapping[str, Any], samples: Samples, index) -> dict[str, Any]:
    """``design`` with the deviations of sample(s) ``index`` added.

    ``index`` is an int (one sample; values stay scalars or symbols) or a slice/array
    (NumPy population: values become columns, shape (k, 1)).
    """
    out = dict(design)
    for name, delta in samples.deltas.items():
        d = delta[index]
        out[name] = design[name] + (d[:, None] if np.ndim(d) else float(d))
    return out


def _tolerance_order(problem: DesignProblem, per_variable: Mapping[str, Any]) -> list[str]:
    # The mechanism's variable table order (R, l, n, p, ...), then the pin's (d).
    from optdesign.problem.variables import variable_table

    return [k for k in variable_table(problem.mechanism) if k in per_variable]


def sampled_objective(
    problem: DesignProblem,
    design: Mapping[str, Any],
    objective: str,
    fit_fraction=None,
    guarded: bool = False,
) -> tuple[ObjectiveTerm, Expressions]:
    """Objective term and expressions of ``design`` with the pin fits at ``fit_fraction``.

    ``fit_fraction``: one entry per pin joint (floats, or (k, 1) columns on the NumPy
    path), or None for the nominal model (the requirement's ``fit_clearance``).
    """
    ex = problem.expressions(design, guarded=guarded, fit_fractions=fit_fraction)
    if objective not in ex.objectives:
        raise unavailable_objective(problem, objective, ex.objectives)
    return ex.objectives[objective], ex


def risk_label(risk: str, alpha: float, k: float, objective: str) -> str:
    """Readable name of the minimised statistic, e.g. ``CVaR_0.9(backlash)``."""
    if risk == "cvar":
        return f"CVaR_{alpha:g}({objective})"
    return f"mean+{k:g}std({objective})"


def build_robust_nlp(
    problem: DesignProblem,
    objective: str | None = None,
    samples: Samples | None = None,
    risk: str | None = None,
    alpha: float | None = None,
    k: float | None = None,
    constrain_samples: bool = False,
) -> NLP:
    """Sample-average NLP of a risk measure of ``objective`` under the tolerances.

    Parameters
    ----------
    objective
        Objective name (default: the problem's first).
    samples
        Fixed scatter samples (default: ``[tolerances]`` samples and seed).
    risk, alpha, k
        ``"cvar"`` (CVaR_alpha) or ``"mean_std"`` (mean + k std); default from the file.
    constrain_samples
        Impose the requirements on every sample as well as on the nominal design.

    Returns
    -------
    NLP
        Decision vector: scaled design, then the per-sample epigraph variables and the
        risk variables. ``objective_values``: the risk measure and the nominal objective
        (for reports).
    """
    tol = tolerances_of(problem)
    objective = objective or problem.objective_names[0]
    risk = risk or tol.risk
    alpha = tol.alpha if alpha is None else alpha
    k = tol.k if k is None else k
    if risk not in ("cvar", "mean_std"):
        raise ProblemError(f"tolerances.risk: {risk!r} is not 'cvar' or 'mean_std'")
    if not 0.0 <= alpha < 1.0:
        raise ProblemError(f"tolerances.alpha: {alpha} must lie in [0, 1)")
    info = problem.objectives.get(objective)
    refusal = smooth_form_refusal(problem, objective, "robust design (an NLP per sample)")
    if refusal:
        raise ProblemError(refusal)
    if info is not None and info.bound_rows is not None:
        raise ProblemError(
            f"robust design: objective {objective!r} is a root of the model, bounded by "
            "implicit rows; the robust NLP takes objectives that are expressions of the design"
        )
    samples = samples if samples is not None else draw_samples(problem, tol.samples, tol.seed, tol)
    S = samples.n
    if S < 1:
        raise ProblemError("tolerances.samples: need at least one sample")

    # The nominal requirements (and objective limits) exactly as the nominal NLP has them.
    base = build_nlp(problem, objectives=[])
    n = base.n_design
    zd = base.z[:n]
    x = base.x_lo + base.x_span * zd
    design = problem.design_dict([x[j] for j in range(n)])
    theta = base.theta
    design.update(
        problem.parameter_design(dict(zip(base.param_names, ca.vertsplit(theta), strict=True)))
    )

    # Magnitudes at the start design (NumPy path): rows are divided by the size of the
    # objective's grid expression, the per-sample values by the objective's value.
    start_term, _ = sampled_objective(problem, problem.design_dict(problem.midpoint()), objective)
    scale = typical(start_term.expr)
    # max/scalar: the value is in units of the expression; a spread is scale-free
    v_scale = typical(numeric_value(start_term)) if start_term.kind == "spread" else scale

    aux, aux_lb, aux_ub, aux_init, aux_names = [], [], [], [], []
    rows = ConstraintRows()
    add = rows.add

    values = []  # per-sample objective, scaled (~1)
    nominal_term, _ = sampled_objective(problem, design, objective, guarded=True)
    for s in range(S):
        design_s = perturb(design, samples, s)
        fit_s = None if samples.fit is None else [float(u) for u in samples.fit[s]]
        term, ex_s = sampled_objective(problem, design_s, objective, fit_s, guarded=True)
        raw = ca.SX(term.expr)
        expr = raw / scale
        labels = problem.phi_labels
        if term.kind == "max":
            t = ca.SX.sym(f"t_{s}")
            aux.append(t)
            aux_lb.append(-np.inf)
            aux_ub.append(np.inf)
            aux_init.append(ca.mmax(expr))
            aux_names.append(f"{objective}_max[s{s}]")
            add(scale * t - raw, 0.0, None, scale, f"{objective}_envelope[s{s}]", labels, term.unit)
            values.append(t)
        elif term.kind == "spread":
            lo, hi = ca.SX.sym(f"lo_{s}"), ca.SX.sym(f"hi_{s}")
            aux += [lo, hi]
            aux_lb += [0.0, 1e-6]
            aux_ub += [np.inf, np.inf]
            aux_init += [ca.mmin(expr), ca.mmax(expr)]
            aux_names += [f"{objective}_lo[s{s}]", f"{objective}_hi[s{s}]"]
            add(raw - scale * lo, 0.0, None, scale, f"{objective}_lower[s{s}]", labels, term.unit)
            add(scale * hi - raw, 0.0, None, scale, f"{objective}_upper[s{s}]", labels, term.unit)
            # lo, hi are in units of scale; the spread is scale-free, bring it to ~1
            values.append(m.spread(lo, hi) / v_scale)
        else:
            values.append(expr)
        if constrain_samples:
            for block in ex_s.constraints:
                if block.lower is None and block.upper is None:
                    continue
                bound = max(abs(block.lower or 0.0), abs(block.upper or 0.0))
                add(
                    block.expr,
                    block.lower,
                    block.upper,
                    bound if bound > 0 else 1.0,
                    f"{block.name}[s{s}]",
                    block.labels,
                    block.unit,
                )
    v = ca.vertcat(*values)

    if risk == "cvar":
        # start: VaR at the sample mean, excesses tight (values at their aux starts)
        v0 = ca.substitute(v, ca.vertcat(*aux), ca.vertcat(*aux_init)) if aux else v
        var0 = ca.sum1(v0) / S
        var = ca.SX.sym("VaR")
        u = ca.SX.sym("u", S)
        aux += [var, *[u[j] for j in range(S)]]
        aux_lb += [-np.inf] + [0.0] * S
        aux_ub += [np.inf] * (S + 1)
        aux_init += [var0, *[ca.fmax(v0[j] - var0, 0.0) for j in range(S)]]
        aux_names += ["VaR"] + [f"cvar_excess[s{j}]" for j in range(S)]
        add(
            v_scale * (u - v + var),
            0.0,
            None,
            v_scale,
            "cvar_excess",
            [f"s{j}" for j in range(S)],
            "",
        )
        f = var + ca.sum1(u) / ((1.0 - alpha) * S)
    else:
        mean = ca.sum1(v) / S
        variance = ca.sum1((v - mean) ** 2) / S
        f = mean + k * ca.sqrt(variance + STD_EPS)

    # Nominal objective value (reporting only; not in f).
    nom = ca.SX(nominal_term.expr)
    if nominal_term.kind == "max":
        nominal_value = ca.mmax(nom)
    elif nominal_term.kind == "spread":
        nominal_value = m.grid_spread(nom)
    else:
        nominal_value = nom

    n_base_aux = base.z.shape[0] - n
    z_aux = ca.vertcat(*aux)
    z = ca.vertcat(base.z, z_aux)
    init_parts = []
    if n_base_aux:
        init_parts.append(base.aux_init(zd, theta))
    init_parts.append(ca.vertcat(*aux_init))
    aux_init_fun = ca.Function("robust_aux_init", [zd, theta], [ca.vertcat(*init_parts)])
    label = risk_label(risk, alpha, k, objective)
    g = ca.vertcat(base.g, *rows.exprs)
    nominal_name = f"{objective} (nominal)"
    nominal_scale = typical(numeric_value(start_term))
    w = ca.SX.sym("w", 2)
    return NLP(
        z=z,
        f=w[0] * f * v_scale + w[1] * nominal_value,
        g=g,
        p=ca.vertcat(w, theta),
        lbz=np.concatenate([base.lbz, aux_lb]),
        ubz=np.concatenate([base.ubz, aux_ub]),
        lbg=np.concatenate([base.lbg, rows.lbg]),
        ubg=np.concatenate([base.ubg, rows.ubg]),
        g_names=base.g_names + rows.names,
        g_units=base.g_units + rows.units,
        g_scale=np.concatenate([base.g_scale, rows.scales]),
        n_design=n,
        x_lo=base.x_lo,
        x_span=base.x_span,
        design_names=base.design_names,
        aux_names=base.aux_names + aux_names,
        targets=[label, nominal_name],
        target_scales=np.array([v_scale, nominal_scale]),
        objective_values={label: f * v_scale, nominal_name: nominal_value},
        eps_rows={},
        default_target=label,
        form="robust-saa",
        aux_init=aux_init_fun,
        param_names=base.param_names,
        param_defaults=base.param_defaults,
    )
