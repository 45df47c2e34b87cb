"""optdesign/models/motor_limits.py: the speed-torque envelope against a hand example and
its two linear rows, and the first-order thermal model against its limits (a cycle short
against tau gives the plain RMS torque, a long one the largest step torque), a
hand-computed two-level cycle and a numerical integration of the thermal lag."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from optdesign.errors import InputError
from optdesign.models import motor as mo
from optdesign.models import motor_limits as ml

RPM = 2 * math.pi / 60


def test_the_envelope_is_flat_to_the_corner_then_falls_to_the_top_speed_torque():
    """6.69 N*m to 5000 1/min, then straight to 5.5 N*m at 6000 1/min: at 5546 1/min
    6.69 - 1.19 x 546 / 1000 = 6.04026 N*m."""
    args = (6690.0, 5000 * RPM, 6000 * RPM, 5500.0)
    speeds = np.array([0.0, 3000.0, 5000.0, 5546.0, 6000.0]) * RPM
    assert ml.available_torque(speeds, *args) == pytest.approx(
        [6690.0, 6690.0, 6690.0, 6040.26, 5500.0], rel=1e-12
    )
    assert np.isnan(ml.available_torque(6001 * RPM, *args))
    s = ml.envelope_slope(*args)
    assert s == pytest.approx(1190.0 / (1000 * RPM))
    assert ml.envelope_intercept(6690.0, 5000 * RPM, s) == pytest.approx(6690.0 + 5.95e3)


@settings(max_examples=100, deadline=None)
@given(
    n=st.floats(0.0, 1.0),
    T=st.floats(0.0, 1.2),
    corner=st.floats(0.05, 0.95),
    top=st.floats(0.0, 1.0),
)
def test_two_linear_rows_are_exactly_the_envelope(n, T, corner, top):
    """Under the peak (T <= T_peak) and under the falling line (T + s n <= T_peak + s n_c)
    exactly when under the envelope, at every speed up to the top speed."""
    peak, n_max = 1.0, 1.0
    s = ml.envelope_slope(peak, corner, n_max, top)
    rows = T <= peak and T + s * n <= ml.envelope_intercept(peak, corner, s)
    # the envelope read independently: straight between the datasheet's three points
    envelope = float(np.interp(n, [0.0, corner, n_max], [peak, peak, top]))
    if abs(T - envelope) > 1e-9:  # the boundary itself is either, within rounding
        assert rows == (T <= envelope)


# --- thermal model -------------------------------------------------------------------------
TORQUES = [3000.0, 1000.0, 2200.0]  # N*mm
SHARES = [0.2, 0.5, 0.3]


def _cycle(period):
    return [s * period for s in SHARES]


def test_a_cycle_short_against_tau_heats_as_its_rms_torque():
    """A 10 s cycle: 0.11 % above the RMS torque at tau = 1000 s (the ripple of the
    winding's temperature, of the order of the cycle over tau), then closer as tau grows,
    to the digit at 3e4 years (the expm1 form keeps them)."""
    rms = float(mo.rms_torque(TORQUES, SHARES))
    assert ml.thermal_torque(TORQUES, _cycle(10.0), 1e3) / rms - 1 == pytest.approx(
        1.08e-3, rel=0.01
    )
    for tau in (1e6, 1e9, 1e12):
        assert ml.thermal_torque(TORQUES, _cycle(10.0), tau) == pytest.approx(rms, rel=2e-6)


def test_a_cycle_long_against_tau_heats_as_its_largest_torque():
    assert ml.thermal_torque(TORQUES, _cycle(10.0), 1e-3) == pytest.approx(3000.0, rel=1e-9)


def test_a_single_long_pulse_heats_as_the_pulse():
    """One 2 N*m pulse of 10 tau in a cycle with 0.1 N*m the rest of the time: the winding
    reaches the pulse's heating to 0.4 % (1 - exp(-10) of the way from its cool state)."""
    thermal = ml.thermal_torque([2000.0, 100.0], [600.0, 600.0], 60.0)
    assert thermal == pytest.approx(2000.0, rel=1e-4)
    assert thermal < 2000.0


def test_a_two_level_cycle_by_hand():
    """3 N*m for 10 s, then 1 N*m for 30 s, tau 20 s: a1 = exp(-0.5), a2 = exp(-1.5); at
    the end of the 3 N*m step x = ((1 - a1) 9 + a1 (1 - a2) 1) / (1 - a1 a2) = 4.64044
    N^2*m^2, i.e. 2.15417 N*m - between the RMS torque sqrt(3) = 1.73205 N*m and 3 N*m."""
    x = ml.thermal_torque_squares([3.0, 1.0], [10.0, 30.0], 20.0)
    assert x[0] == pytest.approx(4.64044, abs=1e-5)
    assert ml.thermal_torque([3.0, 1.0], [10.0, 30.0], 20.0) == pytest.approx(2.15417, abs=1e-5)
    # the end of the 1 N*m step: x0 a2 + (1 - a2) 1, x0 the value above
    a2 = math.exp(-1.5)
    assert x[1] == pytest.approx(4.640435 * a2 + (1 - a2), abs=1e-5)


def test_the_steady_state_equals_an_integration_of_the_thermal_lag():
    """tau dx/dt = T(t)^2 - x integrated by SciPy, step after step, over 12 cycles from a
    cold start: the end-of-step values of the last cycle are the closed form's (the start
    is forgotten as exp(-12 x 8 / 5) = 5e-9)."""
    tau, period = 5.0, 8.0
    t = _cycle(period)
    x, ends = 0.0, []
    for _ in range(12):
        ends = []
        for Tk, tk in zip(TORQUES, t, strict=True):
            sol = solve_ivp(
                lambda _, y, u=Tk**2: (u - y) / tau, (0.0, tk), [x], rtol=1e-10, atol=1e-6
            )
            x = float(sol.y[0, -1])
            ends.append(x)
    assert ends == pytest.approx(ml.thermal_torque_squares(TORQUES, t, tau), rel=1e-6)


@settings(max_examples=60, deadline=None)
@given(
    torques=st.lists(st.floats(0.1, 10.0), min_size=1, max_size=6),
    data=st.data(),
)
def test_the_thermal_torque_lies_between_the_rms_and_the_peak_and_falls_with_tau(torques, data):
    """Each row of weights sums to 1 (a constant torque heats as itself); the thermal
    torque is at least the RMS torque and at most the largest step's, and a longer tau
    never raises it (a longer lag is a mean of the shorter one's response)."""
    n = len(torques)
    t = data.draw(st.lists(st.floats(0.01, 100.0), min_size=n, max_size=n))
    tau = data.draw(st.floats(0.01, 1000.0))
    W = ml.thermal_weights(t, tau)
    assert W.sum(axis=1) == pytest.approx(np.ones(n), rel=1e-9)
    assert np.all(W >= 0)
    thermal = ml.thermal_torque(torques, t, tau)
    assert float(mo.rms_torque(torques, t)) <= thermal * (1 + 1e-9)
    assert thermal <= max(torques) * (1 + 1e-9)
    assert ml.thermal_torque(torques, t, 2 * tau) <= thermal * (1 + 1e-9)


def test_a_cycle_without_time_or_tau_is_refused():
    with pytest.raises(InputError, match="durations"):
        ml.thermal_weights([1.0, 0.0], 10.0)
    with pytest.raises(InputError, match="tau"):
        ml.thermal_weights([1.0], 0.0)
