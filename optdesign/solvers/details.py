"""The details of a result beyond its common fields: a map from formulation name to that
formulation's own typed record, the comparison with a reference design, and what a GP
back-end reports (its dual and timing).

Each formulation keeps its record in its own package (``optdesign.formulations.<name>.
details``) and stores it as ``result.details[name]``; ``result.details.<name>`` reads the
same record (None when the result has none). ``result.json`` writes them under
``"extra"`` with the keys earlier releases wrote (``extra.catalogue.items``,
``extra.gp_timing``, ``extra.risk_label``...), so scripts reading result files see the
same keys and values. These are plain records: they import nothing from the layers
above.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Any, Protocol


def fields_json(record: Any, omit_none: tuple[str, ...] = ()) -> dict[str, Any]:
    """The record's fields as a dict, in declaration order; those of ``omit_none`` only
    when set (a key that older files have only in some cases)."""
    out: dict[str, Any] = {}
    for f in fields(record):
        value = getattr(record, f.name)
        if value is None and f.name in omit_none:
            continue
        out[f.name] = asdict(value) if hasattr(value, "__dataclass_fields__") else value
    return out


@dataclass
class GPTiming:
    """Where a GP solve spent its time (seconds; None: not measured)."""

    build_s: float | None = None
    compile_s: float | None = None
    solver_s: float | None = None
    total_s: float | None = None
    certificate_s: float | None = None
    trace_s: float | None = None

    def to_json(self) -> dict[str, Any]:
        return fields_json(self, tuple(f.name for f in fields(self)))


@dataclass
class GPDual:
    """The GP's dual: whether the dual bound's minimisation converged, and the multipliers
    of the active rows (row label -> multiplier)."""

    dual_bound_converged: bool
    multipliers: dict[str, float] = field(default_factory=dict)


@dataclass
class GPBackEndDetails:
    """What a GP back-end reports beyond the common fields: the dual (with the active
    rows' multipliers) and where the time went. The GP formulation extends it with the
    program's size and the exact NLP (``optdesign.formulations.gp.details.GPDetails``)."""

    dual: GPDual | None = None
    timing: GPTiming | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.dual is not None:
            out["gp_dual"] = asdict(self.dual)
        if self.timing is not None:
            out["gp_timing"] = self.timing.to_json()
        return out

    def extra(self) -> dict[str, Any]:
        """Its keys in ``result.json``'s ``"extra"`` object (at its top level)."""
        return self.to_json()


@dataclass
class ReferenceComparison:
    """A reference design (the file's ``[reference]``) against the optimum, on the NumPy
    path of the same models (:func:`optdesign.formulations.reference.compare_reference`).

    Attributes
    ----------
    label
        The reference's name.
    design
        Its free variables.
    quantities
        Per quantity (ripple, backlash, ratio band...): (reference, optimum).
    reference_violation, reference_violated
        The reference's largest relative violation and the requirements it violates.
    optimum_violation
        The optimum's largest relative violation.
    optimum_design
        The optimum's free variables.
    """

    label: str
    design: dict[str, float]
    quantities: dict[str, tuple[float, float]]
    reference_violation: float
    reference_violated: list[str]
    optimum_violation: float
    optimum_design: dict[str, float] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


class FormulationDetails(Protocol):
    """A formulation's typed record: ``extra()`` gives its keys in ``result.json``'s
    ``"extra"`` object."""

    def extra(self) -> dict[str, Any]: ...


#: Details' own attributes; any other attribute name is a formulation's record.
_OWN = ("records", "reference", "fallback")


class Details:
    """The details a result has beyond the common fields.

    Parameters
    ----------
    records
        Formulation name -> its typed record (``details["catalogue"]``, or
        ``details.catalogue``: None when the result has none).
    reference
        The comparison with the file's reference design.
    fallback
        Why an epsilon point was solved again by Ipopt ("" when it was not).
    **by_name
        Records given by formulation name (``Details(gp=GPDetails(...))``).
    """

    records: dict[str, FormulationDetails]
    reference: ReferenceComparison | None
    fallback: str

    def __init__(
        self,
        records: dict[str, FormulationDetails] | None = None,
        *,
        reference: ReferenceComparison | None = None,
        fallback: str = "",
        **by_name: FormulationDetails,
    ) -> None:
        object.__setattr__(self, "records", {**(records or {}), **by_name})
        object.__setattr__(self, "reference", reference)
        object.__setattr__(self, "fallback", fallback)

    def __getattr__(self, name: str) -> Any:
        # only reached for names that are not attributes: a formulation's record
        if name.startswith("_") or "records" not in self.__dict__:
            raise AttributeError(name)
        return self.__dict__["records"].get(name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _OWN:
            object.__setattr__(self, name, value)
        else:
            self.records[name] = value

    def __getitem__(self, name: str) -> FormulationDetails:
        return self.records[name]

    def __setitem__(self, name: str, record: FormulationDetails) -> None:
        self.records[name] = record

    def __contains__(self, name: object) -> bool:
        return name in self.records

    def get(self, name: str, default: Any = None) -> Any:
        """The record of formulation ``name`` (``default`` when the result has none)."""
        return self.records.get(name, default)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Details):
            return NotImplemented
        return (self.records, self.reference, self.fallback) == (
            other.records,
            other.reference,
            other.fallback,
        )

    def __repr__(self) -> str:
        return (
            f"Details(records={self.records!r}, reference={self.reference!r}, "
            f"fallback={self.fallback!r})"
        )

    def to_json(self) -> dict[str, Any]:
        """The ``"extra"`` object of ``result.json`` (the keys earlier releases wrote):
        the formulations' records, then the fallback and the reference."""
        out: dict[str, Any] = {}
        for record in self.records.values():
            out.update(record.extra())
        if self.fallback:
            out["fallback"] = self.fallback
        if self.reference is not None:
            out["reference"] = self.reference.to_json()
        return out
