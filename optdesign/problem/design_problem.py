"""A design problem as expressions: variables, objective terms, constraint blocks.

:meth:`DesignProblem.expressions` takes a design (a mapping of every variable name to a
float, a NumPy array broadcast against the grid, or a CasADi symbol) and returns the
objective terms and constraint blocks built from the mechanism models. The
formulations (NLP, GP, NSGA-II) and the independent checks all go through it, so each
requirement is written once. Nothing here knows a solver.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.mechanisms import CrankSlider, Joint, PinJoint, ShiftingFork
from optdesign.models import crank_slider as cs_model
from optdesign.models.loads import pin_bearing_pressure, pin_shear_stress
from optdesign.problem.spec import VARIABLE_DESCRIPTIONS, ProblemSpec

#: sqrt guard of the assembly condition on the solver path (mm^2): keeps iterates that
#: leave the assembly region finite; the assembly-margin constraint keeps solutions out.
ASSEMBLY_FLOOR = 1e-6


@dataclass(frozen=True)
class Variable:
    """A design variable, in internal units.

    Attributes
    ----------
    name, description, unit
        Identification (unit is the internal unit, for tables).
    lower, upper
        Bounds of a free variable (None for a fixed one).
    value
        Value of a fixed variable.
    values
        Catalogue values of a discrete variable (None when continuous).
    start
        Preferred initial value of a free variable.
    """

    name: str
    description: str
    unit: str
    lower: float | None = None
    upper: float | None = None
    value: float | None = None
    values: tuple[float, ...] | None = None
    start: float | None = None

    @property
    def free(self) -> bool:
        return self.value is None

    @property
    def discrete(self) -> bool:
        return self.values is not None


@dataclass
class ObjectiveTerm:
    """An objective.

    kind ``"spread"``: (max - min)/(max + min) of ``expr`` over the grid (ripple);
    ``"max"``: the maximum of ``expr`` over the grid; ``"scalar"``: ``expr`` itself.
    """

    name: str
    kind: str
    expr: Any
    unit: str = ""
    description: str = ""


@dataclass
class ConstraintBlock:
    """lower <= expr <= upper, element-wise over the grid (or a scalar).

    ``labels`` name the rows (e.g. the deflection angle), ``unit`` is the unit of expr.
    """

    name: str
    expr: Any
    lower: float | None = None
    upper: float | None = None
    labels: list[str] = field(default_factory=list)
    unit: str = ""
    description: str = ""


@dataclass
class Expressions:
    """Objective terms and constraint blocks of one design."""

    objectives: dict[str, ObjectiveTerm]
    constraints: list[ConstraintBlock]
    mechanism: Any


UNITS = {"length": "mm", "angle": "rad", "dimensionless": ""}


class DesignProblem:
    """A validated design problem.

    Parameters
    ----------
    spec
        The validated problem file.
    variables
        The declared variables (fixed and free), in internal units.
    """

    def __init__(self, spec: ProblemSpec, variables: list[Variable]):
        self.spec = spec
        self.variables = variables
        self.by_name = {v.name: v for v in variables}
        req = spec.requirements
        self.phi = np.linspace(req.deflection.min, req.deflection.max, req.deflection.points)
        self.phi_labels = [f"phi={np.degrees(p):+.1f}deg" for p in self.phi]
        self._check_consistency()

    # --- declared things ---------------------------------------------------------
    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def mechanism_kind(self) -> str:
        return self.spec.mechanism

    @property
    def objective_names(self) -> list[str]:
        return list(self.spec.objective.minimize)

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

    def start(self) -> np.ndarray:
        """Initial design: declared starts, else the middle of the bounds."""
        return np.array(
            [v.start if v.start is not None else 0.5 * (v.lower + v.upper) for v in self.free]
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
        spec = self.spec
        needs_pin = (
            "backlash" in self.objective_names
            or "backlash_rss" in self.objective_names
            or spec.requirements.pin_bearing_pressure_max is not None
            or spec.requirements.pin_shear_stress_max is not None
            or spec.requirements.backlash_max is not None
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
        for name in ("p",) + (("R", "l", "n") if spec.mechanism == "crank_slider" else ("R",)):
            if not self.has(name):
                raise ProblemError(f"variables.{name}: required for a {spec.mechanism}")

    # --- the model ---------------------------------------------------------------------
    def mechanism(self, design: Mapping[str, Any], guarded: bool = False):
        """The mechanism of ``design``; ``guarded`` adds the solver's sqrt guard."""
        get = design.get
        if self.spec.mechanism == "crank_slider":
            return CrankSlider(
                design["R"],
                design["l"],
                design["n"],
                design["p"],
                get("i_a", 1.0),
                get("phi0", 0.0),
                floor=ASSEMBLY_FLOOR if guarded else None,
            )
        return ShiftingFork(design["R"], design["p"], get("i_a", 1.0), get("phi0", 0.0))

    def pin(self, design: Mapping[str, Any], first_order: bool = False) -> PinJoint | None:
        """The pin joint of ``design`` (None if the problem has no pin)."""
        if "d" not in design:
            return None
        d = design["d"]
        L = design["pin_length"] if "pin_length" in design else design["pin_length_ratio"] * d
        mat = self.spec.materials.pin
        req = self.spec.requirements
        return PinJoint(d, L, req.fit, req.fit_clearance, mat.E, mat.nu, 2, first_order)

    def joints(self, mech, pin: PinJoint | None) -> list[Joint]:
        """The clearance chain: the sized pin joint(s) plus the declared fixed clearances
        (``[clearances]`` A, B, C, O, keyed by the paper's joint letters)."""
        c = self.spec.clearances
        fixed = {"A": c.A, "B": c.B, "C": c.C, "O": c.O}
        joints = []
        for joint in mech.default_joints(pin):
            if joint.pin is not None:
                joints.append(joint)
            elif fixed.get(joint.name[0]):
                joints.append(replace(joint, clearance=fixed[joint.name[0]]))
        return joints

    def objective_limits(self) -> dict[str, float]:
        """Upper limits that the requirements put on objective quantities."""
        req = self.spec.requirements
        limits = {}
        if req.ripple_max is not None:
            limits["ripple"] = req.ripple_max
        return limits

    def expressions(
        self, design: Mapping[str, Any], guarded: bool = False, first_order: bool = False
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
        """
        # Every block below asks the mechanism for the same few quantities: share them
        # (one expression node, or one NumPy evaluation, per quantity).
        with m.shared_subexpressions():
            return self._expressions(design, guarded, first_order)

    def _expressions(
        self, design: Mapping[str, Any], guarded: bool, first_order: bool
    ) -> Expressions:
        req = self.spec.requirements
        phi = self.phi
        mech = self.mechanism(design, guarded)
        pin = self.pin(design, first_order)
        M_h = req.hinge_moment
        ratio = mech.ratio(phi)
        labels = self.phi_labels
        obj: dict[str, ObjectiveTerm] = {}
        con: list[ConstraintBlock] = []

        obj["ripple"] = ObjectiveTerm(
            "ripple", "spread", ratio, "", "ratio ripple (i_max - i_min)/(i_max + i_min)"
        )
        travel = mech.nut_position(phi[-1]) - mech.nut_position(phi[0])
        obj["nut_travel"] = ObjectiveTerm("nut_travel", "scalar", travel, "mm", "nut travel")
        if self.spec.mechanism == "crank_slider":
            size = design["R"] + design["l"]
            size_text = "linkage size R + l"
        else:
            size = design["R"]
            size_text = "lever size R"
        obj["size"] = ObjectiveTerm("size", "scalar", size, "mm", size_text)
        torque = mech.motor_torque(phi, M_h, req.eta_screw, req.eta_gear)
        obj["motor_torque"] = ObjectiveTerm(
            "motor_torque", "max", torque, "N*mm", "largest motor torque over the stroke"
        )
        if pin is not None:
            backlash = mech.backlash(phi, self.joints(mech, pin), M_h)
            obj["backlash"] = ObjectiveTerm(
                "backlash", "max", backlash.worst_case, "deg", "worst-case output backlash"
            )
            obj["backlash_rss"] = ObjectiveTerm(
                "backlash_rss", "max", backlash.rss, "deg", "RSS output backlash"
            )

        # The linkage must not pass a dead point inside the stroke: positive ratio.
        con.append(
            ConstraintBlock("ratio_positive", ratio, 1.0, None, labels, "", "ratio i(phi) >= 1")
        )
        if self.spec.mechanism == "crank_slider":
            l = design["l"]
            margin = cs_model.assembly_margin(design["R"], l, design["n"], phi, mech.phi0) / l**2
            con.append(
                ConstraintBlock(
                    "assembly_margin",
                    margin,
                    req.assembly_margin_min,
                    None,
                    labels,
                    "",
                    "(l^2 - u^2)/l^2: the rod reaches the nut line",
                )
            )
            if req.transmission_angle is not None:
                ta = req.transmission_angle
                # cos is decreasing on [0, pi]: mu in [lo, hi] <=> cos mu in [cos hi, cos lo]
                con.append(
                    ConstraintBlock(
                        "transmission_angle",
                        cs_model.transmission_angle_cos(
                            design["R"], l, design["n"], phi, mech.phi0, mech.floor
                        ),
                        None if ta.max is None else float(np.cos(ta.max)),
                        None if ta.min is None else float(np.cos(ta.min)),
                        labels,
                        "",
                        "cos of the transmission angle",
                    )
                )
            if req.rod_inclination_max is not None:
                # |atan2(u, s)| <= theta  <=>  |u|/l <= sin(theta)  (s > 0 on the branch)
                s_max = float(np.sin(req.rod_inclination_max))
                con.append(
                    ConstraintBlock(
                        "rod_inclination",
                        cs_model.rod_rise(design["R"], design["n"], phi, mech.phi0) / l,
                        -s_max,
                        s_max,
                        labels,
                        "",
                        "sin of the rod inclination to the screw axis",
                    )
                )
        if req.mean_ratio is not None:
            con.append(
                ConstraintBlock(
                    "mean_ratio",
                    m.grid_mean(ratio),
                    req.mean_ratio.min,
                    req.mean_ratio.max,
                    [""],
                    "",
                    "mean ratio over the grid",
                )
            )
        if req.nut_travel_max is not None:
            con.append(
                ConstraintBlock(
                    "nut_travel", travel, None, req.nut_travel_max, [""], "mm", "nut travel"
                )
            )
        if pin is not None:
            load = "rod" if self.spec.mechanism == "crank_slider" else "pin_normal"
            F = mech.joint_force(load, phi, M_h)
            if req.pin_bearing_pressure_max is not None:
                con.append(
                    ConstraintBlock(
                        "pin_bearing_pressure",
                        pin_bearing_pressure(F, pin.d, pin.L),
                        None,
                        req.pin_bearing_pressure_max,
                        labels,
                        "MPa",
                        "pin bearing pressure F/(d L)",
                    )
                )
            if req.pin_shear_stress_max is not None:
                planes = req.pin_shear_planes or (2 if self.spec.mechanism == "crank_slider" else 1)
                con.append(
                    ConstraintBlock(
                        "pin_shear_stress",
                        pin_shear_stress(F, pin.d, planes),
                        None,
                        req.pin_shear_stress_max,
                        labels,
                        "MPa",
                        f"pin shear stress ({'double' if planes == 2 else 'single'} shear)",
                    )
                )
            if req.backlash_max is not None:
                con.append(
                    ConstraintBlock(
                        "backlash",
                        obj["backlash"].expr,
                        None,
                        float(np.degrees(req.backlash_max)),
                        labels,
                        "deg",
                        "worst-case output backlash",
                    )
                )
        if req.screw is not None:
            self._screw_constraints(con, mech, phi, M_h, labels)
        if req.lock is not None:
            lock_force = self._lock_force(mech, phi, M_h)
            obj["lock_force"] = ObjectiveTerm(
                "lock_force", "max", lock_force, "N", "magnet force of the motor-shaft lock"
            )
            if req.lock.force_max is not None:
                con.append(
                    ConstraintBlock(
                        "lock_force",
                        lock_force,
                        None,
                        req.lock.force_max,
                        labels,
                        "N",
                        "magnet force of the motor-shaft lock",
                    )
                )
        if req.motor_torque_max is not None:
            con.append(
                ConstraintBlock(
                    "motor_torque",
                    torque,
                    None,
                    req.motor_torque_max,
                    labels,
                    "N*mm",
                    "motor torque",
                )
            )
        return Expressions(obj, con, mech)

    def _screw_constraints(self, con, mech, phi, M_h, labels) -> None:
        """Buckling and yield of the screw shaft under the nut force at every angle."""
        from optdesign.models.screw_sizing import buckling_load, yield_load

        sz = self.spec.requirements.screw
        F_a = mech.nut_force(phi, M_h)
        if sz.buckling_length is not None:
            P1 = buckling_load(sz.root_diameter, sz.buckling_length, sz.mounting)
            con.append(
                ConstraintBlock(
                    "screw_buckling",
                    F_a,
                    None,
                    float(P1),
                    labels,
                    "N",
                    f"nut force <= buckling load ({sz.mounting})",
                )
            )
        if sz.check_yield:
            con.append(
                ConstraintBlock(
                    "screw_yield",
                    F_a,
                    None,
                    float(yield_load(sz.root_diameter)),
                    labels,
                    "N",
                    "nut force <= permissible shaft load",
                )
            )

    def _lock_force(self, mech, phi, M_h):
        """Magnet force the lock needs at each angle (N), seed 002 coupled to the drive."""
        from optdesign.models.lock import FrictionPlateLock, PinLock, motor_shaft_lock_load

        lk = self.spec.requirements.lock
        if lk.kind == "friction_plate":
            lock = FrictionPlateLock(lk.r1, lk.r2, lk.mu)
        else:
            lock = PinLock(lk.radius, bearing="guide" if lk.kind == "pin_rolling" else None)
        load = motor_shaft_lock_load(mech, phi, M_h, lk.eta_screw_back, lk.eta_gear_back)
        return lock.force(load.moment)

    # --- numeric evaluation (NumPy path) ------------------------------------------------
    def evaluate(self, x: np.ndarray) -> dict[str, Any]:
        """Objectives and constraint values of designs ``x`` on the NumPy path.

        Parameters
        ----------
        x
            Free-variable vector (1-D) or population (2-D, one design per row).

        Returns
        -------
        dict
            ``objectives``: name -> value (array over the population);
            ``constraints``: block name -> (values, lower, upper);
            ``violation``: largest relative violation per design.
        """
        x = np.asarray(x, dtype=float)
        single = x.ndim == 1
        X = x[None, :] if single else x
        with np.errstate(invalid="ignore", divide="ignore"):
            ex = self.expressions(self.design_dict(X))
            pop = X.shape[0]
            objectives = {}
            for name, term in ex.objectives.items():
                objectives[name] = term_values(term, pop, len(self.phi))
            constraints = {}
            worst = np.zeros(pop)
            for block in ex.constraints:
                e = np.asarray(block.expr, dtype=float)
                e = e.reshape(pop, -1) if e.size % pop == 0 and e.ndim > 0 else np.full((pop, 1), e)
                viol = relative_violation(e, block.lower, block.upper)
                worst = np.maximum(worst, np.nan_to_num(viol.max(axis=-1), nan=np.inf))
                constraints[block.name] = (e, block.lower, block.upper)
            for name, limit in self.objective_limits().items():
                val = objectives[name][:, None]
                worst = np.maximum(worst, relative_violation(val, None, limit)[:, 0])
                constraints[f"{name}_max"] = (val, None, limit)
        if single:
            objectives = {k: float(v[0]) for k, v in objectives.items()}
            constraints = {k: (v[0][0], v[1], v[2]) for k, v in constraints.items()}
            worst = float(worst[0])
        return {"objectives": objectives, "constraints": constraints, "violation": worst}

    def describe_variable(self, name: str) -> str:
        return VARIABLE_DESCRIPTIONS.get(name, name)


def term_values(term: ObjectiveTerm, pop: int, n_phi: int) -> np.ndarray:
    """Value of an objective term for each of ``pop`` designs on the NumPy path."""
    e = np.broadcast_to(np.asarray(term.expr, dtype=float), (pop, n_phi))
    if term.kind == "spread":
        hi, lo = e.max(axis=-1), e.min(axis=-1)
        return (hi - lo) / (hi + lo)
    if term.kind == "max":
        return e.max(axis=-1)
    return e[:, 0]


def relative_violation(values, lower, upper):
    """Violation of lower <= values <= upper, relative to max(1, |bound|)."""
    values = np.asarray(values, dtype=float)
    viol = np.zeros_like(values)
    if lower is not None:
        viol = np.maximum(viol, (lower - values) / max(1.0, abs(lower)))
    if upper is not None:
        viol = np.maximum(viol, (values - upper) / max(1.0, abs(upper)))
    return np.where(np.isnan(values), np.inf, viol)
