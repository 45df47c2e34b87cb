"""The drive in its position loop, at one fin angle: the plant and the controller as
typed records (docs/loop.md).

The plant is the two-mass drive of :mod:`optdesign.models.motor`, linearised at one fin
angle phi0 where the chain's ratio is f' = dtheta/dphi (motor rad per fin rad):

* the motor side, everything that turns with the rotor or moves with the nut
  (``motor_inertia`` J_m at the motor shaft), seen at the fin as J_1 = J_m f'^2 turning
  psi = theta / f';
* the fin side (``fin_inertia`` J_2 about the hinge) turning phi;
* between them the chain: ``stiffness`` k and ``damping`` c at the fin, in series with
  the chain's clearance, a gap of total width 2 b at the fin (``backlash`` is the
  half-width b, the convention of :class:`optdesign.models.describing_function.Backlash`).
  With the gap the chain's torque at the fin is elastic-backlash (Modelica's
  ElastoBacklash): zero while |psi - phi| < b, k (|psi - phi| - b) + c (psi' - phi') in
  contact, never pulling;
* on the fin, the aerodynamic hinge spring ``hinge_spring`` k_h (dM/dphi: the air puts
  -k_h phi on the fin; negative for a statically unstable fin) and a damping to ground
  ``fin_damping``;
* on the motor, a Coulomb friction ``friction_torque`` and its limits
  ``peak_torque`` and ``max_speed``.

The controller (:class:`PositionLoop`): the motor's torque command

    T_cmd = kp e + ki int(e) - kd y',   e = r - y

on the fin's angle (``feedback="fin"``) or the motor's seen at the fin, y = psi
(``feedback="motor"``: a semi-closed loop, the encoder on the motor), then the current
loop as a first-order lag of time constant ``current_lag`` and the motor's peak torque
as a saturation. Gains are motor torque per fin angle: kp in N*mm/rad, kd in N*mm*s/rad,
ki in N*mm/(rad*s).

The cascade (:class:`CascadeLoop`): an outer position P loop asking a speed
w_ref = Kpos (r - y) of an inner PI loop on the motor's measured speed psi' (the encoder,
seen at the fin),

    T_cmd = Kv (w_ref - psi') + (Kv / Ti) int(w_ref - psi') dt

(``position_gain`` Kpos in 1/s, ``speed_gain`` Kv in N*mm*s/rad, ``speed_integral_time``
Ti in s, 0 for a P speed loop), then the same current loop and saturation.

Both are one rational controller (the :data:`Controller` protocol every consumer reads):

    T_cmd = C_e(s) (r - y) - C_v(s) s v,   C_e = kp + ki / s,   C_v = kd + speed_ki / s

with v the angle whose speed is measured (``speed_feedback``): y itself for the PID
(speed_ki = 0), psi for the cascade, whose kp = Kv Kpos, ki = Kv Kpos / Ti, kd = Kv and
speed_ki = Kv / Ti. A P speed loop is the PID's PD on the motor's speed: kp = Kv Kpos,
kd = Kv.

Units: mm, t, s, N, rad (README "Units"): inertia in t*mm^2, torque in N*mm, stiffness
in N*mm/rad, damping in N*mm*s/rad, speed in rad/s.

Validity
--------
backlash : 0 <= b <= 5 deg at the fin (checked when a plant is built)
    The gap is a rotation of the fin at the operating angle's ratio f'(phi0): the ratio
    is held while the gap is crossed, which needs a gap small against the angle over
    which f' changes (tens of degrees for the linkages here), and the clearance chain's
    own model is a small-angle one (:mod:`optdesign.models.clearance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Literal, TypeAlias

from optdesign.errors import InputError
from optdesign.models.validity import Validity

FEEDBACKS = ("fin", "motor")

BACKLASH = Validity(
    "loop_plant.backlash",
    "linearised drive plant",
    "backlash half-width b at the fin",
    0.0,
    math.radians(5.0),
    "rad",
    "the gap is crossed at the operating angle's ratio, which holds for a gap small "
    "against the angle over which the ratio changes",
    shown_unit="deg",
    scale=180.0 / math.pi,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (BACKLASH,)


def _finite(owner: str, name: str, value: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{owner}.{name}", f"expected a number, got {value!r}") from None
    if not math.isfinite(value):
        raise InputError(f"{owner}.{name}", f"must be finite, got {value!r}")
    return value


@dataclass(frozen=True)
class DrivePlant:
    """The drive at one fin angle (see the module's docstring; internal units).

    Parameters
    ----------
    motor_inertia
        J_m at the motor shaft (t*mm^2), > 0.
    ratio
        f' = dtheta/dphi at the angle (motor rad per fin rad), > 0.
    fin_inertia
        J_2 about the hinge (t*mm^2), > 0.
    stiffness
        The chain's stiffness at the fin with the motor held (N*mm/rad), > 0.
    damping
        The chain's damping at the fin, across the chain (N*mm*s/rad), >= 0.
    hinge_spring
        dM/dphi of the air load (N*mm/rad), either sign.
    fin_damping
        The fin's damping to ground (N*mm*s/rad), >= 0.
    backlash
        Half-width b of the chain's clearance at the fin (rad), >= 0.
    friction_torque
        Coulomb friction at the motor (N*mm), >= 0.
    peak_torque
        The motor's peak torque (N*mm), > 0; ``inf`` for no limit.
    max_speed
        The motor's top speed (rad/s), > 0; ``inf`` for no limit.
    angle
        The fin angle phi0 this plant is linearised at (rad), for messages and records.
    """

    motor_inertia: float
    ratio: float
    fin_inertia: float
    stiffness: float
    damping: float = 0.0
    hinge_spring: float = 0.0
    fin_damping: float = 0.0
    backlash: float = 0.0
    friction_torque: float = 0.0
    peak_torque: float = math.inf
    max_speed: float = math.inf
    angle: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("peak_torque", "max_speed") and value == math.inf:
                continue
            object.__setattr__(self, f.name, _finite("plant", f.name, value))
        for name in (
            "motor_inertia",
            "ratio",
            "fin_inertia",
            "stiffness",
            "peak_torque",
            "max_speed",
        ):
            if not getattr(self, name) > 0:
                raise InputError(f"plant.{name}", f"must be positive, got {getattr(self, name)!r}")
        for name in ("damping", "fin_damping", "backlash", "friction_torque"):
            if getattr(self, name) < 0:
                raise InputError(
                    f"plant.{name}", f"cannot be negative, got {getattr(self, name)!r}"
                )
        if not BACKLASH.contains(self.backlash):
            raise InputError("plant.backlash", BACKLASH.refusal(self.backlash))

    @property
    def motor_inertia_at_fin(self) -> float:
        """J_1 = J_m f'^2: the motor side seen at the fin (t*mm^2)."""
        return self.motor_inertia * self.ratio**2


def _check_controller(record, positive: tuple[str, ...], nonnegative: tuple[str, ...]) -> None:
    """Store a controller record's gains as floats; refuse (naming ``loop.<field>``) one
    that is not finite, not positive (``positive``) or negative (``nonnegative``), and an
    unknown ``feedback``."""
    for name in (*positive, *nonnegative):
        object.__setattr__(record, name, _finite("loop", name, getattr(record, name)))
    for name in positive:
        if not getattr(record, name) > 0:
            raise InputError(f"loop.{name}", f"must be positive, got {getattr(record, name)!r}")
    for name in nonnegative:
        if getattr(record, name) < 0:
            raise InputError(f"loop.{name}", f"cannot be negative, got {getattr(record, name)!r}")
    if record.feedback not in FEEDBACKS:
        raise InputError(
            "loop.feedback", f"expected one of {', '.join(FEEDBACKS)}, got {record.feedback!r}"
        )


@dataclass(frozen=True)
class PositionLoop:
    """The position controller and the current loop (see the module's docstring).

    Parameters
    ----------
    kp
        Proportional gain, motor torque per fin angle (N*mm/rad), > 0.
    kd
        Derivative gain on the measured rate (N*mm*s/rad), >= 0.
    ki
        Integral gain (N*mm/(rad*s)), >= 0.
    current_lag
        Time constant of the current loop (s), >= 0 (0: the torque follows at once).
    feedback
        ``"fin"`` (the fin's angle is measured) or ``"motor"`` (the motor's, at the fin).
    """

    kp: float
    kd: float = 0.0
    ki: float = 0.0
    current_lag: float = 0.0
    feedback: Literal["fin", "motor"] = "fin"

    def __post_init__(self) -> None:
        _check_controller(self, ("kp",), ("kd", "ki", "current_lag"))

    @property
    def speed_ki(self) -> float:
        """The integral gain on the measured speed (none in a PID: 0.0)."""
        return 0.0

    @property
    def speed_feedback(self) -> str:
        """The angle whose speed the derivative reads: the measured one."""
        return self.feedback


@dataclass(frozen=True)
class CascadeLoop:
    """The position/speed cascade and the current loop (see the module's docstring).

    Parameters
    ----------
    position_gain
        Kpos, the speed asked per angle of error (1/s: fin rad/s per fin rad), > 0.
    speed_gain
        Kv, motor torque per fin rad/s of speed error (N*mm*s/rad), > 0.
    speed_integral_time
        Ti, the speed loop's integral time (s), >= 0; 0 for a P speed loop.
    current_lag
        Time constant of the current loop (s), >= 0.
    feedback
        The angle the position loop measures: ``"fin"`` or ``"motor"``. The speed is the
        motor's (its encoder) either way.
    """

    position_gain: float
    speed_gain: float
    speed_integral_time: float = 0.0
    current_lag: float = 0.0
    feedback: Literal["fin", "motor"] = "fin"

    def __post_init__(self) -> None:
        _check_controller(
            self, ("position_gain", "speed_gain"), ("speed_integral_time", "current_lag")
        )

    # the rational form C_e = kp + ki / s on the error, C_v = kd + speed_ki / s on psi'
    @property
    def kp(self) -> float:
        """Kv Kpos (N*mm/rad)."""
        return self.speed_gain * self.position_gain

    @property
    def ki(self) -> float:
        """Kv Kpos / Ti (N*mm/(rad*s)); 0 for a P speed loop."""
        if self.speed_integral_time == 0.0:
            return 0.0
        return self.kp / self.speed_integral_time

    @property
    def kd(self) -> float:
        """Kv (N*mm*s/rad)."""
        return self.speed_gain

    @property
    def speed_ki(self) -> float:
        """Kv / Ti (N*mm/rad): the speed integrator's gain on psi' (0 for a P loop)."""
        if self.speed_integral_time == 0.0:
            return 0.0
        return self.speed_gain / self.speed_integral_time

    @property
    def speed_feedback(self) -> str:
        """The motor's: the speed loop closes on the encoder."""
        return "motor"


#: A position controller: a record with kp, ki, kd, speed_ki, current_lag, feedback and
#: speed_feedback (the rational form of the module's docstring); speed_ki > 0 only with
#: ki > 0, so one integrator state serves both terms.
Controller: TypeAlias = PositionLoop | CascadeLoop

#: The controller records, for ``isinstance``.
CONTROLLERS = (PositionLoop, CascadeLoop)
