"""Transmission-error budget of a screw drive ([L16], Li et al. 2016, eq. 1-6, Table 1),
carried to the output angle of a linkage through its kinematics (docs/clearance_and_backlash.md).

Seed 003 writes the transmission error as the sum of systematic terms plus or minus the
root-sum-square of the random ones (eq. 6):

    Delta x = sum_k Delta x_k  +-  sqrt( sum_l sigma_l^2 )

with terms such as the lead error dP theta / 2 pi (eq. 2), the coaxiality error
e_r sin(theta) P / (d_s pi) (eq. 4), the encoder error P dtheta / 2 pi (eq. 5), the
deformation under load (here F / K of the stiffness chain), backlash, mounting, motor,
bearings, measurement, control and environment, each with its distribution (Table 1).

Each uncertain quantity is an :class:`ErrorSource`: its native value (a lead deviation in
mm/rev, an encoder angle in rad at the motor, a nut-side displacement in mm, a rod-length
change in mm, an output angle in rad), a distribution and whether eq. 6 counts it as
systematic or random. :func:`contribution` maps a value of a source to the output through
the model functions of this module and the mechanism's sensitivities; the deterministic
:func:`budget` and the Monte Carlo (optdesign.reproduce.monte_carlo) both call it, so the
formulas exist once. All terms are linear in their uncertain input, so "gain x value" is
exact.

Output: an angle in rad at the output shaft when a mechanism is given (nut-side error
times 1/(dx/dphi), the sensitivity of models.crank_slider / models.fork); a nut-side
displacement in mm without one (the paper's screw on its own).

Validity
--------
each source small against the lead and the link lengths
    Every term is linear in its source ("gain x value"), mapped to the output by the
    first-order sensitivities of the linkage: the same small-angle range as the
    clearance chain (:data:`optdesign.models.clearance.BACKLASH`, 5 deg at the output).
    Documented (the studies' budgets).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models.validity import Validity

OUTPUT_ERROR = Validity(
    "error_budget.output_error",
    "transmission-error budget",
    "output angle error",
    0.0,
    5.0,
    "deg",
    "the terms are mapped through first-order sensitivities, like the clearance chain",
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (OUTPUT_ERROR,)


#: Distributions of Table 1. ``periodic``: amplitude x sin(uniform phase).
DISTRIBUTIONS = ("fixed", "uniform", "normal", "periodic")

#: What a source's value is, i.e. where it enters the drive chain.
ACTS_ON = ("axial", "lead", "motor_angle", "compliance", "rod_length", "angular")

KINDS = ("systematic", "random")


# --- the paper's terms ([L16] eq. 2-5), pure functions ------------------------------------
def lead_error(dP, theta):
    """Nut displacement error from a lead deviation dP (mm/rev) after a screw turn theta
    (rad): dP theta / 2 pi (mm), eq. 2."""
    return dP * theta / (2.0 * m.pi)


def coaxiality_error(e_r, theta, P, d_s):
    """Error from the thread/journal coaxiality e_r (mm): e_r sin(theta) P / (d_s pi) (mm),
    eq. 4."""
    return e_r * m.sin(theta) * P / (d_s * m.pi)


def encoder_error(P, dtheta, i_a=1.0):
    """Nut displacement for an angle error dtheta (rad) measured at the motor:
    P dtheta / (2 pi i_a) (mm), eq. 5 with the gear ratio i_a between motor and screw."""
    return P * dtheta / (2.0 * m.pi * i_a)


def deformation_error(F, K):
    """Elastic displacement F / K (mm) of the axial stiffness chain K (N/mm) under F (N);
    K from models.screw_sizing.axial_stiffness_chain."""
    return F / K


def transmission_error(systematic: Sequence, sigmas: Sequence):
    """Eq. 6: (sum of systematic terms, root-sum-square of the random sigmas).

    The total is ``total[0] +- total[1]``.
    """
    s = 0.0
    for term in systematic:
        s = s + term
    v = 0.0
    for sigma in sigmas:
        v = v + sigma**2
    return s, m.sqrt(v)


# --- sources --------------------------------------------------------------------------------
@dataclass(frozen=True)
class ErrorSource:
    """One uncertain quantity of the error budget.

    Parameters
    ----------
    name
        Label, e.g. ``"lead error"``.
    kind
        ``"systematic"`` or ``"random"`` (how eq. 6 adds it).
    distribution
        ``"fixed"`` (always ``mean``), ``"uniform"`` (mean +- scale), ``"normal"``
        (mean, standard deviation ``scale``), ``"periodic"`` (mean + scale sin(psi), psi
        uniform in [0, 2 pi)).
    scale
        Half-range, standard deviation or amplitude, in the unit of ``acts_on``.
    mean
        Mean value (same unit).
    acts_on
        ``"axial"`` (nut displacement, mm), ``"lead"`` (lead deviation, mm/rev),
        ``"motor_angle"`` (angle at the motor, rad, e.g. the encoder), ``"compliance"``
        (axial compliance 1/K of the stiffness chain, mm/N, loaded by the nut force of the
        hinge moment ``M_h`` at each angle, or by ``F`` without a mechanism), ``"rod_length"``
        (effective rod length, mm; crank-slider only), ``"angular"`` (output angle, rad).
    """

    name: str
    kind: str
    distribution: str
    scale: float = 0.0
    mean: float = 0.0
    acts_on: str = "axial"

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"source {self.name}.kind", f"{self.kind!r} not in {KINDS}")
        if self.distribution not in DISTRIBUTIONS:
            raise InputError(
                f"source {self.name}.distribution", f"{self.distribution!r} not in {DISTRIBUTIONS}"
            )
        if self.acts_on not in ACTS_ON:
            raise InputError(f"source {self.name}.acts_on", f"{self.acts_on!r} not in {ACTS_ON}")
        if not (np.isfinite(self.scale) and self.scale >= 0):
            raise InputError(f"source {self.name}.scale", f"must be finite and >= 0: {self.scale}")
        if not np.isfinite(self.mean):
            raise InputError(f"source {self.name}.mean", f"must be finite: {self.mean}")

    @property
    def sd(self) -> float:
        """Standard deviation of the native value."""
        return {
            "fixed": 0.0,
            "uniform": self.scale / np.sqrt(3.0),
            "normal": self.scale,
            "periodic": self.scale / np.sqrt(2.0),
        }[self.distribution]

    @property
    def bound(self) -> float:
        """Largest |value| (normal: |mean| + 3 sd)."""
        spread = 3.0 * self.scale if self.distribution == "normal" else self.scale
        if self.distribution == "fixed":
            spread = 0.0
        return abs(self.mean) + spread

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` values drawn from the source's distribution with ``rng``."""
        d = self.distribution
        if d == "fixed":
            return np.full(n, self.mean)
        if d == "uniform":
            x = rng.random(n)
            x *= 2.0 * self.scale
            x += self.mean - self.scale
            return x
        if d == "normal":
            x = rng.standard_normal(n)
            x *= self.scale
            x += self.mean
            return x
        x = rng.random(n)
        x *= 2.0 * np.pi
        np.sin(x, out=x)
        x *= self.scale
        x += self.mean
        return x


