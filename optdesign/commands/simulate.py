"""``optdesign simulate FILE|RESULT``: the time response of a design in its position loop
(:func:`optdesign.simulate`; docs/loop.md).

FILE is a problem file with ``[loop]``: its optimum is solved first. RESULT is the
``result.json`` of ``optdesign solve``: its design, in the problem it names (a shipped
problem's name, or a file beside it of that name). Writes ``simulation.csv`` (units in
the headers) and ``simulation.png`` to the output folder.
"""

from __future__ import annotations

import json
from pathlib import Path

from optdesign import validation as check
from optdesign.cli import as_options, checked, command, literal, output_folder
from optdesign.errors import InputError

#: The largest result.json read (a result of the shipped problems is a few kB).
MAX_RESULT_BYTES = 1 << 22


@command("simulate")
def _simulate(sub):
    p = sub.add_parser("simulate", help="the time response of a design in its position loop")
    p.add_argument("file", type=Path, help="problem file (TOML, solved first) or result.json")
    p.add_argument(
        "--reference",
        choices=("step", "sine", "duty"),
        default="step",
        help="a step, a sine, or requirements.duty_cycle's deflection history and loads",
    )
    p.add_argument("--amplitude", default="1 deg", help='the step or the sine (e.g. "1 deg")')
    p.add_argument("--angle", default=None, help="grid angle simulated (default: mid-stroke)")
    p.add_argument(
        "--horizon", default=None, help='time of a step or a sine (default "0.5 s", at most 600 s)'
    )
    p.add_argument("--frequency", default="5 Hz", help="the sine's frequency")
    p.add_argument(
        "--plant",
        choices=("angle", "path"),
        default=None,
        help="the plant of one grid angle (a step's and a sine's default) or following "
        "the fin along the stroke (the duty cycle's)",
    )
    p.add_argument(
        "--periods",
        type=checked(lambda a, v: check.integer(a, v, 1, 1_000_000), literal),
        default=1,
        help="duty cycles simulated (their time at most 600 s)",
    )
    p.add_argument(
        "--period", default=None, help="the duty cycle's length (default: requirements.duty_period)"
    )
    p.add_argument(
        "--samples",
        type=checked(lambda a, v: check.integer(a, v, 2, 1_000_000), literal),
        default=2001,
        help="output samples (2 to 10^6)",
    )
    p.add_argument(
        "--out", type=checked(check.out_path), default=None, help="output folder (default: new one)"
    )
    p.add_argument("--no-plot", action="store_true", help="skip simulation.png")
    p.set_defaults(func=run_simulate_command)


def _design_of(path: Path):
    """The problem and the design a result.json names."""
    from optdesign.problem import load_problem

    if path.stat().st_size > MAX_RESULT_BYTES:
        raise InputError("file", f"{path} is larger than {MAX_RESULT_BYTES} bytes")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        name, design = doc["problem"], doc["design"]
        values = {k: float(v["value"]) for k, v in design.items()}
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError("file", f"{path} is no result.json of optdesign solve ({exc})") from None
    beside = path.parent / f"{name}.toml"
    return load_problem(beside if beside.is_file() else name), values


def run_simulate_command(args) -> int:
    import optdesign as od
    from optdesign import storage
    from optdesign.problem import load_problem
    from optdesign.problem.loop_time import (
        duty_simulation_history,
        simulation_arguments,
        simulation_csv,
    )

    with as_options():  # refused before any solve
        checked_args = simulation_arguments(
            args.reference,
            args.amplitude,
            args.horizon,
            args.frequency,
            args.plant,
            args.periods,
            args.period,
        )
    if args.file.suffix.lower() == ".json":
        problem, design = _design_of(args.file)
    else:
        problem = load_problem(args.file)
        if checked_args.duty:
            with as_options():  # what the duty cycle needs of the problem, before the solve
                duty_simulation_history(problem, checked_args)
        with as_options():
            result = od.solve(problem, ranges=False, sensitivities=False, diagnose=False)
        if not result.success:
            raise InputError("file", f"{problem.name}: no optimum to simulate ({result.status})")
        design = result.design
    with as_options():
        sim = od.simulate(
            problem,
            args.reference,
            design=design,
            amplitude=args.amplitude,
            angle=args.angle,
            horizon=args.horizon,
            frequency=args.frequency,
            samples=args.samples,
            plant=args.plant,
            periods=args.periods,
            period=args.period,
        )
    with output_folder(args.out, f"simulate-{problem.name}") as out, storage.lock_folder(out):
        storage.ensure_writable(out)
        storage.atomic_write_text(out / "simulation.csv", simulation_csv(sim))
        if not args.no_plot:
            from optdesign.plots import save_figure
            from optdesign.plots.loop_response import plot_loop_response

            save_figure(plot_loop_response(sim), out / "simulation.png")
        where = (
            "over the duty cycle"
            if sim.duty is not None
            else f"at {sim.angle * 57.29577951308232:+.1f} deg"
        )
        print(f"simulated {problem.name} {where}: {out}")
    return 0
