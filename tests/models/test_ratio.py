"""The ratio ripple of optdesign/models/ratio.py by hand, and the paper's neutral angle."""

from __future__ import annotations

import pytest


def test_ripple_by_hand_and_the_papers_neutral_angle():
    import numpy as np

    from optdesign.models.crank_slider import arm_angle
    from optdesign.models.ratio import ratio_ripple, ripple_from_bounds

    # (i_max - i_min) / (i_max + i_min): (300 - 100) / 400 = 0.5; (300 - 200) / 500 = 0.2
    assert float(ratio_ripple(np.array([150.0, 100.0, 300.0, 220.0]))) == pytest.approx(0.5)
    assert float(ripple_from_bounds(200.0, 300.0)) == pytest.approx(0.2)
    assert arm_angle(0.3) == 0.3  # phi0 = 0 unless given (the paper's neutral angle)
    assert arm_angle(0.3, 0.1) == pytest.approx(0.4)
