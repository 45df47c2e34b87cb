"""optdesign.models.loop_linear (issue 38) against python-control and closed forms.

The reference loops are written here a second time, independently of the module: as
state-space models in the *motor* coordinate theta (the module works in the fin's,
psi = theta / f'), states [theta, phi, theta', phi', T_m, z] with the current loop's lag
T_m and the integral z, built into ``control.ss``. python-control then gives the
bandwidth, the margins, the poles and the frequency response to compare with.
"""

from __future__ import annotations

import math

import casadi as ca
import loop_drives
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from optdesign.errors import InputError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import DrivePlant, PositionLoop

ct = pytest.importorskip("control")
pytestmark = pytest.mark.filterwarnings("ignore:Unused output")

# the shared two-mass drive (tests/loop_drives.py): anti-resonance 1000 rad/s
TWO_MASS = DrivePlant(**loop_drives.TWO_MASS)
# a rigid one: the same inertias on a chain 10^5 times stiffer (damped: its mode at
# 3.4e5 rad/s has zeta = 0.017)
RIGID = DrivePlant(motor_inertia=0.02, ratio=60.0, fin_inertia=10.0, stiffness=1e12, damping=1e5)

LOOPS = [
    PositionLoop(kp=2000.0, kd=60.0, ki=0.0, current_lag=2e-4, feedback="motor"),
    PositionLoop(kp=2000.0, kd=60.0, ki=8000.0, current_lag=2e-4, feedback="motor"),
    PositionLoop(kp=1500.0, kd=45.0, ki=0.0, current_lag=0.0, feedback="fin"),
    PositionLoop(kp=1500.0, kd=45.0, ki=5000.0, current_lag=1e-4, feedback="fin"),
]


def _state_space(plant: DrivePlant, loop: PositionLoop):
    """Closed loop r -> phi and open loop (torque command -> -controller's torque), from
    the equations in the motor coordinate:

        J_m theta'' = T_m - tau / f',   J_2 phi'' = tau - k_h phi - c_f phi',
        tau = k (theta / f' - phi) + c (theta' / f' - phi'),
        tau_i T_m' = T_cmd - T_m,       z' = r - y,
        T_cmd = kp (r - y) + ki z - kd y'.
    """
    Jm, f, J2 = plant.motor_inertia, plant.ratio, plant.fin_inertia
    k, c, kh, cf = plant.stiffness, plant.damping, plant.hinge_spring, plant.fin_damping
    # tau = a . [theta, phi, theta', phi']
    a = np.array([k / f, -k, c / f, -c])
    A = np.zeros((4, 4))
    A[0, 2] = A[1, 3] = 1.0
    A[2] = -a / (f * Jm)
    A[3] = (a - np.array([0.0, kh, 0.0, cf])) / J2
    Bu = np.array([0.0, 0.0, 1.0 / Jm, 0.0])
    if loop.feedback == "fin":
        Cy, Cyd = np.array([0, 1.0, 0, 0]), np.array([0, 0, 0, 1.0])
    else:
        Cy, Cyd = np.array([1.0 / f, 0, 0, 0]), np.array([0, 0, 1.0 / f, 0])
    Cphi = np.array([0, 1.0, 0, 0])
    # the plant with its input u = T_m, outputs y, y', phi
    plant_ss = ct.ss(A, Bu[:, None], np.vstack([Cy, Cyd, Cphi]), np.zeros((3, 1)))
    # controller: T_cmd from (r, y, y'); integral state z' = r - y
    if loop.ki > 0:
        ctrl = ct.ss([[0.0]], [[1.0, -1.0, 0.0]], [[loop.ki]], [[loop.kp, -loop.kp, -loop.kd]])
    else:
        ctrl = ct.ss(
            np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((1, 0)), [[loop.kp, -loop.kp, -loop.kd]]
        )
    lag = ct.tf([1.0], [loop.current_lag, 1.0]) if loop.current_lag > 0 else ct.tf([1.0], [1.0])
    lag = ct.ss(lag)
    plant_ss = ct.ss(plant_ss, inputs=["u"], outputs=["y", "yd", "phi"], name="P")
    ctrl = ct.ss(ctrl, inputs=["r", "y", "yd"], outputs=["Tc"], name="C")
    lag = ct.ss(lag, inputs=["Tc"], outputs=["u"], name="G")
    closed = ct.interconnect([plant_ss, ctrl, lag], inputs=["r"], outputs=["phi"])
    # broken at the torque command: v -> lag -> plant -> -(controller at r = 0)
    lag_open = ct.ss(lag, inputs=["v"], outputs=["u"], name="Go")
    ctrl_open = ct.ss(ctrl, inputs=["r", "y", "yd"], outputs=["back"], name="Co")
    neg = ct.ss(
        np.zeros((0, 0)),
        np.zeros((0, 1)),
        np.zeros((1, 0)),
        [[-1.0]],
        inputs=["back"],
        outputs=["Lout"],
        name="neg",
    )
    opened = ct.interconnect(
        [plant_ss, ctrl_open, lag_open, neg], inputs=["v", "r"], outputs=["Lout"]
    )[0, 0]
    return closed, opened


