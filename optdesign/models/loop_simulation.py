"""The drive's time response in its position loop: elastic backlash, friction and the
motor's limits, by ``scipy.integrate.solve_ivp`` with events (docs/loop.md).

The equations are those of :mod:`optdesign.models.loop_plant` in the fin coordinate
(psi = theta / f', J_1 = J_m f'^2):

    J_1 psi'' = f' (T - T_fr) - tau,     J_2 phi'' = tau - k_h phi - c_f phi'

with, piece by piece:

* the chain's torque tau (elastic backlash, d = psi - phi): 0 while |d| < b;
  k (d - b) + c d' while the + flank is in contact, k (d + b) + c d' on the - flank; a
  flank in contact never pulls: when its torque reaches zero the contact opens
  ("unloaded") though the flanks still overlap, and it closes again when the torque would
  push. Each change is an event: the integration stops there and restarts in the new
  contact state, so the jump of the damping torque c d' at the closing is resolved
  exactly;
* the controller T_cmd = kp e + ki z - kd v', z' = e - (kv_i / ki) v', e = r - y (the
  rational form of :mod:`optdesign.models.loop_plant`: for the PID v = y and kv_i = 0,
  z the error's integral; for the cascade v = psi, and ki z = (Kv / Ti) int(w_ref - psi'),
  the speed loop's integral), saturated at +-``peak_torque``, then the current loop
  T' = (T_cmd,sat - T) / tau_i (T = T_cmd,sat when ``current_lag`` = 0). No anti-windup:
  the integral keeps integrating while the torque is saturated;
* Coulomb friction at the motor, event-handled (not smoothed): while the motor turns,
  T_fr = T_f sign(theta'); when theta' reaches zero the motor sticks if the torque on it,
  |f' T - tau| <= f' T_f, and stays stuck (theta' = 0) until that torque reaches the
  friction's; else it reverses. A smooth friction (tanh of the speed) would make the
  motor creep under any torque and make the equations stiff for a small velocity scale;
* the speed limit as the corner of the motor's torque-speed curve: the torque in the
  direction of motion falls linearly from the command's at (1 - SPEED_BAND) max_speed to
  none at ``max_speed`` and above; a braking torque is applied in full. Continuous, so
  no mode: the motor settles just below the limit where the load needs torque, and a
  load that drives it on can take it past the limit. Entering and leaving the band are
  recorded as events ("speed limit", "speed released") without stopping the
  integration (docs/loop.md: why not a held speed).

A :class:`~optdesign.models.loop_path.DrivePath` for the plant: the same equations with
the ratio, stiffness, damping and gap following the angle, and a load on the fin.

Units: mm, t, s, N, rad. Angles in rad at the fin (the motor's as psi = theta / f'),
torques in N*mm (the motor's at its shaft, the chain's at the fin), times in s.

Validity
--------
horizon : 0 < T <= 600 s (call)
    A fin's manoeuvre lasts seconds; a longer run is a mistake of units or a request for
    millions of events, refused before it starts.
output samples : 2 to 10^6 (call)
    Enough to resolve a cycle near the chain's resonance over a run; more is memory.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from optdesign.errors import InputError
from optdesign.models.loop_plant import CONTROLLERS, Controller, DrivePlant
from optdesign.models.loop_references import (
    MAX_HORIZON,
    MAX_SAMPLES,
    Reference,
    SampledReference,
    SineReference,
    StepReference,
    angle_value,
)
from optdesign.models.loop_run import LoopSimulation
from optdesign.models.validity import Validity

#: The most events (contacts, sticks, speed limits) handled before the run is refused.
MAX_EVENTS = 200_000
HORIZON = Validity(
    "loop_simulation.horizon",
    "loop simulation",
    "simulated time",
    0.0,
    MAX_HORIZON,
    "s",
    "a fin's manoeuvre lasts seconds; a longer run is a units mistake or millions of events",
    open_lower=True,
    checked=("call",),
)
SAMPLES = Validity(
    "loop_simulation.samples",
    "loop simulation",
    "output samples",
    2.0,
    float(MAX_SAMPLES),
    "",
    "enough to resolve a cycle near the chain's resonance over a run; more is memory",
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (HORIZON, SAMPLES)

#: The width of the torque-speed curve's corner, a fraction of the top speed: the
#: torque in the direction of motion falls to none over the last 1 % of the speed.
SPEED_BAND = 0.01


# --- the equations -------------------------------------------------------------------------
# state x = [psi, phi, psi', phi', T (current loop), z (the controller's integral)]
# mode = (contact, side, motor): contact in {-1, 0, +1}; side in {-1, 0, +1} the flank
# whose overlap persists while unloaded (contact 0); motor: +-1 turning, 0 stuck


class _System:
    breaks: tuple[float, ...] = ()  # times where a load on the fin jumps: none here

    def __init__(self, plant: DrivePlant, loop: Controller, reference):
        self.p, self.c, self.reference = plant, loop, reference
        # the reference's left limit at a jump ending the current segment: the segment's
        # last point must not see the jump (its events would fire on it, again and again)
        self.left_of = math.inf
        self.J1 = plant.motor_inertia_at_fin
        self.fin = loop.feedback == "fin"
        # the speed the controller reads (the cascade's: the motor's), and the weight of
        # its speed integrator in z' = e - (kv_i / ki) v' (0 for a PID)
        self.rate_fin = loop.speed_feedback == "fin"
        self.rate_weight = loop.speed_ki / loop.ki if loop.ki > 0 else 0.0
        self.w_lim = plant.max_speed / plant.ratio  # psi' at the speed limit
        self.w_band = self.w_lim * (1.0 - SPEED_BAND)  # ... and where its corner begins
        # without clearance the chain is one linear, two-way spring: no contact events
        self.bilateral = plant.backlash == 0.0
        self._rhs: dict[tuple[int, int, int], Callable] = {}
        self._events: dict[tuple[int, int, int], list] = {}

    def r(self, t: float) -> float:
        """The reference, taken from the left at a jump that ends the segment."""
        if t >= self.left_of:
            return self.reference(float(np.nextafter(self.left_of, -math.inf)))
        return self.reference(t)

    def command(self, t, x) -> float:
        """The current loop's output T (N*mm at the motor)."""
        if self.c.current_lag > 0:
            # the lag's state stays within the peak; clipped against the integrator's
            # overshoot of a saturated input
            peak = self.p.peak_torque
            return min(max(x[4], -peak), peak)
        return self.saturated_command(t, x)

    def saturated_command(self, t, x) -> float:
        c = self.c
        y = x[1] if self.fin else x[0]
        vd = x[3] if self.rate_fin else x[2]
        T = c.kp * (self.r(t) - y) + c.ki * x[5] - c.kd * vd
        peak = self.p.peak_torque
        return min(max(T, -peak), peak)

    def raw_chain(self, x, flank: int) -> float:
        """The flank's contact torque, unclipped: k (d - flank b) + c d'."""
        p = self.p
        return p.stiffness * (x[0] - x[1] - flank * p.backlash) + p.damping * (x[2] - x[3])

    def chain(self, x, mode) -> float:
        return self.raw_chain(x, mode[0]) if mode[0] else 0.0

    def hinge_moment(self, t, x) -> float:
        """The air's moment on the fin (N*mm)."""
        return -self.p.hinge_spring * x[1]

    def motor_torque(self, t, x, mode) -> float:
        """The torque the motor applies (N*mm): the command, less in the direction of
        motion over the torque-speed curve's corner (module docstring)."""
        T = self.command(t, x)
        if T * x[2] > 0 and abs(x[2]) > self.w_band:
            return T * max(0.0, (self.w_lim - abs(x[2])) / (self.w_lim - self.w_band))
        return T

    def drive_force(self, t, x, mode) -> float:
        """f' T - tau: the torque on the motor side at the fin, friction apart."""
        return self.p.ratio * self.command(t, x) - self.chain(x, mode)

    def rhs(self, mode):
        """The right-hand side x' = f(t, x) in ``mode`` (the module docstring's equations):
        the chain's torque, the fin's and the motor's accelerations (none while stuck),
        the current loop and the error's integral. The same arithmetic as :meth:`chain`,
        :meth:`motor_torque` and :meth:`saturated_command`, with the plant's and the
        loop's numbers bound once and the reference read once a call, because the
        integrator calls it about 40 times an event and a hunting run has a thousand
        events a second. Remembered per mode."""
        fn = self._rhs.get(mode)
        if fn is not None:
            return fn
        p, c = self.p, self.c
        contact, _, motor = mode
        k, cc, b = p.stiffness, p.damping, contact * p.backlash
        kh, cf, J2, J1 = p.hinge_spring, p.fin_damping, p.fin_inertia, self.J1
        ratio, friction = p.ratio, motor * p.friction_torque
        kp, kd, ki, lag = c.kp, c.kd, c.ki, c.current_lag
        peak, fin, r = p.peak_torque, self.fin, self.r
        rate_fin, zv = self.rate_fin, self.rate_weight
        w_lim, w_band = self.w_lim, self.w_band
        turning = motor in (1, -1)

        def rhs(t, x):
            x0, x1, x2, x3, x4 = x[0], x[1], x[2], x[3], x[4]
            tau = k * (x0 - x1 - b) + cc * (x2 - x3) if contact else 0.0
            dd_phi = (tau - kh * x1 - cf * x3) / J2
            y = x1 if fin else x0
            vd = x3 if rate_fin else x2
            ref = r(t)
            T_sat = kp * (ref - y) + ki * x[5] - kd * vd
            T_sat = min(max(T_sat, -peak), peak)
            if turning:
                T = min(max(x4, -peak), peak) if lag > 0 else T_sat
                if T * x2 > 0 and abs(x2) > w_band:
                    T = T * max(0.0, (w_lim - abs(x2)) / (w_lim - w_band))
                dd_psi = (ratio * (T - friction) - tau) / J1
            else:
                dd_psi = 0.0
            dT = (T_sat - x4) / lag if lag > 0 else 0.0
            return [x2, x3, dd_psi, dd_phi, dT, ref - y - zv * vd if zv else ref - y]

        self._rhs[mode] = rhs
        return rhs

    # -- the events of a mode: (function, direction, kind) ---------------------------------
    def events(self, mode):
        """The terminal events of ``mode``, (function, direction, kind) each, the
        function's ``terminal`` and ``direction`` set for ``solve_ivp``. Remembered per
        mode (a hunting run returns to the same four modes a thousand times a second)."""
        out = self._events.get(mode)
        if out is None:
            out = self._events[mode] = self._new_events(mode)
            for fn, direction, _ in out:
                fn.terminal, fn.direction = True, direction
        return out

    def _new_events(self, mode):
        p = self.p
        b, k, c = p.backlash, p.stiffness, p.damping
        out = []
        contact, side, motor = mode
        # a flank's torque f raw_chain(x, f), written out: the integrator evaluates every
        # event function once a step
        if self.bilateral:
            pass
        elif contact:
            fb = contact * b
            out.append((lambda t, x, f=contact: f * (x[0] - x[1]) - b, -1, "opens"))
            out.append(
                (
                    lambda t, x, f=contact: f * (k * (x[0] - x[1] - fb) + c * (x[2] - x[3])),
                    -1,
                    "unloaded",
                )
            )
        elif side:
            fb = side * b
            out.append(
                (
                    lambda t, x, f=side: f * (k * (x[0] - x[1] - fb) + c * (x[2] - x[3])),
                    1,
                    "closes",
                )
            )
            out.append((lambda t, x, f=side: f * (x[0] - x[1]) - b, -1, "gap"))
        else:
            out.append((lambda t, x: (x[0] - x[1]) - b, 1, "closes"))
            out.append((lambda t, x: -(x[0] - x[1]) - b, 1, "closes"))
        if motor in (1, -1):
            if p.friction_torque > 0:
                out.append((lambda t, x, s=motor: s * x[2], -1, "stops"))
        elif motor == 0:
            ft = p.ratio * p.friction_torque
            out.append((lambda t, x: self.drive_force(t, x, mode) - ft, 1, "slips"))
            out.append((lambda t, x: -self.drive_force(t, x, mode) - ft, 1, "slips"))
        return out

    # -- the mode after an event, or at the start ----------------------------------------
    def gap_at(self, x) -> float:  # b and f' where the drive is (a path's vary)
        return self.p.backlash

    def ratio_at(self, x) -> float:
        return self.p.ratio

    def initial_mode(self, t, x) -> tuple[tuple[int, int, int], np.ndarray]:
        """The mode of a state at rest or in motion (the start of the run)."""
        b = self.gap_at(x)
        d = x[0] - x[1]
        cm = (1, 0) if self.bilateral else (0, 0)
        for f in (1, -1):
            if not self.bilateral and f * d >= b:
                cm = (f, 0) if f * self.raw_chain(x, f) > 0 else (0, f)
                break
        v = x[2]
        if v != 0 or self.p.friction_torque == 0:
            return (*cm, 1 if v >= 0 else -1), x
        return self.stick_check(t, x, (*cm, 0))

    def stick_check(self, t, x, mode):
        """At theta' = 0: stuck while |f' T - tau| <= f' T_f, else turning with it."""
        F = self.drive_force(t, x, mode)
        if abs(F) <= self.ratio_at(x) * self.p.friction_torque:
            x = x.copy()
            x[2] = 0.0
            return (mode[0], mode[1], 0), x
        return (mode[0], mode[1], 1 if F > 0 else -1), x

    def band_events(self):
        """Entering and leaving the torque-speed curve's corner, either way: recorded,
        not stopping the integration (the torque is continuous there)."""
        out = []
        if math.isfinite(self.w_lim):
            for s in (1, -1):
                for direction, kind in ((1, "speed limit"), (-1, "speed released")):
                    g = lambda t, x, s=s: s * x[2] - self.w_band  # noqa: E731
                    g.terminal, g.direction = False, direction
                    out.append((g, kind))
        return out

    def next_mode(self, t, x, mode, kind):
        contact, side, motor = mode
        d = x[0] - x[1]
        if kind == "closes":
            flank = side if side else (1 if d > 0 else -1)
            mode = (flank, 0, motor)
        elif kind == "opens" or kind == "gap":
            mode = (0, 0, motor)
        elif kind == "unloaded":
            mode = (0, contact, motor)
        elif kind == "stops":
            return self.stick_check(t, x, (contact, side, 0))
        elif kind == "slips":
            F = self.drive_force(t, x, mode)
            return (contact, side, 1 if F > 0 else -1), x
        if mode[2] == 0:  # a stuck motor whose load changed: it may slip at once
            return self.stick_check(t, x, mode)
        return mode, x


