"""optdesign.models.loop_backlash and the dead zone of describing_function (issue 38).

The dead zone's describing function against python-control's numerical one; the claim
that the damping gated to the contact has the same describing function, by quadrature;
the Lur'e loop L_d against the linear loop (at N = 1 it closes to the same
characteristic polynomial); the cycles' homogeneity in the gap; the smooth indicator
changing sign at the cycle's amplitude. The simulation's check of the amplitudes is in
test_loop_simulation.py.
"""

from __future__ import annotations

import math

import casadi as ca
import loop_drives
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import trapezoid

from optdesign.errors import InputError
from optdesign.models import describing_function as df
from optdesign.models import loop_backlash as lb
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import DrivePlant, PositionLoop

B = math.radians(0.1)
# fin feedback through a chain with a resonance near 1070 rad/s: the gap sustains a
# cycle just below it (the loop's gain margin is 1.45 at 1066 rad/s)
PLANT = DrivePlant(**loop_drives.TWO_MASS, backlash=B)
FIN_PD = PositionLoop(kp=1500.0, kd=45.0, current_lag=1e-4, feedback="fin")
MOTOR_PID = PositionLoop(kp=2000.0, kd=60.0, ki=8000.0, current_lag=2e-4, feedback="motor")


def _dead_zone(x, b):
    return np.where(np.abs(x) <= b, 0.0, x - np.sign(x) * b)


def test_dead_zone_equals_python_controls_numerical_describing_function():
    ct = pytest.importorskip("control")
    b = 0.3
    for A in [0.31, 0.35, 0.5, 1.0, 3.0, 30.0]:
        theirs = ct.describing_function(lambda x: _dead_zone(x, b), A, num_points=4000)
        assert df.dead_zone_df(A, b) == pytest.approx(np.real(theirs), abs=1e-6), A
    assert df.dead_zone_df(0.2, b) == 0.0
    # at A = 2b: 1 - (2/pi)(pi/6 + sqrt(3)/4) = 0.391002
    assert df.dead_zone_df(0.6, b) == pytest.approx(
        1 - 2 / math.pi * (math.pi / 6 + math.sqrt(3) / 4), rel=1e-12
    )


def test_gated_damping_has_the_dead_zones_describing_function():
    # the fundamental of c x' 1{|x| > b} for x = A sin(theta), w = 1, c = 1: its cos
    # coefficient over A equals the dead zone's N(A) (docs/loop.md)
    theta = np.linspace(0.0, 2 * math.pi, 200001)
    for A_over_b in [1.01, 1.3, 2.0, 5.0]:
        A, b = A_over_b, 1.0
        x, xd = A * np.sin(theta), A * np.cos(theta)
        y = np.where(np.abs(x) > b, xd, 0.0)
        a1 = trapezoid(y * np.cos(theta), theta) / math.pi  # NumPy 1.26 has no np.trapezoid
        assert a1 / A == pytest.approx(df.dead_zone_df(A, b), abs=1e-5)


@given(st.floats(1e-3, 10.0), st.floats(1.0 + 1e-6, 1e4))
def test_dead_zone_amplitude_inverts_the_describing_function(b, ratio):
    A = b * ratio
    N = float(df.dead_zone_df(A, b))
    if 1e-12 < N < 1 - 1e-9:
        assert df.dead_zone_amplitude(N, b) == pytest.approx(A, rel=1e-6)
        assert df.dead_zone_df_derivative(A, b) > 0


@pytest.mark.parametrize(
    "loop",
    [FIN_PD, MOTOR_PID, PositionLoop(kp=1500.0, kd=45.0, ki=3000.0, feedback="fin")],
    ids=["fin-pd", "motor-pid", "fin-pid-no-lag"],
)
def test_deflection_loop_closed_at_unit_gain_is_the_linear_loop(loop):
    num, den = lb.deflection_loop(PLANT, loop)
    lur_e = np.polyadd(num, den)
    char = ll.loop_polynomials(PLANT, loop).closed_denominator
    assert len(lur_e) == len(char)
    ours = np.sort_complex(ll.scaled_roots(lur_e))
    theirs = np.sort_complex(ll.scaled_roots(char))
    assert np.max(np.abs(ours - theirs) / np.abs(theirs)) < 1e-8


def test_fin_feedback_gap_sustains_a_stable_cycle_below_the_chain_resonance():
    cycles = lb.limit_cycles(PLANT, FIN_PD)
    stable = [c for c in cycles.cycles if c.stable]
    assert len(stable) == 1
    c = stable[0]
    # below the linear loop's phase crossover (1066 rad/s): the gap softens the chain
    assert 700.0 < c.frequency < ll.margins(PLANT, FIN_PD).phase_crossover
    assert c.deflection_amplitude > B and c.fin_amplitude > B
    # the balance: N(A) L_d(jw) = -1
    assert c.balance.describing_function * c.balance.loop_response == pytest.approx(-1.0, abs=1e-9)
    assert cycles.largest_stable_fin_amplitude == c.fin_amplitude


