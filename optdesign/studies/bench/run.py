"""The whole benchmark: tasks of (instance, configuration), streamed through the runner's
checkpointed store, then gaps, statistics, profiles and the summary."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from optdesign.errors import InputError, OptDesignError
from optdesign.problem.design_problem import DesignProblem
from optdesign.runtime.run_options import study_folder
from optdesign.safe_io import read_file
from optdesign.storage import atomic_write_text
from optdesign.store_identity import identity_key
from optdesign.studies.bench.configs import default_configs, get_config, preload_modules
from optdesign.studies.bench.instances import Instance, coverage, user_instances
from optdesign.studies.bench.instances import suite as build_suite
from optdesign.studies.bench.rows import BenchRow
from optdesign.studies.bench.sandbox import run_task
from optdesign.studies.bench.scoring import ConfigStats, add_gaps, config_stats


@dataclass
class BenchReport:
    """What a benchmark run produced.

    Attributes
    ----------
    rows
        One :class:`~optdesign.studies.bench.rows.BenchRow` per (instance, configuration)
        run, with its gap to the best known value.
    configs
        The configurations run.
    stats
        Per configuration: runs, success and solved rates, median time and gap, failures.
    summary_markdown
        The summary tables (Markdown).
    paths
        Files written (CSV, profiles PNG, summary).
    wall_time_s
        Wall time of the whole benchmark (resumed runs included).
    skipped
        Registered mechanisms the seeded suite has no instances of, with the reason
        (empty for the caller's own problems).
    """

    rows: list[BenchRow]
    configs: list[str]
    stats: dict[str, ConfigStats] = field(default_factory=dict)
    summary_markdown: str = ""
    paths: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0
    skipped: dict[str, str] = field(default_factory=dict)

    def summary(self) -> str:
        return self.summary_markdown

    def to_frame(self):
        """A pandas DataFrame of the runs (one row per instance and configuration)."""
        import pandas as pd

        keep = (
            "instance",
            "config",
            "kind",
            "status",
            "success",
            "objective",
            "gap",
            "time_s",
            "iterations",
            "reason",
        )
        return pd.DataFrame([{k: getattr(r, k) for k in keep} for r in self.rows])

    def plot(self, ax=None):
        """Dolan-More profiles (time and gap) of the single-objective configurations."""
        from optdesign.studies.bench.report import profiles_figure

        return profiles_figure(self.rows, self.configs)


def make_tasks(
    instances: Sequence[Instance], configs: Sequence[str], time_limit: float, hard_timeout: float
) -> list[dict[str, Any]]:
    """One task per (instance, configuration); fronts only with front configurations."""
    tasks = []
    for inst in instances:
        problem = None
        for name in configs:
            c = get_config(name)
            if (c.kind == "front") != inst.is_front and c.kind != "debug":
                continue
            if c.applies is not None:
                problem = problem or inst.problem()
                if not c.applies(problem):
                    continue
            task = {
                "id": f"{inst.id}|{name}",
                "family": inst.family,
                "seed": inst.seed,
                "config": name,
                "time_limit": time_limit * c.time_factor,
                "hard_timeout": hard_timeout * c.time_factor,
            }
            if inst.given is not None:
                task["problem"] = inst.given
            tasks.append(task)
    return tasks


def run_bench(
    suite: str | None = "default",
    configs: Sequence[str] | None = None,
    out: Path | str | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    time_limit: float = 1.0,
    hard_timeout: float | None = None,
    instances: Sequence[Instance] | None = None,
    problems: Sequence[DesignProblem] | None = None,
    overwrite: bool = False,
) -> BenchReport:
    """Run the benchmark, stream rows to ``out/bench_runs.jsonl``, write CSV, profiles and
    the summary into ``out`` (a new temporary folder by default: never over committed
    files).

    ``problems`` (the caller's own) or ``instances`` replace the suite's instances.
    ``overwrite`` starts afresh in a folder that holds a previous run's store (otherwise
    refused unless ``resume``).
    """
    from optdesign.runtime.runner import Isolation, run_tasks
    from optdesign.studies.bench.report import write_outputs
    from optdesign.studies.bench.sandbox import failed_run, row_check

    names = list(configs) if configs else default_configs()
    for c in names:
        get_config(c)  # InputError naming the unknown one
    if workers < 1:
        raise InputError("workers", f"need at least 1 worker, got {workers}")
    hard = hard_timeout if hard_timeout is not None else time_limit + 3.0
    skipped: dict[str, str] = {}
    if problems is not None:
        instances = user_instances(problems)
        suite_name = "user"
    elif instances is None:
        skipped = coverage().skipped
        suite_name = suite or "default"
        wants_fronts = any(get_config(c).kind == "front" for c in names)
        try:
            instances = build_suite(suite_name, fronts=wants_fronts)
        except KeyError as exc:
            raise InputError("suite", str(exc).strip("'\"")) from None
    else:
        suite_name = suite or "custom"
    tasks = make_tasks(instances, names, time_limit, hard)
    # Solver libraries imported here, before the workers and the runs' children are
    # forked: a run's time is then its solve, not the import of its library.
    preload_modules(names)
    out = study_folder(out, "bench")
    store = out / "bench_runs.jsonl"
    key = bench_identity(suite_name, tasks, time_limit, hard, problems)
    t0 = time.perf_counter()
    records = run_tasks(
        tasks,
        run_task,
        store,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        progress="bench" if progress else False,
        key=key,
        overwrite=overwrite,
        isolate=Isolation(timeout="hard_timeout", failure=failed_run, quiet=True),
        check=row_check(tasks),
    )
    wall = time.perf_counter() - t0
    # Wall time over all invocations of this run (a resumed run adds to the stored one).
    meta_path = out / "bench_meta.json"
    key_text = identity_key(key)
    if resume:
        wall += _stored_wall(meta_path, key_text)
    atomic_write_text(meta_path, json.dumps({"key": key_text, "wall_time_s": wall}))
    # The one place a stored (or just computed) JSON row becomes a BenchRow; each was
    # checked by from_dict on resume (row_check) or comes from the sandbox.
    rows = add_gaps([BenchRow.from_dict(records[t["id"]]) for t in tasks if t["id"] in records])
    paths = write_outputs(rows, out, names, suite_name, wall, time_limit, hard, skipped)
    single = [c for c in names if get_config(c).kind not in ("front", "debug")]
    return BenchReport(
        rows=rows,
        configs=names,
        stats=config_stats([r for r in rows if r.config in single], single),
        summary_markdown=paths["summary_text"],
        paths=paths,
        wall_time_s=wall,
        skipped=skipped,
    )


def bench_identity(
    suite_name: str,
    tasks: Sequence[dict[str, Any]],
    time_limit: float,
    hard: float,
    problems: Sequence[DesignProblem] | None,
) -> dict[str, Any]:
    """The identity of a benchmark's store: suite, runs (instances x configurations),
    time limits, optdesign version (instances and configurations are code) and, for the
    caller's own problems, each one's content, formulation and ``[solver]`` table."""
    from optdesign.runtime.identity import problem_digest, solver_identity, version

    identity: dict[str, Any] = {
        "suite": suite_name,
        "runs": [t["id"] for t in tasks],
        "time_limit": time_limit,
        "hard_timeout": hard,
        "optdesign": version(),
    }
    if problems is not None:
        from optdesign.formulations.nlp.solve import formulation_for

        identity["problems"] = [
            {
                "problem": problem_digest(p),
                "formulation": formulation_for(p).fingerprint,
                "solver": solver_identity(p, "")["file"],
            }
            for p in problems
        ]
    return identity


def _stored_wall(meta_path: Path, key: str | None) -> float:
    """Wall time of the earlier invocations of this run (0 if none, or not this run's)."""
    try:
        meta = json.loads(read_file(meta_path, what="the bench meta file", limit=1 << 16) or b"{}")
        wall = float(meta.get("wall_time_s", 0.0)) if meta.get("key") == key else 0.0
    except (ValueError, TypeError, AttributeError, OptDesignError):
        return 0.0  # not ours, or damaged: the time of this invocation only
    return wall if math.isfinite(wall) and wall >= 0 else 0.0
