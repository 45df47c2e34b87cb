"""A seeded sample of mutants, stratified by module, from ``mutmut results --all true``.

Usage: python benchmarks/mutation/sample.py mutmut-all.txt FRACTION SEED > sample.txt

Each module contributes ``ceil(FRACTION * n)`` of its ``n`` mutants, drawn without
replacement by a generator seeded with SEED, so the same tree gives the same sample,
printed in a seeded random order.
"""

from __future__ import annotations

import math
import random
import sys
from collections import defaultdict

from summary import LINE, module_of


def main(path: str, fraction: float, seed: int) -> int:
    if not 0 < fraction <= 1:
        raise SystemExit(f"FRACTION must be in (0, 1], got {fraction}")
    by_module: dict[str, list[str]] = defaultdict(list)
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            match = LINE.match(line)
            if match:
                full = line.strip().split(":")[0]
                by_module[module_of(match["name"])].append(full)
    rng = random.Random(seed)
    sample = []
    for module in sorted(by_module):
        names = sorted(by_module[module])
        sample += rng.sample(names, math.ceil(fraction * len(names)))
    # in a seeded random order: the mutants run in chunks, so the part of the sample a
    # stopped run got through is itself a random sample
    rng.shuffle(sample)
    print("\n".join(sample))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], float(sys.argv[2]), int(sys.argv[3])))
