"""The requirements of a problem as constraint blocks of one design's quantities.

Generic requirements (every mechanism) are written here from the quantities; the
mechanism adds its assembly rows and its own requirements (:meth:`Mechanism.
requirement_rows`); user constraints (:class:`ConstraintInfo`) come last. Nothing here
names a mechanism.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.mechanisms.base import Rows
from optdesign.models.loads import pin_bearing_pressure, pin_shear_stress
from optdesign.problem.drive_requirements import drive_blocks
from optdesign.problem.loop_requirements import loop_blocks
from optdesign.problem.motor_drive import motor_blocks
from optdesign.problem.objectives import ConstraintBlock, ConstraintInfo
from optdesign.user_code import quantity_of


def _block(rows: Rows, labels: list[str], physical: bool = False) -> ConstraintBlock:
    return ConstraintBlock(
        rows.name,
        rows.expr,
        rows.lower,
        rows.upper,
        labels,
        rows.unit,
        rows.description,
        rows.display,
        rows.display_unit,
        physical=physical,
    )


def requirement_blocks(
    q, user: Sequence[ConstraintInfo] = (), backlash=None
) -> list[ConstraintBlock]:
    """Every constraint block of the design whose quantities are ``q``.

    ``backlash`` is the worst-case backlash expression when the problem has pins (the
    objective term, so the requirement and the objective share it).
    """
    req = q.requirements
    labels = q.labels
    mech = q.mechanism
    phi = q.phi
    blocks: list[ConstraintBlock] = [
        # The linkage must not pass a dead point inside the stroke: positive ratio.
        ConstraintBlock(
            "ratio_positive", q.ratio, 1.0, None, labels, "", "ratio i(phi) >= 1", physical=True
        )
    ]
    blocks += [_block(r, labels, True) for r in q.call_mechanism("assembly_rows", phi)]
    for name in type(mech).requirements:
        value = getattr(req, name)
        if value is not None:
            rows = q.call_mechanism("requirement_rows", name, value, phi)
            blocks += [_block(r, labels) for r in rows]
    if req.mean_ratio is not None:
        blocks.append(
            ConstraintBlock(
                "mean_ratio",
                m.grid_mean(q.ratio),
                req.mean_ratio.min,
                req.mean_ratio.max,
                [""],
                "",
                "mean ratio over the stroke",
            )
        )
    if req.nut_travel_max is not None:
        blocks.append(
            ConstraintBlock(
                "nut_travel", q.nut_travel, None, req.nut_travel_max, [""], "mm", "nut travel"
            )
        )
    if q.pin is not None:
        blocks += _pin_blocks(q, labels, backlash)
    if req.screw is not None:
        blocks += _screw_blocks(q, labels)
    blocks += drive_blocks(q, labels)
    blocks += motor_blocks(q, labels)
    blocks += loop_blocks(q, labels)
    if req.lock is not None and req.lock.force_max is not None:
        blocks.append(
            ConstraintBlock(
                "lock_force",
                q.lock_force,
                None,
                req.lock.force_max,
                labels,
                "N",
                "magnet force of the motor-shaft lock",
            )
        )
    if req.motor_torque_max is not None:
        blocks.append(
            ConstraintBlock(
                "motor_torque",
                q.motor_torque,
                None,
                req.motor_torque_max,
                labels,
                "N*mm",
                "motor torque",
            )
        )
    for c in user:
        blocks.append(user_block(c, q))
    return blocks


def _pin_blocks(q, labels, backlash) -> list[ConstraintBlock]:
    req = q.requirements
    pin = q.pin
    out = []
    if req.pin_bearing_pressure_max is not None or req.pin_shear_stress_max is not None:
        F = q.pin_force
        if req.pin_bearing_pressure_max is not None:
            out.append(
                ConstraintBlock(
                    "pin_bearing_pressure",
                    pin_bearing_pressure(F, pin.d, pin.L),
                    None,
                    req.pin_bearing_pressure_max,
                    labels,
                    "MPa",
                    "pin bearing pressure F/(d L)",
                )
            )
        if req.pin_shear_stress_max is not None:
            planes = req.pin_shear_planes or type(q.mechanism).pin_shear_planes
            out.append(
                ConstraintBlock(
                    "pin_shear_stress",
                    pin_shear_stress(F, pin.d, planes),
                    None,
                    req.pin_shear_stress_max,
                    labels,
                    "MPa",
                    f"pin shear stress ({'double' if planes == 2 else 'single'} shear)",
                )
            )
    if req.pin_contact_pressure_max is not None:
        out.append(
            ConstraintBlock(
                "pin_contact_pressure",
                pin.contact_pressure(m.fabs(q.pin_force)),
                None,
                req.pin_contact_pressure_max,
                labels,
                "MPa",
                f"largest contact pressure of the pin ({req.pin_contact} model)",
            )
        )
    if req.backlash_max is not None:
        out.append(
            ConstraintBlock(
                "backlash",
                backlash,
                None,
                float(np.degrees(req.backlash_max)),
                labels,
                "deg",
                "worst-case output backlash",
            )
        )
    return out


def _screw_blocks(q, labels) -> list[ConstraintBlock]:
    """Buckling and yield of the screw shaft under the nut force at every angle."""
    from optdesign.models.screw_sizing import buckling_load, yield_load

    sz = q.requirements.screw
    F_a = q.nut_force
    out = []
    if sz.buckling_length is not None:
        P1 = buckling_load(sz.root_diameter, sz.buckling_length, sz.mounting)
        out.append(
            ConstraintBlock(
                "screw_buckling",
                F_a,
                None,
                float(P1),
                labels,
                "N",
                f"nut force <= buckling load ({sz.mounting})",
            )
        )
    if sz.check_yield:
        out.append(
            ConstraintBlock(
                "screw_yield",
                F_a,
                None,
                float(yield_load(sz.root_diameter)),
                labels,
                "N",
                "nut force <= permissible shaft load",
            )
        )
    return out


def user_block(c: ConstraintInfo, q) -> ConstraintBlock:
    """The block of a user constraint; a function that fails, or returns a value no
    formulation can use, is reported naming it, its file and line."""
    expr: Any = quantity_of(c.fn, q, f"constraint {c.name!r}", c.over == "stroke")
    labels = q.labels if c.over == "stroke" else [""]
    return ConstraintBlock(c.name, expr, c.lower, c.upper, labels, c.unit, c.description or c.name)


def physical_conditions(problem: Any) -> frozenset[str]:
    """The names of ``problem``'s constraint blocks that are conditions of the physics
    (:attr:`ConstraintBlock.physical`), read at its start design (NumPy path: only the
    declarations matter)."""
    design = problem.design_dict(problem.start()[None, :])
    with np.errstate(all="ignore"):
        blocks = problem.expressions(design).constraints
    return frozenset(b.name for b in blocks if b.physical)
