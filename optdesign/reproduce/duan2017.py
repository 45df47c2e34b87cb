"""Reproduction of Duan, Huang, Liu (2017), *Study on transmission mechanism of ball screw
actuator* ([D17]): ratio ranges and ripple of the crank-slider and the shifting fork,
the position of the ratio maximum, the Hertz pin example and the backlash of D + E.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from optdesign import math as m
from optdesign.display.tables import Comparison, comparison_table
from optdesign.mechanisms import CrankSlider, PinJoint, ShiftingFork
from optdesign.models.fit_formulas import fit_clearance
from optdesign.models.hertz_line import contact_half_width, pin_flattening
from optdesign.plots.curves import plot_curves

#: The paper's actuator (section 1): lead 5 mm, gears 2, arm 90, offset 50, rod 80.
PAPER_DESIGN = {"p": 5.0, "i_a": 2.0, "R": 90.0, "n": 50.0, "l": 80.0}
#: The paper's deflection range and the step of its finite-difference ratio (eq. 5, 9);
#: the paper does not print its step; 1 deg is used and stated.
PHI_MAX_DEG = 30.0
STEP_DEG = 1.0
#: The Hertz example of section 2.1.
HERTZ_EXAMPLE = {"D": 10.0, "L": 20.0, "F": 20e3, "nu": 0.3, "E": 2.1e5}


def compute(n_grid: int = 6001) -> dict[str, float]:
    """All numbers of the reproduction, computed from the models (dense grid)."""
    d = PAPER_DESIGN
    phi = np.radians(np.linspace(-PHI_MAX_DEG, PHI_MAX_DEG, n_grid))
    step = np.radians(STEP_DEG)
    cs = CrankSlider(R=d["R"], l=d["l"], n=d["n"], p=d["p"], i_a=d["i_a"])
    cs.check_assembly(phi)
    fork = ShiftingFork(R=d["R"], p=d["p"], i_a=d["i_a"])
    i_cs, i_f = cs.ratio(phi), fork.ratio(phi)
    i_cs_fd, i_f_fd = cs.ratio_finite_step(phi, step), fork.ratio_finite_step(phi, step)
    h = HERTZ_EXAMPLE
    delta = pin_flattening(h["D"], h["F"], h["L"], h["E"], h["nu"])
    out = {
        "cs_i_min": i_cs.min(),
        "cs_i_max": i_cs.max(),
        "cs_ripple": cs.ripple(phi),
        "cs_argmax_deg": np.degrees(phi[np.argmax(i_cs)]),
        "cs_fd_i_min": i_cs_fd.min(),
        "cs_fd_i_max": i_cs_fd.max(),
        "cs_fd_ripple": m.grid_spread(i_cs_fd),
        "fork_i_min": i_f.min(),
        "fork_i_max": i_f.max(),
        "fork_ripple": fork.ripple(phi),
        "fork_argmin_deg": np.degrees(phi[np.argmin(i_f)]),
        "fork_asymmetry": float(np.max(np.abs(i_f - i_f[::-1]))),
        "cs_asymmetry": float(np.max(np.abs(i_cs - i_cs[::-1]))),
        "hertz_b": contact_half_width(h["D"], h["F"], h["L"], h["E"], h["nu"]),
        "hertz_delta": delta,
        "hertz_delta_pin_and_bore": 2.0 * delta,
        # Another reading that matches the printed 0.012 mm: pin and bore, and eq. 10
        # without its (1 - nu^2) factor (nu = 0), i.e. E instead of E/(1 - nu^2).
        "hertz_delta_pin_and_bore_no_nu": 2.0 * pin_flattening(h["D"], h["F"], h["L"], h["E"], 0.0),
    }
    # Backlash of the two rod pins (D + E) of the paper's crank-slider, and of the fork's
    # pin in its slot, with the section 2.1 pin (10 mm x 20 mm). The paper gives neither
    # the hinge moment nor the fit: stated assumptions are M_h = 500 N*m and H7/g6.
    M_h = 500e3
    for which in ("min", "max"):
        pin = PinJoint(h["D"], h["L"], "H7/g6", which, h["E"], h["nu"])
        rod_pins = [j for j in cs.joints(phi, M_h, pin) if j.pin is not None]
        out[f"cs_DE_backlash_{which}"] = float(np.max(cs.backlash(phi, rod_pins).worst_case))
        slot = [j for j in fork.joints(phi, M_h, pin) if j.pin is not None]
        out[f"fork_C_backlash_{which}"] = float(np.max(fork.backlash(phi, slot).worst_case))
    out["fit_max_clearance_um"] = 1e3 * fit_clearance(h["D"], "H7/g6", "max")
    out["phi_deg"] = np.degrees(phi)
    out["curves"] = {"cs": (i_cs, i_cs_fd), "fork": (i_f, i_f_fd)}
    return out


def run(out: Path) -> int:
    """Print the paper-vs-computed table and write Fig. 3 and Fig. 6 as PNG into ``out``."""
    r = compute()
    rows = [
        Comparison("crank-slider ratio min", 155, r["cs_i_min"], "", "exact derivative"),
        Comparison("crank-slider ratio max", 250, r["cs_i_max"], "", "exact derivative"),
        Comparison("crank-slider ripple", 23.5, 100 * r["cs_ripple"], "%", "(max-min)/(max+min)"),
        Comparison(
            "crank-slider ratio max at",
            None,
            r["cs_argmax_deg"],
            "deg",
            "paper: not at 0, asymmetric",
        ),
        Comparison(
            "crank-slider ratio min, eq. 5", 155, r["cs_fd_i_min"], "", f"step {STEP_DEG} deg"
        ),
        Comparison(
            "crank-slider ratio max, eq. 5", 250, r["cs_fd_i_max"], "", f"step {STEP_DEG} deg"
        ),
        Comparison(
            "crank-slider ripple, eq. 5", 23.5, 100 * r["cs_fd_ripple"], "%", f"step {STEP_DEG} deg"
        ),
        Comparison("fork ratio min", 225, r["fork_i_min"], "", "exact derivative"),
        Comparison("fork ratio max", 300, r["fork_i_max"], "", "exact derivative"),
        Comparison("fork ripple", 14.3, 100 * r["fork_ripple"], "%", "depends on phi_max only"),
        Comparison("fork ratio min at", 0.0, r["fork_argmin_deg"], "deg", "symmetric"),
        Comparison("Hertz half-width b", None, r["hertz_b"], "mm", "eq. 10"),
        Comparison(
            "Hertz flattening, eq. 11", 0.012, r["hertz_delta"], "mm", "one body (implemented)"
        ),
        Comparison(
            "Hertz flattening, pin + bore", 0.012, r["hertz_delta_pin_and_bore"], "mm", "2 x eq. 11"
        ),
        Comparison(
            "Hertz flattening, pin + bore, no (1-nu^2)",
            0.012,
            r["hertz_delta_pin_and_bore_no_nu"],
            "mm",
            "2 x eq. 11 with nu = 0 (not implemented)",
        ),
        Comparison(
            "crank-slider D+E backlash",
            0.03,
            r["cs_DE_backlash_min"],
            "deg",
            "paper: < 0.03; H7/g6 smallest clearance",
        ),
        Comparison(
            "crank-slider D+E backlash",
            0.03,
            r["cs_DE_backlash_max"],
            "deg",
            "paper: < 0.03; H7/g6 largest clearance",
        ),
        Comparison(
            "fork C backlash", 0.04, r["fork_C_backlash_min"], "deg", "H7/g6 smallest clearance"
        ),
        Comparison(
            "fork C backlash", 0.04, r["fork_C_backlash_max"], "deg", "H7/g6 largest clearance"
        ),
    ]
    print(
        "Duan, Huang, Liu (2017): p = 5 mm, i_a = 2, R = 90 mm, n = 50 mm, l = 80 mm, "
        f"phi in [-{PHI_MAX_DEG:g}, +{PHI_MAX_DEG:g}] deg"
    )
    print(comparison_table(rows))
    print(
        "\nNotes:\n"
        "- The paper's ratio ranges (155...250, 225...300) are read off its figures and rounded;\n"
        "  the exact derivative of eq. 2 and eq. 6 gives the computed values. Its finite-step\n"
        "  eq. 5 / eq. 9 lags the derivative by half a step (step not printed; 1 deg used).\n"
        "- Hertz example (D = 10 mm, L = 20 mm, F = 20 kN, nu = 0.3, E = 2.1e5 MPa): eq. 10-11 as\n"
        f"  written give {r['hertz_delta']:.5f} mm for one body; the paper prints 0.012 mm. Counting\n"
        f"  the flattening of both pin and bore gives {r['hertz_delta_pin_and_bore']:.5f} mm, 8 % below\n"
        "  the printed figure. The printed 0.012 mm is also matched by pin and bore with eq. 10\n"
        f"  written without its (1 - nu^2) factor: 2 x Delta(nu = 0) = {r['hertz_delta_pin_and_bore_no_nu']:.5f} mm\n"
        "  (+1.1 %); the paper may have used that form, but eq. 10 as printed has the factor.\n"
        f"  optdesign implements eq. 11 as printed for one body and counts 2 x Delta =\n"
        f"  {r['hertz_delta_pin_and_bore']:.5f} mm per pin joint.\n"
        "- Backlash rows assume M_h = 500 N*m and an H7/g6 fit of the section 2.1 pin, which the\n"
        "  paper does not state; its figures (< 0.03 deg, 0.04 deg) are bounds for its own actuator.\n"
        f"  H7/g6 largest clearance at 10 mm: {r['fit_max_clearance_um']:.1f} um (ISO 286 formula)."
    )
    phi_deg = r["phi_deg"]
    for key, fig, name in (("cs", "Fig. 3", "crank-slider"), ("fork", "Fig. 6", "shifting fork")):
        exact, fd = r["curves"][key]
        path = plot_curves(
            phi_deg,
            {
                "exact derivative": exact,
                f"finite step {STEP_DEG:g} deg (eq. {5 if key == 'cs' else 9})": fd,
            },
            "reduction ratio i",
            f"{name} ratio vs deflection (Duan 2017 {fig})",
            out / f"duan2017_{key}_ratio.png",
            styles={"exact derivative": "-"},
        )
        print(f"wrote {path}")
    return 0
