"""The drive in its loop along the stroke: a plant that follows the fin angle, a hinge
load history, and the deflection history of a duty cycle (docs/loop.md, "The duty cycle
in the loop").

:class:`~optdesign.models.loop_plant.DrivePlant` holds the drive linearised at one fin
angle. A duty cycle sweeps the stroke, over which the ratio f', the chain's stiffness k,
damping c and clearance b change: :class:`DrivePath` holds them on the stroke's grid and
gives them at any angle. :func:`optdesign.models.loop_simulation.simulate` takes either.

The coordinates are those of the fixed plant with the ratio made a function: the motor's
angle theta = g(psi), psi the fin angle the motor's position would give through a rigid,
tight chain (g' = f'), and phi the fin's. With J_m at the motor and the chain's elastic
energy V = k(psi) p^2 / 2 on the flank f in contact (its penetration p = f (psi - phi) -
b(psi) >= 0), Lagrange's equations are

    J_m f'^2 psi'' = f' (T - T_fr) - tau + p (k b' - k' p / 2) - J_m f' f'' psi'^2
    J_2 phi''      = tau - k_h phi - c_f phi' + M(t)

with tau = f k p + c (psi' - phi') the chain's torque on the fin as in the fixed plant,
M(t) an external moment on the fin (:class:`LoadHistory`) and ' the derivatives in psi
of f', k and b. The term J_m f' f'' psi'^2 is the motor side's inertia changing with the
ratio (theta'' = f' psi'' + f'' psi'^2); p (k b' - k' p / 2) is the chain's energy
changing with the angle, which keeps the equations conservative (kinetic plus elastic
energy is constant without friction, damping and motor torque: the test). It is of
relative size p k' / k against tau: 6e-5 on fin_actuator_loop's optimum under 450 N*m
(p = 3e-4 rad, k' / k = 0.2 per rad); kept because it costs two products.

k, c and b are taken at psi, not at phi: they differ by the chain's deflection and gap,
below a tenth of a degree, over which k and b change by less than 1e-4 relatively, and
with one angle the right-hand side locates its grid interval once per call.

Units: mm, t, s, N, rad (those of :mod:`optdesign.models.loop_plant`).

Validity
--------
grid angles : 2 or more, strictly increasing (call)
    A spline and its derivative need two angles at least. Between the first and the last
    the plant is interpolated, not extrapolated: a reference or a start outside them is
    refused; a motion that overshoots the grid's end holds the end's values (f'' = k' =
    b' = 0).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from optdesign.errors import InputError
from optdesign.models.loop_plant import BACKLASH, DrivePlant
from optdesign.models.loop_references import (
    MAX_HORIZON,
    SampledReference,
)
from optdesign.models.loop_simulation import SPEED_BAND, _System
from optdesign.models.validity import Validity

GRID_ANGLES = Validity(
    "loop_path.grid_angles",
    "drive plant along the stroke",
    "grid angles",
    2.0,
    None,
    "",
    "a spline and its derivative need two angles; between the first and the last the "
    "plant is interpolated, outside them a reference or a start is refused",
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (GRID_ANGLES,)

#: The plant's quantities that may vary along the stroke (interpolated) ...
VARYING = ("ratio", "stiffness", "damping", "backlash")
#: ... and those that must not (a varying J_m would need its own Lagrange term).
CONSTANT = (
    "motor_inertia",
    "fin_inertia",
    "hinge_spring",
    "fin_damping",
    "friction_torque",
    "peak_torque",
    "max_speed",
)


def _array(name: str, values, size: int | None = None) -> np.ndarray:
    try:
        a = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError(name, "expected numbers") from None
    if not np.all(np.isfinite(a)):
        raise InputError(name, "must be finite")
    if size is not None and a.size != size:
        raise InputError(name, f"needs one value per angle ({size}), got {a.size}")
    return a


@dataclass(frozen=True)
class DrivePath:
    """The drive along the stroke (the module's docstring; internal units).

    Parameters
    ----------
    angles
        The grid's fin angles (rad), at least 2, strictly increasing.
    ratio, stiffness, damping, backlash
        f' (> 0), k (> 0), c (>= 0) and the clearance's half-width b (in [0, 5 deg]) at
        each angle, as in :class:`~optdesign.models.loop_plant.DrivePlant`.
    motor_inertia, fin_inertia, hinge_spring, fin_damping, friction_torque, peak_torque, max_speed
        As in :class:`~optdesign.models.loop_plant.DrivePlant`, one value for the stroke.
        The hinge spring acts on the fin's angle itself, -k_h phi (the fixed plant's on
        the angle from its operating point).

    The ratio is a cubic spline through the grid (``scipy.interpolate.CubicSpline``): its
    derivative f'' enters the equation of motion, and a spline's is continuous, so the
    integrator meets no kink at the nodes and g stays the integral of f'. k, c and b are
    PCHIP interpolants: they never leave the range of their neighbouring values, so a
    gap or a stiffness interpolated between two positive values stays positive.
    """

    angles: tuple[float, ...]
    ratio: tuple[float, ...]
    stiffness: tuple[float, ...]
    damping: tuple[float, ...]
    backlash: tuple[float, ...]
    motor_inertia: float
    fin_inertia: float
    hinge_spring: float = 0.0
    fin_damping: float = 0.0
    friction_torque: float = 0.0
    peak_torque: float = math.inf
    max_speed: float = math.inf
    _pieces: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import CubicSpline, PchipInterpolator

        phi = _array("path.angles", self.angles)
        if not GRID_ANGLES.contains(phi.size) or np.any(np.diff(phi) <= 0):
            raise InputError("path.angles", "needs at least 2 strictly increasing angles")
        arrays = {name: _array(f"path.{name}", getattr(self, name), phi.size) for name in VARYING}
        for name in ("ratio", "stiffness"):
            if not np.all(arrays[name] > 0):
                raise InputError(f"path.{name}", "must be positive at every angle")
        if np.any(arrays["damping"] < 0):
            raise InputError("path.damping", "cannot be negative")
        for b in arrays["backlash"]:
            if not BACKLASH.contains(b):
                raise InputError("path.backlash", BACKLASH.refusal(b))
        object.__setattr__(self, "angles", tuple(phi.tolist()))
        for name, a in arrays.items():
            object.__setattr__(self, name, tuple(a.tolist()))
        # the constants are checked as a fixed plant's (their names in the messages)
        DrivePlant(
            **{name: getattr(self, name) for name in CONSTANT},
            ratio=1.0,
            stiffness=1.0,
        )
        for name in CONSTANT:
            object.__setattr__(self, name, float(getattr(self, name)))
        f = CubicSpline(phi, arrays["ratio"])
        if np.any(f(np.linspace(phi[0], phi[-1], 20 * phi.size)) <= 0):
            raise InputError("path.ratio", "its spline crosses zero between the angles")
        shape = [PchipInterpolator(phi, arrays[n]) for n in ("stiffness", "damping", "backlash")]
        # the polynomial coefficients as Python lists: the right-hand side evaluates them
        # with float arithmetic, several times faster than NumPy's on scalars
        object.__setattr__(self, "_pieces", (phi.tolist(), *(p.c.T.tolist() for p in (f, *shape))))

    @classmethod
    def from_plants(cls, plants: Sequence[DrivePlant]) -> DrivePath:
        """The path through fixed plants at increasing angles (their ``angle``); those of
        :data:`CONSTANT` must agree (to 1e-9 relatively), else refused naming the field."""
        if len(plants) < 2:
            raise InputError("plants", f"needs at least 2 plants, got {len(plants)}")
        for name in CONSTANT:
            values = [getattr(p, name) for p in plants]
            if not all(v == values[0] or math.isclose(v, values[0], rel_tol=1e-9) for v in values):
                raise InputError(
                    f"plant.{name}",
                    f"varies along the stroke ({min(values):.6g} to {max(values):.6g}); "
                    "the path plant takes it constant",
                )
        return cls(
            angles=tuple(p.angle for p in plants),
            **{name: tuple(getattr(p, name) for p in plants) for name in VARYING},
            **{name: getattr(plants[0], name) for name in CONSTANT},
        )

    @property
    def range(self) -> tuple[float, float]:
        """The grid's first and last angles (rad)."""
        return self.angles[0], self.angles[-1]

    def at(self, psi: float) -> tuple[float, float, float, float, float, float, float]:
        """(f', f'', k, k', c, b, b') at the angle ``psi`` (rad), held at the grid's end
        values outside it (derivatives zero there)."""
        x, fc, kc, cc, bc = self._pieces
        lo, hi = x[0], x[-1]
        if psi <= lo or psi >= hi:
            i, s, outside = (0, 0.0, True) if psi <= lo else (len(x) - 2, hi - x[-2], True)
        else:
            i = bisect_right(x, psi) - 1
            s, outside = psi - x[i], False
        a = fc[i]
        f = ((a[0] * s + a[1]) * s + a[2]) * s + a[3]
        a = kc[i]
        k = ((a[0] * s + a[1]) * s + a[2]) * s + a[3]
        a = cc[i]
        c = ((a[0] * s + a[1]) * s + a[2]) * s + a[3]
        a = bc[i]
        b = ((a[0] * s + a[1]) * s + a[2]) * s + a[3]
        if outside:
            return f, 0.0, k, 0.0, c, b, 0.0
        a = fc[i]
        f2 = (3.0 * a[0] * s + 2.0 * a[1]) * s + a[2]
        a = kc[i]
        k1 = (3.0 * a[0] * s + 2.0 * a[1]) * s + a[2]
        a = bc[i]
        b1 = (3.0 * a[0] * s + 2.0 * a[1]) * s + a[2]
        return f, f2, k, k1, c, b, b1

    def plant_at(self, psi: float) -> DrivePlant:
        """The fixed plant at ``psi`` (rad, within the grid)."""
        f, _, k, _, c, b, _ = self.at(psi)
        return DrivePlant(
            ratio=f,
            stiffness=k,
            damping=c,
            backlash=max(b, 0.0),
            angle=psi,
            **{name: getattr(self, name) for name in CONSTANT},
        )

    def equations(self, loop, reference, psi0: float, phi0: float, load=None) -> PathSystem:
        """The equations :func:`~optdesign.models.loop_simulation.simulate` integrates,
        for a start and a reference within the grid (else refused naming them) and an
        optional :class:`LoadHistory`."""
        if load is not None and not isinstance(load, LoadHistory):
            raise InputError("load", f"must be a LoadHistory, got {load!r}")
        refuse_outside(self, reference, psi0, phi0)
        return PathSystem(self, loop, reference, load)

    # the scales the integrator's absolute tolerances are taken from (the largest)
    @property
    def backlash_scale(self) -> float:
        return max(self.backlash)

    @property
    def stiffness_scale(self) -> float:
        return max(self.stiffness)


