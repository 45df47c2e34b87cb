"""A design problem: variables, objectives and constraints of a mechanism, as expressions.

:meth:`DesignProblem.expressions` takes a design (every variable name -> a float, a NumPy
array broadcast against the grid, or a CasADi symbol) and returns the objective terms and
constraint blocks computed from the design's quantities. The formulations (NLP, GP,
robust, NSGA-II) and the independent checks all go through it, so each requirement is
written once. Objectives come from the built-in declarations
(:mod:`optdesign.problem.objectives`) plus those a user adds; constraints from the
requirements plus those a user adds. Nothing here knows a solver, nor names a mechanism.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError, ProblemError
from optdesign.problem import declarations, drive
from optdesign.problem.evaluation import Evaluation, evaluation_of
from optdesign.problem.objectives import (
    BUILTIN_OBJECTIVES,
    ConstraintBlock,
    ConstraintInfo,
    ObjectiveInfo,
    ObjectiveTerm,
    bound_rows_of,
)
from optdesign.problem.quantities import Quantities
from optdesign.problem.requirements import requirement_blocks
from optdesign.problem.spec import ProblemSpec
from optdesign.problem.spec_validation import validate_spec
from optdesign.problem.variables import Variable
from optdesign.user_code import UserCodeError, is_users, quantity_of


@dataclass
class Expressions:
    """Objective terms and constraint blocks of one design, and its quantities."""

    objectives: dict[str, ObjectiveTerm]
    constraints: list[ConstraintBlock]
    quantities: Quantities

    @property
    def mechanism(self):
        return self.quantities.mechanism


#: The sections of a problem whose numbers :meth:`DesignProblem.with_setting` moves (and a
#: sweep varies): the requirements, the motion the fin must make, the load it drives and
#: the position loop around the drive (its placed bandwidth, its lag, ...).
SETTING_SECTIONS = ("requirements", "motion", "load", "loop")


class DesignProblem:
    """A validated design problem.

    Parameters
    ----------
    spec
        The validated problem file (or dict).
    variables
        The declared variables (fixed and free), in internal units.
    mechanism
        The mechanism plug-in class.
    """

    #: Unit text of each quantity the problem file wrote (path -> unit, set by the loader),
    #: so that reports answer in the file's units; empty for a problem built in code.
    written_units: Mapping[str, str] = MappingProxyType({})

    def __init__(self, spec: ProblemSpec, variables: list[Variable], mechanism: type):
        self.spec = spec
        self.mechanism = mechanism
        self.variables = variables
        self.by_name = {v.name: v for v in variables}
        self._objectives: dict[str, ObjectiveInfo] = dict(BUILTIN_OBJECTIVES)
        self._constraints: list[ConstraintInfo] = []
        self._grid()
        self._check_consistency()
        self._try_mechanism()
        self._touch()

    def _try_mechanism(self) -> None:
        """A user's mechanism runs once at the middle of the bounds, so that an error in
        its code is reported when the problem is loaded (its class, method, file, line)."""
        if not is_users(self.mechanism):
            return
        q = self.quantities(self.design_dict(self.midpoint()))
        q.doing = "while loading the problem (the mechanism at the middle of the bounds)"
        try:
            with np.errstate(all="ignore"):
                q.nut_position, q.ratio  # noqa: B018 (computed for their errors)
        except UserCodeError:
            raise
        except Exception:  # not the user's code: the solve reports it where it belongs
            return

    def _grid(self) -> None:
        d = self.spec.requirements.deflection
        self.phi = np.linspace(d.min, d.max, d.points)
        self.phi_labels = [f"phi={np.degrees(p):+.1f}deg" for p in self.phi]

    def _touch(self) -> None:
        # A new token whenever the problem changes: in-process caches of formulations
        # and solvers are keyed on it, so a changed problem never reuses a stale solver.
        self.token = uuid.uuid4().hex
        self._blob: bytes | None = None

    # --- pickling (problems travel to worker processes) ---------------------------------
    def __getstate__(self) -> dict[str, Any]:
        # User functions (lambdas), a mechanism class defined in a notebook and the
        # spec's model class (derived at run time) do not pickle by reference:
        # cloudpickle carries the callables and the class by value (once per problem
        # state), the spec travels as its validated data.
        if self._blob is None:
            import cloudpickle

            self._blob = cloudpickle.dumps((self.mechanism, self._objectives, self._constraints))
        return {
            "spec": self.spec.model_dump(mode="python"),
            "variables": self.variables,
            "blob": self._blob,
            "token": self.token,
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        import pickle

        mechanism, objectives, constraints = pickle.loads(state["blob"])
        self.mechanism = mechanism
        self.spec = validate_spec(state["spec"], mechanism, internal=True)
        self.variables = state["variables"]
        self.by_name = {v.name: v for v in self.variables}
        self._objectives = objectives
        self._constraints = constraints
        self._grid()
        self.token = state["token"]
        self._blob = state["blob"]

    # --- declared things ---------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def mechanism_name(self) -> str:
        return self.mechanism.name

    @property
    def objective_names(self) -> list[str]:
        """The objectives the problem minimises (first: the default)."""
        return list(self.spec.objective.minimize)

    @property
    def objectives(self) -> dict[str, ObjectiveInfo]:
        """Every objective this problem can compute (built-in and added)."""
        return dict(self._objectives)

    @property
    def user_constraints(self) -> list[ConstraintInfo]:
        return list(self._constraints)

    @property
    def free(self) -> list[Variable]:
        return [v for v in self.variables if v.free]

    @property
    def fixed_values(self) -> dict[str, float]:
        return {v.name: v.value for v in self.variables if not v.free}

    def has(self, name: str) -> bool:
        return name in self.by_name

    def lower(self) -> np.ndarray:
        return np.array([v.lower for v in self.free], dtype=float)

    def upper(self) -> np.ndarray:
        return np.array([v.upper for v in self.free], dtype=float)

    def midpoint(self) -> np.ndarray:
        """The middle of the bounds: where formulations take their scales (a declared
        start never changes the scaling, so it cannot steer the search)."""
        return 0.5 * (self.lower() + self.upper())

    def start(self) -> np.ndarray:
        """Initial design: declared starts, else the middle of the bounds."""
        mid = self.midpoint()
        return np.array(
            [v.start if v.start is not None else mid[k] for k, v in enumerate(self.free)]
        )

    def design_dict(self, x: np.ndarray | Any) -> dict[str, Any]:
        """Full design (fixed + free) from the free-variable vector ``x``.

        ``x`` may be a 1-D array (one design), a 2-D array (population, one row per
        design; values become columns broadcast against the grid) or a CasADi vector.
        """
        design: dict[str, Any] = dict(self.fixed_values)
        if isinstance(x, np.ndarray) and x.ndim == 2:
            for k, v in enumerate(self.free):
                design[v.name] = x[:, k : k + 1]
        else:
            for k, v in enumerate(self.free):
                design[v.name] = x[k]
        return design

    def _check_consistency(self) -> None:
        table = self.mechanism.variable_table()
        missing = [k for k, info in table.items() if info.default is None and not self.has(k)]
        if missing:
            raise ProblemError(
                f"variables.{missing[0]}: required for a {self.mechanism.label()} "
                f"({table[missing[0]].description})"
            )
        req = self.spec.requirements
        needs_pin = (
            any(o in ("backlash", "backlash_rss") for o in self.objective_names)
            or req.pin_bearing_pressure_max is not None
            or req.pin_shear_stress_max is not None
            or req.backlash_max is not None
        )
        if needs_pin:
            if not self.has("d"):
                raise ProblemError(
                    "variables.d: the pin diameter is needed by the backlash objective or the "
                    "pin requirements; declare it (fixed or free)"
                )
            if self.has("pin_length") == self.has("pin_length_ratio"):
                raise ProblemError(
                    "variables: declare exactly one of pin_length and pin_length_ratio"
                )
        unknown = [o for o in self.objective_names if o not in self._objectives]
        if unknown:
            raise ProblemError(
                f"objective.minimize: unknown objective {unknown[0]!r} "
                f"(known: {', '.join(self._objectives)})"
            )
        from optdesign.problem.consistency import check_problem

        check_problem(self)

    # --- user additions ----------------------------------------------------------------
    def add_objective(
        self,
        name: str,
        fn: Callable[[Quantities], Any],
        unit: str = "",
        kind: str | None = None,
        description: str = "",
        formula: str = "",
        display_unit: str | None = None,
        display_scale: float | None = None,
        *,
        replace: bool = False,
    ) -> ObjectiveInfo:
        """Declare an objective ``fn(q)`` (see :class:`~optdesign.problem.quantities.
        Quantities` for ``q``), written with :mod:`optdesign.math`.

        ``name``: letters, digits and underscores (it becomes a column header and a JSON
        key); an existing objective - a built-in one such as ``backlash`` included - is
        replaced only with ``replace=True``. ``kind``: ``"max"`` (largest value over the
        stroke), ``"spread"`` ((max - min)/(max + min) over the stroke) or ``"scalar"``
        (one value per design); default: ``"max"`` when ``fn`` returns a value per grid
        angle, else ``"scalar"``. ``unit`` is the internal unit of the value (a unit
        expression such as ``"N*mm/rad"``, ``""`` for a plain number). Reports show
        ``value * display_scale`` in ``display_unit``, a unit of the same dimension, angles
        counted; ``display_scale`` defaults to the factor between the two units and, when
        given, must equal it. ``fn`` is tried at the middle of the bounds now: an error, or
        a value no formulation can use, is refused naming the function and its file and
        line. The objective is then available to every study (solve, Pareto, bench ...) by
        its name.
        """
        declarations.objective_declaration(
            self, name, fn, unit, kind, description, formula, display_unit, display_scale, replace
        )
        display_scale = _display_scale(unit, display_unit, display_scale)
        q = self.quantities(self.design_dict(self.midpoint()))
        value = quantity_of(
            fn,
            q,
            f"objective {name!r}",
            kind != "scalar",
            "while trying it at the middle of the bounds",
        )
        if kind is None:
            kind = "max" if self.quantities_on_grid(value) else "scalar"
        info = ObjectiveInfo(
            name, fn, kind, unit, description or name, formula, display_unit, display_scale
        )
        self._objectives[name] = info
        self._touch()
        return info

    def add_constraint(
        self,
        name: str,
        fn: Callable[[Quantities], Any],
        lower: Any = None,
        upper: Any = None,
        unit: str = "",
        over: str = "stroke",
        description: str = "",
    ) -> ConstraintInfo:
        """Require ``lower <= fn(q) <= upper`` (at every grid angle for ``over="stroke"``,
        once for ``over="design"``).

        ``name``: a new name of letters, digits and underscores. Bounds are numbers in
        ``unit`` or quantity strings (``"3 kN"``) converted to ``unit``; ``unit`` is the
        internal unit of ``fn``'s value (e.g. ``"N"``). ``fn`` is tried at the middle of
        the bounds now (see :meth:`add_objective`).
        """
        lower, upper = declarations.constraint_declaration(
            self, name, fn, lower, upper, unit, over, description
        )
        q = self.quantities(self.design_dict(self.midpoint()))
        quantity_of(
            fn,
            q,
            f"constraint {name!r}",
            over == "stroke",
            "while trying it at the middle of the bounds",
        )
        info = ConstraintInfo(name, fn, lower, upper, unit, over, description)
        self._constraints.append(info)
        self._touch()
        return info

    def remove_constraint(self, name: str) -> None:
        """Drop the user constraint ``name``."""
        before = len(self._constraints)
        self._constraints = [c for c in self._constraints if c.name != name]
        if len(self._constraints) == before:
            raise InputError("remove_constraint", f"no user constraint {name!r}")
        self._touch()

    def set_requirement(self, name: str, value: Any) -> None:
        """Change (or add; None removes) requirement ``name``, validated like a file."""
        data = self.spec.model_dump(mode="python")
        reqs = dict(data["requirements"])
        if value is None:
            reqs.pop(name, None)
        else:
            reqs[name] = value
        self._revalidate({**data, "requirements": reqs})

    def with_requirement(self, path: str, value: Any) -> DesignProblem:
        """A copy whose requirement ``path`` (``"hinge_moment"``, ``"mean_ratio.min"``,
        ``"deflection.points"``) is ``value`` in internal units, validated like a file; this
        problem is left as it is (its solver caches stay valid). The copy shares this
        problem's mechanism, variables and added objectives and constraints."""
        return self.with_setting(f"requirements.{path}", value)

    def with_setting(self, path: str, value: Any) -> DesignProblem:
        """A copy whose value at ``path`` - a requirement (``"requirements.hinge_moment"``)
        or a number of the motion, the load or the loop (``"motion.rise_time"``,
        ``"load.inertia"``, ``"loop.bandwidth"``; :data:`SETTING_SECTIONS`) - is ``value``
        in internal units, validated like a file; as :meth:`with_requirement` otherwise.
        ProblemError when the problem has no such section."""
        section, _, rest = path.partition(".")
        if section not in SETTING_SECTIONS or not rest:
            raise ProblemError(
                f"{path}: not a setting (give {', '.join(s + '.NAME' for s in SETTING_SECTIONS)})"
            )
        data = self.spec.model_dump(mode="python")
        node = data[section]
        if node is None:
            raise ProblemError(f"{path}: the problem has no [{section}] section")
        keys = rest.split(".")
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
        new = object.__new__(type(self))  # not copy.copy: that would pickle the user code
        new.__dict__.update(self.__dict__)
        new.spec = validate_spec(data, self.mechanism, source=self.name, internal=True)
        new._grid()
        new._check_consistency()
        new._touch()
        return new

    def set_objective(self, *names: str) -> None:
        """Change the objective(s) the problem minimises."""
        data = self.spec.model_dump(mode="python")
        self._revalidate({**data, "objective": {"minimize": list(names)}})

    def _revalidate(self, data: dict[str, Any]) -> None:
        self.spec = validate_spec(data, self.mechanism, source=self.name)
        self._grid()
        self._check_consistency()
        self._touch()

    def quantities_on_grid(self, value) -> bool:
        """True when ``value`` varies over the deflection grid."""
        n = len(self.phi)
        if m.is_symbolic(value):
            return value.shape[0] == n and n > 1
        shape = getattr(value, "shape", np.shape(value))
        return bool(shape) and shape[-1] == n and n > 1

    # --- the model ---------------------------------------------------------------------
    def quantities(
        self,
        design: Mapping[str, Any],
        guarded: bool = False,
        first_order: bool = False,
        fit_fractions=None,
    ) -> Quantities:
        """The quantities of ``design`` (computed lazily)."""
        return Quantities(self, design, guarded, first_order, fit_fractions)

    def parameters(self) -> dict[str, float]:
        """The problem's parameters (values fixed per solve on the solver path: catalogue
        item data, table-fit ratios) and their defaults; see :mod:`optdesign.problem.drive`."""
        return drive.parameter_defaults(self)

    def parameter_values(self, box: Mapping[str, tuple[float, float]]) -> dict[str, float]:
        """Parameter values of a solve whose discrete variables lie in ``box``."""
        return drive.parameter_values(self, dict(box))

    @staticmethod
    def parameter_design(values: Mapping[str, Any]) -> dict[str, Any]:
        """Design-dict entries that carry parameter values (symbols on the solver path)."""
        return {drive.PARAM + k: v for k, v in values.items()}

    def objective_limits(self) -> dict[str, float]:
        """Upper limits that the requirements put on objective quantities."""
        req = self.spec.requirements
        return {"ripple": req.ripple_max} if req.ripple_max is not None else {}

    def expressions(
        self,
        design: Mapping[str, Any],
        guarded: bool = False,
        first_order: bool = False,
        fit_fractions=None,
        share: bool = True,
    ) -> Expressions:
        """Objective terms and constraint blocks of ``design``.

        Parameters
        ----------
        design
            Every variable name -> value (float, NumPy array or CasADi symbol).
        guarded
            Guard square roots for a solver (CasADi path).
        first_order
            Use first-order Hertz flattening (the GP form).
        fit_fractions
            One fit fraction per sized pin (robust design), None for the nominal fit.
        share
            Share the model functions' results within this call (False: each use
            computes its own, to show that sharing changes no value).
        """
        if not share:
            return self._build(design, guarded, first_order, fit_fractions)
        # Every block asks for the same few quantities: share the model functions'
        # results (one expression node, or one NumPy evaluation, per quantity).
        with m.shared_subexpressions():
            return self._build(design, guarded, first_order, fit_fractions)

    def _build(self, design, guarded, first_order, fit_fractions) -> Expressions:
        q = self.quantities(design, guarded, first_order, fit_fractions)
        objectives: dict[str, ObjectiveTerm] = {}
        for info in self._objectives.values():
            if not is_users(info.fn):  # built-in (also after pickling to a worker)
                expr = info.fn(q)  # None: not available for this problem (e.g. no pin)
            else:  # a user's function: its failure names it, its file and line
                expr = quantity_of(info.fn, q, f"objective {info.name!r}", info.kind != "scalar")
            if expr is not None:
                # the smooth pieces of a kinked objective, for the solver's epigraph only
                pieces = info.pieces(q) if info.pieces is not None and m.is_symbolic(expr) else ()
                bound = bound_rows_of(info, q, expr)
                objectives[info.name] = ObjectiveTerm(
                    info.name, info.kind, expr, info.unit, info.description, tuple(pieces), bound
                )
        backlash = objectives["backlash"].expr if "backlash" in objectives else None
        blocks = requirement_blocks(q, self._constraints, backlash)
        return Expressions(objectives, blocks, q)

    # --- numeric evaluation (NumPy path) ------------------------------------------------
    def evaluate(self, x: np.ndarray) -> Evaluation:
        """Objectives and constraint values of designs ``x`` on the NumPy path.

        ``x``: the free-variable vector (1-D) or a population (2-D, one design per row).
        """
        x = np.asarray(x, dtype=float)
        single = x.ndim == 1
        X = x[None, :] if single else x
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            ex = self.expressions(self.design_dict(X))
        return evaluation_of(ex, X.shape[0], len(self.phi), self.objective_limits(), single)


def _display_scale(unit: str, display_unit: str | None, scale: float | None) -> float:
    """The factor from an objective's ``unit`` to its ``display_unit`` (checked against
    ``scale`` when one is given)."""
    from optdesign.units import parse_unit, unit_factor

    parse_unit(unit, "add_objective.unit")
    if display_unit is None:
        factor = 1.0
    else:
        factor = unit_factor(unit, display_unit, "add_objective.display_unit")
    if scale is None:
        return factor
    if isinstance(scale, bool) or not isinstance(scale, int | float) or not np.isfinite(scale):
        raise InputError("add_objective.display_scale", f"expected a number, got {scale!r}")
    if not np.isclose(scale, factor, rtol=1e-9, atol=0.0):
        shown = f"{unit!r}" if unit else "a plain number"
        raise InputError(
            "add_objective.display_scale",
            f"{scale:g} does not turn {shown} into {display_unit or unit!r} "
            f"(the factor is {factor:.10g}; leave display_scale out to use it)",
        )
    return float(scale)
