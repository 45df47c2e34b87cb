"""Crank-slider mechanism: arm R, rod l, offset n, neutral angle phi0 ([D17] Fig. 2)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from optdesign import math as m
from optdesign.mechanisms.base import Mechanism, RequirementInfo, Rows, Sketch, VariableInfo
from optdesign.mechanisms.joints import Joint, PinJoint
from optdesign.mechanisms.registry import register_mechanism
from optdesign.models import crank_slider as cs
from optdesign.models.impossibility import ANGLE_TOL, Impossibility, NutVelocityBounds
from optdesign.models.impossibility import degrees_text as _deg
from optdesign.models.loads import force_from_rate

#: sqrt guard of the assembly condition on the solver path (mm^2): keeps iterates that
#: leave the assembly region finite; the assembly-margin requirement keeps solutions out.
ASSEMBLY_FLOOR = 1e-6


@register_mechanism
class CrankSlider(Mechanism):
    """Crank-slider linkage driven by a ball screw.

    The arm OB (length R) turns with the output; the rod BC (length l) joins it to the
    nut pin C, which slides on a line parallel to the screw axis at distance n from O.

    Variables: R (arm), l (rod), n (offset), phi0 (neutral angle, the arm sits at
    phi0 + phi) and the drive's p, i_a.
    """

    name = "crank_slider"
    title = "crank-slider"
    variables: ClassVar = {
        "R": VariableInfo("length", "arm length"),
        "l": VariableInfo("length", "rod length"),
        "n": VariableInfo("length", "offset of the screw axis", positive=False),
        "phi0": VariableInfo("angle", "neutral angle", positive=False, default=0.0),
    }
    requirements: ClassVar = {
        "transmission_angle": RequirementInfo(
            "band",
            "angle",
            "angle between arm and rod at B (90 deg is ideal)",
            valid=(0.0, np.pi),
        ),
        "rod_inclination_max": RequirementInfo(
            "value",
            "angle",
            "largest inclination of the rod to the screw axis",
            valid=(0.0, np.pi / 2),
        ),
        "assembly_margin_min": RequirementInfo(
            "value",
            "dimensionless",
            "smallest (l^2 - u^2)/l^2 over the stroke (distance from the toggle position)",
            default=0.01,
            valid=(0.0, 1.0),
        ),
    }
    fixed_clearances: ClassVar = {
        "A": ("length", "screw bearings (axial)"),
        "B": ("length", "screw/nut (axial)"),
        "C": ("length", "nut slide, across the screw axis"),
        "O": ("angle", "output shaft"),
    }
    pin_shear_planes = 2
    size_description = "linkage size R + l"
    bench_families: ClassVar = {
        "cs_ripple": ("ripple",),
        "cs_backlash": ("backlash",),
        "cs_size": ("size",),
        "cs_torque": ("motor_torque",),
        "cs_front": ("ripple", "backlash"),
    }

    @property
    def floor(self) -> float | None:
        return ASSEMBLY_FLOOR if self.guarded else None

    def _args(self):
        return self.R, self.l, self.n

    # --- kinematics: closed forms ([D17] eq. 2 and its derivative) -------------------
    def nut_position(self, phi):
        return cs.nut_position(*self._args(), phi, self.phi0, self.floor)

    def nut_velocity(self, phi):
        return cs.nut_velocity(*self._args(), phi, self.phi0, self.floor)

    def assembly_margin(self, phi):
        return cs.assembly_margin(*self._args(), phi, self.phi0)

    def rod_run(self, phi):
        """Rod extent along the screw axis, sqrt(l^2 - u^2) (mm)."""
        return cs.rod_run(*self._args(), phi, self.phi0, self.floor)

    def rod_length_rate(self, phi):
        """d|BC|/dphi with the nut held (mm/rad)."""
        return cs.rod_length_rate(*self._args(), phi, self.phi0, self.floor)

    def transmission_angle(self, phi):
        """Angle between arm and rod at B (rad)."""
        return cs.transmission_angle(*self._args(), phi, self.phi0, self.floor)

    def rod_inclination(self, phi):
        """Signed inclination of the rod to the screw axis (rad)."""
        return cs.rod_inclination(*self._args(), phi, self.phi0, self.floor)

    def pin_positions(self, phi):
        """(B, C) coordinates of the arm pin and nut pin, each a pair (x, y) in mm."""
        a = cs.arm_angle(phi, self.phi0)
        B = (self.R * m.sin(a), self.R * m.cos(a))
        C = (self.nut_position(phi), self.n + 0.0 * phi)
        return B, C

    # --- loads and clearance ---------------------------------------------------------------
    def rod_force(self, phi, M_h):
        """Axial force of the rod (N), M_h / (d|BC|/dphi)."""
        return force_from_rate(M_h, self.rod_length_rate(phi))

    def sensitivity_rod_length(self, phi):
        """Output rotation per unit change of the effective rod length (rad/mm)."""
        return cs.sensitivity_rod_length(*self._args(), phi, self.phi0, self.floor)

    def sensitivity_lateral(self, phi):
        """Output rotation per unit clearance of the nut slide across the screw (rad/mm)."""
        return cs.sensitivity_lateral(*self._args(), phi, self.phi0, self.floor)

    def joints(self, phi, M_h, pin: PinJoint | None = None) -> list[Joint]:
        """Seed 000 Fig. 8: A (screw bearings) and B (screw/nut) preloaded, C (nut slide)
        small, O (output shaft) ~0, D and E the two rod pins (the main source)."""
        axial = self.sensitivity_axial(phi)
        rod = self.sensitivity_rod_length(phi)
        F_rod = self.rod_force(phi, M_h)
        return [
            Joint("A screw bearings", "A", sensitivity=axial),
            Joint("B screw/nut", "B", sensitivity=axial),
            Joint("C nut slide", "C", sensitivity=self.sensitivity_lateral(phi)),
            Joint("O output shaft", "O", angular=True),
            Joint("D rod pin (arm)", "", sensitivity=rod, force=F_rod, pin=pin),
            Joint("E rod pin (nut)", "", sensitivity=rod, force=F_rod, pin=pin),
        ]

    def pin_force(self, phi, M_h):
        """Both rod pins carry the rod force."""
        return self.rod_force(phi, M_h)

    # --- requirements ----------------------------------------------------------------------
    @classmethod
    def impossible(cls, stroke, requirements, bounds) -> list[Impossibility]:
        """The transmission angle's sweep. Wherever the ratio is positive (the nut
        velocity R cos(a + beta) / cos(beta) > 0, beta the rod's inclination), cos(mu) =
        sin(a + beta) gives mu = 90 deg - (phi0 + phi) - beta exactly. Over the stroke mu
        so changes by the stroke less the change of beta: at least the stroke less twice
        the rod's inclination limit (90 deg without one), whatever R, l and n. Two proofs
        follow: that sweep exceeds the transmission band, or the neutral angle phi0 that
        puts mu inside the band at both ends of the stroke lies outside its bounds."""
        lo, hi = stroke
        band = requirements.get("transmission_angle")
        mu_lo = band.min if band is not None and band.min is not None else 0.0
        mu_hi = band.max if band is not None and band.max is not None else np.pi
        tilt = requirements.get("rod_inclination_max")
        beta = np.pi / 2 if tilt is None else float(tilt)
        named = ("deflection",) + ("transmission_angle",) * (band is not None)
        named += ("rod_inclination_max",) * (tilt is not None)
        width, sweep = mu_hi - mu_lo, (hi - lo) - 2 * beta
        if sweep > width + ANGLE_TOL:
            remedies = [f"a stroke of at most {_deg(width + 2 * beta)} deg"]
            if sweep < np.pi:
                remedies.append(f"a transmission band at least {_deg(sweep)} deg wide")
            if (hi - lo - width) / 2 < np.pi / 2:
                remedies.append(
                    f"rod_inclination_max of at least {_deg((hi - lo - width) / 2)} deg"
                )
            reason = (
                "the transmission angle of a crank-slider is 90 deg - (phi0 + phi) - (the "
                "rod's inclination) wherever its ratio is positive, so over the stroke of "
                f"{_deg(hi - lo)} deg it sweeps at least {_deg(hi - lo)} - 2 x {_deg(beta)} = "
                f"{_deg(sweep)} deg, more than the {_deg(width)} deg between {_deg(mu_lo)} and "
                f"{_deg(mu_hi)} deg that it may take"
            )
            return [Impossibility(named, reason, tuple(remedies))]
        # mu(lo) <= mu_hi and mu(hi) >= mu_lo, with |beta| <= its limit, bound phi0
        window = (np.pi / 2 - lo - beta - mu_hi, np.pi / 2 - hi + beta - mu_lo)
        p_lo, p_hi = bounds["phi0"]
        if p_hi < window[0] - ANGLE_TOL or p_lo > window[1] + ANGLE_TOL:
            reason = (
                "the transmission angle 90 deg - (phi0 + phi) - (the rod's inclination) "
                f"stays between {_deg(mu_lo)} and {_deg(mu_hi)} deg at both ends of the stroke "
                f"only with phi0 between {_deg(window[0])} and {_deg(window[1])} deg, and its "
                f"bounds are {_deg(p_lo)} to {_deg(p_hi)} deg"
            )
            remedy = f"bounds of phi0 that reach {_deg(window[0])} to {_deg(window[1])} deg"
            return [Impossibility(("variables.phi0", *named), reason, (remedy,))]
        return []

    @classmethod
    def nut_velocity_bounds(cls, stroke, requirements, bounds) -> NutVelocityBounds | None:
        """The nut velocity is R cos(a + beta) / cos(beta) (beta the rod's inclination), so
        |dx/dphi| <= R / cos(beta) at every angle: at most the arm's upper bound over the
        cosine of the inclination limit, or of the assembly margin's (cos^2 beta = the
        margin (l^2 - u^2)/l^2). No lower bound: it tends to 0 at a dead point."""
        R_hi = bounds["R"][1]
        tilt = requirements.get("rod_inclination_max")
        margin = requirements.get("assembly_margin_min")
        cosines = {}
        if tilt is not None and float(tilt) < np.pi / 2:
            cosines["rod_inclination_max"] = float(np.cos(float(tilt)))
        if margin is not None and float(margin) > 0.0:
            cosines["assembly_margin_min"] = float(np.sqrt(float(margin)))
        if not cosines:
            return None
        name, cos_beta = max(cosines.items(), key=lambda kv: kv[1])
        upper = R_hi / cos_beta
        what = (
            f"cos(beta) >= cos({_deg(float(tilt))} deg)"
            if name == "rod_inclination_max"
            else f"cos(beta) >= sqrt({float(margin):g}), the assembly margin's floor"
        )
        reason = (
            "a crank-slider's nut velocity R cos(phi0 + phi + beta) / cos(beta) is at most "
            f"R / cos(beta) = {R_hi:.4g} / {cos_beta:.4g} = {upper:.4g} mm/rad (R <= "
            f"{R_hi:.4g} mm, {what})"
        )
        return NutVelocityBounds(0.0, upper, reason, ("variables.R", name))

    def requirement_rows(self, name: str, value: Any, phi) -> list[Rows]:
        R, l, n, phi0 = self.R, self.l, self.n, self.phi0
        if name == "assembly_margin_min":
            margin = cs.assembly_margin(R, l, n, phi, phi0) / l**2
            return [
                Rows(
                    "assembly_margin",
                    margin,
                    float(value),
                    None,
                    "",
                    "(l^2 - u^2)/l^2: the rod reaches the nut line",
                )
            ]
        if name == "transmission_angle":
            # cos is decreasing on [0, pi]: mu in [lo, hi] <=> cos mu in [cos hi, cos lo];
            # the cosine is smooth where arccos is not (solvers see the cosine).
            return [
                Rows(
                    "transmission_angle",
                    cs.transmission_angle_cos(R, l, n, phi, phi0, self.floor),
                    None if value.max is None else float(np.cos(value.max)),
                    None if value.min is None else float(np.cos(value.min)),
                    "",
                    "transmission angle",
                    display=_degrees_of_arccos,
                    display_unit="deg",
                )
            ]
        if name == "rod_inclination_max":
            # |atan2(u, s)| <= theta  <=>  |u|/l <= sin(theta)  (s > 0 on the branch)
            s_max = float(np.sin(value))
            return [
                Rows(
                    "rod_inclination",
                    cs.rod_rise(R, n, phi, phi0) / l,
                    -s_max,
                    s_max,
                    "",
                    "rod inclination to the screw axis",
                    display=_degrees_of_arcsin,
                    display_unit="deg",
                )
            ]
        return super().requirement_rows(name, value, phi)

    def size(self):
        return self.R + self.l

    # --- drawing ---------------------------------------------------------------------------
    def sketch(self, phi: float) -> Sketch:
        with np.errstate(invalid="ignore"):
            (bx, by), (cx, cy) = self.pin_positions(np.asarray(phi, dtype=float))
        B, C = (float(bx), float(by)), (float(cx), float(cy))
        n = float(self.n)
        return Sketch(
            links=[[(0.0, 0.0), B], [B, C]],
            pivots=[(0.0, 0.0)],
            slider=C,
            axis=((min(0.0, C[0]) - 0.5 * float(self.l), n), (max(0.0, C[0]) + 10.0, n)),
        )

    @classmethod
    def bench_template(cls) -> tuple[dict[str, Any], dict[str, Any]]:
        """Variables and requirements of the benchmark's crank-slider instances."""
        variables = {
            "R": {"lower": "30 mm", "upper": "120 mm"},
            "l": {"lower": "40 mm", "upper": "200 mm"},
            "n": {"lower": "0 mm", "upper": "150 mm"},
            "p": None,  # the screw lead, drawn by the benchmark, goes here
            "phi0": {"lower": "-0.6 rad", "upper": "0.6 rad"},
        }
        requirements = {
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "rod_inclination_max": "30 deg",
        }
        return variables, requirements


def _degrees_of_arccos(c):
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def _degrees_of_arcsin(s):
    return np.degrees(np.arcsin(np.clip(s, -1.0, 1.0)))
