"""Ball-screw catalogue data: nominal diameter x lead with load ratings, root diameter,
ball diameter and nut rigidity, from one public catalogue (package data).

Source (the CSV's header repeats it): HIWIN GmbH, *Ballscrews & Accessories*,
BS-08-2-EN-1704-K (2017), ground ball screws, Table 6.6 (flange single nut FSI, pp. 52-53)
and Table 6.4 (DIN single nut FSC, pp. 48-49), rows with d0 8-40 mm and leads 2-20 mm.
Values are transcribed as printed. In that catalogue C0a > Ca on every row, and Ca grows
with d0 at equal lead, ball and circuits with one exception the CSV marks (R20-2T4-FSI,
printed with a higher Ca than R25-2T4-FSI and a higher rigidity than R20-2T6-FSI).

Units in the records: mm, N, N/mm (the catalogue's N/um x 1000), kg.

Validity
--------
items : the rows of the CSV (d0 8-40 mm, leads 2-20 mm)
    Catalogue data hold for the items printed; a (d0, p) pair the catalogue does not
    list is no screw (refused by the lookups, and by the problem when read).
"""

from __future__ import annotations

import csv
import functools
import io
import re
from dataclasses import dataclass
from importlib import resources

from optdesign.errors import InputError
from optdesign.models.validity import Validity

CATALOGUE_ITEMS = Validity(
    "screw_catalogue.diameter",
    "ball-screw catalogue",
    "nominal diameter d0",
    8.0,
    40.0,
    "mm",
    "the catalogue's data hold for the items it prints (d0 8-40 mm, leads 2-20 mm)",
    checked=("call", "file"),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (CATALOGUE_ITEMS,)


#: The catalogue every record comes from.
CATALOGUE_SOURCE = (
    "HIWIN GmbH, Ballscrews & Accessories, BS-08-2-EN-1704-K (2017), "
    "Table 6.4 (pp. 48-49) and Table 6.6 (pp. 52-53)"
)

_RESOURCE = "data/ball_screws.csv"


@dataclass(frozen=True)
class BallScrew:
    """One nut of the catalogue on its shaft (units: mm, N, N/mm, kg).

    Attributes
    ----------
    id
        Designation and ball diameter, unique (``"R32-10K5-FSC/4.763"``).
    designation
        The catalogue's article number.
    nut
        Nut type, ``"FSI"`` (internal single recirculation) or ``"FSC"`` (end-cap total
        recirculation, DIN 69051-5).
    circuits
        Number of recirculations (the digit after T/K in the designation).
    d0, p, ball_d, d1
        Nominal diameter, lead, ball diameter, core (root) diameter of the shaft (mm).
    K_nut
        Nut rigidity (N/mm), calculated without preload for an axial load of 0.3 Ca.
    Ca, C0a
        Basic dynamic and static axial load ratings (N).
    nut_mass
        Nut mass (kg) where printed (FSI), else None.
    table, page
        Where in the catalogue.
    note
        Remark on the printed values, if any.
    """

    id: str
    designation: str
    nut: str
    circuits: int
    d0: float
    p: float
    ball_d: float
    d1: float
    K_nut: float
    Ca: float
    C0a: float
    nut_mass: float | None
    table: str
    page: int
    note: str = ""

    @property
    def source(self) -> str:
        """Citation of this row."""
        return f"HIWIN BS-08-2-EN-1704-K, Table {self.table}, p. {self.page}, {self.designation}"


_DESIGNATION = re.compile(r"^R(?P<d0>\d+)-(?P<p>[\d.]+)(?P<rec>[TK])(?P<n>\d)-(?P<nut>[A-Z]+)$")


def _parse(text: str) -> tuple[BallScrew, ...]:
    rows = csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#"))
    out = []
    for row in rows:
        match = _DESIGNATION.match(row["designation"])
        if match is None:
            raise InputError(
                "designation", f"unparsed catalogue designation {row['designation']!r}"
            )
        mass = row["nut_mass_kg"].strip()
        out.append(
            BallScrew(
                id=row["id"],
                designation=row["designation"],
                nut=match["nut"],
                circuits=int(match["n"]),
                d0=float(row["d0"]),
                p=float(row["p"]),
                ball_d=float(row["ball_d"]),
                d1=float(row["d1"]),
                K_nut=1e3 * float(row["rigidity_N_per_um"]),
                Ca=float(row["Ca"]),
                C0a=float(row["C0a"]),
                nut_mass=float(mass) if mass else None,
                table=row["table"],
                page=int(row["page"]),
                note=row["note"].strip(),
            )
        )
    return tuple(out)


@functools.cache
def load_ball_screws() -> tuple[BallScrew, ...]:
    """All catalogue rows, in the catalogue's order (read once from the package data)."""
    text = resources.files("optdesign").joinpath(_RESOURCE).read_text(encoding="utf-8")
    return _parse(text)


def find(d0: float | None = None, p: float | None = None, nut: str | None = None):
    """Rows matching a nominal diameter, a lead and/or a nut type (exact values, mm).

    Returns a tuple (empty if nothing matches); ``find()`` returns every row.
    """
    return tuple(
        r
        for r in load_ball_screws()
        if (d0 is None or r.d0 == d0) and (p is None or r.p == p) and (nut is None or r.nut == nut)
    )


def by_id(row_id: str) -> BallScrew:
    """The row with this id (designation/ball diameter); InputError naming ``id`` if none."""
    for r in load_ball_screws():
        if r.id == row_id:
            return r
    raise InputError("id", f"{row_id!r} is not in the catalogue ({CATALOGUE_SOURCE})")


def sizes() -> tuple[tuple[float, float], ...]:
    """The distinct (d0, p) pairs, sorted."""
    return tuple(sorted({(r.d0, r.p) for r in load_ball_screws()}))
