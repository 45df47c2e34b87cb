"""The actuator in its position loop, from the design (docs/loop.md): the
drive's plant at every grid angle and the controller of ``[loop]``, for any mechanism.

Everything here reads the design's quantities (:class:`~optdesign.problem.quantities.
Quantities`: the ratio f'(phi), the motor-side inertia, the chain's stiffness, the
clearance chain's worst-case backlash) and the problem's ``[motor]``, ``[load]`` and
``[loop]`` sections; the equations are :mod:`optdesign.models.loop_plant`'s. Two forms:

* :func:`plant_grid` and :func:`loop_gains`: the plant and the gains as expressions over
  the grid (CasADi on the solver path, NumPy arrays on the checking path), which the
  requirement rows (:mod:`optdesign.problem.loop_requirements`) are built from;
* :func:`drive_plants` and :func:`position_loop`: one :class:`~optdesign.models.
  loop_plant.DrivePlant` per grid angle and the controller (a :class:`~optdesign.models.
  loop_plant.PositionLoop` or :class:`~optdesign.models.loop_plant.CascadeLoop`),
  numbers, for the post-solve analyses (poles, limit cycles, simulation).

Internal units: mm, t, s, N, rad (the current loop's lag is read from the file in h).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError, ProblemError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import CascadeLoop, Controller, DrivePlant, PositionLoop

#: The chain's damping ratio when ``[loop]`` gives none: 2 % of critical, a steel drive
#: of bearings, a ball nut and pins (a lightly damped structure, 1-5 %).
DEFAULT_CHAIN_DAMPING_RATIO = 0.02

#: The hours of a file's time in seconds.
HOUR = 3600.0

#: The static gain is |T| this many times below the bandwidth's frequency.
STATIC_BELOW = 1e4

#: Plants whose poles, cycles and bandwidths are remembered (a few kB each).
CACHED_PLANTS = 4096


@dataclass(frozen=True)
class PlantGrid:
    """The drive's plant at every grid angle (the fields of :class:`~optdesign.models.
    loop_plant.DrivePlant`, each a grid expression or a number; internal units). ``phi``
    holds the grid angles (rad)."""

    motor_inertia: Any
    ratio: Any
    fin_inertia: float
    stiffness: Any
    damping: Any
    hinge_spring: float
    fin_damping: float
    backlash: Any
    friction_torque: float
    peak_torque: Any
    max_speed: Any
    phi: Any

    @property
    def motor_inertia_at_fin(self) -> Any:
        """J_1 = J_m f'^2 over the grid (t*mm^2)."""
        return self.motor_inertia * self.ratio**2


@dataclass(frozen=True)
class LoopGains:
    """The controller of ``[loop]`` in the rational form of :mod:`optdesign.models.
    loop_plant` (kp, kd, ki, speed_ki: motor torque per fin angle, internal units;
    ``current_lag`` in s): numbers for fixed gains, design expressions for gains placed
    from a bandwidth (:func:`loop_gains`). A cascade's own gains (``position_gain`` in
    1/s, ``speed_gain``, ``speed_integral_time`` in s) make its record."""

    kp: Any
    kd: Any
    ki: Any
    current_lag: float
    feedback: str
    speed_ki: Any = 0.0
    speed_feedback: str | None = None
    structure: str = "pid"
    position_gain: Any = None
    speed_gain: Any = None
    speed_integral_time: float = 0.0

    @property
    def speed_on(self) -> str:
        """The angle whose speed kd and speed_ki read."""
        return self.feedback if self.speed_feedback is None else self.speed_feedback


def _need_loop(q):
    spec = q.problem.spec
    if spec.loop is None:
        raise ProblemError("the position loop: needs a [loop] section (its gains or bandwidth)")
    for section, what in (
        ("motor", "the motor's inertia and limits"),
        ("load", "the fin's inertia"),
        ("screw", "the chain's stiffness: its bearings, nut and shaft"),
    ):
        if getattr(spec, section) is None:
            raise ProblemError(f"[loop]: needs a [{section}] section ({what})")
    return spec.loop


def chain_damping(q, stiffness, J1, J2) -> Any:
    """The chain's viscous damping at the fin (N*mm*s/rad) over the grid: ``[loop]
    chain_damping``, or 2 zeta sqrt(k J1 J2 / (J1 + J2)) for its ``chain_damping_ratio``
    (default :data:`DEFAULT_CHAIN_DAMPING_RATIO`): zeta of critical for the chain's own
    mode, the two inertias beating against each other on k."""
    loop = q.problem.spec.loop
    if loop.chain_damping is not None:
        return loop.chain_damping + 0.0 * stiffness
    zeta = loop.chain_damping_ratio
    zeta = DEFAULT_CHAIN_DAMPING_RATIO if zeta is None else zeta
    return 2.0 * zeta * m.sqrt(stiffness * J1 * J2 / (J1 + J2))


def backlash_half_width(q) -> Any:
    """b: half the clearance chain's worst-case backlash at the fin (rad) over the grid;
    the backlash of :class:`~optdesign.mechanisms.joints.Backlash` is the full play
    between the two contacts, in degrees. 0 for a chain without clearance."""
    if not q.joints:
        return 0.0 * q.ratio
    return q.backlash.worst_case * (np.pi / 180.0) / 2.0


def plant_grid(q) -> PlantGrid:
    """The design's plant at every grid angle (see the module's docstring): J_m from
    ``motor_side_inertia``, f' the ratio, the fin's inertia, hinge spring and damping of
    ``[load]``, the chain's stiffness at the fin with the motor held, its damping
    (:func:`chain_damping`), b (:func:`backlash_half_width`), the motor's friction, peak
    torque and top speed."""
    _need_loop(q)
    load = q.problem.spec.load
    motor = q.motor_data
    k = q.output_stiffness
    Jm = q.motor_side_inertia
    f = q.ratio
    J2 = load.inertia
    return PlantGrid(
        motor_inertia=Jm,
        ratio=f,
        fin_inertia=J2,
        stiffness=k,
        damping=chain_damping(q, k, Jm * f**2, J2),
        hinge_spring=load.hinge_spring,
        fin_damping=load.damping,
        backlash=backlash_half_width(q),
        friction_torque=motor.friction_torque,
        peak_torque=motor.peak_torque,
        max_speed=motor.max_speed,
        phi=q.phi,
    )


def bandwidth_factor(zeta: float) -> float:
    """w_b / w_n of the second-order loop w_n^2 / (s^2 + 2 zeta w_n s + w_n^2): the
    frequency where its gain falls to 1/sqrt(2), over its natural frequency: 1 at zeta =
    1/sqrt(2), 0.6436 at zeta = 1, 1.5538 at zeta = 0."""
    a = 1.0 - 2.0 * zeta**2
    return float(np.sqrt(a + np.sqrt(a * a + 1.0)))


def _on_grid(mean, like):
    # A design's mean (one value) against its grid: NumPy keeps the grid on the last axis.
    if m.is_symbolic(mean, like):
        return mean
    return np.asarray(mean)[..., None] if np.ndim(like) > np.ndim(mean) else mean


def loop_gains(q) -> LoopGains:
    """The controller: ``[loop]``'s gains, or kp and kd placed for its ``bandwidth`` and
    ``damping_ratio`` on the rigid drive at the design's mean ratio: with J = J_m f'^2 +
    J_fin (J_m and f' their grid means), f' kp = J w_n^2 - k_h and f' kd = 2 zeta w_n J -
    c_fin, w_n = 2 pi bandwidth / :func:`bandwidth_factor`. One controller for the stroke:
    at an angle whose ratio is above the mean the loop is faster, below it slower.

    A cascade is placed as the P speed loop equal to that PD on the motor's speed
    (:func:`cascade_gains`): Kv = kd, Kpos = kp / kd; its ``speed_integral_time``, if
    any, is the file's."""
    loop = _need_loop(q)
    lag = loop.current_lag * HOUR
    if loop.bandwidth is None:
        if loop.structure == "cascade":
            return cascade_gains(loop.position_gain * loop.speed_gain, loop.speed_gain, loop, lag)
        return LoopGains(loop.kp, loop.kd or 0.0, loop.ki, lag, loop.feedback)
    kp, kd = _placed(q, loop)
    if loop.structure == "cascade":
        return cascade_gains(kp, kd, loop, lag)
    return LoopGains(kp, kd, loop.ki, lag, loop.feedback)


def cascade_gains(kp: Any, kd: Any, loop, lag: float) -> LoopGains:
    """The cascade of ``[loop]`` with Kv Kpos = ``kp`` and Kv = ``kd`` (numbers or design
    expressions) in the rational form: ki = kp / Ti, speed_ki = kd / Ti on the motor's
    speed (0 without ``speed_integral_time``)."""
    ti = (loop.speed_integral_time or 0.0) * HOUR
    ki, speed_ki = (kp / ti, kd / ti) if ti > 0 else (0.0, 0.0)
    return LoopGains(
        kp,
        kd,
        ki,
        lag,
        loop.feedback,
        speed_ki=speed_ki,
        speed_feedback="motor",
        structure="cascade",
        position_gain=loop.position_gain,  # None when placed: kp / kd, a design's
        speed_gain=kd,
        speed_integral_time=ti,
    )


def _placed(q, loop) -> tuple[Any, Any]:
    """kp and kd for ``[loop]``'s bandwidth and damping ratio (:func:`loop_gains`)."""
    load = q.problem.spec.load
    f = _on_grid(m.grid_mean(q.ratio), q.ratio)
    Jm = _on_grid(m.grid_mean(q.motor_side_inertia + 0.0 * q.ratio), q.ratio)
    J = Jm * f**2 + load.inertia
    wn = 2.0 * np.pi * loop.bandwidth / bandwidth_factor(loop.zeta)
    kp = (J * wn**2 - load.hinge_spring) / f
    kd = m.fmax(2.0 * loop.zeta * wn * J - load.damping, 0.0) / f
    return kp, kd


def loop_angles(problem) -> np.ndarray:
    """Indices of the grid angles that carry the loop's rows: ``[loop] angles`` of them
    (at most the grid's), evenly spread, both ends included."""
    n = len(problem.phi)
    count = min(problem.spec.loop.angles, n)
    return np.unique(np.round(np.linspace(0, n - 1, count)).astype(int))


def _pick(x: Any, idx: np.ndarray, n: int) -> Any:
    """The entries ``idx`` of a grid quantity (a number stays a number)."""
    if m.is_symbolic(x):
        return x[[int(i) for i in idx]] if x.shape[0] == n else x
    a = np.asarray(x)
    return a[..., idx] if a.ndim and a.shape[-1] == n else x


def picked(grid: PlantGrid, idx: np.ndarray, n: int) -> PlantGrid:
    """The plant at the grid indices ``idx`` of its ``n`` angles."""
    return PlantGrid(**{f.name: _pick(getattr(grid, f.name), idx, n) for f in fields(PlantGrid)})


def response(grid: PlantGrid, gains: LoopGains, omega) -> ll.LoopResponse:
    """L(jw) and T(jw) of the loop at ``omega`` (rad/s) over a plant's grid."""
    return ll.loop_response(
        grid.motor_inertia,
        grid.ratio,
        grid.fin_inertia,
        grid.stiffness,
        grid.damping,
        grid.hinge_spring,
        grid.fin_damping,
        gains.kp,
        gains.kd,
        gains.ki,
        gains.current_lag,
        omega,
        gains.feedback,
        gains.speed_ki,
        gains.speed_on,
    )


def bandwidth_ratio(q, grid: PlantGrid, gains: LoopGains, f_b: float) -> Any:
    """|T(j w_b)|^2 / |T(j w_b / 10^4)|^2 over the grid: the requirement row ``bandwidth``
    (:mod:`~optdesign.problem.loop_requirements`) and the objective ``bandwidth_period``'s
    implicit rows (:mod:`~optdesign.problem.loop_bandwidth`)."""
    w = 2.0 * np.pi * f_b
    at = ll.closed_loop_gain_squared(response(grid, gains, w))
    static = ll.closed_loop_gain_squared(response(grid, gains, w / STATIC_BELOW))
    return at / static


def resonance_frequency(q, idx: np.ndarray | None = None) -> Any:
    """w_r (rad/s): the drive's own mode, motor free, over the grid (at ``idx``)."""
    w2 = q.two_mass_frequency_squared
    return m.sqrt(w2 if idx is None else _pick(w2, idx, len(q.phi)))


def resonance_gain(q, grid: PlantGrid, gains: LoopGains, idx) -> Any:
    """|L(j w_r)| at the loop's angles ``idx``: the loop's gain at the drive's own mode."""
    r = response(grid, gains, resonance_frequency(q, idx))
    return m.sqrt(r.open_re**2 + r.open_im**2)


def loop_resonance_gain(q) -> Any:
    """|L(j w_r)| at every grid angle (the objective ``resonance_gain``)."""
    return resonance_gain(q, plant_grid(q), loop_gains(q), None)


def _rows(value: Any, pop: int, width: int) -> np.ndarray:
    """A grid quantity of a population as a (pop, width) array (a number, a grid, or one
    row per design)."""
    a = np.asarray(value, dtype=float)
    if a.ndim == 2 and a.shape[0] == pop:
        return np.broadcast_to(a, (pop, width))
    return np.broadcast_to(a.reshape(-1) if a.ndim else a, (pop, width))


def population_size(q) -> int:
    """How many designs the NumPy quantities ``q`` hold (1: one design)."""
    sizes = [np.shape(v)[0] for v in q.design.values() if np.ndim(v) == 2]
    return max(sizes, default=1)


def drive_plants_of(
    q, angles=None, strict: bool = True
) -> list[tuple[list[DrivePlant], Controller] | None]:
    """For each design of the NumPy quantities ``q`` (one design, or a population: one
    row per design), its :class:`~optdesign.models.loop_plant.DrivePlant` at every grid
    angle (or at the grid indices ``angles``) and its controller (:func:`controller`).

    ``strict`` False: a design whose drive is no plant (a ratio that is not positive: a
    dead point inside the stroke; a linkage that does not assemble: NaN; a loop gain
    placed at or below zero) gives None instead of the error, as the NumPy path answers
    NaN for a design that does not work (a population's rows)."""
    grid, gains = plant_grid(q), loop_gains(q)
    phi = np.asarray(q.phi, dtype=float).reshape(-1)
    pop, width = population_size(q), len(phi)
    names = [f.name for f in fields(DrivePlant) if f.name != "angle"]
    values = {n: _rows(getattr(grid, n), pop, width) for n in names}
    kp, kd = _rows(gains.kp, pop, 1)[:, 0], _rows(gains.kd, pop, 1)[:, 0]
    out: list[tuple[list[DrivePlant], Controller] | None] = []
    for i in range(pop):
        try:
            if not kp[i] > 0:
                raise ProblemError(
                    f"loop.bandwidth: places kp = {kp[i]:.4g} N*mm/rad at this design; the "
                    "fin's hinge spring alone is stiffer than the loop asked for: raise the "
                    "bandwidth"
                )
            loop = controller(gains, float(kp[i]), float(kd[i]))
            plants = [
                DrivePlant(**{n: float(values[n][i, k]) for n in names}, angle=float(phi[k]))
                for k in (range(width) if angles is None else angles)
            ]
        except (InputError, ProblemError):
            if strict:
                raise
            out.append(None)
            continue
        out.append((plants, loop))
    return out


def controller(gains: LoopGains, kp: float, kd: float) -> Controller:
    """The controller record of one design whose kp and kd are ``kp`` and ``kd`` (a
    cascade's Kv Kpos and Kv): a :class:`~optdesign.models.loop_plant.PositionLoop`, or a
    :class:`~optdesign.models.loop_plant.CascadeLoop` (a placed Kpos = kp / kd; a placed
    Kv that is not positive, the fin's own damping above the loop's, refused naming
    ``loop.bandwidth``)."""
    if gains.structure != "cascade":
        return PositionLoop(kp, kd, gains.ki, gains.current_lag, gains.feedback)
    if not kd > 0:
        raise ProblemError(
            f"loop.bandwidth: places speed_gain = {kd:.4g} N*mm*s/rad at this design; the "
            "fin's own damping is more than the loop asked for: raise the bandwidth or "
            "the damping_ratio"
        )
    position_gain = kp / kd if gains.position_gain is None else gains.position_gain
    return CascadeLoop(
        float(position_gain), kd, gains.speed_integral_time, gains.current_lag, gains.feedback
    )


def drive_plants(q) -> list[DrivePlant]:
    """One :class:`~optdesign.models.loop_plant.DrivePlant` per grid angle of the design
    whose NumPy quantities are ``q`` (one design)."""
    return drive_plants_of(q)[0][0]


def position_loop(q) -> Controller:
    """The controller (:func:`controller`) of the design whose NumPy
    quantities are ``q``; a placed kp that is not positive (a bandwidth below the fin's
    own frequency on its stabilising hinge spring) refused naming ``loop.bandwidth``."""
    return drive_plants_of(q)[0][1]


def check_loop(problem) -> None:
    """Refuse (:class:`~optdesign.errors.ProblemError` naming ``loop``) a ``[loop]``
    without the sections it closes around, or whose closed loop is unstable at every one
    of its angles (``[loop] angles`` of the grid) at the problem's start design: the
    file's gains (or bandwidth) are wrong for this drive, not one design."""
    from optdesign.models.loop_linear import closed_loop_poles

    q = problem.quantities(problem.design_dict(problem.start()))
    _need_loop(q)
    plants, loop = drive_plants_of(q, loop_angles(problem))[0]
    rightmost = []
    for plant in plants:
        poles = closed_loop_poles(plant, loop)
        if np.all(poles.real < -1e-9 * np.maximum(np.abs(poles), 1e-300)):
            return
        rightmost.append((float(np.max(poles.real)), plant))
    worst, plant = max(rightmost, key=lambda item: item[0])
    spec = problem.spec
    rigid = -spec.load.hinge_spring / plant.ratio  # f' kp + k_h > 0, the rigid loop's
    raise ProblemError(
        f"loop: the position loop ({_gains_text(loop)}, current "
        f"lag {loop.current_lag * 1e3:.3g} ms, {loop.feedback} feedback) is unstable at "
        f"every one of its {len(plants)} angles at the start design: a closed-loop pole at Re s = {worst:.4g} "
        f"rad/s at {np.degrees(plant.angle):+.1f} deg. Check the gains: the rigid loop "
        f"alone needs f' kp + k_h > 0 (kp > {max(rigid, 0.0) * 1e-3:.4g} N*m/rad there) "
        "and kd > 0; with integral action, ki < (f' kd + c_fin) (f' kp + k_h) / (f' J), "
        "J = J_m f'^2 + J_fin"
    )


def _gains_text(loop: Controller) -> str:
    """The controller's gains as a message shows them (N*m for the torques)."""
    if isinstance(loop, CascadeLoop):
        return (
            f"cascade: position_gain = {loop.position_gain:.4g} 1/s, speed_gain = "
            f"{loop.speed_gain * 1e-3:.4g} N*m*s/rad, speed_integral_time = "
            f"{loop.speed_integral_time * 1e3:.4g} ms; kp = Kv Kpos = {loop.kp * 1e-3:.4g} N*m/rad"
        )
    return (
        f"kp = {loop.kp * 1e-3:.4g} N*m/rad, kd = {loop.kd * 1e-3:.4g} N*m*s/rad, ki = "
        f"{loop.ki * 1e-3:.4g} N*m/(rad*s)"
    )
