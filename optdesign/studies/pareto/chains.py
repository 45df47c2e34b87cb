"""The task graph of an epsilon-constraint front: anchors, then warm-started chains.

Two objectives: :class:`TwoChains` adds the sweep's tasks as records come in (the
``expand`` hook of :func:`~optdesign.runtime.runner.run_tasks`): one chain ascends from
anchor A, the other descends from anchor B, and they meet wherever they meet. Three
objectives: :func:`three_objective_tasks` builds the rows of a grid once the anchors are
in.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from optdesign.errors import InfeasibleRequirementsError
from optdesign.formulations.diagnosis import violated_text
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.pareto.tasks import ANCHOR_SLACK
from optdesign.tolerances import OBJECTIVE_TIE_TOL


def anchor_tasks(
    common: Mapping[str, Any], objectives: Sequence[str], starts: int, seed: int, agree: int | None
) -> list[dict[str, Any]]:
    """Two tasks per objective: its multistart (``anchor-{name}-ms``), then its
    lexicographic tie-breaks (``anchor-{name}``, the anchor). The multistarts come first
    in the list, so that with several workers they run side by side."""
    m = len(objectives)
    ms, ties = [], []
    for k, name in enumerate(objectives):
        order = [name] + [objectives[(k + j) % m] for j in range(1, m)]
        base = {**common, "order": order}
        ms.append(
            {
                **base,
                "id": f"anchor-{name}-ms",
                "kind": "anchor-multistart",
                "starts": starts,
                "seed": seed,
                "agree": agree,
            }
        )
        ties.append(
            {
                **base,
                "id": f"anchor-{name}",
                "kind": "anchor",
                "multistart": f"anchor-{name}-ms",
                "after": [f"anchor-{name}-ms"],
            }
        )
    return ms + ties


class NoFeasibleAnchor(InfeasibleRequirementsError):
    """An anchor of a front (the optimum of one objective) has no feasible design: the
    front cannot be traced. The message names the requirements the best point found
    violates, by name and amount in the problem file's units."""

    def __init__(self, objective: str, record: PointRecord, problem: Any = None):
        self.objective = objective
        self.record = record
        super().__init__(anchor_message(objective, record, problem))


def anchor_message(objective: str, rec: PointRecord, problem: Any = None) -> str:
    """Why anchor ``objective`` failed, in one line."""
    head = f"anchor {objective}: no feasible design found (status {rec.status})"
    free = [v.name for v in problem.free] if problem is not None else []
    if problem is None or not rec.design or any(k not in rec.design for k in free):
        return f"{head}; violated: {', '.join(rec.violated) or 'none reported'}"
    shown = violated_text(problem, np.array([rec.design[k] for k in free]))
    if not shown:
        return (
            f"{head}: no requirement is violated at the best point found (the solver "
            f"stopped: {rec.message or rec.status}); more starts (starts=) may find one"
        )
    return (
        f"{head}; at the best point found: {shown}; od.solve (optdesign solve) gives the "
        "smallest relaxation of each"
    )


def check_anchor(rec: PointRecord, name: str, problem: Any = None) -> None:
    """Raise :class:`NoFeasibleAnchor` unless ``rec`` is a verified feasible anchor."""
    if not rec.success:
        raise NoFeasibleAnchor(name, rec, problem)


def ideal_reached(anchor_a: PointRecord, optimum_b: PointRecord, b: str) -> bool:
    """Whether anchor A (the least A, then the least B there) also has the least B
    (``optimum_b``'s, to the tie tolerance): that design is then at least as good as any
    other in both objectives, and the front is that one point. Swept anyway, its points
    are the same design up to the solver's tolerance (a front of near-copies that
    differ in the 8th digit)."""
    least = optimum_b.objectives[b]
    return anchor_a.objectives[b] <= least + OBJECTIVE_TIE_TOL * max(abs(least), 1e-300)