# --- convenience constructors with the paper's distributions (Table 1) ------------------------
def lead_error_source(dP_max: float) -> ErrorSource:
    """Lead deviation dP, systematic, uniform in +-dP_max (mm/rev)."""
    return ErrorSource("lead error", "systematic", "uniform", dP_max, acts_on="lead")


def coaxiality_source(e_r: float, P: float, d_s: float) -> ErrorSource:
    """Coaxiality e_r of thread and journal, systematic, periodic, amplitude e_r P/(d_s pi)."""
    amplitude = float(coaxiality_error(e_r, np.pi / 2.0, P, d_s))
    return ErrorSource("coaxiality", "systematic", "periodic", amplitude)


def backlash_source(backlash: float) -> ErrorSource:
    """Return (backlash) error, systematic, a fixed value (mm at the nut)."""
    return ErrorSource("backlash", "systematic", "fixed", 0.0, mean=backlash)


def deformation_source(F: float, K: float, cv: float = 0.1) -> ErrorSource:
    """Deformation under load F/K, random, normal around F/K with coefficient of
    variation ``cv`` (load and stiffness scatter)."""
    delta = float(deformation_error(F, K))
    return ErrorSource("deformation", "random", "normal", abs(cv * delta), mean=delta)


def compliance_source(K: float, cv: float = 0.1) -> ErrorSource:
    """Deformation of the stiffness chain K (N/mm) under the nut force at each angle:
    random, compliance 1/K normal with coefficient of variation ``cv``. Needs ``M_h``
    (with a mechanism) or ``F`` (without) in :func:`contribution`."""
    return ErrorSource(
        "deformation", "random", "normal", abs(cv) / K, mean=1.0 / K, acts_on="compliance"
    )


def encoder_source(sigma_rad: float) -> ErrorSource:
    """Encoder angle error at the motor, random, normal with sd ``sigma_rad``."""
    return ErrorSource("encoder", "random", "normal", sigma_rad, acts_on="motor_angle")


def random_source(
    name: str, sigma: float, acts_on: str = "axial", distribution: str = "normal"
) -> ErrorSource:
    """Any other random term (mounting, motor, bearings, measurement, environment)."""
    return ErrorSource(name, "random", distribution, sigma, acts_on=acts_on)