# --- the run ---------------------------------------------------------------------------------
def _positive(field: str, value, limit: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"expected a number, got {value!r}") from None
    if not (math.isfinite(value) and 0.0 < value <= limit):
        raise InputError(field, f"must be in (0, {limit:g}], got {value!r}")
    return value


def simulate(
    plant: DrivePlant,
    loop: Controller,
    reference: Reference,
    horizon: float,
    samples: int = 2001,
    initial_motor_angle: float = 0.0,
    initial_fin_angle: float = 0.0,
    rtol: float = 1e-6,
    max_events: int = 20_000,
    load: Any = None,
) -> LoopSimulation:
    """The drive's response in its loop from rest (module docstring).

    Parameters
    ----------
    plant, loop
        The drive at one fin angle, or along the stroke (a ``DrivePath``: its angles the
        fin's own, the reference within its grid), and the controller.
    reference
        :class:`StepReference`, :class:`SineReference` or :class:`SampledReference`.
    horizon
        The simulated time (s), in (0, 600].
    samples
        Output samples, evenly spaced over [0, horizon], 2 to 10^6.
    initial_motor_angle, initial_fin_angle
        psi(0) = theta(0) / f' and phi(0) (rad; at rest).
    rtol
        The integrator's relative tolerance, in [1e-12, 1e-3] (absolute tolerances follow
        from the plant's scales).
    max_events
        The most events (contact changes, sticks, speed limits) allowed, 1 to 200000; a
        run that needs more (a chattering contact) is refused.
    load
        A ``LoadHistory``, a moment on the fin: with a ``DrivePath`` only (the fixed
        plant is linearised about its angle without a mean load); None: none.

    Returns
    -------
    LoopSimulation
        The samples, the event times and what was simulated.

    Raises
    ------
    InputError
        An argument out of its range, naming it and its limit, or more events than
        ``max_events``.
    """
    from scipy.integrate import solve_ivp

    # a DrivePath (loop_path, which builds on this module) brings its own equations
    if not isinstance(plant, DrivePlant) and not hasattr(plant, "equations"):
        raise InputError("plant", f"must be a DrivePlant or a DrivePath, got {plant!r}")
    if load is not None and isinstance(plant, DrivePlant):
        raise InputError("load", "must be a LoadHistory, with a DrivePath plant")
    if not isinstance(loop, CONTROLLERS):
        raise InputError("loop", f"must be a PositionLoop or a CascadeLoop, got {loop!r}")
    if not isinstance(reference, StepReference | SineReference | SampledReference):
        raise InputError(
            "reference", f"must be a step, sine or sampled reference, got {reference!r}"
        )
    horizon = _positive("horizon", horizon, MAX_HORIZON)
    if not isinstance(samples, int | np.integer) or not 2 <= samples <= MAX_SAMPLES:
        raise InputError("samples", f"must be an integer in [2, {MAX_SAMPLES}], got {samples!r}")
    if not isinstance(max_events, int | np.integer) or not 1 <= max_events <= MAX_EVENTS:
        raise InputError(
            "max_events", f"must be an integer in [1, {MAX_EVENTS}], got {max_events!r}"
        )
    rtol = float(rtol)
    if not (math.isfinite(rtol) and 1e-12 <= rtol <= 1e-3):
        raise InputError("rtol", f"must be in [1e-12, 1e-3], got {rtol!r}")
    psi0 = angle_value("initial_motor_angle", initial_motor_angle)
    phi0 = angle_value("initial_fin_angle", initial_fin_angle)

    if isinstance(plant, DrivePlant):
        sys = _System(plant, loop, reference)
        gap, stiffness = plant.backlash, plant.stiffness
    else:
        sys = plant.equations(loop, reference, psi0, phi0, load)
        gap, stiffness = plant.backlash_scale, plant.stiffness_scale
    # absolute tolerances from the plant's scales: an angle of the gap or the reference
    angle = max(gap, *map(abs, reference.span), abs(psi0), abs(phi0), 1e-6)
    rate = angle * math.sqrt(stiffness / plant.fin_inertia)
    torque = max(loop.kp * angle, 1e-9)
    atol = rtol * np.array([angle, angle, rate, rate, torque, angle * horizon]) * 1e-2

    t_out = np.linspace(0.0, horizon, int(samples))
    pieces: list[tuple[np.ndarray, np.ndarray, tuple[int, int, int]]] = []
    x = np.array([psi0, phi0, 0.0, 0.0, 0.0, 0.0])
    if loop.current_lag > 0:
        x[4] = sys.saturated_command(0.0, x)
    t = 0.0
    mode, x = sys.initial_mode(t, x)
    band = sys.band_events()
    breaks = sorted(set(reference.breaks) | set(sys.breaks))
    stops = [b for b in breaks if 0.0 < b < horizon] + [horizon]
    event_times: list[float] = []
    event_kinds: list[str] = []
    done = 0  # samples already taken
    h = None  # the step the integration restarts with (None: solve_ivp's choice)
    while True:
        t_stop = next(b for b in stops if b > t)
        sys.left_of = t_stop if t_stop < horizon else math.inf
        evs = sys.events(mode)
        funcs = [fn for fn, _, _ in evs] + [g for g, _ in band]
        sol = solve_ivp(
            sys.rhs(mode),
            (t, t_stop),
            x,
            method="RK45",
            events=funcs,
            rtol=rtol,
            atol=atol,
            dense_output=True,
            # the last full step before the event: solve_ivp's own first step, chosen
            # from the derivatives alone, cost about two rejected steps a restart (4800
            # in the 2141 restarts of a hunting 2 s step; about 1100 from the last step)
            first_step=h if h is not None and h < t_stop - t else None,
        )
        if sol.t.size >= 3:
            h = float(sol.t[-2] - sol.t[-3])
        if sol.status < 0:
            raise InputError("plant", f"the integration failed at t = {t:.6g} s: {sol.message}")
        sys.left_of = math.inf  # from here on, the reference's value at t itself
        t_end = float(sol.t[-1])
        for j, (_, kind) in enumerate(band, start=len(evs)):
            for te in sol.t_events[j]:
                if te < t_end or sol.status != 1:
                    event_times.append(float(te))
                    event_kinds.append(kind)
        last = t_end >= horizon
        upto = int(np.searchsorted(t_out, t_end, side="right" if last else "left"))
        if upto > done:
            ts = t_out[done:upto]
            pieces.append((ts, sol.sol(ts), mode))
            done = upto
        if last:
            break
        t, x = t_end, np.array(sol.y[:, -1])
        if sol.status == 1:
            k = min(
                (j for j in range(len(evs)) if sol.t_events[j].size),
                key=lambda j: sol.t_events[j][0],
            )
            kind = evs[k][2]
            event_times.append(t)
            event_kinds.append(kind)
            if len(event_times) > max_events:
                raise InputError(
                    "max_events",
                    f"more than {max_events} events by t = {t:.6g} s (the last: {kind}): "
                    + _chatter(event_kinds[-100:]),
                )
            mode, x = sys.next_mode(t, x, mode, kind)
        elif mode[2] == 0:  # a jump of the reference: a stuck motor may slip at once
            mode, x = sys.stick_check(t, x, mode)
            if mode[2] != 0:
                event_times.append(t)
                event_kinds.append("slips")
    return _record(sys, pieces, event_times, event_kinds, reference)


