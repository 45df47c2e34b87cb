"""Objectives and constraints as declarations: name, unit, description, formula, and the
function of the design's :class:`~optdesign.problem.quantities.Quantities` that computes
them. The built-in objectives are declared once here; a user adds more with
:meth:`DesignProblem.add_objective` / :meth:`DesignProblem.add_constraint`, and every
formulation, check, report and plot reads names and units from these records.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.problem.objective_refusals import motor_mass_needs

#: Objective kinds: how a grid quantity becomes one number.
#: ``spread``: (max - min)/(max + min) over the grid (the ratio ripple);
#: ``max``: the largest value over the grid; ``scalar``: one value per design.
KINDS = ("spread", "max", "scalar")


def _is_range(valid: Any) -> bool:
    """``valid`` is ``(lower, upper)``: finite numbers or None, lower <= upper."""
    if not (isinstance(valid, tuple) and len(valid) == 2):
        return False
    bounds = [b for b in valid if b is not None]
    if not all(
        isinstance(b, int | float) and not isinstance(b, bool) and math.isfinite(b) for b in bounds
    ):
        return False
    return len(bounds) < 2 or bounds[0] <= bounds[1]


#: The range of a value that cannot be negative (a length, a clearance, a force ...).
NON_NEGATIVE: tuple[float | None, float | None] = (0.0, None)

#: The range of a fraction (a ripple: a spread of positive values; a loss of power).
FRACTION: tuple[float | None, float | None] = (0.0, 1.0)


@dataclass(frozen=True)
class ObjectiveInfo:
    """A minimisable quantity.

    Attributes
    ----------
    name
        Key (``[objective] minimize = [...]``, ``--objectives``).
    fn
        ``fn(q) -> expression`` (over the grid for ``spread``/``max``, one value for
        ``scalar``), or None when the problem lacks what it needs (e.g. no pin).
    kind
        One of :data:`KINDS`.
    unit
        Internal unit of the value ("" for dimensionless).
    description, formula
        What it is and how it is computed, for reports and docs.
    display_unit, display_scale
        How users read it: value * display_scale in display_unit (e.g. ripple in %).
    valid
        The physical range of the value, ``(lower, upper)`` in ``unit`` (None: no bound on
        that side): a ripple lies in [0, 1] (a spread of positive ratios), a backlash, a
        size, a torque cannot be negative. A value outside it is no result, whatever a
        solver reports (an epigraph variable or an iterate where the mechanism does not
        assemble gives one): :meth:`range_problem` says why. None (the default, and a
        user's objective) declares no range: the value must only be finite.
    needs
        ``needs(problem)``: why a problem lacks this objective (``fn`` gives None), in
        the words of its file (``""``: no reason known beyond the objective's own data).
    pieces
        ``pieces(q)``: smooth expressions whose element-wise max is ``fn(q)`` (built-ins
        with a kink: the NLP bounds each piece; :class:`ObjectiveTerm`).
    bound_rows
        ``bound_rows(q, t) -> (rows, labels)``: smooth rows, each ``>= 0``, that hold
        together exactly when ``t`` bounds the objective from above (``max`` kind only).
        For an objective that is no explicit function of the design but a root (the
        closed loop's bandwidth): the NLP's epigraph variable ``t`` is bounded by these
        implicit rows instead of ``t - piece >= 0``, of which they are the general form.
        On the solver path ``fn(q)`` then gives only a start for ``t`` (an estimate, not
        the value); on the NumPy path it gives the exact value, as for every objective.
    numeric_only
        Why the objective has no smooth form (``""``: it has one). Such an objective is
        computed on the NumPy path only (``fn`` gives None on the solver path), for the
        population methods; every formulation that needs a smooth form refuses it before
        any work with this reason
        (:func:`~optdesign.problem.objective_refusals.smooth_form_refusal`).
    not_posynomial
        Why a GP cannot pose the objective whatever the problem (``""``: it may, as the
        GP's own check of the traced model decides).
    """

    name: str
    fn: Callable[[Any], Any]
    kind: str
    unit: str = ""
    description: str = ""
    formula: str = ""
    display_unit: str | None = None
    display_scale: float = 1.0
    valid: tuple[float | None, float | None] | None = None
    needs: Callable[[Any], str] | None = None
    pieces: Callable[[Any], tuple[Any, ...]] | None = None
    bound_rows: Callable[[Any, Any], tuple[Any, list[str]]] | None = None
    numeric_only: str = ""
    not_posynomial: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"objective {self.name}.kind", f"{self.kind!r} not in {KINDS}")
        if self.bound_rows is not None and (self.kind != "max" or self.pieces is not None):
            raise InputError(
                f"objective {self.name}.bound_rows",
                "only for a 'max' objective without pieces (the rows replace them)",
            )
        if not callable(self.fn):
            raise InputError(f"objective {self.name}.fn", "must be a function of the quantities")
        if self.valid is not None and not _is_range(self.valid):
            raise InputError(
                f"objective {self.name}.valid",
                f"expected (lower, upper) of finite numbers or None; got {self.valid!r}",
            )

    @property
    def shown_unit(self) -> str:
        return self.unit if self.display_unit is None else self.display_unit

    def range_problem(self, value: Any) -> str:
        """Why ``value`` cannot be this objective's value, or ``""``: a value that is not
        a finite number (NaN, inf), or one outside :attr:`valid` (shown in the display
        unit, e.g. ``ripple -21 % is below its physical range [0, 100] %``)."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            return f"{self.name} is not a number ({value!r:.40})"
        if not math.isfinite(v):
            return f"{self.name} is {v!r}, not a finite number"
        if self.valid is None:
            return ""
        lo, hi = self.valid
        below, above = lo is not None and v < lo, hi is not None and v > hi
        if not (below or above):
            return ""
        s, unit = self.display_scale, self.shown_unit
        shown = "".join(
            [
                "[",
                "-inf" if lo is None else f"{lo * s:g}",
                ", ",
                "inf" if hi is None else f"{hi * s:g}",
                "]",
                f" {unit}" if unit else "",
            ]
        )
        where = "below" if below else "above"
        return (
            f"{self.name} {v * s:.6g}{' ' + unit if unit else ''} is {where} its physical "
            f"range {shown}"
        )


@dataclass(frozen=True)
class ConstraintInfo:
    """A user-declared requirement ``lower <= fn(q) <= upper``.

    ``over="stroke"``: ``fn`` returns a value per grid angle, each must hold;
    ``over="design"``: one value. Bounds are in ``unit`` (internal units of the value).
    """

    name: str
    fn: Callable[[Any], Any]
    lower: float | None = None
    upper: float | None = None
    unit: str = ""
    over: str = "stroke"
    description: str = ""

    def __post_init__(self):
        if self.over not in ("stroke", "design"):
            raise InputError(f"constraint {self.name}.over", "use 'stroke' or 'design'")
        if self.lower is None and self.upper is None:
            raise InputError(f"constraint {self.name}", "give a lower or an upper bound")
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise InputError(
                f"constraint {self.name}", f"lower {self.lower:g} is above upper {self.upper:g}"
            )
        if not callable(self.fn):
            raise InputError(f"constraint {self.name}.fn", "must be a function of the quantities")


@dataclass
class ObjectiveTerm:
    """An objective of one design: its declaration's name and kind, and the expression.
    ``pieces``: smooth expressions whose element-wise max is ``expr`` (on the solver path,
    for a ``max`` objective with a kink, e.g. |x| = max(x, -x)): the NLP's epigraph bounds
    each piece, which keeps it smooth (:func:`piece_rows`). ``bound_rows``: on the solver
    path, ``t -> (rows, labels)``, rows ``>= 0`` that hold exactly when ``t`` bounds the
    objective (:attr:`ObjectiveInfo.bound_rows`); ``expr`` is then a start for ``t``, not
    the objective."""

    name: str
    kind: str
    expr: Any
    unit: str = ""
    description: str = ""
    pieces: tuple[Any, ...] = ()
    bound_rows: Callable[[Any], tuple[Any, list[str]]] | None = None


@dataclass
class ConstraintBlock:
    """``lower <= expr <= upper``, element-wise over the grid (or one value).

    ``labels`` name the rows (the deflection angle), ``unit`` is the unit of ``expr``;
    ``display``/``display_unit`` map a row value to what a user reads (e.g. degrees of an
    angle whose cosine is constrained).
    """

    name: str
    expr: Any
    lower: float | None = None
    upper: float | None = None
    labels: list[str] = field(default_factory=list)
    unit: str = ""
    description: str = ""
    display: Callable[[Any], Any] | None = None
    display_unit: str = ""
    #: Smooth expressions whose element-wise max is ``expr`` (solver path; an upper bound
    #: only, since max(pieces) <= upper holds exactly when every piece does).
    pieces: tuple[Any, ...] = ()
    #: A condition of the physics, not a wish: the linkage passes no dead point and
    #: assembles. A diagnosis never proposes to relax it (a design beyond it does not
    #: work at all); the stroke or the bounds must change instead.
    physical: bool = False

    def __post_init__(self):
        if self.pieces and self.lower is not None:
            raise InputError(f"constraint {self.name}.pieces", "only with an upper bound alone")


def bound_rows_of(info: ObjectiveInfo, q: Any, expr: Any) -> Callable[[Any], Any] | None:
    """The implicit epigraph rows ``t -> (rows, labels)`` of an objective that declares
    them (:attr:`ObjectiveInfo.bound_rows`), on the solver path only: the NumPy path has
    the exact value."""
    if info.bound_rows is None or not m.is_symbolic(expr):
        return None
    bound_rows = info.bound_rows
    return lambda t: bound_rows(q, t)


def piece_rows(
    expr: Any, pieces: tuple[Any, ...], labels: list[str]
) -> list[tuple[Any, list[str]]]:
    """The rows an NLP poses for ``expr``: ``expr`` itself, or each of its smooth
    ``pieces`` (their element-wise max is ``expr``) with the labels marked by the piece's
    number (``phi=-30.0deg (2)``), so that a row's name still starts with its block's."""
    if not pieces:
        return [(expr, labels)]
    return [
        (piece, [f"{lab} ({k})" if lab else f"({k})" for lab in labels])
        for k, piece in enumerate(pieces, 1)
    ]


def _drive_loss(q):
    return 1.0 - q.drive_efficiency


def _screw_mass(q):
    """Screw shaft mass (solid steel of d0 over the support length), kg. The nut is left
    out: the catalogue prints the masses of some nuts only."""
    from optdesign.models.screw_sizing import shaft_mass

    screw, data = q.problem.spec.screw, q.screw
    if screw is None or screw.length is None or data is None or data.d0 is None:
        return None
    return shaft_mass(data.d0, screw.length)


def _motor_inertia(q):
    """Screw shaft inertia reflected to the motor shaft through the gear, kg*mm^2."""
    from optdesign.models.screw_sizing import reflected_inertia
    from optdesign.problem.drive import screw_shaft_inertia

    J_screw = screw_shaft_inertia(q)
    if J_screw is None:
        return None
    return reflected_inertia(J_screw, 0.0, q.screw.p, q.mechanism.i_a)


def _hinge_compliance(q):
    screw = q.problem.spec.screw
    if screw is None or (screw.bearing_stiffness is None and screw.nut_offset is None):
        return None
    return q.output_compliance


def _motor_peak_torque(q):
    if q.motor_data is None or q.motion is None:
        return None
    return q.motor_peak_torque


def _motor_peak_torque_pieces(q):
    return q.motor_peak_torque_pieces


def _motor_rms_torque(q):
    return None if not q.problem.spec.requirements.duty_cycle else q.motor_rms_torque


def _natural_period(q):
    spec = q.problem.spec
    return None if spec.load is None or spec.screw is None else q.natural_period


def _resonance_gain(q):
    if q.problem.spec.loop is None:
        return None
    from optdesign.problem.loop import loop_resonance_gain

    return loop_resonance_gain(q)


def _bandwidth_period(q):
    from optdesign.problem.loop_bandwidth import bandwidth_period

    return bandwidth_period(q)


def _bandwidth_period_rows(q, t):
    from optdesign.problem.loop_bandwidth import bandwidth_period_rows

    return bandwidth_period_rows(q, t)


#: Why ``limit_cycle_amplitude`` has no smooth form, and what to use instead: the text of
#: every refusal (docs/loop.md gives the argument in full).
LIMIT_CYCLE_NOT_SMOOTH = (
    "the amplitude of the largest limit cycle is a root of the harmonic balance, with no "
    "smooth form (a cycle appears or vanishes where a phase crossover of L_d passes -1), "
    "so it is computed on the NumPy path only: trace a front with method='nsga2', or bound "
    "it with the requirement limit_cycle_amplitude_max (the independent check enforces it) "
    "and minimise backlash"
)


def _sensitivity_peak(q):
    from optdesign.problem.loop_objectives import sensitivity_peak

    return sensitivity_peak(q)


def _limit_cycle_amplitude(q):
    from optdesign.problem.loop_objectives import limit_cycle_amplitude

    return limit_cycle_amplitude(q)


def _needs_loop(problem: Any) -> str:
    return "" if problem.spec.loop is not None else "needs a [loop] section"


def _motor_mass(q):
    motor = q.motor_data
    if motor is None or motor.mass is None or motor_mass_needs(q.problem):
        return None
    return motor.mass


def _backlash(q):
    return None if q.pin is None else q.backlash.worst_case


def _backlash_rss(q):
    return None if q.pin is None else q.backlash.rss


#: The built-in objectives, declared once, each with its physical range (``valid``): every
#: design that meets the requirements has a ratio >= 1 (``ratio_positive``), so its ripple
#: is a fraction, its nut travel and motor torque are positive; clearances, sizes, masses,
#: compliances and forces are never negative; the drive's loss is a fraction of its power.
BUILTIN_OBJECTIVES: dict[str, ObjectiveInfo] = {
    o.name: o
    for o in (
        ObjectiveInfo(
            "ripple",
            lambda q: q.ratio,
            "spread",
            "",
            "ratio ripple",
            "(i_max - i_min)/(i_max + i_min) of the ratio over the stroke",
            display_unit="%",
            display_scale=100.0,
            valid=FRACTION,
        ),
        ObjectiveInfo(
            "backlash",
            _backlash,
            "max",
            "deg",
            "worst-case output backlash",
            "max over the stroke of the sum of each joint's clearance times its sensitivity",
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "backlash_rss",
            _backlash_rss,
            "max",
            "deg",
            "RSS output backlash",
            "max over the stroke of the root-sum-square of the joints' contributions",
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "size",
            lambda q: q.size,
            "scalar",
            "mm",
            "size of the mechanism",
            "the mechanism's size measure (crank-slider R + l, fork R, ...)",
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "nut_travel",
            lambda q: q.nut_travel,
            "scalar",
            "mm",
            "nut travel",
            "x(phi_max) - x(phi_min)",
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "motor_torque",
            lambda q: q.motor_torque,
            "max",
            "N*mm",
            "largest motor torque over the stroke",
            "max of F_nut p / (2 pi i_a eta_screw eta_gear)",
            display_unit="N*m",
            display_scale=1e-3,
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "drive_loss",
            _drive_loss,
            "scalar",
            "",
            "power lost in the drive",
            "1 - forward efficiency of screw x gear",
            display_unit="%",
            display_scale=100.0,
            valid=FRACTION,
        ),
        ObjectiveInfo(
            "screw_mass",
            _screw_mass,
            "scalar",
            "kg",
            "mass of the screw shaft",
            "solid steel shaft of d0 over the support length",
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "motor_inertia",
            _motor_inertia,
            "scalar",
            "kg*mm^2",
            "screw inertia at the motor shaft",
            "J_screw / i_a^2, J_screw of a solid steel shaft of d0 over the support length",
            display_unit="kg*cm^2",
            display_scale=1e-2,
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "hinge_compliance",
            _hinge_compliance,
            "max",
            "rad/(N*mm)",
            "largest compliance at the output over the stroke (1/stiffness)",
            "sum over the chain of (sensitivity^2 / member stiffness)",
            display_unit="urad/(N*m)",
            display_scale=1e9,
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "motor_peak_torque",
            _motor_peak_torque,
            "max",
            "N*mm",
            "largest torque the motion asks of the motor",
            "max over the stroke of J_m (f' alpha + |f''| omega^2) + M_out / (f' eta) + T_f",
            display_unit="N*m",
            display_scale=1e-3,
            valid=NON_NEGATIVE,
            pieces=_motor_peak_torque_pieces,
        ),
        ObjectiveInfo(
            "motor_rms_torque",
            _motor_rms_torque,
            "scalar",
            "N*mm",
            "RMS motor torque of the duty cycle",
            "sqrt(sum T_i^2 t_i / sum t_i), T_i = M_i / (f'(phi_i) eta) + T_f",
            display_unit="N*m",
            display_scale=1e-3,
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "natural_period",
            _natural_period,
            "max",
            "s",
            "longest period of the fin on the chain, motor held (1 / natural frequency)",
            "max over the stroke of 2 pi sqrt(J_fin / (k_chain + k_hinge))",
            display_unit="ms",
            display_scale=1e3,
            valid=NON_NEGATIVE,
        ),
        ObjectiveInfo(
            "resonance_gain",
            _resonance_gain,
            "max",
            "",
            "largest gain of the position loop at the drive's own mode (1 / resonance margin)",
            "max over the stroke of |L(j w_r)|, w_r the two-mass mode with the motor free",
            valid=NON_NEGATIVE,
            needs=_needs_loop,
        ),
        ObjectiveInfo(
            "bandwidth_period",
            _bandwidth_period,
            "max",
            "s",
            "1 / the least closed-loop bandwidth over the stroke (minimising it raises the "
            "bandwidth)",
            "max over the loop's angles of 1 / f_k, f_k the first frequency where "
            "|T(j 2 pi f)|^2 falls to half its static value",
            display_unit="ms",
            display_scale=1e3,
            valid=NON_NEGATIVE,
            needs=_needs_loop,
            bound_rows=_bandwidth_period_rows,
        ),
        ObjectiveInfo(
            "sensitivity_peak",
            _sensitivity_peak,
            "max",
            "",
            "peak of the sensitivity function Ms = 1 / min |1 + L| (an upper bound of it over "
            "the margins' 14 frequencies)",
            "max over the loop's angles of 1 / the soft minimum of |1 + L(jw)| that the "
            "phase and modulus margin rows hold",
            valid=NON_NEGATIVE,
            needs=_needs_loop,
            not_posynomial="a power sum (sum_k |1 + L_k|^-2p)^(1/2p) of reciprocals of "
            "signomials (|1 + L|^2 is a difference of posynomials), not a posynomial of the "
            "design; use formulation='nlp' or 'catalogue'",
        ),
        ObjectiveInfo(
            "limit_cycle_amplitude",
            _limit_cycle_amplitude,
            "max",
            "deg",
            "fin amplitude of the largest stable backlash limit cycle (NumPy path only)",
            "max over the loop's angles of the harmonic balance's largest stable cycle",
            valid=NON_NEGATIVE,
            needs=_needs_loop,
            numeric_only=LIMIT_CYCLE_NOT_SMOOTH,
        ),
        ObjectiveInfo(
            "motor_mass",
            _motor_mass,
            "scalar",
            "t",
            "mass of the motor",
            "the catalogue's or the file's motor mass",
            display_unit="kg",
            display_scale=1e3,
            valid=NON_NEGATIVE,
            needs=motor_mass_needs,
        ),
        ObjectiveInfo(
            "lock_force",
            lambda q: q.lock_force,
            "max",
            "N",
            "magnet force of the motor-shaft lock",
            "lock force holding the hinge moment reflected to the motor shaft",
            valid=NON_NEGATIVE,
        ),
    )
}