class TwoChains:
    """The tasks of a two-objective sweep, decided as records come in.

    Two warm-started chains: one ascends from anchor A (points 0, 1, ...), the other
    descends from anchor B (n-1, n-2, ...). A finished point adds its successor unless
    the other chain has it already, so the chains meet wherever they meet: with two
    workers the chain whose anchor is ready first does more points, instead of a worker
    idling while the other anchor's tie-break runs. With one worker they alternate and
    meet in the middle (deterministic). With ``split`` the chains meet at that index
    whatever the timing: the same front for any number of workers.

    Arc spacing (default) normalises the objectives by a frame from anchor A and anchor
    B's *multistart* optimum, so chain A can start while B's tie-break still runs; the
    last point (epsilon = A at the tie-broken anchor B) is exact. Uniform or explicit
    epsilon values, and a fixed ``split``, need both tie-broken anchors before the first
    point: the frame is then the front's own two ends (B's multistart optimum is one
    point of a set when B's optimum is not unique).
    """

    def __init__(
        self,
        objectives: Sequence[str],
        n: int,
        name: str,
        common: Mapping[str, Any],
        spacing: str,
        eps_values: Sequence[float] | None,
        split: int | None = None,
    ):
        self.a, self.b = objectives
        self.split = split
        self.n, self.name, self.common, self.spacing = n, name, dict(common), spacing
        self.eps_values = None if eps_values is None else [float(v) for v in eps_values]
        self.frame: dict[str, float] | None = None
        #: the anchors reach both objectives' least values: the front is one point
        self.single = False
        self.claimed: set[int] = set()
        self.tasks: list[dict[str, Any]] = []

    def __call__(
        self, task: Mapping[str, Any], record: Mapping[str, Any], done: Mapping[str, Any]
    ) -> list[dict[str, Any]]:
        a, b, n = self.a, self.b, self.n
        tie_a, ms_b, tie_b = f"anchor-{a}", f"anchor-{b}-ms", f"anchor-{b}"
        new: list[dict[str, Any]] = []
        if self.frame is None and tie_a in done and ms_b in done:
            # Uniform or explicit epsilon need B's tie-break; so does a fixed split: its
            # frame then rests on the two ends of the front, not on whichever point of B's
            # optimal set the multistart returned.
            arc = self.spacing == "arc" and self.eps_values is None and self.split is None
            if arc or tie_b in done:
                rec_a = PointRecord.from_dict(done[tie_a])
                check_anchor(rec_a, a, self.common.get("problem"))
                far = PointRecord.from_dict(done[ms_b] if arc else done[tie_b])
                check_anchor(far, b, self.common.get("problem"))
                tie = PointRecord.from_dict(done[tie_b]) if tie_b in done else None
                self._make_frame(rec_a, far, tie)
                self.single = ideal_reached(rec_a, far, b)
                new.append(self._point(0, +1, tie_a, done))
        if self.single:
            return new  # point 0 is the front
        if self.frame is not None and tie_b in done and n - 1 not in self.claimed:
            check_anchor(PointRecord.from_dict(done[tie_b]), b, self.common.get("problem"))
            new.append(self._point(n - 1, -1, tie_b, done))
        if task.get("kind") == "eps" and task["id"].startswith(f"{self.name}-"):
            # The ascending chain stops before n-1: that point's epsilon is A at the
            # tie-broken anchor B, which the descending chain starts from.
            j = task["index"] + task["dir"]
            # With a fixed split the ascending chain owns 0..split-1, the other the rest.
            own = self.split is None or (j < self.split) == (task["dir"] > 0)
            if 0 < j < n - 1 and j not in self.claimed and own:
                new.append(self._point(j, task["dir"], task["id"], done))
        return new

    def _make_frame(self, anchor_a: PointRecord, far_b: PointRecord, tie_b) -> None:
        a, b = self.a, self.b
        lo = anchor_a.objectives[a] * (1 + ANCHOR_SLACK) + 1e-12
        hi = far_b.objectives[a]
        if self.eps_values is None and self.spacing == "uniform":
            hi = tie_b.objectives[a]
            self.eps_values = [float(v) for v in np.linspace(lo, hi, self.n)]
        self.frame = {
            "a0": anchor_a.objectives[a],
            "b0": anchor_a.objectives[b],
            "ra": max(hi - anchor_a.objectives[a], 1e-300),
            "rb": max(anchor_a.objectives[b] - far_b.objectives[b], 1e-300),
            "a_lo": lo,
            "a_hi": max(hi, lo),
        }

    def _point(self, i: int, d: int, warm: str, done: Mapping[str, Any]) -> dict[str, Any]:
        a, n, f = self.a, self.n, self.frame
        assert f is not None
        self.claimed.add(i)
        task = {
            **self.common,
            "id": f"{self.name}-{i:04d}",
            "kind": "eps",
            "target": self.b,
            "warm": warm,
            "after": [warm],
            "index": i,
            "dir": d,
        }
        if self.eps_values is not None:
            task["eps"] = {a: self.eps_values[i]}
        elif i == 0:
            task["eps"] = {a: f["a_lo"]}
        elif i == n - 1:
            task["eps"] = {a: PointRecord.from_dict(done[f"anchor-{self.b}"]).objectives[a]}
        else:
            task.update(
                eps_name=a,
                arc=i * 2.0 / max(n - 1, 1),
                frame=f,
                fallback_eps=float(f["a_lo"] + (f["a_hi"] - f["a_lo"]) * i / (n - 1)),
            )
        self.tasks.append(task)
        return task


def three_objective_tasks(
    anchors: Mapping[str, PointRecord],
    objectives: Sequence[str],
    n_points: int,
    name: str,
    common: Mapping[str, Any],
) -> list[dict[str, Any]]:
    """Row tasks of a three-objective front ``[A, B, C]``.

    Row r fixes A <= e1[r]. Its head (min B s.t. A <= e1, a chain along e1 from anchor A)
    gives the smallest feasible e2 of the row, so that the row's grid e2 in [B_min(e1),
    B_max] holds no infeasible corner; each row is then a warm-started chain of
    min C s.t. A <= e1, B <= e2 from the tightest e2 up.
    """
    a, b, c = objectives
    n_side = max(2, math.ceil(math.sqrt(n_points)))
    lo_a = anchors[a].objectives[a] * (1 + ANCHOR_SLACK) + 1e-12
    hi_a = max(r.objectives[a] for r in anchors.values())
    hi_b = max(r.objectives[b] for r in anchors.values())
    tasks: list[dict[str, Any]] = []
    prev = f"anchor-{a}"
    for r, v1 in enumerate(np.linspace(lo_a, hi_a, n_side)):
        head = {
            **common,
            "id": f"{name}-{r:03d}-head",
            "kind": "eps",
            "target": b,
            "eps": {a: float(v1), c: math.inf},
            "warm": prev,
            "after": [prev],
            "index": r * (n_side + 1),
            "head": True,
        }
        tasks.append(head)
        prev, row_prev = head["id"], head["id"]
        for k in range(n_side):
            task = {
                **common,
                "id": f"{name}-{r:03d}-{k:03d}",
                "kind": "eps",
                "target": c,
                "eps_row": {a: float(v1)},
                "row_head": head["id"],
                "b_name": b,
                "b_hi": float(hi_b),
                "frac": k / (n_side - 1),
                "warm": row_prev,
                "after": sorted({row_prev, head["id"]}),
                "index": r * (n_side + 1) + k + 1,
                "jump": None,  # grid steps are large: jumps are expected
            }
            tasks.append(task)
            row_prev = task["id"]
    return tasks