# --- mapping to the output ---------------------------------------------------------------------
def screw_angle(mechanism, phi, phi_ref=0.0):
    """Screw rotation theta (rad) between the reference deflection and phi:
    2 pi (x(phi) - x(phi_ref)) / p."""
    return (
        2.0 * m.pi * (mechanism.nut_position(phi) - mechanism.nut_position(phi_ref)) / (mechanism.p)
    )


def contribution(
    source: ErrorSource,
    value,
    mechanism=None,
    phi=0.0,
    *,
    p=None,
    i_a=1.0,
    theta=None,
    M_h=None,
    F=None,
):
    """Error at the output caused by ``value`` (native unit) of ``source``.

    With a mechanism: output angle (rad). Nut-side values pass through the axial
    sensitivity 1/(dx/dphi); a lead deviation through lead_error over the screw angle from
    phi = 0 (:func:`screw_angle`); a motor angle through encoder_error with the
    mechanism's lead and gear ratio; a compliance through deformation_error under the nut
    force of the hinge moment ``M_h`` (N*mm) at phi; a rod-length change through the rod
    sensitivity.

    Without a mechanism (a screw on its own, [L16]): nut displacement (mm), using the
    lead ``p``, gear ratio ``i_a``, screw angle ``theta`` and axial load ``F`` given here.

    ``value`` and ``phi`` may be arrays (one entry per Monte Carlo sample).
    """
    a = source.acts_on
    if mechanism is None:
        if a in ("rod_length", "angular"):
            raise InputError(f"source {source.name}.acts_on", f"{a!r} needs a mechanism")
        if a == "axial":
            return value
        if a == "compliance":
            if F is None:
                raise InputError("F", "a compliance needs the axial load F")
            return deformation_error(F, 1.0 / value)
        if a == "lead":
            if theta is None:
                raise InputError("theta", "a lead error needs the screw angle theta")
            return lead_error(value, theta)
        if p is None:
            raise InputError("p", "an angle error at the motor needs the lead p")
        return encoder_error(p, value, i_a)
    if a == "angular":
        return value
    if a == "rod_length":
        return value * mechanism.sensitivity_rod_length(phi)
    if a == "axial":
        nut = value
    elif a == "lead":
        nut = lead_error(value, screw_angle(mechanism, phi))
    elif a == "compliance":
        if M_h is None:
            raise InputError("M_h", "a compliance needs the hinge moment M_h")
        nut = deformation_error(mechanism.nut_force(phi, M_h), 1.0 / value)
    else:
        nut = encoder_error(mechanism.p, value, mechanism.i_a)
    return nut * mechanism.sensitivity_axial(phi)


def gains(sources: Sequence[ErrorSource], mechanism=None, phi=0.0, **kwargs) -> list:
    """Output per unit native value of each source, ``contribution(source, 1.0, ...)``.

    Exact because every term is linear in its uncertain input. Evaluated once per distinct
    ``acts_on`` (the kinematics of a sampled stroke are the expensive part).
    """
    cache: dict[str, Any] = {}
    out = []
    for s in sources:
        if s.acts_on not in cache:
            cache[s.acts_on] = contribution(s, 1.0, mechanism, phi, **kwargs)
        out.append(cache[s.acts_on])
    return out


@dataclass
class Budget:
    """Deterministic budget of eq. 6 at one angle (output units, see module doc).

    ``systematic``: sum of the systematic terms at their bounds (worst sign);
    ``rss``: sqrt(sum sigma^2) of the random terms (their means are added to
    ``systematic`` as offsets); the total lies within ``systematic +- rss``
    (``total = systematic + rss`` is the figure to compare with a requirement).
    """

    systematic: Any
    rss: Any
    per_source: dict[str, Any] = field(default_factory=dict)

    @property
    def total(self):
        """systematic + rss."""
        return self.systematic + self.rss


def budget(sources: Sequence[ErrorSource], mechanism=None, phi=0.0, **kwargs) -> Budget:
    """Eq. 6 for ``sources``: systematic terms at their bound, random terms by their sd.

    ``kwargs`` (p, i_a, theta) as in :func:`contribution`. Each source's figure is the
    gain of :func:`contribution` (the same model path as the Monte Carlo) times its bound
    (systematic) or standard deviation (random).
    """
    systematic, sigmas, per = [], [], {}
    for s in sources:
        gain = m.fabs(contribution(s, 1.0, mechanism, phi, **kwargs))
        if s.kind == "systematic":
            systematic.append(gain * s.bound)
            per[s.name] = gain * s.bound
        else:
            # A random term's mean (e.g. the deformation F/K) is a fixed offset.
            systematic.append(gain * abs(s.mean))
            sigmas.append(gain * s.sd)
            per[s.name] = gain * s.sd
    total_sys, rss = transmission_error(systematic, sigmas)
    return Budget(total_sys, rss, per)
