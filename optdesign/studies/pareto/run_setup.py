"""What every front method does before its first task: the problem and objectives
checked, the store's path and identity, and the check of a stored record before a resume
trusts it. Shared by :mod:`~optdesign.studies.pareto.methods` and
:mod:`~optdesign.studies.pareto.catalogue_front`.
"""

from __future__ import annotations

import functools
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from optdesign.errors import InfeasibleRequirementsError, InputError
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.necessary import impossibilities
from optdesign.runtime.identity import run_identity
from optdesign.runtime.run_options import RunOptions as RunOptions  # the fronts import it here
from optdesign.safe_io import slug
from optdesign.studies.pareto.records import record_problem


def check_front_problem(problem: DesignProblem) -> None:
    """Refuse, before any work, a problem no front can be traced on: no free variable,
    or a mechanism's proof that no design within the bounds meets the requirements."""
    if not problem.free:
        raise InputError(
            "variables",
            "no free variable: a front trades objectives by moving the design, and this "
            "problem's design is fixed (od.solve, optdesign solve, checks it)",
        )
    proofs = impossibilities(problem)
    if proofs:
        raise InfeasibleRequirementsError(
            "no design within the bounds can meet the requirements, so there is no front "
            f"(proved before any solve): {'; '.join(p.text() for p in proofs)}"
        )


def check_objectives(problem: DesignProblem, objectives: Sequence[str]) -> list[str]:
    """Two or three distinct objectives the problem can compute."""
    check_front_problem(problem)
    objectives = list(objectives)
    if len(objectives) not in (2, 3):
        raise InputError("objectives", f"give two or three objectives, got {objectives}")
    if len(set(objectives)) != len(objectives):
        raise InputError("objectives", f"repeated objective in {objectives}")
    ex = problem.expressions(problem.design_dict(problem.midpoint()))
    for k in objectives:
        if k not in ex.objectives:
            raise InputError(
                "objectives",
                f"{k!r} is not an objective of {problem.name} (available: {', '.join(ex.objectives)})",
            )
    return objectives


def store_path(out: Path | str | None, name: str) -> Path:
    """The store file of method ``name`` in ``out`` (a new temporary folder when None):
    the name is a plain file name, never a path."""
    if not isinstance(name, str) or slug(name) != name:
        raise InputError(
            "name", f"{name!r}: a method's name names its store file: use letters, digits, ._-"
        )
    base = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="optdesign-pareto-"))
    base.mkdir(parents=True, exist_ok=True)
    return base / f"{name}.jsonl"


def run_key(
    problem: DesignProblem, objectives: Sequence[str], back_end: str, /, **settings: Any
) -> dict[str, Any]:
    """Identity of a front's run (the components of
    :func:`optdesign.runtime.identity.run_identity`): problem, formulation, objectives,
    the method's ``settings``, the solver ``back_end`` with every option, version."""
    nlp = formulation_for(problem, tuple(sorted(objectives)))
    return run_identity(
        problem, objectives, formulation=nlp.fingerprint, back_end=back_end, method=settings
    )


def record_check(problem: DesignProblem, objectives: Sequence[str]):
    """``check(record)`` for :func:`run_tasks`: why a stored record of a front of
    ``problem`` cannot be trusted (see :func:`record_problem`)."""
    nlp = formulation_for(problem, tuple(sorted(objectives)))
    return functools.partial(record_problem, problem, nlp=nlp)