#: The events of the motor's friction (:meth:`_System.next_mode`).
_FRICTION_EVENTS = ("stops", "sticks", "slips")


def _chatter(kinds: list[str]) -> str:
    """What the last events say of a run past its event limit: the motor sticking and
    slipping ever faster at its friction (an integral action, e.g. a cascade's speed
    integrator, winding up against it: the hybrid friction model has no dwell, so the
    switches accumulate), a chattering contact, or a horizon too long for the limit."""
    friction = sum(kind in _FRICTION_EVENTS for kind in kinds)
    if friction > len(kinds) // 2:
        return (
            "the motor sticks and slips ever faster at its friction torque (an integral "
            "action winding up against it); a shorter horizon, no integral action, or "
            "[motor] friction_torque = 0 simulates it"
        )
    return "a chattering contact, or a horizon too long for the limit"


def _record(sys: _System, pieces, event_times, event_kinds, reference) -> LoopSimulation:
    ts = np.concatenate([p[0] for p in pieces])
    X = np.concatenate([p[1] for p in pieces], axis=1)
    torque = np.empty(ts.size)
    chain = np.empty(ts.size)
    hinge = np.empty(ts.size)
    contact = np.zeros(ts.size, dtype=int)
    i = 0
    for tp, Xp, mode in pieces:
        for j in range(tp.size):
            x = Xp[:, j]
            torque[i] = sys.motor_torque(tp[j], x, mode)
            chain[i] = sys.chain(x, mode)
            hinge[i] = sys.hinge_moment(tp[j], x)
            contact[i] = int(np.sign(chain[i])) if sys.bilateral else mode[0]
            i += 1
    ref = np.array([reference(tk) for tk in ts])
    return LoopSimulation(
        times=ts,
        reference=ref,
        fin_angle=X[1],
        fin_rate=X[3],
        motor_angle=X[0],
        motor_rate=X[2],
        motor_torque=torque,
        chain_torque=chain,
        hinge_moment=hinge,
        contact=contact,
        event_times=tuple(event_times),
        event_kinds=tuple(event_kinds),
        plant=sys.p,
        loop=sys.c,
        input_reference=reference,
    )
