"""Requirements on the drive as constraint blocks: efficiency and back-drivability, the
screw's buckling, yield, critical speed, DN, static safety and life, and the output
stiffness. Each names what it needs from the problem file when that is missing."""

from __future__ import annotations

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.models import screw_sizing as sizing
from optdesign.problem.drive import nut_stiffness_rule
from optdesign.problem.objectives import ConstraintBlock


def _need(value, what: str, field: str):
    if value is None:
        raise ProblemError(f"{field}: needs {what}")
    return value


def _nut_text(q) -> str:
    spec = q.problem.spec
    rule = nut_stiffness_rule(spec)
    if spec.screw.catalogue is None:
        return "as given" if spec.screw.nut_stiffness is not None else "rigid"
    if rule == "table":
        return "the catalogue's table value"
    if rule == "preload":
        return f"HIWIN F 3.34 at a preload of {spec.screw.nut_preload:g} Ca"
    load = (
        "the duty cycle's mean load"
        if spec.requirements.stiffness_load == "duty-mean"
        else "the hinge moment's nut force"
    )
    return f"HIWIN F 3.35 at {load}"


def drive_blocks(q, labels: list[str]) -> list[ConstraintBlock]:
    """Blocks of the drive requirements of ``q``'s problem (none when it asks for none)."""
    spec = q.problem.spec
    req, screw = spec.requirements, spec.screw
    out: list[ConstraintBlock] = []
    if req.efficiency_min is not None:
        out.append(
            ConstraintBlock(
                "efficiency",
                q.drive_efficiency,
                req.efficiency_min,
                None,
                [""],
                "",
                "forward efficiency of screw and gear",
            )
        )
    if req.back_drive is not None:
        _need(screw, "a [screw] section (its type, friction and size)", "requirements.back_drive")
        lo, hi = (0.0, None) if req.back_drive == "required" else (None, 0.0)
        text = "back-drivable" if req.back_drive == "required" else "self-locking"
        out.append(
            ConstraintBlock(
                "back_drive",
                q.efficiency_back,
                lo,
                hi,
                [""],
                "",
                f"back-driving efficiency ({text})",
            )
        )
    if screw is None:
        needs_screw = {
            "critical_speed": req.critical_speed,
            "dn_max": req.dn_max is not None,
            "static_safety_min": req.static_safety_min is not None,
            "life_min": req.life_min is not None,
            "stiffness_min": req.stiffness_min is not None,
        }
        for name, asked in needs_screw.items():
            if asked:
                raise ProblemError(
                    f"requirements.{name}: needs a [screw] section (its size, catalogue "
                    "and mounting)"
                )
        return out
    data = q.screw
    F = m.fabs(q.nut_force)
    if data is not None and data.on_catalogue is not None:
        # the NumPy check of a design: a (d0, p) pair the catalogue lacks is not a screw
        out.append(
            ConstraintBlock(
                "screw_catalogue_membership",
                data.on_catalogue,
                1.0,
                None,
                [""],
                "",
                "(d0, p) is a screw of the catalogue",
            )
        )
    if screw.length is not None and screw.check_buckling:
        rule = screw.mounting_factors
        P1 = sizing.buckling_load(data.d1, screw.length, screw.mounting, rule=rule)
        eta2 = sizing.BUCKLING_FACTORS[rule][screw.mounting]
        out.append(
            ConstraintBlock(
                "screw_buckling",
                F / P1,
                None,
                1.0,
                labels,
                "",
                f"nut force / buckling load ({screw.mounting}, {rule} factor eta_2 = {eta2:.4g})",
            )
        )
    if screw.check_yield and data.d1 is not None:
        out.append(
            ConstraintBlock(
                "screw_yield",
                F / sizing.yield_load(data.d1),
                None,
                1.0,
                labels,
                "",
                "nut force / permissible shaft load",
            )
        )
    if req.critical_speed:
        length = _need(
            screw.length,
            "screw.length (the distance between the supports)",
            "requirements.critical_speed",
        )
        rule = screw.mounting_factors
        N1 = sizing.critical_speed(data.d1, length, screw.mounting, rule)
        lam2 = sizing.CRITICAL_SPEED_FACTORS[rule][screw.mounting]
        out.append(
            ConstraintBlock(
                "critical_speed",
                q.screw_speed / N1,
                None,
                1.0,
                labels,
                "",
                f"screw speed / critical speed ({screw.mounting}, {rule} factor "
                f"lambda_2 = {lam2:.4g})",
            )
        )
    if req.dn_max is not None:
        d0 = _need(data.d0, "the screw's diameter d0 (a variable)", "requirements.dn_max")
        grade = req.dn_max if isinstance(req.dn_max, str) else None
        diameter, limit = sizing.dn_rule(req.dn_rule, grade)
        limit = float(req.dn_max) if limit is None else limit
        # the ball-centre diameter is the thread's mean diameter d_m (= d0 for the shipped
        # catalogue, which prints no ball-circle diameter)
        d = d0 if diameter == "nominal" else data.d_m
        symbol = "d0" if diameter == "nominal" else "d_m"
        what = f"{grade} " if grade else ""
        out.append(
            ConstraintBlock(
                "dn",
                d * q.screw_speed,
                None,
                limit,
                labels,
                "mm/min",
                f"{symbol} x screw speed (DN value; rule {req.dn_rule}: {what}limit "
                f"{limit:,.0f} on the {diameter} diameter)",
            )
        )
    if req.static_safety_min is not None:
        C0a = _need(
            data.C0a,
            'a catalogue screw ([screw] catalogue = "HIWIN")',
            "requirements.static_safety_min",
        )
        out.append(
            ConstraintBlock(
                "static_safety",
                F * req.static_safety_min / C0a,
                None,
                1.0,
                labels,
                "",
                "f_s x nut force / static rating C0a",
            )
        )
    if req.life_min is not None:
        _need(data.Ca, 'a catalogue screw ([screw] catalogue = "HIWIN")', "requirements.life_min")
        out.append(
            ConstraintBlock(
                "life",
                q.life_hours,
                req.life_min,
                None,
                [""],
                "h",
                f"rated life L10 over the duty cycle (f_w = {req.f_w:g}; HIWIN f_p: 1.1-1.2 "
                "without impact, 1.3-1.8 normal, 2-3 impact and vibration)",
            )
        )
    if req.stiffness_min is not None:
        out.append(
            ConstraintBlock(
                "stiffness",
                q.output_compliance * req.stiffness_min,
                None,
                1.0,
                labels,
                "",
                f"required stiffness / stiffness at the output (nut: {_nut_text(q)})",
            )
        )
    return out
