"""The mechanisms' necessary conditions (``Mechanism.impossible``): a proof that no design
within the bounds can turn through the stroke under its requirements.

Each proof is checked against designs: whatever a design that works over a stroke
(positive ratio, assembled) shows of its transmission angle and its rod's inclination,
the requirements it meets must never be called impossible; and the identity the
crank-slider's proof rests on is checked against the model's own angles.
"""

from types import SimpleNamespace

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from optdesign.mechanisms import CrankSlider, ShiftingFork
from optdesign.mechanisms.pivoting_screw import PivotingScrew
from optdesign.models.impossibility import Impossibility

DEG = np.pi / 180


def _band(lo, hi):
    return SimpleNamespace(min=lo, max=hi)


def _working(mech, phi) -> bool:
    """The design turns through ``phi``: assembled, ratio positive at every angle (a
    design that does not assemble gives NaN, quietly)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.asarray(mech.ratio(phi), dtype=float)
    return bool(np.all(np.isfinite(ratio)) and np.all(ratio > 0))


crank_designs = st.fixed_dictionaries(
    {
        "R": st.floats(20, 150),
        "l": st.floats(20, 300),
        "n": st.floats(-150, 150),
        "phi0": st.floats(-1.5, 1.5),
        "p": st.just(5.0),
    }
)


@settings(max_examples=300, deadline=None)
@given(crank_designs, st.floats(-2.5, 0.5), st.floats(0.05, 3.0))
def test_a_crank_slider_that_turns_through_a_stroke_is_never_called_impossible(design, start, span):
    """The requirements a working design meets (its own transmission band and rod
    inclination over the stroke, its own phi0) are never proved impossible."""
    phi = np.linspace(start, start + span, 241)
    mech = CrankSlider(**design)
    assume(_working(mech, phi))
    with np.errstate(invalid="ignore"):
        mu = np.asarray(mech.transmission_angle(phi), dtype=float)
    assume(np.all(np.isfinite(mu)))  # arccos of a cosine rounded past 1 at a fold
    beta = np.abs(np.asarray(mech.rod_inclination(phi), dtype=float))
    met = {"transmission_angle": _band(mu.min(), mu.max()), "rod_inclination_max": beta.max()}
    bounds = {"phi0": (design["phi0"], design["phi0"])}
    assert CrankSlider.impossible((phi[0], phi[-1]), met, bounds) == []
    # the identity the proof rests on: mu = 90 deg - (phi0 + phi) - beta, exactly
    signed = np.asarray(mech.rod_inclination(phi), dtype=float)
    np.testing.assert_allclose(mu, np.pi / 2 - (design["phi0"] + phi) - signed, atol=1e-9)


def test_the_crank_sliders_proof_names_the_conflict_and_what_lifts_it():
    req = {"transmission_angle": _band(40 * DEG, 140 * DEG), "rod_inclination_max": 30 * DEG}
    bounds = {"phi0": (-0.6, 0.6)}
    (proof,) = CrankSlider.impossible((-120 * DEG, 120 * DEG), req, bounds)
    assert proof.requirements == ("deflection", "transmission_angle", "rod_inclination_max")
    assert "240 - 2 x 30 = 180 deg, more than the 100 deg" in proof.reason
    # the band alone would need 180 deg: more than any band; so two remedies, not three
    assert proof.remedies == (
        "a stroke of at most 160 deg",
        "rod_inclination_max of at least 70 deg",
    )
    # each remedy lifts it, and just beyond it the proof holds again
    assert CrankSlider.impossible((-80 * DEG, 80 * DEG), req, bounds) == []
    assert CrankSlider.impossible((-80.01 * DEG, 80 * DEG), req, bounds)
    assert (
        CrankSlider.impossible(
            (-120 * DEG, 120 * DEG), {**req, "rod_inclination_max": 70 * DEG}, bounds
        )
        == []
    )
    # the shipped stroke turns, but not with phi0 held where the band cannot be met
    (phi0,) = CrankSlider.impossible((-30 * DEG, 30 * DEG), req, {"phi0": (1.0, 1.2)})
    assert phi0.requirements[0] == "variables.phi0" and "between -50 and 50 deg" in phi0.reason


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-1.5, 1.5),
    st.floats(-3.0, 0.5),
    st.floats(0.05, 3.5),
)
def test_a_fork_that_turns_through_a_stroke_is_never_called_impossible(phi0, start, span):
    phi = np.linspace(start, start + span, 241)
    mech = ShiftingFork(R=50.0, phi0=phi0, p=5.0)
    a = phi0 + phi
    turns = bool(np.all(np.abs(a) < np.pi / 2))
    proofs = ShiftingFork.impossible((phi[0], phi[-1]), {}, {"phi0": (phi0, phi0)})
    assert (proofs == []) == turns
    if turns:
        assert _working(mech, phi)


@settings(max_examples=300, deadline=None)
@given(
    st.floats(20, 150),
    st.floats(-300, 300),
    st.floats(-300, 300),
    st.floats(-1.5, 1.5),
    st.floats(-2.5, 0.5),
    st.floats(0.05, 3.0),
)
def test_a_pivoting_screw_that_turns_is_never_called_impossible(R, a_T, b_T, phi0, start, span):
    """Whatever least transmission angle a working design shows, its stroke is allowed."""
    phi = np.linspace(start, start + span, 241)
    mech = PivotingScrew(R=R, a_T=a_T, b_T=b_T, phi0=phi0, p=5.0)
    assume(_working(mech, phi))
    gamma = np.arccos(np.clip(np.asarray(mech.transmission_angle_cos(phi), dtype=float), -1, 1))
    met = {"transmission_angle": _band(gamma.min(), None)}
    assert PivotingScrew.impossible((phi[0], phi[-1]), met, {"phi0": (phi0, phi0)}) == []


def test_the_fork_and_the_pivoting_screw_name_the_stroke():
    (fork,) = ShiftingFork.impossible((-95 * DEG, 95 * DEG), {}, {"phi0": (0.0, 0.0)})
    assert fork.requirements == ("deflection",) and "190 deg" in fork.reason
    (held,) = ShiftingFork.impossible((-30 * DEG, 30 * DEG), {}, {"phi0": (1.2, 1.4)})
    assert held.requirements == ("variables.phi0", "deflection")
    band = {"transmission_angle": _band(40 * DEG, 140 * DEG)}
    (pivot,) = PivotingScrew.impossible((-75 * DEG, 75 * DEG), band, {"phi0": (0.0, 0.0)})
    assert pivot.requirements == ("deflection", "transmission_angle")
    assert pivot.remedies == (
        "a stroke of less than 140 deg",
        "a least transmission angle below 30 deg",
    )
    assert PivotingScrew.impossible((-69 * DEG, 69 * DEG), band, {"phi0": (0.0, 0.0)}) == []


def test_a_proof_reads_as_one_paragraph():
    proof = Impossibility(("deflection",), "too wide", ("a stroke of 10 deg", "another"))
    assert (
        proof.text()
        == "deflection: too wide; any one of these lifts it: a stroke of 10 deg; another"
    )
    assert proof.to_json()["remedies"] == ["a stroke of 10 deg", "another"]
