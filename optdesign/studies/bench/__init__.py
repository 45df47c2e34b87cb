"""Solver benchmarks: seeded instances from every mechanism (or the caller's problems) x
configurations, each run sandboxed with a hard timeout and checked independently, then
gaps, Dolan-More profiles and the summary.

- :mod:`.configs`: the configurations registry (solver back-ends, GP, DE, fronts);
- :mod:`.instances`: instance families from the mechanisms, the shipped problems;
- :mod:`.sandbox`: one run in a forked child; :mod:`.rows`: :class:`BenchRow`, one run's
  typed record (the stored JSON line); :mod:`.metrics`: gaps, profiles, stats;
- :mod:`.report`: CSV, PNG and the Markdown summary; :mod:`.run`: :func:`run_bench`.
"""

from optdesign.studies.bench.configs import (
    CONFIGS,
    Config,
    NotApplicable,
    default_configs,
    get_config,
    register_config,
)
from optdesign.studies.bench.rows import BenchRow
from optdesign.studies.bench.run import BenchReport, make_tasks, run_bench

__all__ = [
    "CONFIGS",
    "BenchReport",
    "BenchRow",
    "Config",
    "NotApplicable",
    "default_configs",
    "get_config",
    "make_tasks",
    "register_config",
    "run_bench",
]
