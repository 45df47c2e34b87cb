"""Catalogue variables whose items only the requirements read, and the item a node's
design already meets.

A catalogue variable is *objective-free* when neither its value nor any parameter read
from its item (:func:`~optdesign.problem.drive.parameter_owners`) enters the searched
objective (:meth:`~optdesign.programs.nlp.NLP.objective_reads`, structurally). When no
row reads its value either - only its item data enter the rows (a motor's number under
a backlash objective) - its items differ only in which designs they allow, and its
relaxed value lies wherever the start left it. The branch and bound
(:mod:`optdesign.formulations.catalogue.bnb`) then treats it in two ways
(:func:`split_last_variables`):

- it is split last, once the other catalogue variables sit on items: splitting it first
  copies the other variables' tree under each of its halves, whose relaxations differ in
  none of their values (only its rows read its data);
- at a node whose other variables sit on items ``c``, the node's design is checked
  against each of its items in turn, smallest first (every row and the objective
  evaluated at the design, no NLP: :func:`first_item_met`). The first item ``j`` the
  design meets gives the combination ``(c, j)`` solved as the node's leaf: the design is
  feasible for it, so its value is the node's. The box is then split at ``j`` (below,
  at, above), on this variable first when its sides at and above ``j`` hold no
  combination before ``(c, j)`` in the order of the items (:func:`split_first`): they
  lose a tie with the leaf and go on the node's value, leaving only the side below
  (usually proved infeasible) to solve; else on the others first, down to ``c``.

Why the answer stays the enumeration's: these rules choose *where* a box is split and
*when* a side is solved, never what may be discarded. Every split partitions the box's
item combinations; a side is pruned only by the search's own rule
(:func:`~optdesign.formulations.catalogue.bnb.box_cannot_win`: its bound worse than the
incumbent beyond the tie tolerance, or a tie and no combination of the side before the
incumbent's in the order of the items), on the value of the node it came from - the same
value on which the search already prunes that node's whole box once its leaf is solved
(a sub-box's data are no more favourable, so its value is no lower). Ties are still
decided by value, then by the items in their declared order, wherever the variable is
declared. Nothing here reads the variable's name: a user's catalogue variable whose
data enter only the requirements is treated the same way.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from optdesign.formulations.catalogue.discrete import discrete_variables, items_within
from optdesign.problem.drive import box_has_item, parameter_owners
from optdesign.solvers.multistart import improves
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: Violation of a scaled row (or of a scaled variable bound) still counted as met by a
#: node's design: the node's solve meets its rows to Ipopt's tolerance (1e-9); the check
#: only picks where to split, the leaf it names is solved as any other.
ROW_TOL = 1e-7


def objective_free_variables(ns) -> frozenset[str]:
    """The catalogue variables of the node solver ``ns`` whose value and item data do
    not enter its objective (empty when the back-end's NLP cannot say). A parameter no
    variable claims counts as read from every catalogue variable."""
    dvars = [v.name for v in discrete_variables(ns.problem)]
    try:  # a node solver whose NLP cannot say (a test's double): none
        design, params = ns.nlp.objective_reads(ns.target)
    except (AttributeError, NotImplementedError, RuntimeError):
        return frozenset()
    owners = parameter_owners(ns.problem)
    read = {ns.nlp.design_names[k] for k in design}
    for k in params:
        read.update(owners.get(ns.nlp.param_names[k], dvars))
    return frozenset(name for name in dvars if name not in read)


def split_last_variables(ns) -> frozenset[str]:
    """The catalogue variables the search splits last, at the first item a node's design
    meets: objective-free (:func:`objective_free_variables`) and whose own value no row
    reads either, only their item data do - a relaxed value of such a variable lies
    wherever the start left it, so its distance from an item says nothing. (A screw's
    diameter, objective-free under a backlash objective, moves the design through its
    value: it is split as before.)"""
    import casadi as ca

    free = objective_free_variables(ns)
    if not free:
        return frozenset()
    nlp = ns.nlp
    g = ca.SX(nlp.g)
    return frozenset(
        name for name in free if not ca.depends_on(g, nlp.z[nlp.design_names.index(name)])
    )


def meets(ns, x: np.ndarray, items: Mapping[str, float], value: float) -> bool:
    """Whether the design ``x`` with the catalogue variables of ``items`` set to those
    items meets every row of the node solver's NLP for them (its limits ``eps`` and
    dropped rows included) with an objective no higher than ``value`` (a tie counts)."""
    nlp, problem = ns.nlp, ns.problem
    box = {name: (item, item) for name, item in items.items()}
    node = {v.name: box.get(v.name, (v.lower, v.upper)) for v in discrete_variables(problem)}
    if not box_has_item(problem, node):
        return False
    x = np.array(x, dtype=float, copy=True)
    for name, item in items.items():
        x[ns.names.index(name)] = item
    bounds = nlp.bounds(eps=ns.eps, box=box, parameters=problem.parameter_values(node))
    theta = nlp.parameter_values(bounds.parameters)
    z = nlp.z_from_x(x, bounds.parameters)
    lbg, ubg = np.array(bounds.lbg, dtype=float), np.array(bounds.ubg, dtype=float)
    if ns.free_rows.size:
        lbg[ns.free_rows], ubg[ns.free_rows] = -np.inf, np.inf
    g = np.asarray(nlp.g_fun(z, theta), dtype=float).ravel()
    with np.errstate(invalid="ignore"):
        ok = (
            np.all(np.isfinite(g))
            and np.all(g >= lbg - ROW_TOL)
            and np.all(g <= ubg + ROW_TOL)
            and np.all(z >= bounds.lbz - ROW_TOL)
            and np.all(z <= bounds.ubz + ROW_TOL)
        )
    if not ok:
        return False
    values = np.asarray(nlp.values_fun(z, theta), dtype=float).ravel()
    objective = nlp.objective_of(ns.target, values)
    return bool(np.isfinite(objective)) and not improves(value, objective, OBJECTIVE_TIE_TOL)


def first_item_met(
    ns, box: Mapping[str, tuple[float, float]], design: np.ndarray, value: float,
    name: str, items: Mapping[str, float],
) -> float | None:  # fmt: skip
    """The first item of the variable ``name`` in ``box`` (in the catalogue's order) at
    which the node's ``design`` meets every row, the other catalogue variables on
    ``items``, with an objective no higher than the node's ``value``; None when none."""
    var = ns.problem.by_name[name]
    others = {k: v for k, v in items.items() if k != name}
    for item in sorted(items_within(var.values, *box[name])):
        if meets(ns, design, {**others, name: item}, value):
            return item
    return None


def first_items_met(
    ns, dvars, last: frozenset[str], box, res, items: dict[str, float], worst
) -> tuple[Any, list[str]]:
    """The variable to split at the node ``res`` over ``box`` (None: the node is a leaf of
    the combination ``items``, updated here), given the variables split last (``last``,
    :func:`split_last_variables`), and those of them whose item the design meets.

    When ``worst`` is one of them and every other catalogue variable sits on an item, the
    node is a leaf: ``worst`` takes the first of its items that the design meets (else its
    nearest item), and the node is split on the others' items first, on it last. At a
    leaf, each of them still wide in the box takes the first item the design meets, when
    there is one."""
    from optdesign.formulations.catalogue.branching import on_items

    x = ns.x_of(res)
    if x is None:
        return worst, []
    if worst is not None:
        others = [v for v in dvars if v is not worst]
        if worst.name not in last or on_items(others, box, res)[0] is not None:
            return worst, []
    met = []
    for v in dvars:
        if v.name in last and box[v.name][0] != box[v.name][1]:
            item = first_item_met(ns, box, x, res.objective, v.name, items)
            if item is not None:
                items[v.name] = item
                met.append(v.name)
    return None, met


def split_first(dvars, met: list[str], box, items: Mapping[str, float], names) -> Any:
    """The variable of ``met`` (those whose item the leaf's design meets) to split a
    leaf's box on before the others, or None.

    Split at its item ``j``, the box's sides are it below ``j``, at ``j`` and above
    ``j``. When the side at ``j`` holds no combination before the leaf's in the order of
    the items (``names``: the variables that decide a tie, in their declared order; the
    side above comes later still), the leaf's value prunes both on a tie and only the
    side below is left to solve: the first such variable is returned. Otherwise (the
    box's other variables reach below the leaf's items) the others are split first, down
    to the leaf's items, so that the sides of this variable hold one combination of the
    others each - never a copy of their tree."""
    leaf = tuple(float(items[k]) for k in names)
    for v in dvars:
        if v.name in met:
            at = tuple(float(items[k]) if k == v.name else float(box[k][0]) for k in names)
            if at >= leaf:
                return v
    return None
