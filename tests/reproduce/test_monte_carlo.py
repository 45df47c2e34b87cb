"""The Monte Carlo of the transmission error ([L16], optdesign/reproduce/monte_carlo.py)
on the error budget's sources mapped through a crank-slider: reproducible, statistically
stable, and equal to the exact sums of independent terms."""

import numpy as np
import pytest
from models.test_error_budget import MECH, budget_sources

from optdesign.errors import InputError
from optdesign.models import error_budget as eb
from optdesign.reproduce.monte_carlo import run_monte_carlo


def test_monte_carlo_reproducible_and_statistically_stable():
    kw = dict(mechanism=MECH, phi_range=(-0.5, 0.5), chunk=50_000)
    a = run_monte_carlo(budget_sources(), 200_000, 7, keep_samples=True, **kw)
    b = run_monte_carlo(budget_sources(), 200_000, 7, keep_samples=True, **kw)
    c = run_monte_carlo(budget_sources(), 200_000, 8, keep_samples=True, **kw)
    assert np.array_equal(a.samples, b.samples)
    assert a.mean == b.mean and a.std == b.std and a.ranking() == b.ranking()
    assert not np.array_equal(a.samples, c.samples)
    # Different seeds: means within 5 standard errors, sds within 2 %.
    assert abs(a.mean - c.mean) < 5 * a.std / np.sqrt(a.n)
    assert c.std == pytest.approx(a.std, rel=0.02)
    assert sum(a.mean_square_share.values()) == pytest.approx(1.0)


def test_monte_carlo_matches_the_budget_at_one_angle():
    src = budget_sources()
    phi = 0.2
    res = run_monte_carlo(src, 400_000, 1, MECH, phi=phi)
    g = eb.gains(src, MECH, phi)
    # Exact mean and sd of a sum of independent terms.
    mean = sum(gi * s.mean for gi, s in zip(g, src, strict=True))
    sd = np.sqrt(sum((gi * s.sd) ** 2 for gi, s in zip(g, src, strict=True)))
    assert res.mean == pytest.approx(mean, abs=5 * sd / np.sqrt(res.n))
    assert res.std == pytest.approx(sd, rel=0.01)
    # The deterministic budget bounds the sampled error (systematic + 3 sigma).
    b = eb.budget(src, MECH, phi)
    assert res.abs_max < float(b.systematic) + 5 * float(b.rss)
    # Fixed backlash ranks although it has no variance.
    # (a constant column's variance is zero up to rounding: 5e-13 with NumPy 1.26)
    assert res.mean_square_share["backlash"] > 0.0
    assert res.variance_share["backlash"] == pytest.approx(0.0, abs=1e-9)


def test_too_few_samples_are_refused_naming_n():
    with pytest.raises(InputError, match="n"):
        run_monte_carlo(budget_sources(), 1, 0, MECH)
