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
  f_ref / 2 to 4 f_ref around the crossover (:func:`~optdesign.problem.loop_margins.margin_frequencies`), and seven
  about the drive's own mode, w_r (1 + 0.02 j), j = -3 ... 3, which move with the
  design. The row holds a smooth lower bound of the smallest |1 + L| on those
  frequencies, (sum_k |1 + L_k|^-2p)^(-1/2p) with p = :data:`~optdesign.problem.loop_margins.SOFT_MIN_POWER`: never
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

import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import Controller, DrivePlant
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.problem.loop import (
    CACHED_PLANTS,
    bandwidth_ratio,
    loop_angles,
    loop_gains,
    picked,
    plant_grid,
    resonance_gain,
)
from optdesign.problem.loop_margins import (
    limit_cycle_amplitudes,
    per_plant_rows,
    soft_least_return_difference,
)
from optdesign.problem.objectives import ConstraintBlock

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


@lru_cache(maxsize=CACHED_PLANTS)
def _least_damping(plant: DrivePlant, loop: Controller) -> float:
    # the records are frozen, so a plant met again (the sensitivities evaluate the same
    # two designs under every moved requirement) is answered from the cache
    poles = ll.closed_loop_poles(plant, loop)
    return float(np.min(-poles.real / np.maximum(np.abs(poles), 1e-300)))


def least_pole_damping(q, idx: np.ndarray) -> np.ndarray | RowsOnDemand:
    """The smallest damping ratio -Re p / |p| of the closed loop's poles at each loop
    angle ``idx`` (NumPy, one row per design of a population; NaN for a design whose
    drive is no plant, :func:`~optdesign.problem.loop.drive_plants_of`)."""
    return per_plant_rows(q, idx, _least_damping)


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