def test_stable_cycle_equals_python_controls_describing_function_response():
    ct = pytest.importorskip("control")
    if not hasattr(ct, "describing_function_response"):
        pytest.skip("python-control < 0.10 has no describing_function_response")
    import warnings

    class DeadZoneNL(ct.DescribingFunctionNonlinearity):
        def __init__(self, b):
            self.b = b

        def __call__(self, x):
            return _dead_zone(x, self.b)

        def _isstatic(self):
            return True

        def describing_function(self, A):
            return df.dead_zone_df(A, self.b)

    num, den = lb.deflection_loop(PLANT, FIN_PD)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = ct.describing_function_response(
            ct.tf(list(num), list(den)),
            DeadZoneNL(B),
            B * np.geomspace(1.0001, 100.0, 400),
            omega=np.geomspace(10.0, 1e4, 2000),
        ).intersections
    # python-control's minimiser finds the stable cycle; near A = b (the unstable one)
    # it leaves the amplitude range
    ((a_pc, w_pc),) = [(a, w) for a, w in theirs if w > 500.0]
    ours = next(c for c in lb.limit_cycles(PLANT, FIN_PD).cycles if c.stable)
    assert ours.deflection_amplitude == pytest.approx(a_pc, rel=1e-3)
    assert ours.frequency == pytest.approx(w_pc, rel=1e-4)


def test_cycles_scale_with_the_gap():
    big = lb.limit_cycles(PLANT, FIN_PD)
    small = lb.limit_cycles(DrivePlant(**{**PLANT.__dict__, "backlash": B / 7}), FIN_PD)
    assert len(big.cycles) == len(small.cycles) >= 2
    for c1, c2 in zip(big.cycles, small.cycles, strict=True):
        assert c2.fin_amplitude * 7 == pytest.approx(c1.fin_amplitude, rel=1e-7)
        assert c2.motor_amplitude * 7 == pytest.approx(c1.motor_amplitude, rel=1e-7)
        assert c2.frequency == pytest.approx(c1.frequency, rel=1e-9)


def test_motor_feedback_with_a_stable_fin_has_no_cycle_and_says_why():
    cycles = lb.limit_cycles(PLANT, MOTOR_PID)
    assert cycles.none and "gain is below 1" in cycles.reason
    assert cycles.largest_stable_fin_amplitude == 0.0
    free = lb.limit_cycles(DrivePlant(**{**PLANT.__dict__, "backlash": 0.0}), FIN_PD)
    assert free.none and "no clearance" in free.reason and free.harmonic_balance is None


def _margin(c, amplitude_max, plant=PLANT):
    return lb.cycle_amplitude_margin(
        c.balance.loop_response.real,
        c.frequency,
        amplitude_max,
        plant.backlash,
        plant.stiffness,
        plant.damping,
        plant.fin_inertia,
        plant.fin_damping,
        plant.hinge_spring,
    )


def test_cycle_amplitude_margin_changes_sign_at_the_cycles_fin_amplitude():
    for c in lb.limit_cycles(PLANT, FIN_PD).cycles:
        assert _margin(c, 0.99 * c.fin_amplitude) < 0 < _margin(c, 1.01 * c.fin_amplitude)
        assert _margin(c, c.fin_amplitude) == pytest.approx(0.0, abs=1e-9)
    # a limit below the gap: no deflection reaches it, N(A_max) = 0
    c = lb.limit_cycles(PLANT, FIN_PD).cycles[-1]
    assert _margin(c, 1e-3 * B) == pytest.approx(1.0 / c.balance.loop_response.real)


def test_cycle_amplitude_margin_is_a_casadi_expression():
    c = lb.limit_cycles(PLANT, FIN_PD).cycles[-1]
    L, w, a = ca.SX.sym("L"), ca.SX.sym("w"), ca.SX.sym("a")
    p = PLANT
    expr = lb.cycle_amplitude_margin(
        L, w, a, p.backlash, p.stiffness, p.damping, p.fin_inertia, p.fin_damping, p.hinge_spring
    )
    fn = ca.Function("g", [L, w, a], [expr, ca.gradient(expr, a)])
    value, grad = fn(c.balance.loop_response.real, c.frequency, 2 * c.fin_amplitude)
    assert float(value) == pytest.approx(_margin(c, 2 * c.fin_amplitude), rel=1e-12)
    h = 1e-6 * c.fin_amplitude
    fd = (_margin(c, 2 * c.fin_amplitude + h) - _margin(c, 2 * c.fin_amplitude - h)) / (2 * h)
    assert float(grad) == pytest.approx(fd, rel=1e-5)


@settings(max_examples=25, deadline=None)
@given(
    k=st.floats(3e6, 5e7),
    kd=st.floats(30.0, 90.0),
    feedback=st.sampled_from(["fin", "motor"]),
)
def test_every_cycle_balances_the_loop_and_lies_outside_the_gap(k, kd, feedback):
    plant = DrivePlant(**{**PLANT.__dict__, "stiffness": k})
    loop = PositionLoop(kp=1500.0, kd=kd, current_lag=1e-4, feedback=feedback)
    for c in lb.limit_cycles(plant, loop).cycles:
        assert c.deflection_amplitude > B
        N = df.dead_zone_df(c.deflection_amplitude, B)
        assert abs(1 + N * c.balance.loop_response) < 1e-8


def test_bad_input_is_refused_naming_the_argument():
    with pytest.raises(InputError, match="plant"):
        lb.limit_cycles("drive", FIN_PD)
    with pytest.raises(InputError, match="loop"):
        lb.limit_cycles(PLANT, None)
    with pytest.raises(InputError, match="half_width"):
        df.DeadZone(0.0)
    with pytest.raises(InputError, match="N"):
        df.dead_zone_amplitude(1.0, B)
