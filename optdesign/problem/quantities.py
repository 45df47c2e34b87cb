"""The quantities of one design over the deflection grid: what objectives and constraints
(built-in and user-written) are functions of.

``q = problem.quantities(design)`` gives, computed once each on first use, the
mechanism's drive coordinate and its derivative, the ratio, the nut force, the motor
torque, the nut travel, the clearance chain and backlash, the sized pin and its load,
the size, the lock force; ``q.mechanism`` is the mechanism instance itself (for its own
quantities, e.g. ``q.mechanism.transmission_angle(q.phi)``) and ``q.R`` any design
variable. The values are CasADi expressions on the solver path, NumPy arrays (a design,
or a population broadcast on the last axis) on the checking path, and signomial tracers
in the GP diagnosis: write functions of ``q`` with :mod:`optdesign.math`.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping, Sequence
from functools import cached_property
from typing import TYPE_CHECKING, Any

from optdesign.mechanisms.joints import (
    Backlash,
    Joint,
    PinJoint,
    with_fixed_clearances,
    with_sampled_fits,
)
from optdesign.models.lug_flexibility import Lug
from optdesign.problem import drive, motor_drive
from optdesign.user_code import call_method, stage

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem


class Quantities:
    """Lazily computed quantities of ``design`` (see the module docstring).

    Parameters
    ----------
    problem
        The design problem (grid, requirements, materials).
    design
        Every variable name -> value.
    guarded
        Solver path: guarded square roots.
    first_order
        First-order Hertz flattening (the GP form).
    fit_fractions
        One fit fraction per sized pin joint (robust design), or None for the
        requirement's ``fit_clearance``.
    """

    def __init__(
        self,
        problem: DesignProblem,
        design: Mapping[str, Any],
        guarded: bool = False,
        first_order: bool = False,
        fit_fractions: Sequence[Any] | None = None,
    ):
        self.problem = problem
        self.design = dict(design)
        self.guarded = guarded
        self.first_order = first_order
        self.fit_fractions = fit_fractions
        self.phi = problem.phi
        self.labels = problem.phi_labels
        self.requirements = problem.spec.requirements
        # a parameter of the solver's model when a sweep varies it (one NLP for every
        # point, optdesign.studies.sweep_solver), else the requirement's value
        self.hinge_moment = self.design.get(
            drive.PARAM + "hinge_moment", self.requirements.hinge_moment
        )

    def __getattr__(self, item: str) -> Any:
        design = self.__dict__.get("design")
        if design is not None and item in design and not item.startswith(drive.PARAM):
            return design[item]
        if _defined(type(self), item):
            # A quantity whose computation raised AttributeError, which Python turns into
            # this call: computed again here, its own error (file, line) propagates
            # instead of "no quantity" for a quantity that exists.
            return inspect.getattr_static(type(self), item).__get__(self, type(self))
        raise AttributeError(
            f"no quantity or variable {item!r} (variables: {', '.join(design or {})}; "
            "quantities: see optdesign.problem.quantities.Quantities)"
        )

    @cached_property
    def doing(self) -> str:
        """What these quantities are computed for, for the errors of a user's code
        ("while building the solver's model", ...)."""
        return stage(self.design)

    def call_mechanism(self, method: str, *args: Any) -> Any:
        """``self.mechanism.method(*args)``; a user's mechanism that fails gives an error
        naming its class, the method and the user's file and line."""
        return call_method(self.mechanism, method, *args, doing=self.doing)

    # --- mechanism ---------------------------------------------------------------------
    @cached_property
    def mechanism(self):
        """The mechanism instance of this design."""
        cls = self.problem.mechanism
        names = cls.variable_table()
        values = {k: v for k, v in self.design.items() if k in names}
        return call_method(cls, "__init__", values, guarded=self.guarded, doing=self.doing)

    @cached_property
    def nut_position(self):
        """Drive coordinate x(phi) over the grid (mm)."""
        return self.call_mechanism("nut_position", self.phi)

    @cached_property
    def nut_velocity(self):
        """dx/dphi over the grid (mm/rad)."""
        return self.call_mechanism("nut_velocity", self.phi)

    @cached_property
    def ratio(self):
        """Reduction ratio i(phi) = 2 pi i_a (dx/dphi)/p over the grid."""
        return self.call_mechanism("ratio", self.phi)

    @cached_property
    def nut_travel(self):
        """x(phi_max) - x(phi_min) (mm)."""
        return self.call_mechanism("nut_travel", self.phi[0], self.phi[-1])

    @cached_property
    def nut_force(self):
        """Nut axial force over the grid (N), by virtual work."""
        return self.call_mechanism("nut_force", self.phi, self.hinge_moment)

    @cached_property
    def motor_torque(self):
        """Motor torque over the grid (N*mm) through the forward efficiencies of the screw
        and the gear."""
        gear, _ = drive.gear_efficiencies(self.problem.spec)
        return self.call_mechanism(
            "motor_torque", self.phi, self.hinge_moment, self.efficiency, gear
        )

    # --- the drive (screw, efficiency, speed, life, stiffness) ---------------------------
    @cached_property
    def screw(self) -> drive.ScrewData | None:
        """The screw: lead, mean and root diameters, catalogue ratings (or None)."""
        return drive.screw_data(self)

    @cached_property
    def efficiencies(self):
        return drive.efficiencies(self)

    @property
    def efficiency(self):
        """Forward efficiency of the screw (the model of ``[screw]``, else eta_screw)."""
        return self.efficiencies[0]

    @property
    def efficiency_back(self):
        """Back-driving efficiency of the screw (<= 0: self-locking)."""
        return self.efficiencies[1]

    @cached_property
    def drive_efficiency(self):
        """Forward efficiency of screw and gear together."""
        gear, _ = drive.gear_efficiencies(self.problem.spec)
        return self.efficiency * gear

    @cached_property
    def screw_speed(self):
        """Screw speed (1/min) over the grid at the required deflection rate."""
        return drive.screw_speed(self)

    @cached_property
    def life_hours(self):
        """Rated life (h) of the screw over the duty cycle (ISO 3408-5 L10)."""
        return drive.life_hours(self)

    @cached_property
    def output_compliance(self):
        """Compliance at the output over the grid (rad/(N*mm))."""
        return drive.output_compliance(self)

    @cached_property
    def output_stiffness(self):
        """Stiffness at the output over the grid (N*mm/rad)."""
        return 1.0 / self.output_compliance

    @cached_property
    def size(self):
        """The mechanism's size measure (mm)."""
        return self.call_mechanism("size")

    # --- pins and clearance --------------------------------------------------------------
    @cached_property
    def pin(self) -> PinJoint | None:
        """The sized pin (None when the problem declares no pin diameter)."""
        d = self.design
        if "d" not in d:
            return None
        L = d["pin_length"] if "pin_length" in d else d["pin_length_ratio"] * d["d"]
        mat = self.problem.spec.materials.pin
        req = self.requirements
        values = drive.fit_values(self.problem)
        ratios = {}
        if values == "table" and drive.PARAM + "fit_ratio_max" in d:
            ratios = {
                "ratio_max": d[drive.PARAM + "fit_ratio_max"],
                "ratio_min": d[drive.PARAM + "fit_ratio_min"],
            }
        return PinJoint(
            d["d"],
            L,
            req.fit,
            req.fit_clearance,
            mat.E,
            mat.nu,
            2,
            self.first_order,
            contact=req.pin_contact,
            values=values,
            lug=self._lug(),
            **ratios,
        )

    def _lug(self) -> Lug | None:
        """The lug around the sized pin (``[materials.lug]``), in single or double shear
        as the pin's shear check counts it (``pin_shear_planes``, else the mechanism's)."""
        lug = self.problem.spec.materials.lug
        if lug is None:
            return None
        planes = self.requirements.pin_shear_planes or self.problem.mechanism.pin_shear_planes
        return Lug(lug.cheek_thickness, lug.thickness, lug.E, lug.cheek_E, planes, lug.fastener)

    @cached_property
    def pin_force(self):
        """Force on the sized pin(s) over the grid (N)."""
        return self.call_mechanism("pin_force", self.phi, self.hinge_moment)

    @cached_property
    def joints(self) -> list[Joint]:
        """The clearance chain: sized pins and the declared fixed clearances."""
        chain = self.call_mechanism("joints", self.phi, self.hinge_moment, self.pin)
        clearances = self.problem.spec.clearances
        fixed = dict(clearances) if clearances is not None else {}
        chain = with_fixed_clearances(chain, fixed)
        if self.fit_fractions is not None:
            chain = with_sampled_fits(chain, self.fit_fractions)
        return chain

    @cached_property
    def backlash(self) -> Backlash:
        """Output backlash over the grid (deg): per joint, worst case, RSS."""
        return self.call_mechanism("backlash", self.phi, self.joints)

    # --- the motor, the fin's inertia and frequencies (optdesign.problem.motor_drive) -------
    @cached_property
    def motor_data(self) -> motor_drive.MotorData | None:
        """The design's motor: its data, or the catalogue's motor its variable numbers."""
        return motor_drive.motor_of(self)

    @cached_property
    def motion(self) -> motor_drive.MotionDemand | None:
        """The fin's top rate and acceleration (``[motion]``), or None without a rate."""
        return motor_drive.motion_demand(self.problem.spec)

    @cached_property
    def natural_period(self):
        """2 pi / omega of the fin on the chain, motor held, over the grid (s)."""
        return motor_drive.natural_period(self)

    @cached_property
    def ratio_rate(self):
        """f''(phi) = d(ratio)/d(phi) over the grid (1/rad)."""
        return motor_drive.ratio_rate(self)

    @cached_property
    def motor_side_inertia(self):
        """Inertia at the motor of what turns with it or moves with the nut (t*mm^2)."""
        return motor_drive.motor_side_inertia(self)

    @cached_property
    def inertia_at_motor(self):
        """Total inertia at the motor, J_m + J_fin / ratio^2, over the grid (t*mm^2)."""
        return motor_drive.inertia_at_motor(self)

    @cached_property
    def inertia_ratio(self):
        """Load inertia at the motor over the rotor's, over the grid."""
        return motor_drive.inertia_ratio(self)

    @cached_property
    def motor_speed(self):
        """Motor speed at the fin's top rate over the grid (rad/s)."""
        return motor_drive.motor_speed(self)

    @cached_property
    def motor_peak_torque(self):
        """Torque the motion asks of the motor over the grid (N*mm), inertia included."""
        return motor_drive.motor_peak_torque(self)

    @cached_property
    def motor_peak_torque_pieces(self):
        """The peak torque's two smooth pieces (:func:`~optdesign.problem.motor_drive.
        motor_peak_torque_pieces`)."""
        return motor_drive.motor_peak_torque_pieces(self)

    @cached_property
    def motor_rms_torque(self):
        """RMS motor torque of the duty cycle (N*mm)."""
        return motor_drive.motor_rms_torque(self)

    @cached_property
    def locked_frequency_squared(self):
        """Squared natural frequency of the fin on the chain, motor held (rad^2/s^2)."""
        return motor_drive.locked_frequency_squared(self)

    @cached_property
    def two_mass_frequency_squared(self):
        """Squared frequency of the drive's mode, motor free (rad^2/s^2)."""
        return motor_drive.two_mass_frequency_squared(self)

    # --- drive extras ----------------------------------------------------------------------
    @cached_property
    def lock_force(self):
        """Magnet force of the motor-shaft lock over the grid (N), [Y16] coupled to the
        drive (None without a ``lock`` requirement)."""
        from optdesign.models.lock import FrictionPlateLock, PinLock, motor_shaft_lock_load

        lk = self.requirements.lock
        if lk is None:
            return None
        if lk.kind == "friction_plate":
            lock = FrictionPlateLock(lk.r1, lk.r2, lk.mu)
        else:
            lock = PinLock(lk.radius, bearing="guide" if lk.kind == "pin_rolling" else None)
        if self.problem.spec.screw is not None:
            _, gear_back = drive.gear_efficiencies(self.problem.spec)
            eta_back = self.efficiency_back
        else:
            eta_back, gear_back = lk.eta_screw_back, lk.eta_gear_back
        load = motor_shaft_lock_load(
            self.mechanism, self.phi, self.hinge_moment, eta_back, gear_back
        )
        return lock.force(load.moment)


def _defined(cls: type, item: str) -> bool:
    """``item`` is a property (or cached property) of ``cls``."""
    return hasattr(inspect.getattr_static(cls, item, None), "__get__") and not item.startswith("__")
