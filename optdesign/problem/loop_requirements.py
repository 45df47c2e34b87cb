"""The position loop's requirements (docs/loop.md): smooth rows at the loop's
angles of the grid, built from the design's plant (:mod:`optdesign.problem.loop`) and
the loop's frequency response (:func:`optdesign.models.loop_linear.loop_response`).

What each row checks, at each loop angle, on the linear loop (the gap closed, no
friction, no torque or speed limit):

* ``bandwidth`` (``requirements.bandwidth_min`` = f_b): |T(j w_b)|^2 / |T(j w_b / 10^4)|^2
  >= 1/2, w_b = 2 pi f_b: the closed loop from the reference to the fin still passes half
  the power of its static gain at f_b. The static gain is read four decades below f_b,
  where T is flat unless the loop has a corner that low (an integral action's zero at
  ki / kp would be one); at the shipped optimum it is T(0) to 1e-8;
* ``phase_margin`` (``phase_margin_min`` = PM) and ``modulus_margin``
  (``modulus_margin_min`` = s): the return difference |1 + L(jw)| kept at or above
  2 sin(PM / 2), or s, on 14 frequencies: seven fixed ones half an octave apart from
  f_ref / 2 to 4 f_ref around the crossover (:func:`margin_frequencies`), and seven
  about the drive's own mode, w_r (1 + 0.02 j), j = -3 ... 3, which move with the
  design. The row holds a smooth lower bound of the smallest |1 + L| on those
  frequencies, (sum_k |1 + L_k|^-2p)^(-1/2p) with p = :data:`SOFT_MIN_POWER`: never
  above that minimum. It is a check on these frequencies, not on every w: a dip of
  |1 + L| between them is missed (at the shipped optimum the row is 0.2-0.25 % above the
  exact modulus margin of :func:`optdesign.models.loop_linear.margins`). Where |L| = 1,
  |1 + L| = 2 sin(PM' / 2), PM' the phase margin: where the gain crossover is on the
  frequencies, the row implies a phase margin of at least PM and a gain margin of at
  least 1 / (1 - 2 sin(PM / 2)); it asks more than the phase margin alone;
* ``resonance_margin`` (``resonance_margin_min`` = g): 1 / |L(j w_r)| >= g at the
  frequency w_r of the drive's own mode (motor free, :func:`~optdesign.problem.
  motor_drive.two_mass_frequency_squared`): the loop's gain at the resonance stays g
  times below 1, whatever its phase (gain stabilisation of the mode);
* ``loop_stable`` (always, with ``[loop]``): the smallest damping ratio -Re p / |p| of the
  closed loop's poles p at each loop angle, above 1e-9 (as
  :func:`optdesign.models.loop_linear.is_stable`). Checked on the NumPy path only, the
  independent check of every solver's answer (the margins' rows steer the solver): a
  solver's design whose loop is unstable is no verified result;
* ``limit_cycle_amplitude`` (``limit_cycle_amplitude_max``): the fin amplitude of the
  largest stable limit cycle of the chain's clearance at each loop angle, by harmonic
  balance (:func:`optdesign.models.loop_backlash.limit_cycles`): on the NumPy path only,
  as ``loop_stable``. The amplitude is a root of the balance, not a smooth function of
  the design (a cycle appears or vanishes where a phase crossover of L_d crosses -1), so
  the NLP does not carry it; with the loop's shape fixed it grows with the backlash, which
  the objective ``backlash`` minimises.

The rows sit at ``[loop] angles`` of the stroke's grid angles (:func:`loop_angles`), not
at all of them: each row costs the solver one frequency response per frequency checked,
and the plant changes slowly along the stroke (the NumPy checks are held to the same
angles: each costs a polynomial's roots or a harmonic balance per angle and evaluation).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.models.loop_plant import DrivePlant, PositionLoop
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.problem.loop import (
    CACHED_PLANTS,
    LoopGains,
    PlantGrid,
    bandwidth_ratio,
    drive_plants_of,
    loop_angles,
    loop_gains,
    picked,
    plant_grid,
    population_size,
    resonance_frequency,
    resonance_gain,
    response,
)
from optdesign.problem.objectives import ConstraintBlock

#: The margins' frequencies about the drive's mode: w_r (1 + RESONANCE_STEP j), j = -3..3
#: (the mode's dip of |1 + L| is a few % of w_r wide at 5 % damping; 4 % steps missed
#: the shipped optimum's minimum by 2 %, these by 0.3 %).
RESONANCE_STEP = 0.02
#: The power p of the smooth minimum (sum x^-p)^(-1/p) of |1 + L|^2 over the frequencies:
#: it is below the least |1 + L| by at most a factor n^(1/2p), n the frequencies equally
#: near it (three: 0.9 %; p = 16 gave 3.5 %, enough to move a design across a limit).
SOFT_MIN_POWER = 64
#: Frequencies the harmonic balance samples to bracket L_d's phase crossovers: over the
#: loop's span of about five decades, 400 a decade (8000, the model's default, gives the
#: same cycles at the shipped problem's seven angles, nine times slower).
CYCLE_POINTS = 2000
#: The smallest damping ratio of a stable loop's poles (the roots' own precision).
STABLE_DAMPING = 1e-9


#: The requirements that need ``[loop]``.
LOOP_REQUIREMENTS = (
    "bandwidth_min",
    "phase_margin_min",
    "modulus_margin_min",
    "resonance_margin_min",
    "limit_cycle_amplitude_max",
)


def reference_frequency(spec) -> float:
    """f_ref (Hz), the middle of the margins' grid: the required bandwidth, else the
    bandwidth the gains are placed for, else 10 Hz."""
    req, loop = spec.requirements, spec.loop
    if req.bandwidth_min is not None:
        return req.bandwidth_min
    if loop is not None and loop.bandwidth is not None:
        return loop.bandwidth
    return 10.0


def margin_frequencies(spec) -> np.ndarray:
    """The margins' fixed frequencies (rad/s): f_ref x 2^(k/2), k = -2 ... 4 (half an
    octave apart from f_ref / 2 to 4 f_ref, around the loop's crossover;
    :func:`reference_frequency`)."""
    f = reference_frequency(spec)
    return 2.0 * np.pi * f * 2.0 ** (np.arange(-2, 5) / 2.0)


def soft_least_return_difference(q, grid: PlantGrid, gains: LoopGains, idx) -> Any:
    """The smooth lower bound of min |1 + L(jw)| over the margins' frequencies and about
    w_r (see the module's docstring), at the loop's angles ``idx``: (sum_k x_k^-p)^(-1/2p)
    of x_k = |1 + L_k|^2, summed as a log-sum-exp shifted by its largest term (the shift
    cancels in the value and its derivatives; unshifted, x^-p overflows where |1 + L| is
    small)."""
    p = SOFT_MIN_POWER
    w_r = resonance_frequency(q, idx)
    around = [w_r * (1.0 + RESONANCE_STEP * j) for j in range(-3, 4)]
    z = [
        -p * m.log(ll.return_difference_squared(response(grid, gains, w)) + 1e-300)
        for w in (*margin_frequencies(q.problem.spec), *around)
    ]
    top = z[0]
    for zk in z[1:]:
        top = m.fmax(top, zk)
    total = 0.0
    for zk in z:
        total = total + m.exp(zk - top)
    return m.exp(-(top + m.log(total)) / (2.0 * p))


@lru_cache(maxsize=CACHED_PLANTS)
def _least_damping(plant: DrivePlant, loop: PositionLoop) -> float:
    # the records are frozen, so a plant met again (the sensitivities evaluate the same
    # two designs under every moved requirement) is answered from the cache
    poles = ll.closed_loop_poles(plant, loop)
    return float(np.min(-poles.real / np.maximum(np.abs(poles), 1e-300)))


@lru_cache(maxsize=CACHED_PLANTS)
def _largest_cycle(plant: DrivePlant, loop: PositionLoop) -> float:
    return float(np.degrees(limit_cycles(plant, loop, CYCLE_POINTS).largest_stable_fin_amplitude))


def least_pole_damping(q, idx: np.ndarray) -> np.ndarray | RowsOnDemand:
    """The smallest damping ratio -Re p / |p| of the closed loop's poles at each loop
    angle ``idx`` (NumPy, one row per design of a population; NaN for a design whose
    drive is no plant, :func:`~optdesign.problem.loop.drive_plants_of`)."""
    return _per_plant(q, idx, _least_damping)


def limit_cycle_amplitudes(q, idx: np.ndarray) -> np.ndarray | RowsOnDemand:
    """The fin amplitude (deg) of the largest stable limit cycle the chain's clearance
    sustains at each loop angle ``idx``, by harmonic balance
    (:func:`optdesign.models.loop_backlash.limit_cycles`; 0 where there is none), NumPy,
    one row per design of a population (NaN for a design whose drive is no plant)."""
    return _per_plant(q, idx, _largest_cycle)


def _per_plant(q, idx: np.ndarray, fn) -> np.ndarray | RowsOnDemand:
    # a population's rows are screened: computed for the designs that pass every other
    # row only (optdesign.problem.evaluation), which spares a global search's start
    # sample a harmonic balance per design and angle
    drives: list = []

    def rows_of(designs: np.ndarray) -> np.ndarray:
        if not drives:
            drives.extend(drive_plants_of(q, idx, strict=False))
        return np.array(
            [
                [np.nan] * len(idx)
                if drives[i] is None
                else [fn(p, drives[i][1]) for p in drives[i][0]]
                for i in designs
            ],
            dtype=float,
        ).reshape(len(designs), len(idx))

    pop = population_size(q)
    rows = RowsOnDemand(rows_of, pop, len(idx))
    return np.asarray(rows) if pop == 1 else rows


def _phase_margin(modulus):
    return np.degrees(2.0 * np.arcsin(np.clip(np.asarray(modulus, dtype=float) / 2.0, -1, 1)))


def _inverse(x):
    return 1.0 / np.asarray(x, dtype=float)


def loop_blocks(q, labels: list[str]) -> list[ConstraintBlock]:
    """The loop's rows (module docstring); none without ``[loop]``."""
    spec = q.problem.spec
    req = spec.requirements
    wanted = [name for name in LOOP_REQUIREMENTS if getattr(req, name) is not None]
    if spec.loop is None:
        if wanted:
            raise ProblemError(f"requirements.{wanted[0]}: needs a [loop] section (its gains)")
        return []
    full, gains = plant_grid(q), loop_gains(q)
    idx = loop_angles(q.problem)
    grid = picked(full, idx, len(q.phi))
    at = [labels[i] for i in idx]
    out: list[ConstraintBlock] = []
    if req.bandwidth_min is not None:
        out.append(
            ConstraintBlock(
                "bandwidth",
                bandwidth_ratio(q, grid, gains, req.bandwidth_min),
                0.5,
                None,
                at,
                "",
                f"closed-loop gain at {req.bandwidth_min:g} Hz over its static gain, squared "
                "(>= 1/2: the -3 dB bandwidth is above it)",
            )
        )
    least = None
    if req.phase_margin_min is not None or req.modulus_margin_min is not None:
        least = soft_least_return_difference(q, grid, gains, idx)
    if req.phase_margin_min is not None:
        out.append(
            ConstraintBlock(
                "phase_margin",
                least,
                2.0 * np.sin(req.phase_margin_min / 2.0),
                None,
                at,
                "",
                "phase margin in its modulus form, 2 asin(min |1 + L| / 2) over the "
                "margins' 14 frequencies (the row holds min |1 + L|)",
                display=_phase_margin,
                display_unit="deg",
            )
        )
    if req.modulus_margin_min is not None:
        out.append(
            ConstraintBlock(
                "modulus_margin",
                least,
                req.modulus_margin_min,
                None,
                at,
                "",
                "smallest return difference |1 + L(jw)| over the margins' 14 frequencies",
            )
        )
    if req.resonance_margin_min is not None:
        out.append(
            ConstraintBlock(
                "resonance_margin",
                resonance_gain(q, grid, gains, idx),
                None,
                1.0 / req.resonance_margin_min,
                at,
                "",
                "1 / loop gain at the drive's own mode (the row holds the gain |L(j w_r)|)",
                display=_inverse,
                display_unit="",
            )
        )
    if m.is_symbolic(q.ratio):
        return out
    if req.limit_cycle_amplitude_max is not None:
        out.append(
            ConstraintBlock(
                "limit_cycle_amplitude",
                limit_cycle_amplitudes(q, idx),
                None,
                float(np.degrees(req.limit_cycle_amplitude_max)),
                at,
                "deg",
                "fin amplitude of the largest stable backlash limit cycle (harmonic balance; "
                "checked on the independent NumPy path, not a row of the NLP)",
            )
        )
    out.append(
        ConstraintBlock(
            "loop_stable",
            least_pole_damping(q, idx),
            STABLE_DAMPING,
            None,
            at,
            "",
            "smallest damping ratio of the closed loop's poles (> 0: stable; checked on "
            "the independent NumPy path, not a row of the NLP)",
        )
    )
    return out
