"""Control cases: inputs whose verdict is known, to show that the judge is not blind (a
wrong expectation, a file touched outside, raw control characters, a crash, a hang, a
broken output file). Not part of the corpus's counts."""

from __future__ import annotations

import os
import sys
import time
from typing import Any

from hostile_classes.common import SOLVE, api_solve, base
from hostile_classes.model import SUCCESS, Case, refuse

RIPPLE = base("cs_min_ripple")


def _touch(ctx: Any) -> Any:
    (ctx.outside / "victim.txt").write_text("changed\n")
    return None


def _escape(ctx: Any) -> Any:
    sys.stdout.write("\x1b[2Jcleared\n")
    return None


def _abort(ctx: Any) -> Any:
    sys.stdout.flush()
    os.abort()


def _sleep(ctx: Any) -> Any:
    time.sleep(30)


def _formula_csv(ctx: Any) -> Any:
    ctx.out.mkdir(parents=True, exist_ok=True)
    (ctx.out / "front.csv").write_text("method,=cmd|' /C calc'!A0\nepsilon,1\n")
    return None


def _raw_error(ctx: Any) -> Any:
    return {}["missing"]


def cases() -> list[Case]:
    return [
        Case("control:a valid file expected refused", "control", refuse("anything"), text=RIPPLE, api=api_solve),
        Case("control:a valid file", "control", SUCCESS, argv=SOLVE, text=RIPPLE, json=False),
        Case("control:a file written outside", "control", SUCCESS, api=_touch),
        Case("control:an escape sequence printed", "control", SUCCESS, api=_escape),
        Case("control:abort", "control", SUCCESS, api=_abort),
        Case("control:sleeps past its time limit", "control", SUCCESS, api=_sleep, timeout=1),
        Case("control:a formula in front.csv", "control", SUCCESS, api=_formula_csv),
        Case("control:a raw KeyError", "control", refuse("missing"), api=_raw_error),
    ]  # fmt: skip