def _tf(num, den):
    return ct.tf(list(num), list(den))


@pytest.mark.parametrize("loop", LOOPS, ids=lambda lp: f"{lp.feedback}-ki{lp.ki:g}")
def test_frequency_response_equals_an_independent_state_space(loop):
    closed, opened = _state_space(TWO_MASS, loop)
    w = np.geomspace(1.0, 1e5, 61)
    L, T = ll.frequency_response(TWO_MASS, loop, w)
    L_ref = opened(1j * w)
    T_ref = closed(1j * w)
    assert np.max(np.abs(L - L_ref) / np.abs(L_ref)) < 1e-6
    assert np.max(np.abs(T - T_ref) / np.abs(T_ref)) < 1e-6
    pol = ll.loop_polynomials(TWO_MASS, loop)
    assert np.allclose(_tf(pol.open_numerator, pol.open_denominator)(1j * w), L, rtol=1e-9)
    assert np.allclose(_tf(pol.closed_numerator, pol.closed_denominator)(1j * w), T, rtol=1e-9)


@pytest.mark.parametrize("loop", LOOPS, ids=lambda lp: f"{lp.feedback}-ki{lp.ki:g}")
def test_poles_and_stability_equal_the_state_space_eigenvalues(loop):
    closed, _ = _state_space(TWO_MASS, loop)
    ref = np.sort_complex(np.linalg.eigvals(closed.A))
    ours = np.sort_complex(ll.closed_loop_poles(TWO_MASS, loop))
    assert len(ours) == len(ref)
    assert np.max(np.abs(ours - ref) / np.abs(ref)) < 1e-7
    assert ll.is_stable(TWO_MASS, loop) == bool(np.all(ref.real < 0))


@pytest.mark.parametrize("loop", LOOPS, ids=lambda lp: f"{lp.feedback}-ki{lp.ki:g}")
def test_bandwidth_and_margins_equal_python_controls(loop):
    closed, opened = _state_space(TWO_MASS, loop)
    half_power_db = 20.0 * math.log10(1.0 / math.sqrt(2.0))
    assert ll.bandwidth(TWO_MASS, loop) == pytest.approx(
        ct.bandwidth(closed, dbdrop=half_power_db), rel=1e-6
    )
    gm, pm, sm, wpc, wgc, wsm = ct.stability_margins(ct.tf(opened))
    got = ll.margins(TWO_MASS, loop)
    if gm > 1e9:  # python-control's crossing far beyond the loop's corners: none here
        assert got.gain_margin == math.inf
    else:
        assert got.gain_margin == pytest.approx(gm, rel=1e-6)
    assert got.phase_margin == pytest.approx(pm, rel=1e-6, abs=1e-6)
    for ours, theirs in [(got.phase_crossover, wpc), (got.gain_crossover, wgc)]:
        if math.isnan(theirs) or (
            theirs == wpc and gm > 1e9
        ):  # no crossing: inf margin, nan frequency in both
            assert math.isnan(ours)
        else:
            assert ours == pytest.approx(theirs, rel=1e-6)
    assert got.stability_margin == pytest.approx(sm, rel=1e-6)
    assert got.stability_margin_frequency == pytest.approx(wsm, rel=1e-4)
    # the peak of |T| on a grid, refined by a golden-section search of python-control's T
    w = np.geomspace(1e-1, 1e6, 3001)
    i = int(np.argmax(np.abs(closed(1j * w))))
    peak = minimize_scalar(
        lambda x: -abs(complex(closed(1j * x))), bracket=(w[i - 1], w[i], w[i + 1])
    )
    assert got.resonance_peak == pytest.approx(-peak.fun, rel=1e-9)
    assert got.resonance_frequency == pytest.approx(peak.x, rel=1e-4)


def test_rigid_drive_is_the_second_order_loop_of_the_summed_inertias():
    # omega_n^2 = f' kp / (J_m f'^2 + J_2), 2 zeta omega_n = f' kd / (J_m f'^2 + J_2):
    # 60 * 1500 / (72 + 10) = 1097.56 rad^2/s^2
    loop = PositionLoop(kp=1500.0, kd=40.0)
    wn = ll.rigid_natural_frequency(RIGID, loop)
    assert wn == pytest.approx(math.sqrt(60.0 * 1500.0 / 82.0), rel=1e-12)
    zeta = 60.0 * 40.0 / 82.0 / (2.0 * wn)
    second_order = ct.tf([wn**2], [1.0, 2.0 * zeta * wn, wn**2])
    slow = sorted(ll.closed_loop_poles(RIGID, loop), key=abs)[:2]
    assert np.allclose(np.sort_complex(slow), np.sort_complex(second_order.poles()), rtol=1e-6)
    assert ll.bandwidth(RIGID, loop) == pytest.approx(
        ct.bandwidth(second_order, dbdrop=-10 * math.log10(2.0)), rel=1e-5
    )
    # closed form of a second-order loop's -3 dB point
    x = 1 - 2 * zeta**2
    assert ll.bandwidth(RIGID, loop) == pytest.approx(
        wn * math.sqrt(x + math.sqrt(x * x + 1)), rel=1e-5
    )
    w = np.geomspace(1.0, 300.0, 50)
    assert np.allclose(ll.frequency_response(RIGID, loop, w)[1], second_order(1j * w), rtol=1e-5)


