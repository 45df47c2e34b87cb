"""Benchmark outputs: the runs as CSV, the profiles as PNG, the Markdown summary, and the
:class:`BenchReport` a caller reads (summary, frame, figure).

Names in them (configurations, instances: a user's problem names its instance) are
made safe for each: CSV cells by :func:`optdesign.text.csv_cell`, Markdown table cells
by :func:`md_cell`; ``bench_stats.json`` writes a value that is not finite as ``null``."""

from __future__ import annotations

import csv
import io
import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.solvers.result import clean_json
from optdesign.storage import atomic_output, atomic_write_text
from optdesign.studies.bench.configs import get_config
from optdesign.studies.bench.rows import BenchRow
from optdesign.studies.bench.scoring import (
    GAP_FLOOR,
    SOLVED_GAP,
    ConfigStats,
    best_config,
    config_stats,
    measure_table,
    paired_time_ratio,
    performance_profile,
)
from optdesign.text import csv_cell, printable
from optdesign.tolerances import FEASIBILITY_TOL


def md_cell(text: object) -> str:
    """``text`` as one Markdown table cell: one printable line
    (:func:`~optdesign.text.printable`), with ``\\``, ``|`` (a new cell), ``<`` (inline
    HTML) and a backtick (code) escaped by a backslash, which Markdown shows as the
    character itself."""
    out = printable(text)
    for ch in ("\\", "|", "<", "`"):
        out = out.replace(ch, "\\" + ch)
    return out


