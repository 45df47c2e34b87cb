"""The whole fin actuator's optimum against the hinge moment and the deflection rate: a
design chart of ``problems/fin_actuator.toml`` (a catalogue ball screw, ISO 2338 pins,
the motor-shaft lock) with public names only. Run it as a script:

    python examples/fin_actuator_sweep.py [OUT]

It writes ``OUT/sweep.jsonl`` as the points finish (run it again to resume a killed
run), then ``sweep.csv``, ``sweep.png`` (the design chart) and ``sweep.html`` (hover a
point: its design, sketch and limits). Default ``OUT``: ``fin_actuator_sweep`` in the
current folder.

One change to the shipped file: the lock's magnet may pull 60 N instead of 30 N. With
30 N the back-driving torque of the surface leaves no feasible design above about
500 N*m (the summary of ``optdesign solve`` at 900 N*m names the lock force as the
requirement to relax, to 53 N), and the chart would be mostly shaded.
"""

import sys
import tomllib
from pathlib import Path

import optdesign as od

PROBLEM = Path(__file__).resolve().parents[1] / "problems" / "fin_actuator.toml"

VARY = {
    "requirements.hinge_moment": ("300 N*m", "900 N*m", 7),
    "requirements.deflection_rate": ("60 deg/s", "180 deg/s", 3),
}


def strong_lock_actuator() -> dict:
    """The shipped fin actuator with a 60 N lock magnet (a problem as a dict)."""
    data = tomllib.loads(PROBLEM.read_text(encoding="utf-8"))
    data["name"] = "fin_actuator_60N_lock"
    data["requirements"]["lock"]["force_max"] = "60 N"
    return data


def main(out: Path) -> od.Sweep:
    """Sweep (resuming a stored run in ``out``), then write the table and the charts."""
    resume = (out / "sweep.jsonl").exists()
    sweep = od.sweep(strong_lock_actuator(), VARY, out=out, resume=resume, workers=2)
    sweep.to_frame().to_csv(out / "sweep.csv", index=False)
    sweep.plot().savefig(out / "sweep.png", dpi=110)
    od.report(sweep, out / "sweep.html")
    return sweep


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("fin_actuator_sweep")
    print(main(folder).summary())
