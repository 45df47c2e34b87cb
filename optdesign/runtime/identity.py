"""The identity of a stored run: every input that changes its records.

A resumable run (a front, a benchmark) writes its identity as the first line of its
store (:func:`optdesign.storage.open_store`); a resume is refused unless every component
is the same. The components are kept apart, so that the refusal names what changed:

- ``problem``: a hash of the problem's whole content (mechanism, variables and bounds,
  requirements, materials, tolerances, screw ...) - not its name, description or
  ``[solver]`` table, which have components of their own;
- ``formulation``: the NLP's fingerprint (functions, bounds, scales), which also covers
  objectives and constraints added in Python and a user mechanism's code;
- ``objectives``, ``method`` (the method's settings);
- ``solver``: the back-end's name, the problem file's ``[solver]`` table (starts, seed,
  agree, every Ipopt option) and the options given in code;
- ``optdesign``: the version, since records depend on the code that computed them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from optdesign.store_identity import digest

#: Parts of a problem file that do not change what is computed (or that the ``solver``
#: component holds).
_NOT_CONTENT = {"name", "description", "solver"}


def problem_digest(problem) -> str:
    """Hash of the problem's content: what its records depend on, not its name."""
    data = problem.spec.model_dump(mode="json", exclude=_NOT_CONTENT)
    data["__mechanism__"] = f"{problem.mechanism.__module__}.{problem.mechanism.__qualname__}"
    data["__user__"] = {
        "objectives": sorted(problem.objectives),
        "constraints": [c.name for c in problem.user_constraints],
    }
    return digest(data)


def solver_identity(
    problem, back_end: str, options: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """The ``solver`` component: back-end, the file's ``[solver]`` table, code options."""
    return {
        "back_end": back_end,
        "file": problem.spec.solver.model_dump(mode="json"),
        "options": dict(options or {}),
    }


def version() -> str:
    from optdesign import __version__

    return __version__


def run_identity(
    problem,
    objectives: Sequence[str],
    *,
    formulation: str,
    back_end: str,
    method: Mapping[str, Any],
    options: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The identity components of a run of ``problem`` (see the module docstring);
    ``formulation`` is the fingerprint of the NLP the run solves (the caller builds it:
    the engine knows no formulation)."""
    return {
        "problem": problem_digest(problem),
        "formulation": formulation,
        "objectives": list(objectives),
        "method": dict(method),
        "solver": solver_identity(problem, back_end, options),
        "optdesign": version(),
    }
