"""optdesign.search.odds: Boender and Rinnooy Kan's estimates, their closed forms against
sums of the posterior, and the posterior against a simulation of its own model."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import gammaln

from optdesign.search.odds import UNSEEN_LIMIT, odds, settled
from optdesign.solvers.result import percent


def _posterior(n: int, w: int, terms: int = 2_000_000) -> tuple[np.ndarray, np.ndarray]:
    # P(K = k | n, w) on k = w .. w + terms, summed directly from its definition
    k = np.arange(w, w + terms, dtype=float)
    logs = gammaln(k + 1) + gammaln(k) - gammaln(k - w + 1) - gammaln(n + k)
    p = np.exp(logs - logs.max())
    return k, p / p.sum()


@pytest.mark.parametrize(("n", "w"), [(8, 1), (12, 1), (17, 2), (24, 5), (30, 3), (9, 4)])
def test_closed_forms_equal_sums_of_the_posterior(n, w):
    k, p = _posterior(n, w)
    o = odds(n, w)
    assert o.expected_optima == pytest.approx((p * k).sum(), rel=1e-4)
    # the unseen share of the starts' distribution: E[(k - w) / (n + k)]
    assert o.p_better == pytest.approx((p * (k - w) / (n + k)).sum(), rel=1e-5)
    # the best optimum any one of the k: P(unseen) = 1 - w E[1/K]
    assert o.p_better_any == pytest.approx(1 - w * (p / k).sum(), rel=1e-5)


def test_the_posterior_is_the_simulated_model():
    """Draw the model itself - K optima (uniform on 1..40), region shares uniform on the
    simplex, n independent starts - keep the draws with w distinct optima seen, and
    compare the unseen share and the chance that the best region is unseen with the
    estimates (the truncated prior changes them by less than the sampling error)."""
    rng = np.random.default_rng(7)
    n, trials = 12, 400_000
    unseen = {1: [], 2: [], 3: []}
    best_missed = {1: [], 2: [], 3: []}
    for _chunk in range(8):
        K = rng.integers(1, 41, trials // 8)
        for k in range(1, 41):
            rows = np.flatnonzero(K == k)
            if not len(rows):
                continue
            shares = rng.dirichlet(np.ones(k), len(rows))
            hits = rng.multinomial(n, shares)
            w = (hits > 0).sum(axis=1)
            share_unseen = (shares * (hits == 0)).sum(axis=1)
            # the best optimum: a region drawn by its share (the estimate's reading)
            u = rng.random((len(rows), 1))
            best = np.minimum((np.cumsum(shares, axis=1) < u).sum(axis=1), k - 1)
            missed = hits[np.arange(len(rows)), best] == 0
            for m in unseen:
                sel = w == m
                unseen[m] += list(share_unseen[sel])
                best_missed[m] += list(missed[sel])
    for m in (1, 2, 3):
        o = odds(n, m)
        est, sd = np.mean(unseen[m]), np.std(unseen[m]) / math.sqrt(len(unseen[m]))
        assert abs(est - o.p_better) < 4 * sd + 1e-4, (m, est, o.p_better)
        freq = np.mean(best_missed[m])
        sd = math.sqrt(max(freq * (1 - freq), 1e-6) / len(best_missed[m]))
        assert abs(freq - o.p_better) < 4 * sd + 1e-4, (m, freq, o.p_better)


def test_one_optimum_in_eight_starts():
    o = odds(8, 1)
    assert o.expected_optima == pytest.approx(7 / 5)
    assert o.p_better == pytest.approx(2 / 56)
    assert o.p_better_any == pytest.approx(1 / 7)
    assert o.text() == (
        "1 local optimum seen in 8 counted starts; estimated probability that a better "
        "one exists: 3.6 %"
    )


def test_too_few_starts_say_so():
    assert odds(3, 3).p_better == 1.0 and math.isinf(odds(3, 3).expected_optima)
    assert "too few starts" in odds(4, 3).text()
    assert odds(0, 0).text() == "0 local optima seen in 0 counted starts"
    with pytest.raises(ValueError, match="cannot come from"):
        odds(2, 3)


def test_the_rule_stops_once_half_an_optimum_is_expected_unseen():
    # one optimum: E[K] - 1 = 2 / (n - 3) < 1/2 from n = 8 on
    assert not settled(odds(7, 1)) and settled(odds(8, 1))
    # two optima: 2 (n - 1) / (n - 4) - 2 < 1/2 from n = 17 on
    assert not settled(odds(16, 2)) and settled(odds(17, 2))
    assert odds(17, 2).expected_unseen < UNSEEN_LIMIT <= odds(16, 2).expected_unseen
    # a target on the probability holds it back further
    assert not settled(odds(8, 1), target=0.01) and settled(odds(15, 1), target=0.01)
    assert not settled(odds(10, 0))


@pytest.mark.parametrize(
    ("p", "text"), [(0.0004, "< 0.1 %"), (0.004, "0.4 %"), (0.036, "3.6 %"), (0.14, "14 %")]
)
def test_percent(p, text):
    assert percent(p) == text
