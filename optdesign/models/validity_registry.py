"""Every model's range of validity, collected from the models' own declarations.

Each module of :mod:`optdesign.models` declares its ranges once, as ``VALIDITY`` (a tuple
of :class:`~optdesign.models.validity.Validity`); :func:`declared_ranges` gathers them by
name for the documentation's table, the tests and whoever wants to read them. A record
two models share (an elastic modulus) appears once.
"""

from __future__ import annotations

import importlib

from optdesign.models.validity import Validity

#: The model modules, each with its ``VALIDITY``.
MODEL_MODULES = (
    "validity",
    "clearance",
    "hertz_line",
    "pin_contact",
    "lug_flexibility",
    "loads",
    "iso286",
    "fit_formulas",
    "crank_slider",
    "fork",
    "ratio",
    "screw",
    "screw_efficiency",
    "screw_sizing",
    "screw_catalogue",
    "stiffness",
    "lock",
    "roller_screw",
    "error_budget",
    "hertz_point",
    "thread_surface",
    "differential_geometry",
    "prsm",
    "motor",
    "motor_limits",
    "motor_catalogue",
    "describing_function",
    "harmonic_balance",
    "loop_plant",
    "loop_linear",
    "loop_backlash",
    "loop_references",
    "loop_simulation",
    "loop_path",
)


def ranges_of(module: str) -> tuple[Validity, ...]:
    """The ranges the model module ``optdesign.models.<module>`` declares."""
    return tuple(importlib.import_module(f"optdesign.models.{module}").VALIDITY)


def declared_ranges() -> dict[str, Validity]:
    """Every declared range by name (each record once), in the order of
    :data:`MODEL_MODULES`."""
    out: dict[str, Validity] = {}
    for module in MODEL_MODULES:
        for record in ranges_of(module):
            known = out.get(record.name)
            if known is not None and known is not record:
                raise ValueError(f"validity {record.name!r} is declared twice, differently")
            out[record.name] = record
    return out
