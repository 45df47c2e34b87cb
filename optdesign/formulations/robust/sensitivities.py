"""What a robust optimum depends on: the sensitivities of the sample-average NLP
(:mod:`optdesign.formulations.robust.program`) to every requirement and active bound.

The envelope theorem of :mod:`optdesign.formulations.nlp.sensitivities` applies to the robust NLP as
to any: ``dv*/dp = sum_i mu_i (dg_i/dp - db_i/dp)`` over its rows, with the multipliers in
the problem's units (``mu_i = lam_g_i T / s_i``). The rows are of three kinds:

- the nominal requirements, exactly the nominal NLP's rows (the nominal row model);
- per sample ``s`` the epigraph of its objective (``t_s >= theta_s(phi_k)``, or the
  ``lo_s``/``hi_s`` band of a spread) and, with ``constrain_samples``, the requirements
  again: their ``p``-dependence is the sample's model, evaluated on the NumPy path for
  all samples at once (the same :func:`~optdesign.formulations.robust.program.sampled_objective`
  as the solver's); a requirement's multipliers are so summed over its samples;
- the CVaR excess rows ``u_s >= v_s - VaR``, which hold no parameter.

The risk measure itself is a function of the auxiliaries only (no ``p``), so the rows
carry every parameter dependence; a one-value (scalar) objective enters the risk
measure directly and is not covered (no sensitivities, a note says so).
"""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np

from optdesign.formulations.robust.program import Samples, perturb, sampled_objective
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import Result, Sensitivity

_SAMPLE_ROW = re.compile(r"^(.*?)\[s(\d+)\]")


class _SampleRows:
    """The parameter-dependent part of the robust NLP's rows at a fixed design."""

    def __init__(self, nlp, mu: np.ndarray, samples: Samples, objective: str):
        from optdesign.formulations.nlp.sensitivities import _RowModel

        self.objective = objective
        self.samples = samples
        robust = [i for i, n in enumerate(nlp.g_names) if _SAMPLE_ROW.match(n)]
        n_base = min(robust) if robust else len(nlp.g_names)
        base = SimpleNamespace(g_names=nlp.g_names[:n_base], eps_rows={})
        self.base = _RowModel(base, nlp.default_target, mu[:n_base])
        self.rows: list[tuple[int, str, int, int]] = []  # (row, prefix, sample, index)
        seen: dict[tuple[str, int], int] = {}
        for i in robust:
            match = _SAMPLE_ROW.match(nlp.g_names[i])
            prefix, s = match.group(1), int(match.group(2))
            k = seen.get((prefix, s), 0)
            seen[(prefix, s)] = k + 1
            if mu[i] != 0.0 and prefix != "cvar_excess":
                self.rows.append((i, prefix, s, k))
        self.mu = mu

    def value(self, problem: DesignProblem, x: np.ndarray) -> float:
        total = self.base.value(problem, x)
        if not self.rows:
            return total
        S = self.samples.n
        full = {**problem.fixed_values, **problem.design_dict(x)}
        columns = {name: np.full((S, 1), float(v)) for name, v in full.items()}
        design = perturb(columns, self.samples, slice(0, S))
        fit = self.samples.fit
        fits = None if fit is None else [fit[:, j : j + 1] for j in range(fit.shape[1])]
        with np.errstate(all="ignore"):
            term, ex = sampled_objective(problem, design, self.objective, fits)
            theta = np.asarray(term.expr, dtype=float).reshape(S, -1)
            blocks = {
                b.name: (np.asarray(b.expr, dtype=float).reshape(S, -1), b.lower, b.upper)
                for b in ex.constraints
            }
        for i, prefix, s, k in self.rows:
            mu = float(self.mu[i])
            if prefix == f"{self.objective}_envelope" or prefix == f"{self.objective}_upper":
                total += mu * -theta[s, k]  # scale * t_s - theta (or hi_s): t_s fixed
            elif prefix == f"{self.objective}_lower":
                total += mu * theta[s, k]
            else:  # a requirement imposed on the sample
                values, lo, hi = blocks[prefix]
                b = hi if mu > 0 else lo
                g = values[s, k if values.shape[1] > 1 else 0]
                total += mu * (g - (b if b is not None and math.isfinite(b) else 0.0))
        return total


def robust_sensitivities(
    problem: DesignProblem, result: Result, nlp, samples: Samples, objective: str
) -> list[Sensitivity]:
    """The sensitivities of a robust optimum (``result`` of the robust NLP ``nlp`` of
    ``objective`` over ``samples``, with the solver's multipliers in ``result.raw``), ranked as
    :func:`~optdesign.formulations.nlp.sensitivities.nlp_sensitivities` ranks them; empty without
    multipliers or for a one-value objective."""
    from optdesign.formulations.nlp.sensitivities import from_multipliers

    raw = result.raw
    if not result.success or "lam_g" not in raw or "lam_x" not in raw:
        return []
    label = nlp.default_target
    return from_multipliers(
        problem, result, nlp, label, label, lambda mu: _SampleRows(nlp, mu, samples, objective)
    )
