"""The mechanism contract: what a screw-driven linkage plug-in declares and computes.

A mechanism turns the output deflection ``phi`` into the travel of the screw's nut (the
*drive coordinate*). Everything else the framework derives from that, for any mechanism:
the reduction ratio ``i = 2 pi i_a (dx/dphi) / p``, the nut force by virtual work
``M_h / (dx/dphi)``, the motor torque, the nut travel, the ratio ripple. A plug-in
subclasses :class:`Mechanism`, declares its own :attr:`~Mechanism.variables` and writes
:meth:`~Mechanism.nut_position` with :mod:`optdesign.math`; the rest has defaults it may
override with closed forms (the nut velocity, the clearance chain, the pin load, the size,
assembly rows, mechanism-specific requirements, the sketch).

An instance holds one design: every variable's value as a float, a NumPy array (a
population, broadcast against the deflection grid on the last axis) or a CasADi symbol.
``guarded`` asks for the solver's guards (square roots that never produce NaN at an
iterate outside the domain). The screw lead ``p`` and gear ratio ``i_a`` are drive
variables every mechanism has (:data:`DRIVE_VARIABLES`); the pin variables live in the
problem, not here.
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from optdesign import math as m
from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms.joints import Backlash, Joint, PinJoint, backlash_of
from optdesign.models._checks import require_finite, require_positive
from optdesign.models.impossibility import Impossibility, NutVelocityBounds
from optdesign.models.loads import force_from_rate, motor_torque
from optdesign.models.ratio import ratio_finite_step, ratio_from_nut_velocity
from optdesign.models.validity import Validity
from optdesign.user_code import call_method

#: Physical dimensions a variable may have (keys of optdesign.units.INTERNAL_UNITS).
DIMENSIONS = ("length", "angle", "dimensionless")


@dataclass(frozen=True)
class VariableInfo:
    """A design variable a mechanism (or the framework) declares.

    Attributes
    ----------
    dimension
        ``"length"`` (mm), ``"angle"`` (rad) or ``"dimensionless"``.
    description
        What it is, for tables and error messages.
    positive
        Fixed values and lower bounds must be > 0 (lengths such as an arm).
    default
        Value used when a problem does not declare the variable (None: required).
    valid
        The range of validity of the models the variable feeds
        (:class:`~optdesign.models.validity.Validity`, internal units): a problem file's
        value, bound, start or catalogue value outside it is refused when read (None:
        any positive or finite value).
    """

    dimension: str
    description: str
    positive: bool = True
    default: float | None = None
    valid: Validity | None = None

    def __post_init__(self):
        if self.dimension not in DIMENSIONS:
            raise InputError(
                "dimension", f"{self.dimension!r} is not one of {', '.join(DIMENSIONS)}"
            )


def as_variable_info(value: VariableInfo | str | tuple) -> VariableInfo:
    """Accept the short forms ``"length"`` or ``("length", "arm length")``."""
    if isinstance(value, VariableInfo):
        return value
    if isinstance(value, str):
        return VariableInfo(value, "")
    return VariableInfo(*value)


#: Drive variables of every mechanism: the screw lead and the gear pair.
DRIVE_VARIABLES: dict[str, VariableInfo] = {
    "p": VariableInfo("length", "screw lead"),
    "i_a": VariableInfo("dimensionless", "gear ratio motor -> screw", default=1.0),
}


@dataclass(frozen=True)
class RequirementInfo:
    """A requirement only some mechanisms have (e.g. the transmission angle).

    The problem-file schema of a mechanism gains one field per declared requirement;
    :meth:`Mechanism.requirement_rows` turns its value into constraint rows.

    Attributes
    ----------
    kind
        ``"band"`` (a table ``{min, max}``) or ``"value"`` (one quantity).
    dimension
        Dimension of the value(s): ``"length"``, ``"angle"``, ``"dimensionless"``.
    description
        What it limits.
    default
        Value imposed when the file omits it (None: not imposed).
    valid
        Physical range (inclusive, internal units) of the value or of a band's ends,
        checked when the file is read (None: any finite value).
    """

    kind: str
    dimension: str
    description: str
    default: Any = None
    valid: tuple[float, float] | None = None


@dataclass
class Rows:
    """``lower <= expr <= upper`` over the deflection grid (or one value), as a mechanism
    or a requirement states it; the problem turns these into named constraint blocks.

    ``expr`` and the bounds are in ``unit`` (internal units: mm, N, MPa, N*mm, rad; ""
    for a plain number). Reports show a row in ``display_unit``: ``display`` maps the
    row's values to the quantity a user reads, already in ``display_unit`` (degrees of
    the angle whose cosine the row bounds); without ``display``, the values are converted
    from ``unit`` to ``display_unit`` (``unit="rad", display_unit="deg"`` shows degrees;
    units of different dimensions are refused, naming the row). Without either, a row
    is shown in its ``unit``.
    """

    name: str
    expr: Any
    lower: float | None = None
    upper: float | None = None
    unit: str = ""
    description: str = ""
    display: Callable[[Any], Any] | None = None
    display_unit: str = ""

    def __post_init__(self):
        if self.display is None and self.display_unit and self.display_unit != self.unit:
            from optdesign.units import unit_factor

            where = f"Rows({self.name!r}).display_unit"
            self.display = Scaled(unit_factor(self.unit, self.display_unit, where))


@dataclass(frozen=True)
class Scaled:
    """``value * factor``: a row shown in another unit of its dimension (picklable)."""

    factor: float

    def __call__(self, value):
        return value * self.factor


@dataclass
class Sketch:
    """Points of a linkage at one deflection, for drawings (mm, output axis at the origin).

    ``links``: polylines drawn as bars; ``pivots``: fixed joints (ground); ``slider``: the
    nut; ``axis``: the screw axis as two points.
    """

    links: list[list[tuple[float, float]]] = field(default_factory=list)
    pivots: list[tuple[float, float]] = field(default_factory=list)
    slider: tuple[float, float] | None = None
    axis: tuple[tuple[float, float], tuple[float, float]] | None = None


class Mechanism:
    """Base of every mechanism plug-in.

    Subclass, set :attr:`name` and :attr:`variables`, write :meth:`nut_position`, declare
    the pins (:attr:`pin_joints` or :meth:`joints`), then register the class with
    :func:`optdesign.register_mechanism` (the whole contract: docs/mechanisms.md). Example::

        @register_mechanism
        class Lever(Mechanism):
            name = "lever"
            variables = {"R": ("length", "lever arm")}
            pin_joints = ("pin",)  # on the screw's line, loaded by the nut force

            def nut_position(self, phi):
                return self.R * m.sin(phi)

    Class attributes
    ----------------
    name
        Registry key, the ``mechanism`` field of problem files.
    title
        Human name for reports.
    variables
        Own design variables: name -> :class:`VariableInfo` (or a short form).
    requirements
        Mechanism-specific requirements: name -> :class:`RequirementInfo`.
    fixed_clearances
        Keys of the clearance chain's fixed clearances (``[clearances]`` of a problem
        file): key -> (dimension, description).
    pin_joints
        Names of the sized pins of the default clearance chain, each on the screw's line
        of action and carrying the nut force (a Scotch yoke's crank pin in the yoke's
        slot: ``("crank pin",)``; ``()``: no pin). None: undeclared - a class that does
        not write :meth:`joints` must declare it (refused when registered), so that the
        chain never guesses a mechanism's pins.
    pin_shear_planes
        Shear planes of the sized pin (default of ``pin_shear_planes``).
    size_description
        What :meth:`size` measures.
    """

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    variables: ClassVar[Mapping[str, Any]] = {}
    requirements: ClassVar[Mapping[str, RequirementInfo]] = {}
    fixed_clearances: ClassVar[Mapping[str, tuple[str, str]]] = {
        "A": ("length", "screw bearings (axial)"),
        "B": ("length", "screw/nut (axial)"),
        "O": ("angle", "output shaft"),
    }
    pin_joints: ClassVar[tuple[str, ...] | None] = None
    pin_shear_planes: ClassVar[int] = 1
    size_description: ClassVar[str] = "sum of the mechanism's lengths"

    # --- construction ----------------------------------------------------------------
    def __init__(self, design: Mapping[str, Any] | None = None, /, *, guarded=False, **values):
        merged = {**(design or {}), **values}
        table = self.variable_table()
        unknown = sorted(k for k in merged if k not in table)
        if unknown and design is None:
            raise InputError(
                unknown[0], f"not a variable of a {self.label()} (known: {', '.join(table)})"
            )
        v: dict[str, Any] = {}
        for name, info in table.items():
            if name in merged:
                v[name] = merged[name]
            elif info.default is not None:
                v[name] = info.default
            else:
                raise InputError(name, f"required by a {self.label()} ({info.description})")
            if info.positive:
                require_positive(name, v[name])
            else:
                require_finite(name, v[name])
        self.values = v
        self.guarded = bool(guarded)

    @classmethod
    def variable_table(cls) -> dict[str, VariableInfo]:
        """Every variable the mechanism needs: its own, then the drive's (p, i_a)."""
        own = {k: as_variable_info(v) for k, v in cls.variables.items()}
        return {**own, **{k: v for k, v in DRIVE_VARIABLES.items() if k not in own}}

    @classmethod
    def label(cls) -> str:
        return cls.title or cls.name or cls.__name__

    def __getattr__(self, item: str) -> Any:
        # Design values read as attributes (self.R); only reached for missing attributes.
        values = self.__dict__.get("values")
        if values is not None and item in values:
            return values[item]
        attr = inspect.getattr_static(type(self), item, None)
        if hasattr(attr, "__get__") and not item.startswith("__"):
            # A property of the class that raised AttributeError, which Python turns into
            # this call: run again here, its own error (file, line) propagates instead
            # of "no attribute" for an attribute the class defines.
            return attr.__get__(self, type(self))
        known = f" (its variables: {', '.join(values)})" if values else ""
        raise AttributeError(f"{type(self).__name__} has no attribute {item!r}{known}")

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.values.items())
        return f"{type(self).__name__}({args})"

    # --- kinematics (override nut_position; the rest follows) -------------------------
    def nut_position(self, phi):
        """Drive coordinate x(phi): the nut's travel along the screw (mm), increasing
        with phi. Every plug-in writes this (with :mod:`optdesign.math`)."""
        raise NotImplementedError(f"{type(self).__name__} must define nut_position(phi)")

    def nut_velocity(self, phi):
        """dx/dphi (mm/rad). Default: exact derivative of :meth:`nut_position` by CasADi
        algorithmic differentiation, on both paths (override with a closed form)."""
        return _derivative(self, phi)

    def nut_acceleration(self, phi):
        """d2x/dphi2 (mm/rad^2): how the ratio changes along the stroke, which makes the
        motor accelerate at a constant fin rate. Default: exact second derivative of
        :meth:`nut_position` by CasADi algorithmic differentiation, on both paths."""
        return _derivative(self, phi, order=2)

    def ratio(self, phi):
        """Exact reduction ratio i(phi) = 2 pi i_a (dx/dphi) / p."""
        return ratio_from_nut_velocity(self.nut_velocity(phi), self.p, self.i_a)

    def ripple(self, phi):
        """Ratio ripple (i_max - i_min)/(i_max + i_min) over the grid ``phi``."""
        return m.grid_spread(self.ratio(phi))

    def ratio_finite_step(self, phi, step):
        """The papers' finite-step ratio ([D17] eq. 5 / 9) with step ``step`` (rad)."""
        return ratio_finite_step(self.nut_position, phi, step, self.p, self.i_a)

    def nut_travel(self, phi_lo, phi_hi):
        """Nut travel x(phi_hi) - x(phi_lo) (mm)."""
        return self.nut_position(phi_hi) - self.nut_position(phi_lo)

    # --- loads ---------------------------------------------------------------------------
    def nut_force(self, phi, M_h):
        """Nut axial force (N) carrying the hinge moment M_h (N*mm), by virtual work."""
        return force_from_rate(M_h, self._divisor(self.nut_velocity(phi)))

    def motor_torque(self, phi, M_h, eta_screw=1.0, eta_gear=1.0):
        """Motor torque (N*mm) that holds/drives the hinge moment M_h."""
        return motor_torque(self.nut_force(phi, M_h), self.p, self.i_a, eta_screw, eta_gear)

    # --- clearance chain -------------------------------------------------------------------
    def sensitivity_axial(self, phi):
        """Output rotation per unit nut-side axial clearance (rad/mm) = 1/(dx/dphi)."""
        return 1.0 / self._divisor(self.nut_velocity(phi))

    def _divisor(self, rate):
        # The solver path never divides by zero: a design at a dead point (dx/dphi = 0
        # somewhere on the grid) gets huge, finite forces and sensitivities.
        return m.away_from_zero(rate) if self.guarded else rate

    def joints(self, phi, M_h, pin: PinJoint | None = None) -> list[Joint]:
        """The clearance chain (joints whose clearance reaches the output).

        Default: the screw's support bearings (A) and the screw/nut (B), axial; the
        output shaft (O), angular; and, when the problem sizes a pin, one joint per name
        of :attr:`pin_joints`, each on the screw's line of action and loaded by the nut
        force (its clearance moves the output as the nut's would: 1/(dx/dphi) rad/mm).
        A linkage whose pins sit elsewhere (on a rod, a crank) writes its own chain.
        """
        if type(self).pin_joints is None:
            raise InputError(
                "pin_joints",
                f"a {self.label()} declares no pins: set pin_joints or write joints()",
            )
        s = self.sensitivity_axial(phi)
        chain = [
            Joint("A screw bearings", "A", sensitivity=s),
            Joint("B screw/nut", "B", sensitivity=s),
            Joint("O output shaft", "O", angular=True),
        ]
        if pin is not None:
            F = self.nut_force(phi, M_h)
            chain += [Joint(n, "", sensitivity=s, force=F, pin=pin) for n in self.pin_joints]
        return chain

    def pin_force(self, phi, M_h):
        """Force on the sized pin(s) (N) for the bearing-pressure and shear requirements:
        one pin size serves every pin joint of :meth:`joints`, so the default is the
        largest magnitude of their forces at each angle."""
        marker = PinJoint.placeholder()
        forces = [j.force for j in self.joints(phi, M_h, marker) if j.pin is marker]
        if not forces:
            raise InputError("pin", f"a {self.label()} has no sized pin joint")
        largest = m.fabs(forces[0])
        for force in forces[1:]:
            largest = m.fmax(largest, m.fabs(force))
        return largest

    def backlash(self, phi, joints: Sequence[Joint]) -> Backlash:
        """Output backlash (degrees) at each angle of ``phi``: per joint, worst case, RSS."""
        return backlash_of(joints, phi)

    # --- requirements ----------------------------------------------------------------------
    def assembly_rows(self, phi) -> list[Rows]:
        """Rows that keep the linkage assembled over the stroke (none by default)."""
        return []

    @classmethod
    def impossible(
        cls,
        stroke: tuple[float, float],
        requirements: Mapping[str, Any],
        bounds: Mapping[str, tuple[float, float]],
    ) -> list[Impossibility]:
        """Closed-form proofs that no design of this mechanism within ``bounds`` can turn
        through the stroke under its requirements: necessary conditions of the geometry,
        checked before any solve, so that a problem no design can meet gets its verdict
        in milliseconds and the names of the requirements to change.

        Parameters
        ----------
        stroke
            The deflection range (min, max) in rad.
        requirements
            The mechanism's own requirements the problem sets (:attr:`requirements`),
            name -> parsed value (internal units; a band has ``.min`` and ``.max``).
        bounds
            Every variable of :meth:`variable_table` -> (lower, upper), internal units
            (a fixed variable as (value, value)).

        Returns
        -------
        list of Impossibility
            Empty when no condition is known to fail (the default): a necessary
            condition only, never a claim that the problem is feasible.
        """
        return []

    @classmethod
    def nut_velocity_bounds(
        cls,
        stroke: tuple[float, float],
        requirements: Mapping[str, Any],
        bounds: Mapping[str, tuple[float, float]],
    ) -> NutVelocityBounds | None:
        """Closed-form bounds of the nut velocity dx/dphi over the stroke for every design
        within ``bounds`` that meets ``requirements`` (arguments as for
        :meth:`impossible`). From them the problem proves, before any solve, that a ratio
        band lies beyond every ratio 2 pi i_a v / p the bounds allow, or that the nut
        force M / v exceeds what every catalogue screw carries.

        Returns
        -------
        NutVelocityBounds or None
            None (the default): nothing known, no such proof.
        """
        return None

    def requirement_rows(self, name: str, value: Any, phi) -> list[Rows]:
        """Rows of the mechanism-specific requirement ``name`` with its parsed ``value``."""
        raise NotImplementedError(f"{type(self).__name__} declares {name!r} but builds no rows")

    def size(self):
        """A size measure to minimise (mm). Default: the sum of the length variables."""
        total = 0.0
        for k, info in type(self).variables.items():
            if as_variable_info(info).dimension == "length":
                total = total + self.values[k]
        return total

    # --- drawings and checks ---------------------------------------------------------------
    def sketch(self, phi: float) -> Sketch | None:
        """Points to draw the linkage at deflection ``phi`` (numeric designs); None when
        the plug-in does not draw itself."""
        return None

    def assembly_margin(self, phi):
        """Positive where the linkage assembles. Default: 1 where the nut position is
        finite (NaN on the NumPy path marks angles where the geometry has no solution)."""
        x = np.asarray(self.nut_position(np.asarray(phi, dtype=float)), dtype=float)
        return np.where(np.isfinite(x), 1.0, -1.0)

    def check_assembly(self, phi) -> None:
        """Raise AssemblyError at the first angle of ``phi`` where the linkage cannot
        assemble (numeric designs only)."""
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        with np.errstate(invalid="ignore", divide="ignore"):
            margin = np.asarray(self.assembly_margin(phi), dtype=float)
        margin = np.broadcast_to(margin, np.broadcast_shapes(margin.shape, phi.shape))
        bad = np.argwhere(~(margin > 0))
        if bad.size:
            idx = tuple(bad[0])
            raise AssemblyError(np.degrees(phi[idx[-1]]), margin[idx], self.describe())

    def describe(self) -> str:
        """Short text of the design, for messages."""
        shown = ", ".join(f"{k}={_short(v)}" for k, v in self.values.items())
        return f"{self.label()} {shown}"

    #: Benchmark instance families of this mechanism: family name -> objectives (see
    #: optdesign.studies.bench.instances); empty: the benchmark has none of its own.
    bench_families: ClassVar[Mapping[str, tuple[str, ...]]] = {}

    @classmethod
    def bench_template(cls) -> tuple[dict[str, Any], dict[str, Any]]:
        """The mechanism's own variables and requirements of a benchmark instance, as
        problem-file tables (the benchmark adds the drive, pins and common requirements;
        ``"p": None`` marks where the drawn screw lead goes in the variable order)."""
        return {}, {}