@dataclass(frozen=True)
class LoadHistory:
    """An external moment on the fin (N*mm, positive turning it to +phi), piecewise
    constant: ``moments[j]`` from ``times[j]`` to the next time (s), the last held on;
    none before the first time."""

    times: tuple[float, ...]
    moments: tuple[float, ...]

    def __post_init__(self):
        t = _array("load.times", self.times)
        m = _array("load.moments", self.moments, t.size)
        if t.size < 1 or t[0] < 0 or np.any(np.diff(t) <= 0):
            raise InputError("load.times", "needs 1 or more non-negative increasing times")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "moments", tuple(m.tolist()))

    def __call__(self, t: float) -> float:
        j = bisect_right(self.times, t) - 1
        return self.moments[j] if j >= 0 else 0.0

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times where the moment jumps (the integration restarts there)."""
        return tuple(t for t in self.times if t > 0)


@dataclass(frozen=True)
class DutyHistory:
    """A duty cycle as a deflection history and a load: the reference (rad at the fin),
    the external moment on the fin, the horizon (s) and each step's hold, as
    (start, end, step index) in s."""

    reference: SampledReference
    load: LoadHistory
    horizon: float
    holds: tuple[tuple[float, float, int], ...]


def duty_history(
    deflections: Sequence[float],
    moments: Sequence[float],
    shares: Sequence[float],
    period: float,
    rate: float,
    periods: int = 1,
    hinge_spring: float = 0.0,
) -> DutyHistory:
    """The deflection history and the hinge load of a duty cycle over ``periods`` periods.

    Step k takes ``shares[k]`` / sum(shares) of ``period`` (s). Within it the fin first
    moves from the previous step's deflection at ``rate`` (rad/s), a ramp whose time is
    taken from the step's, then holds ``deflections[k]`` (rad). The history starts at
    rest at the first step's deflection, so the first period's first step has no ramp; a
    period whose step is shorter than its ramp is refused naming ``period``.

    The load: during step k's time (its ramp included) the air's moment on the fin is
    -s_k M_k - k_h (phi - phi_k): the step's hinge moment M_k (``moments[k]`` > 0, N*mm)
    at its deflection, opposing it (s_k its sign; at zero deflection, the sign of the
    move into the step, the first step's being the move from the last: the cycle
    repeats), with the fin's hinge spring k_h about it. Opposing, because the duty cycle
    sizes the drive with the motor driving the load (forward efficiency, the motor's
    torques and the screw's life). The plant puts -k_h phi on the fin itself, so the
    external moment is -s_k M_k + k_h phi_k.
    """
    phi = _array("duty_cycle.deflection", deflections)
    M = _array("duty_cycle.hinge_moment", moments, phi.size)
    w = _array("duty_cycle.time", shares, phi.size)
    if phi.size < 1 or np.any(M <= 0) or np.any(w <= 0):
        raise InputError("duty_cycle", "needs steps with positive hinge moments and times")
    period, rate = float(period), float(rate)
    if not (math.isfinite(rate) and rate > 0):
        raise InputError("deflection_rate", f"must be positive, got {rate!r}")
    if not isinstance(periods, int | np.integer) or isinstance(periods, bool) or periods < 1:
        raise InputError("periods", f"must be a whole number >= 1, got {periods!r}")
    if not (math.isfinite(period) and period > 0):
        raise InputError("period", f"must be positive, got {period!r} s")
    if periods * period > MAX_HORIZON:
        raise InputError(
            "periods",
            f"{periods} periods of {period:g} s exceed the {MAX_HORIZON:g} s a run may last",
        )
    windows = w / w.sum() * period
    moves = np.abs(phi - np.roll(phi, 1)) / rate  # the ramp into each step
    for k in range(phi.size):
        if moves[k] > windows[k] * (1.0 + 1e-12):
            raise InputError(
                "period",
                f"{period:g} s gives step {k} ({math.degrees(phi[k]):g} deg) "
                f"{windows[k]:.4g} s, less than its move of {moves[k]:.4g} s at "
                f"{math.degrees(rate):g} deg/s: lengthen the period",
            )
    into = np.sign(phi - np.roll(phi, 1))
    sign = np.where(phi != 0, np.sign(phi), np.where(into != 0, into, 1.0))
    external = -sign * M + hinge_spring * phi
    # the reference's corners: each window opens at the last deflection (the previous
    # hold's end) and reaches its own at the ramp's end
    times, angles, load_t, load_m, holds = [0.0], [float(phi[0])], [], [], []
    t = 0.0
    for n in range(periods):
        for k in range(phi.size):
            load_t.append(t)
            load_m.append(float(external[k]))
            start = t + (moves[k] if (n or k) else 0.0)
            for corner, angle in ((t, angles[-1]), (start, float(phi[k]))):
                if corner > times[-1]:
                    times.append(corner)
                    angles.append(angle)
            t += windows[k]
            holds.append((start, t, k))
    times.append(t)
    angles.append(angles[-1])
    ref = SampledReference(tuple(times), tuple(angles))
    return DutyHistory(ref, LoadHistory(tuple(load_t), tuple(load_m)), t, tuple(holds))


def refuse_outside(path, reference, psi0: float, phi0: float) -> None:
    """Refuse a start or a reference outside the path's grid (interpolated, not
    extrapolated), naming it."""
    lo, hi = path.range
    span = reference.span
    for name, (a, b) in (
        ("initial_motor_angle", (psi0, psi0)),
        ("initial_fin_angle", (phi0, phi0)),
        ("reference", span),
    ):
        if a < lo - 1e-12 or b > hi + 1e-12:
            raise InputError(
                name,
                f"{math.degrees(a):g} to {math.degrees(b):g} deg leaves the path's grid "
                f"({math.degrees(lo):g} to {math.degrees(hi):g} deg)",
            )


# --- the equations along the path ------------------------------------------------------------
class PathSystem(_System):
    """The equations of :class:`DrivePath` (module docstring) for the integrator of
    :func:`optdesign.models.loop_simulation.simulate`: the same modes and events as the
    fixed plant's, the ratio, stiffness, damping and gap read at the motor's angle psi,
    the speed limit on the motor's speed f' psi', and the external moment."""

    def __init__(self, plant: DrivePath, loop, reference, load: LoadHistory | None = None):
        super().__init__(plant.plant_at(plant.angles[0]), loop, reference)
        self.p = plant
        self.path = plant
        self.load = load
        self.breaks = load.breaks if load is not None else ()
        self.J1 = None  # varies: J_m f'(psi)^2
        self.top = plant.max_speed  # the motor's speed at the limit ...
        self.corner = plant.max_speed * (1.0 - SPEED_BAND)  # ... where the corner begins
        self.bilateral = max(plant.backlash) == 0.0

    def moment(self, t: float) -> float:
        """The external moment, from the left at a jump ending the segment."""
        if self.load is None:
            return 0.0
        if t >= self.left_of:
            return self.load(float(np.nextafter(self.left_of, -math.inf)))
        return self.load(t)

    def hinge_moment(self, t, x) -> float:
        return self.moment(t) - self.p.hinge_spring * x[1]

    def raw_chain(self, x, flank: int) -> float:
        _, _, k, _, c, b, _ = self.path.at(x[0])
        return k * (x[0] - x[1] - flank * b) + c * (x[2] - x[3])

    def _generalised(self, x, flank: int) -> tuple[float, float]:
        """(tau on the fin, the force on psi's side) of the flank in contact (0: none)."""
        _, _, k, k1, c, b, b1 = self.path.at(x[0])
        if not flank:
            return 0.0, 0.0
        p = flank * (x[0] - x[1]) - b
        tau = flank * k * p + c * (x[2] - x[3])
        return tau, -tau + p * (k * b1 - 0.5 * k1 * p)

    def motor_torque(self, t, x, mode) -> float:
        T = self.command(t, x)
        speed = abs(x[2]) * self.path.at(x[0])[0]
        if T * x[2] > 0 and speed > self.corner:
            return T * max(0.0, (self.top - speed) / (self.top - self.corner))
        return T

    def drive_force(self, t, x, mode) -> float:
        return self.path.at(x[0])[0] * self.command(t, x) + self._generalised(x, mode[0])[1]

    def rhs(self, mode):
        """x' = f(t, x) in ``mode``: the module docstring's equations, the controller (a
        PID or the cascade) as the fixed plant's: its output by :meth:`command`, its
        integral's rate by the same arithmetic."""
        fn = self._rhs.get(mode)
        if fn is not None:
            return fn
        contact, _, motor = mode
        path, at = self.path, self.path.at
        kh, cf, J2, Jm = path.hinge_spring, path.fin_damping, path.fin_inertia, path.motor_inertia
        friction = motor * path.friction_torque
        lag, top, corner = self.c.current_lag, self.top, self.corner
        fin, r, command, saturated = self.fin, self.r, self.command, self.saturated_command
        rate_fin, zv = self.rate_fin, self.rate_weight  # the cascade's speed integrator
        moment = self.moment
        turning = motor in (1, -1)

        def rhs(t, x):
            x0, x1, x2, x3 = x[0], x[1], x[2], x[3]
            f, f2, k, k1, c, b, b1 = at(x0)
            if contact:
                p = contact * (x0 - x1) - b
                tau = contact * k * p + c * (x2 - x3)
                side = -tau + p * (k * b1 - 0.5 * k1 * p)
            else:
                tau = side = 0.0
            dd_phi = (tau - kh * x1 - cf * x3 + moment(t)) / J2
            T_sat = saturated(t, x)
            if turning:
                T = command(t, x) if lag > 0 else T_sat
                speed = abs(x2) * f
                if T * x2 > 0 and speed > corner:
                    T = T * max(0.0, (top - speed) / (top - corner))
                dd_psi = (f * (T - friction) + side - Jm * f * f2 * x2 * x2) / (Jm * f * f)
            else:
                dd_psi = 0.0
            dT = (T_sat - x[4]) / lag if lag > 0 else 0.0
            # z' as the fixed plant's: the error, less the cascade's weighted speed
            y = x1 if fin else x0
            e = r(t) - y
            return [x2, x3, dd_psi, dd_phi, dT, e - zv * (x3 if rate_fin else x2) if zv else e]

        self._rhs[mode] = rhs
        return rhs

    def _new_events(self, mode):
        at = self.path.at
        out = []
        contact, side, motor = mode

        def flank_torque(f):
            def g(t, x):
                _, _, k, _, c, b, _ = at(x[0])
                return f * (k * (x[0] - x[1] - f * b) + c * (x[2] - x[3]))

            return g

        def overlap(f):
            return lambda t, x: f * (x[0] - x[1]) - at(x[0])[5]

        if self.bilateral:
            pass
        elif contact:
            out += [(overlap(contact), -1, "opens"), (flank_torque(contact), -1, "unloaded")]
        elif side:
            out += [(flank_torque(side), 1, "closes"), (overlap(side), -1, "gap")]
        else:
            out += [(overlap(1), 1, "closes"), (overlap(-1), 1, "closes")]
        if motor in (1, -1):
            if self.path.friction_torque > 0:
                out.append((lambda t, x, s=motor: s * x[2], -1, "stops"))
        elif motor == 0:
            T_f = self.path.friction_torque
            out.append((lambda t, x: self.drive_force(t, x, mode) - at(x[0])[0] * T_f, 1, "slips"))
            out.append((lambda t, x: -self.drive_force(t, x, mode) - at(x[0])[0] * T_f, 1, "slips"))
        return out

    def next_mode(self, t, x, mode, kind):
        """The fixed plant's, but a flank unloaded where its overlap has already closed
        goes to the gap at once: without chain damping the flank's torque k p and its
        overlap p vanish together, and the root finder may place the unloading just past
        the overlap's zero, where the gap's event (the overlap falling through zero)
        would never fire."""
        mode, x = super().next_mode(t, x, mode, kind)
        side = mode[1]
        if side and side * (x[0] - x[1]) - self.path.at(x[0])[5] <= 0.0:
            mode = (0, 0, mode[2])
        return mode, x

    def gap_at(self, x) -> float:
        return self.path.at(x[0])[5]

    def ratio_at(self, x) -> float:
        return self.path.at(x[0])[0]

    def band_events(self):
        out = []
        if math.isfinite(self.top):
            at = self.path.at
            for s in (1, -1):
                for direction, kind in ((1, "speed limit"), (-1, "speed released")):
                    g = lambda t, x, s=s: s * x[2] * at(x[0])[0] - self.corner  # noqa: E731
                    g.terminal, g.direction = False, direction
                    out.append((g, kind))
        return out
