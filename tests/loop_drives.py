"""The two-mass drive the loop's model tests share (tests/models/test_loop_*.py): 0.02
t*mm^2 at the motor (2e-5 kg*m^2), ratio 60, a fin of 10 t*mm^2 (0.01 kg*m^2), a chain of
1e7 N*mm/rad at the fin (anti-resonance 1000 rad/s), damped, on a stabilising hinge
spring. Internal units (mm, t, s, N, rad)."""

TWO_MASS = dict(
    motor_inertia=0.02,
    ratio=60.0,
    fin_inertia=10.0,
    stiffness=1e7,
    damping=400.0,
    hinge_spring=2e4,
    fin_damping=20.0,
)
