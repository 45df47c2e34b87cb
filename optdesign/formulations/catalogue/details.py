"""The catalogue formulation's typed record (``result.details["catalogue"]``): how the
exact catalogue optimum was found, and what a MINLP back-end did with the items.

``result.json`` writes it under ``"extra"`` as ``"catalogue"``, with the keys earlier
releases wrote.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from optdesign.solvers.details import fields_json


@dataclass
class CatalogueCombination:
    """One combination of catalogue items solved by the enumeration."""

    items: dict[str, float]
    status: str
    objective: float


@dataclass
class MINLPDetails:
    """What a MINLP back-end did with a catalogue problem (method ``"minlp"``).

    Attributes
    ----------
    solver, algorithm, status
        The back-end (``"bonmin"``), its algorithm and its return status.
    binaries, groups
        One-hot binaries of the encoding, and the catalogue variables of each group.
    seconds
        Time of the encoding and the MINLP solve.
    items, objective_scaled
        The items it chose and its objective (the NLP's scaled one); None when it found
        no integer-feasible point.
    """

    solver: str
    algorithm: str
    status: str
    binaries: int
    groups: list[list[str]]
    seconds: float
    items: dict[str, float] | None = None
    objective_scaled: float | None = None

    def to_json(self) -> dict[str, Any]:
        return fields_json(self, ("items", "objective_scaled"))


@dataclass
class CatalogueDetails:
    """How the exact catalogue optimum was found (:func:`optdesign.formulations.catalogue.search.
    solve_catalogue`).

    Attributes
    ----------
    method
        ``"enumerate"``, ``"bnb"`` or ``"minlp"`` (a MINLP back-end picked the items).
    combinations
        Number of item combinations.
    variables
        The catalogue values of each discrete variable.
    relaxation_bound, relaxation_status, relaxation_design
        The continuous relaxation (every catalogue range at once): its optimum (None when
        it failed), status and design - a lower bound of the catalogue optimum.
    relaxation_angles
        The grid angles the relaxation was solved on: fewer than the problem's when the
        branch and bound solved it on every other angle (a relaxation of the relaxation,
        so still a lower bound, a little weaker); None: the problem's own grid.
    starts_per_node
        Multistart of each node's NLP.
    enumerated
        Every combination and its solve (enumeration only).
    nodes, pruned, infeasible, leaves
        Branch-and-bound counts (branch and bound only).
    seeded
        Nodes solved for the first incumbents (a front's neighbouring optima).
    warm_fallbacks
        Warm nodes that fell back to the full multistart.
    implied_infeasible
        Boxes proved infeasible with no NLP (:class:`~optdesign.formulations.catalogue.bnb.
        InfeasibleBoxes`).
    minlp
        What the MINLP back-end did (method ``"minlp"`` only).
    nlp_solves
        NLP solves spent.
    thinned_solves
        Of those, the solves on every other grid angle (nodes of several item
        combinations).
    checked_starts, resolved_starts
        Starts solved on every other grid angle first (each leaf's, each node's of a
        search that prunes ties): those whose point met every row left out and was kept
        (a KKT point of the node's own NLP, no solve on the whole grid), and those solved
        again on the whole grid from there (each counted twice in ``nlp_solves``).
    first_solver, first_starts, first_failed, first_certified
        The back-end that tried the starts of nodes of several item combinations first
        (:class:`~optdesign.solvers.registry.NodeFirst`; None: none), the starts it
        tried, those it did not solve (each counted twice in ``nlp_solves``), and of
        those the ones its phase 1 certified locally infeasible; the others the node's
        back-end solved again from the same point
        (:mod:`~optdesign.formulations.catalogue.first_solver`).
    learned_angles
        Grid angles (labels) the thinned grid kept besides every other one: where a
        checked start's point missed a row left out (this search's, or an earlier one's
        of the same front).
    items
        The items chosen (None: no feasible combination).
    gap_to_relaxation_rel
        (optimum - relaxation bound) / |relaxation bound| (None without a bound).
    """

    method: str
    combinations: int
    variables: dict[str, list[float]]
    relaxation_bound: float | None
    relaxation_status: str
    relaxation_design: dict[str, float | None]
    starts_per_node: int
    relaxation_angles: int | None = None
    enumerated: list[CatalogueCombination] | None = None
    nodes: int | None = None
    pruned: int | None = None
    infeasible: int | None = None
    leaves: int | None = None
    seeded: int | None = None
    warm_fallbacks: int | None = None
    implied_infeasible: int | None = None
    minlp: MINLPDetails | None = None
    nlp_solves: int = 0
    thinned_solves: int = 0
    checked_starts: int = 0
    resolved_starts: int = 0
    first_solver: str | None = None
    first_starts: int = 0
    first_failed: int = 0
    first_certified: int = 0
    learned_angles: list[str] = field(default_factory=list)
    items: dict[str, float] | None = None
    gap_to_relaxation_rel: float | None = None
    #: The boxes the search proved infeasible, with the epsilon limits of each proof
    #: (:class:`~optdesign.formulations.catalogue.bnb.InfeasibleBoxes`): the neighbouring
    #: items of the optimum read them before solving. In memory only (not in result.json).
    infeasible_boxes: list[tuple[dict[str, tuple[float, float]], dict[str, float]]] = field(
        default_factory=list, repr=False
    )

    def to_json(self) -> dict[str, Any]:
        out = fields_json(
            self,
            (
                "enumerated",
                "nodes",
                "pruned",
                "infeasible",
                "leaves",
                "seeded",
                "warm_fallbacks",
                "implied_infeasible",
                "minlp",
                "items",
                "gap_to_relaxation_rel",
                "first_solver",
            ),
        )
        if self.enumerated is not None:
            out["enumerated"] = [asdict(row) for row in self.enumerated]
        if self.minlp is not None:
            out["minlp"] = self.minlp.to_json()
        out.pop("infeasible_boxes")
        return out

    def extra(self) -> dict[str, Any]:
        """Its keys in ``result.json``'s ``"extra"`` object: one, ``"catalogue"``."""
        return {"catalogue": self.to_json()}
