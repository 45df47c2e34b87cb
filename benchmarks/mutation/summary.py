"""Count the outcome of each mutant in ``mutmut results --all true`` output, per module.

Usage: python benchmarks/mutation/summary.py mutmut-results.txt
"""

from __future__ import annotations

import math
import re
import sys
from collections import Counter, defaultdict

LINE = re.compile(r"^\s*(?P<name>[\w.]+)__mutmut_\d+: (?P<status>.+?)\s*$")


def module_of(name: str) -> str:
    """The module of a mutated function's name:
    optdesign.models.loads.x_motor_torque / ...crank_slider.xǁCrankSliderǁjoints."""
    return re.sub(r"\.(x[ΛǁŁ_].*|[A-Za-z_]+ǁ.*)$", "", name)


def wilson(killed: int, tried: int, z: float = 1.96) -> tuple[float, float]:
    """The 95 % Wilson score interval of a kill rate (for a sampled run)."""
    if tried == 0:
        return (0.0, 1.0)
    p = killed / tried
    centre = (p + z * z / (2 * tried)) / (1 + z * z / tried)
    half = z * math.sqrt(p * (1 - p) / tried + z * z / (4 * tried * tried)) / (1 + z * z / tried)
    return (centre - half, centre + half)


def main(path: str) -> int:
    per_module: dict[str, Counter] = defaultdict(Counter)
    survivors: list[str] = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            match = LINE.match(line)
            if not match:
                continue
            name, status = match["name"], match["status"]
            module = module_of(name)
            per_module[module][status] += 1
            if status == "survived":
                survivors.append(line.strip().split(":")[0])
    total: Counter = Counter()
    print(f"{'module':45s} {'tried':>6s} {'killed':>7s} {'survived':>9s} {'timeout':>8s} other")
    for module in sorted(per_module):
        c = per_module[module]
        total.update(c)
        other = sum(v for k, v in c.items() if k not in ("killed", "survived", "timeout"))
        print(
            f"{module:45s} {sum(c.values()):6d} {c['killed']:7d} {c['survived']:9d} "
            f"{c['timeout']:8d} {other}"
        )
    tried = sum(total.values())
    other = sum(v for k, v in total.items() if k not in ("killed", "survived", "timeout"))
    print(
        f"{'total':45s} {tried:6d} {total['killed']:7d} {total['survived']:9d} "
        f"{total['timeout']:8d} {other}"
    )
    # a mutant not run, or whose tests hung (stopped by watchdog.py: "suspicious"), is
    # neither killed nor survived: left out of the rate, and counted on its own line
    unjudged = total["suspicious"] + total["not checked"]
    judged = tried - unjudged
    if judged:
        killed = total["killed"] + total["timeout"]
        low, high = wilson(killed, judged)
        print(
            f"killed (timeouts count as killed): {killed} of {judged} judged, "
            f"{100 * killed / judged:.1f} % (95 % interval if sampled: "
            f"{100 * low:.1f}-{100 * high:.1f} %); not judged: {unjudged}"
        )
    print(
        "other statuses:",
        dict((k, v) for k, v in total.items() if k not in ("killed", "survived", "timeout")),
    )
    print("survivors:")
    for s in survivors:
        print("  " + s)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