def stats_table(
    stats: Mapping[str, ConfigStats],
    descriptions: Mapping[str, str],
    rows: Sequence[BenchRow],
) -> str:
    """Markdown table of :func:`config_stats`, best configuration first, with the median
    per-instance ratio of each configuration's time to the best one's."""
    best = best_config(stats)
    order = sorted(
        stats,
        key=lambda c: (
            c != best,
            -(stats[c].solved_rate or 0),
            stats[c].median_time_s if math.isfinite(stats[c].median_time_s) else 1e9,
        ),
    )
    lines = [
        "| configuration | what | runs | success | solved (gap <= 1e-4) | median time (s) "
        "| time / best (median, paired) | median gap | failures |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for c in order:
        s = stats[c]
        if not s.runs:
            continue
        ratio, n_pairs = paired_time_ratio(rows, c, best) if best else (float("nan"), 0)
        fails = ", ".join(f"{md_cell(k)} {v}" for k, v in sorted(s.failures.items())) or "-"
        name = md_cell(c)
        lines.append(
            f"| {'**' + name + '**' if c == best else name} | {md_cell(descriptions.get(c, ''))} "
            f"| {s.runs} | "
            f"{100 * s.success_rate:.0f} % | {100 * s.solved_rate:.0f} % | "
            f"{_fmt(s.median_time_s, '.3g')} | {_fmt(ratio, '.2f')} ({n_pairs}) | "
            f"{_fmt(s.median_gap, '.1e')} | {fails} |"
        )
    return "\n".join(lines)


def _fmt(v: float, spec: str) -> str:
    return "-" if v is None or not math.isfinite(v) else format(v, spec)


CSV_FIELDS = [
    "instance",
    "family",
    "seed",
    "mechanism",
    "objective_name",
    "catalogue",
    "config",
    "kind",
    "status",
    "success",
    "objective",
    "best_known",
    "gap",
    "violation",
    "time_s",
    "iterations",
    "n_fun",
    "n_grad",
    "n_hess",
    "n_subproblems",
    "reason",
]


def eval_counts(n_evals: Mapping[str, int]) -> tuple[int | None, int | None, int | None]:
    """(function, first-derivative, Hessian) evaluation counts from a back-end's counters.

    Ipopt: nlp_f / nlp_grad_f / nlp_hess_l; sqpmethod: nlp_fg / nlp_jac_fg / nlp_hess_l;
    scipy: f / grad_f / hess_f; DE: designs evaluated. ``None`` when not reported.
    """
    if not n_evals:
        return None, None, None
    f = n_evals.get("nlp_f", n_evals.get("nlp_fg", n_evals.get("f")))
    g = n_evals.get("nlp_grad_f", n_evals.get("nlp_jac_fg", n_evals.get("grad_f")))
    h = n_evals.get("nlp_hess_l", n_evals.get("hess_f"))
    return f, g, h


def write_outputs(
    rows: Sequence[BenchRow], out: Path, configs, suite_name, wall, time_limit, hard, skipped=None
) -> dict[str, Any]:
    """bench_runs.csv, bench_profiles.png, summary.md, bench_stats.json in ``out``;
    ``skipped``: mechanism -> why the suite has no instances of it (listed last)."""

    out = Path(out)
    with io.StringIO() as fh:
        w = csv.DictWriter(fh, CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            f, g, h = eval_counts(r.n_evals or {})
            counts = {"n_fun": f, "n_grad": g, "n_hess": h, "reason": str(r.reason)[:200]}
            w.writerow(
                {k: csv_cell(counts[k] if k in counts else getattr(r, k)) for k in CSV_FIELDS}
            )
        atomic_write_text(out / "bench_runs.csv", fh.getvalue())
    single = [c for c in configs if get_config(c).kind not in ("front", "debug")]
    fronts = [c for c in configs if get_config(c).kind == "front"]
    if single:
        from optdesign.display.figures import save_figure

        fig = profiles_figure(rows, configs)
        with atomic_output(out / "bench_profiles.png") as tmp:
            save_figure(fig, tmp, tight=False)
    desc = {c: get_config(c).description for c in configs}
    stats_all = config_stats([r for r in rows if r.config in single], single)
    shipped = [r for r in rows if r.family == "shipped"]
    n_inst = len({r.instance for r in rows})
    lines = [
        f"Suite `{suite_name}`: {n_inst} instances, {len(rows)} runs, wall time {wall:.0f} s "
        f"(soft time limit {time_limit:g} s per run, hard timeout {hard:g} s). "
        "Time = wall time of one run from the problem to the answer (formulation, solver "
        "set-up and solve; catalogue combinations summed), median over successful runs. "
        "Success = the solver reports success and the independent NumPy check passes "
        f"(violation <= {FEASIBILITY_TOL:g}); solved = success with gap <= {SOLVED_GAP:g} to the "
        "best value any configuration found. Best configuration (bold) = among those run "
        "on every instance of the table, the highest solved rate, then the lowest median "
        "time; 'time / best' = median over the instances both solved of the per-instance "
        "time ratio (number of such instances in brackets).",
        "",
        "### All single-objective instances",
        "",
        stats_table(stats_all, desc, rows),
    ]
    if shipped:
        lines += [
            "",
            "### Shipped problems (problems/*.toml)",
            "",
            stats_table(
                config_stats([r for r in shipped if r.config in single], single), desc, shipped
            ),
        ]
        lines += ["", _shipped_table(shipped, single)]
    if fronts:
        st = config_stats([r for r in rows if r.config in fronts], fronts)
        lines += [
            "",
            "### Pareto-front instances (gap = 1 - hypervolume / best hypervolume)",
            "",
            stats_table(st, desc, rows),
        ]
    if skipped:
        lines += ["", "### Registered mechanisms without instances", ""]
        lines += [f"- {md_cell(name)}: {md_cell(why)}" for name, why in skipped.items()]
    text = "\n".join(lines) + "\n"
    atomic_write_text(out / "summary.md", text)
    atomic_write_text(
        out / "bench_stats.json",
        json.dumps(
            clean_json(
                {
                    "all": {c: asdict(s) for c, s in stats_all.items()},
                    "wall_time_s": wall,
                    "suite": suite_name,
                }
            ),
            indent=1,
            default=str,
            allow_nan=False,
        ),
    )
    return {
        "csv": out / "bench_runs.csv",
        "profiles": out / "bench_profiles.png",
        "summary": out / "summary.md",
        "summary_text": text,
    }


def _shipped_table(rows: Sequence[BenchRow], configs: Sequence[str]) -> str:
    insts = sorted({r.instance for r in rows})
    head = "| configuration | " + " | ".join(f"{md_cell(i)}: time (s) / gap" for i in insts) + " |"
    lines = [head, "|---|" + "---|" * len(insts)]
    by = {(r.instance, r.config): r for r in rows}
    for c in configs:
        cells = []
        for i in insts:
            r = by.get((i, c))
            if r is None or not r.applicable:
                cells.append("n/a")
            elif not r.success:
                cells.append(md_cell(r.status))
            else:
                cells.append(f"{r.time_s:.3g} / {r.gap:.1e}")
        lines.append(f"| {md_cell(c)} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: Markers of the generated block in benchmarks/README.md.
README_BEGIN = "<!-- bench-summary:begin (generated by optdesign bench) -->"
README_END = "<!-- bench-summary:end -->"


#: Largest file ``update_readme`` (``--update-readme``) reads (benchmarks/README.md is ~20 kB).
README_MAX_BYTES = 4 << 20


def read_readme(readme: Path | str, option: str = "update_readme") -> str:
    """The text of the file ``update_readme`` names: a regular UTF-8 file of at most
    :data:`README_MAX_BYTES` (a FIFO, a device such as /dev/zero or a folder is refused,
    naming the option, before anything is read).

    Raises
    ------
    InputError
        Naming ``option``: missing, not a regular file, too large, not UTF-8.
    """
    from optdesign.errors import InputError
    from optdesign.safe_io import UnsafeFileError, read_file

    try:
        # The user named this path: a link to a regular file is followed.
        data = read_file(readme, what=option, limit=README_MAX_BYTES, follow=True)
    except UnsafeFileError as exc:
        raise InputError(option, f"{readme} {exc.reason}") from None
    except OSError as exc:
        raise InputError(option, f"cannot read {readme}: {exc.strerror}") from None
    if data is None:
        raise InputError(option, f"{readme} does not exist")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(option, f"{readme} is not UTF-8 text") from None


def has_readme_markers(text: str) -> bool:
    """Whether ``text`` has the generated block's markers, in order."""
    a, b = text.find(README_BEGIN), text.find(README_END)
    return 0 <= a < b


def update_readme(readme: Path, summary: str) -> bool:
    """Replace the text between the markers of ``readme`` by ``summary``; False if the
    markers are absent. ``readme`` is read as :func:`read_readme` reads it and replaced
    atomically; a link given as ``readme`` is the user's: its target is updated."""
    readme = Path(os.path.realpath(readme))
    text = read_readme(readme)
    if not has_readme_markers(text):
        return False
    a, b = text.find(README_BEGIN), text.find(README_END)
    atomic_write_text(readme, text[: a + len(README_BEGIN)] + "\n" + summary + text[b:])
    return True


def profiles(
    rows: Sequence[BenchRow], configs: Sequence[str]
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Time and gap performance profiles of the single-objective configurations."""
    single = [c for c in configs if get_config(c).kind not in ("front", "debug")]
    chosen = [r for r in rows if r.config in single]
    taus_t = np.logspace(0, 3, 200)
    taus_g = np.logspace(0, 6, 200)
    _, Tt = measure_table(chosen, single, "time")
    _, Tg = measure_table(chosen, single, "gap")
    return {
        "time": (taus_t, performance_profile(Tt, taus_t)),
        "gap": (taus_g, performance_profile(Tg, taus_g, floor=GAP_FLOOR)),
    }


def profiles_figure(rows: Sequence[BenchRow], configs: Sequence[str]):
    """The profiles as a matplotlib Figure."""
    from optdesign.display.profiles import plot_profiles

    single = [c for c in configs if get_config(c).kind not in ("front", "debug")]
    return plot_profiles(profiles(rows, configs), single, gap_floor=GAP_FLOOR)