def test_hinge_spring_stiffens_the_rigid_loop():
    stiff_air = DrivePlant(
        motor_inertia=0.02,
        ratio=60.0,
        fin_inertia=10.0,
        stiffness=1e12,
        damping=1e5,
        hinge_spring=-4e4,
    )
    loop = PositionLoop(kp=1500.0)
    # (f' kp + k_h) / (J_1 + J_2) = (9e4 - 4e4) / 82
    assert ll.rigid_natural_frequency(stiff_air, loop) == pytest.approx(
        math.sqrt(5e4 / 82), rel=1e-12
    )
    poles = ll.closed_loop_poles(stiff_air, loop)
    slow = min(poles, key=abs)
    assert abs(slow.imag) == pytest.approx(math.sqrt(5e4 / 82), rel=1e-6)
    # a hinge spring stronger than the loop's diverges
    assert not ll.is_stable(stiff_air, PositionLoop(kp=600.0, kd=10.0))
    assert ll.is_stable(stiff_air, PositionLoop(kp=1000.0, kd=10.0))


def test_undamped_resonance_is_no_crossing():
    # c = c_f = 0: L has poles on the axis, where Im L changes sign through infinity (a
    # heavy motor side, a soft hinge: the poles near 2.8 and 1.3e4 rad/s)
    params = dict(motor_inertia=0.113, ratio=48.0, fin_inertia=21.1, stiffness=1.52e8)
    undamped = DrivePlant(**params, hinge_spring=2192.0)
    barely = DrivePlant(**params, hinge_spring=2192.0, damping=1e-3, fin_damping=1e-4)
    loop = PositionLoop(kp=307.0, kd=115.7, current_lag=1e-4, feedback="motor")
    a, b = ll.margins(undamped, loop), ll.margins(barely, loop)
    assert a.phase_margin == pytest.approx(b.phase_margin, rel=1e-4)
    assert a.gain_crossover == pytest.approx(b.gain_crossover, rel=1e-6)
    assert ll.bandwidth(undamped, loop) == pytest.approx(ll.bandwidth(barely, loop), rel=1e-5)


def test_loop_response_builds_casadi_expressions_equal_to_numpy():
    loop = LOOPS[3]
    args = ll.plant_arguments(TWO_MASS, loop)
    J, f, k = ca.SX.sym("J"), ca.SX.sym("f"), ca.SX.sym("k")
    w = ca.SX.sym("w")
    sym = {**args, "motor_inertia": J, "ratio": f, "stiffness": k, "omega": w}
    r = ll.loop_response(**sym)
    rows = ca.vertcat(ll.closed_loop_gain_squared(r), ll.return_difference_squared(r))
    fn = ca.Function("rows", [J, f, k, w], [rows, ca.jacobian(rows, ca.vertcat(J, f, k))])
    val, jac = fn(0.02, 60.0, 1e7, 150.0)
    L, T = ll.frequency_response(TWO_MASS, loop, 150.0)
    assert float(val[0]) == pytest.approx(abs(T) ** 2, rel=1e-12)
    assert float(val[1]) == pytest.approx(abs(1 + L) ** 2, rel=1e-12)
    # the derivative in the ratio against a central difference
    h = 1e-5 * 60.0
    up = ll.frequency_response(DrivePlant(**{**TWO_MASS.__dict__, "ratio": 60.0 + h}), loop, 150.0)[
        1
    ]
    dn = ll.frequency_response(DrivePlant(**{**TWO_MASS.__dict__, "ratio": 60.0 - h}), loop, 150.0)[
        1
    ]
    assert float(jac[0, 1]) == pytest.approx((abs(up) ** 2 - abs(dn) ** 2) / (2 * h), rel=1e-6)


def test_bad_input_is_refused_naming_the_field():
    args = ll.plant_arguments(TWO_MASS, LOOPS[0])
    with pytest.raises(InputError, match="omega"):
        ll.loop_response(**args, omega=0.0)
    with pytest.raises(InputError, match="omega"):
        ll.loop_response(**args, omega=np.array([1.0, np.inf]))
    with pytest.raises(InputError, match="feedback"):
        ll.loop_response(**{**args, "feedback": "rate"}, omega=1.0)
