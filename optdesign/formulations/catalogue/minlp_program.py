"""The catalogue problem as one mixed-integer NLP (for MINLP solvers such as Bonmin).

Encoding (exact): one-hot binaries over catalogue items. The catalogue variables are
grouped by the item data they share - variables whose items come as rows of one table
(a screw's (d0, lead) pairs with their ratings) form one group, a variable with its own
data (a pin diameter with its table fit) another. Each group ``G`` gets one binary
``b_j`` per valid item ``j`` of the group (a row of the table; only rows that exist),
with

    sum_j b_j = 1,   x_v = sum_j b_j v_j  (each variable v of G),
    theta_k = sum_j b_j theta_k(j)  (each item datum k of G: load rating, fit ratio, ...),

so that at any integer point the NLP is exactly the NLP of the chosen items (the node
NLP of :mod:`optdesign.formulations.catalogue.search` with every catalogue variable fixed). The
continuous relaxation (0 <= b_j <= 1) is the MINLP solver's own; the NLP's rows,
scaling and epsilon rows are the problem's NLP (:func:`optdesign.programs.nlp.build_nlp`)
with its parameters replaced by the expressions above. No SOS1 constraint is used.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.problem.drive import box_has_item
from optdesign.programs.nlp import NLP, Target

#: Above this many item combinations the grouping of the catalogue variables is not
#: computed from the full table (the one-hot encoding would be too large anyway).
MAX_COMBINATIONS = 20_000


@dataclass
class ItemGroup:
    """Catalogue variables that share item data, and their valid items."""

    names: tuple[str, ...]
    items: list[tuple[float, ...]]
    data: dict[str, list[float]] = field(default_factory=dict)  # datum -> value per item
    offset: int = 0  # position of the group's first binary in the MINLP's x


@dataclass
class CatalogueMINLP:
    """``min f(x) s.t. lbg <= g(x) <= ubg, lbx <= x <= ubx``, x = [z; binaries]."""

    nlp: NLP
    x: Any
    f: Any
    g: Any
    lbx: np.ndarray
    ubx: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    discrete: list[bool]
    groups: list[ItemGroup]
    n_z: int

    def start(self, design: np.ndarray, parameters: np.ndarray | None = None) -> np.ndarray:
        """x0 from a design vector: z from the NLP, each group's binaries on the item
        nearest the design (relative distance)."""
        z0 = self.nlp.z_from_x(design, parameters)
        b0 = []
        names = self.nlp.design_names
        for grp in self.groups:
            here = np.array([design[names.index(n)] for n in grp.names])
            dist = [
                np.sum(np.abs(np.array(it) - here) / np.maximum(1.0, np.abs(it)))
                for it in grp.items
            ]
            one = np.zeros(len(grp.items))
            one[int(np.argmin(dist))] = 1.0
            b0.append(one)
        return np.concatenate([z0, *b0])

    def items(self, x: np.ndarray) -> dict[str, float]:
        """The catalogue items chosen at ``x`` (the largest binary of each group)."""
        out: dict[str, float] = {}
        for grp in self.groups:
            b = np.asarray(x[grp.offset : grp.offset + len(grp.items)], dtype=float)
            item = grp.items[int(np.argmax(b))]
            out.update(zip(grp.names, item, strict=True))
        return out


def _table(problem, dvars) -> dict[tuple[float, ...], dict[str, float]]:
    """Item data of every combination of items (valid ones only)."""
    table = {}
    for combo in itertools.product(*(v.values for v in dvars)):
        box = {v.name: (float(c), float(c)) for v, c in zip(dvars, combo, strict=True)}
        if not box_has_item(problem, box):
            continue
        table[tuple(float(c) for c in combo)] = problem.parameter_values(box)
    return table


def item_groups(problem) -> list[ItemGroup]:
    """Group the catalogue variables by the item data (and validity) they share."""
    dvars = discrete_variables(problem)
    n = int(np.prod([len(v.values) for v in dvars]))
    if n > MAX_COMBINATIONS:
        raise ProblemError(
            f"catalogue MINLP: {n} item combinations (at most {MAX_COMBINATIONS} for the encoding)"
        )
    table = _table(problem, dvars)
    if not table:
        raise ProblemError("catalogue MINLP: no valid combination of catalogue items")
    keys = sorted({k for d in table.values() for k in d})
    parent = list(range(len(dvars)))

    def find(i):
        while parent[i] != i:
            i = parent[i]
        return i

    # a datum (or validity) that changes with variable i and with variable j joins them
    depends: dict[str, set[int]] = {k: set() for k in [*keys, "__valid__"]}
    combos = list(itertools.product(*(v.values for v in dvars)))
    for combo in combos:
        c = tuple(float(x) for x in combo)
        for i, v in enumerate(dvars):
            for other in v.values:
                c2 = (*c[:i], float(other), *c[i + 1 :])
                a, b = table.get(c), table.get(c2)
                if (a is None) != (b is None):
                    depends["__valid__"].add(i)
                elif a is not None and b is not None:
                    for k in keys:
                        if a.get(k) != b.get(k):
                            depends[k].add(i)
    for members in depends.values():
        members = sorted(members)
        for j in members[1:]:
            parent[find(j)] = find(members[0])
    roots = sorted({find(i) for i in range(len(dvars))})
    groups = []
    for r in roots:
        idx = [i for i in range(len(dvars)) if find(i) == r]
        own = [k for k in keys if depends[k] and depends[k] <= set(idx)]
        items: dict[tuple[float, ...], dict[str, float]] = {}
        for c, data in table.items():
            key = tuple(c[i] for i in idx)
            items.setdefault(key, {k: data[k] for k in own})
        ordered = sorted(items)
        groups.append(
            ItemGroup(
                tuple(dvars[i].name for i in idx),
                ordered,
                {k: [items[it][k] for it in ordered] for k in own},
            )
        )
    # the valid combinations must be the product of the groups' items (else one group)
    if len(groups) > 1:
        prod = 1
        for g in groups:
            prod *= len(g.items)
        if prod != len(table):
            names = tuple(v.name for v in dvars)
            ordered = sorted(table)
            groups = [ItemGroup(names, ordered, {k: [table[c][k] for c in ordered] for k in keys})]
    return groups


def build_catalogue_minlp(
    problem,
    nlp: NLP,
    target: Target,
    eps: Mapping[str, float] | None = None,
) -> CatalogueMINLP:
    """The one-hot MINLP of ``problem``'s NLP ``nlp`` for ``target`` (see the module
    docstring), with epsilon limits ``eps``."""
    groups = item_groups(problem)
    n_z = int(nlp.z.numel())
    n_b = sum(len(g.items) for g in groups)
    sym = ca.SX if isinstance(nlp.z, ca.SX) else ca.MX
    b = sym.sym("b", n_b)
    theta = [ca.DM(float(v)) for v in nlp.param_defaults]
    link, lo, hi = [], [], []
    x_lo, x_span = nlp.x_lo, nlp.x_span
    names = nlp.design_names
    offset = 0
    for grp in groups:
        grp.offset = n_z + offset
        bg = b[offset : offset + len(grp.items)]
        offset += len(grp.items)
        link.append(ca.sum1(bg) - 1)
        lo.append(0.0)
        hi.append(0.0)
        for pos, name in enumerate(grp.names):
            k = names.index(name)
            vals = np.array([it[pos] for it in grp.items])
            # in the NLP's scaled variable: z_k = (x - x_lo) / x_span
            link.append(nlp.z[k] - ca.dot(bg, ca.DM((vals - x_lo[k]) / x_span[k])))
            lo.append(0.0)
            hi.append(0.0)
        for datum, vals in grp.data.items():
            if datum in nlp.param_names:
                theta[nlp.param_names.index(datum)] = ca.dot(bg, ca.DM(vals))
    bounds = nlp.bounds(eps=eps)
    p_num = nlp.params(target)
    weights = ca.DM(p_num[: len(nlp.targets)])
    fg = ca.Function("fg", [nlp.z, nlp.p], [nlp.f, nlp.g])
    f, g = fg(nlp.z, ca.vertcat(weights, *theta))
    x = ca.vertcat(nlp.z, b)
    return CatalogueMINLP(
        nlp,
        x,
        f,
        ca.vertcat(g, *link),
        np.concatenate([bounds.lbz, np.zeros(n_b)]),
        np.concatenate([bounds.ubz, np.ones(n_b)]),
        np.concatenate([bounds.lbg, lo]),
        np.concatenate([bounds.ubg, hi]),
        [False] * n_z + [True] * n_b,
        groups,
        n_z,
    )
