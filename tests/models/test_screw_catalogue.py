"""Ball-screw catalogue data (HIWIN BS-08-2-EN-1704-K, ground nuts): loader and checks."""

import dataclasses
import itertools
import tomllib
from collections import defaultdict
from pathlib import Path

import pytest

from optdesign.errors import InputError
from optdesign.models import screw_catalogue as cat


def test_loader_reads_the_typed_frozen_rows():
    rows = cat.load_ball_screws()
    assert len(rows) == 50
    assert len({r.id for r in rows}) == len(rows)
    r = cat.by_id("R8-2.5T3-FSI/1.500")
    assert (r.d0, r.p, r.ball_d, r.d1) == (8.0, 2.5, 1.5, 6.65)
    assert (r.Ca, r.C0a, r.K_nut, r.nut_mass, r.circuits, r.nut) == (
        1700.0,
        2670.0,
        80e3,
        0.04,
        3,
        "FSI",
    )
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.Ca = 1.0  # type: ignore[misc]
    assert "Table 6.6, p. 52" in r.source
    with pytest.raises(InputError, match=r"^id"):
        cat.by_id("R99-1T1-FSI/1.000")
    assert all(8 <= d0 <= 40 and 2 <= p <= 20 for d0, p in cat.sizes())
    assert len(cat.sizes()) == 23  # distinct (d0, p) pairs; 50 nuts


@pytest.mark.parametrize(
    ("row_id", "printed"),
    [
        # (ball_d, d1, rigidity N/um, Ca, C0a) as printed in Table 6.6 (p. 52) / 6.4 (p. 48-49)
        ("R25-5T4-FSI/3.175", (3.175, 22.32, 370, 12_520, 30_850)),
        ("R32-10T4-FSI/6.350", (6.350, 26.91, 480, 32_520, 71_020)),
        ("R32-10K5-FSC/4.763", (4.763, 28.13, 860, 38_500, 108_900)),
        ("R40-20K4-FSC/6.350", (6.350, 34.91, 870, 51_300, 144_400)),
    ],
)
def test_rows_against_the_printed_tables(row_id, printed):
    r = cat.by_id(row_id)
    assert (r.ball_d, r.d1, r.K_nut / 1e3, r.Ca, r.C0a) == printed


def test_fsi_rows_match_the_cylindrical_rsi_table():
    # Table 6.8 (p. 56) prints the same nuts as cylindrical RSI nuts: ball, circuits,
    # rigidity K, Cdyn, C0. An independent printed copy of the FSI values.
    rsi = {
        "R16-5T3": (3.175, 3, 110, 7_310, 13_310),
        "R20-5T4": (3.175, 4, 270, 10_910, 23_560),
        "R25-5T4": (3.175, 4, 370, 12_520, 30_850),
        "R32-5T6": (3.175, 6, 630, 20_270, 61_620),
        "R32-10T4": (6.350, 4, 480, 32_520, 71_020),
        "R40-5T6": (3.175, 6, 740, 22_650, 79_190),
        "R40-10T3": (6.350, 3, 400, 29_590, 70_690),
    }
    for name, (ball, n, K, Ca, C0a) in rsi.items():
        (r,) = [x for x in cat.load_ball_screws() if x.designation == f"{name}-FSI"]
        assert (r.ball_d, r.circuits, r.K_nut / 1e3, r.Ca, r.C0a) == (ball, n, K, Ca, C0a)


def test_physical_sanity_of_every_row():
    for r in cat.load_ball_screws():
        assert r.C0a > r.Ca, r.id  # this catalogue: static rating above dynamic everywhere
        assert r.d1 < r.d0, r.id
        # the core diameter sits about one ball below d0 (0.80-1.03 ball diameters here): a
        # mistyped d1 or ball diameter shows up
        assert 0.75 * r.ball_d < r.d0 - r.d1 < 1.05 * r.ball_d, r.id
        assert 50e3 <= r.K_nut <= 1.2e6 and r.Ca > 1000


def test_ratings_grow_with_diameter_and_circuits_except_where_printed_otherwise():
    rows = cat.load_ball_screws()
    by_family = defaultdict(list)  # same nut, lead, ball and circuits: only d0 differs
    for r in rows:
        by_family[(r.nut, r.p, r.ball_d, r.circuits)].append(r)
    falls = []
    for family in by_family.values():
        family.sort(key=lambda r: r.d0)
        falls += [(a.id, b.id) for a, b in itertools.pairwise(family) if b.Ca <= a.Ca]
    assert falls == [("R20-2T4-FSI/1.500", "R25-2T4-FSI/1.500")]
    # more circuits on the same shaft: higher Ca and C0a always, higher rigidity except once
    by_size = defaultdict(list)
    for r in rows:
        by_size[(r.nut, r.d0, r.p, r.ball_d)].append(r)
    stiff_falls = []
    for size in by_size.values():
        size.sort(key=lambda r: r.circuits)
        for a, b in itertools.pairwise(size):
            assert b.Ca > a.Ca and b.C0a > a.C0a
            if b.K_nut <= a.K_nut:
                stiff_falls.append((a.id, b.id))
    assert stiff_falls == [("R20-2T4-FSI/1.500", "R20-2T6-FSI/1.500")]
    assert "as printed" in cat.by_id("R20-2T4-FSI/1.500").note


def test_find_and_package_data_is_shipped():
    assert {r.id for r in cat.find(32.0, 10.0)} == {
        "R32-10T3-FSI/6.350",
        "R32-10T4-FSI/6.350",
        "R32-10K5-FSC/3.969",
        "R32-10K5-FSC/4.763",
        "R32-10K5-FSC/6.350",
    }
    assert cat.find(32.0, 10.0, nut="FSI") == tuple(
        r for r in cat.find(32.0, 10.0) if r.nut == "FSI"
    )
    assert cat.find(12.0, 4.0) == ()
    pyproject = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    assert "data/*.csv" in pyproject["tool"]["setuptools"]["package-data"]["optdesign"]