def _short(v: Any) -> str:
    if m.is_symbolic(v):
        return "<symbolic>"
    a = np.asarray(v)
    return f"{float(a):g}" if a.ndim == 0 else f"<array {a.shape}>"


# --- automatic derivative of the nut position ------------------------------------------
_DERIVATIVES: dict[tuple, ca.Function] = {}


def _derivative(mech: Mechanism, phi, order: int = 1):
    """dx/dphi (``order`` 1) or d2x/dphi2 (2) of ``mech.nut_position`` by CasADi AD,
    evaluated like the model itself.

    One CasADi Function ``(phi, v_1..v_k) -> derivative`` is built per mechanism class and
    order (on scalar symbols) and cached; it is called element-wise with the design's
    values: CasADi symbols give an expression per grid angle, NumPy arrays are broadcast.
    """
    cls = type(mech)
    names = list(mech.values)
    key = (cls, tuple(names), mech.guarded, order)
    fun = _DERIVATIVES.get(key)
    if fun is None:
        phi_s = ca.SX.sym("phi")
        syms = {k: ca.SX.sym(k) for k in names}
        probe = cls.__new__(cls)
        probe.values = dict(syms)
        probe.guarded = mech.guarded
        x = call_method(probe, "nut_position", phi_s, doing="while differentiating it (CasADi)")
        # CasADi takes letters, digits and single underscores in a name: a class named
        # _Yoke or Yoke__v2 would otherwise be refused when its derivative is built
        name = "_".join([f"d{order}x", *re.findall(r"[A-Za-z0-9]+", cls.__name__)])
        dx = ca.jacobian(x, phi_s)
        if order == 2:
            dx = ca.jacobian(dx, phi_s)
        fun = ca.Function(name, [phi_s, *syms.values()], [dx])
        _DERIVATIVES[key] = fun
    args = [mech.values[k] for k in names]
    if m.is_symbolic(phi, *args):
        phi_col = np.atleast_1d(np.asarray(phi, dtype=float)) if not m.is_symbolic(phi) else phi
        if m.is_symbolic(phi):
            return fun(phi, *args)
        return ca.vertcat(*[fun(float(p), *args) for p in phi_col.ravel()])
    values = [np.asarray(a) for a in (phi, *args)]
    if any(v.dtype.kind not in "fiub" for v in values):
        # e.g. the GP diagnosis's tracers: AD cannot see through them, and a numeric
        # stand-in would give a wrong model, so say why instead.
        raise TypeError(
            f"{cls.__name__}.nut_velocity is the automatic derivative of nut_position, "
            "which needs CasADi or NumPy values; write nut_velocity in closed form to "
            "trace it (GP diagnosis)"
        )
    arrays = np.broadcast_arrays(*[v.astype(float) for v in values])
    shape = arrays[0].shape
    flat = [a.astype(float).ravel() for a in arrays]
    n = flat[0].size
    out = fun.map(n)(*[a[None, :] for a in flat])
    return np.asarray(out, dtype=float).reshape(shape)
