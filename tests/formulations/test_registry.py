"""The formulation protocol (issue 22): ``applies(problem, request)`` and ``solve(problem,
request)``, registered by name, and optionally its own ``diagnose``, ``sensitivities`` and
typed record (else the NLP's); ``auto`` takes the first that applies with the caller's
request; a named one that does not apply is refused with its reason; a user's own
formulation is one module (tests/formulation_example.py) and one registration line."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

import optdesign as od
from optdesign.errors import InputError, ProblemError
from optdesign.formulations import registry
from optdesign.formulations.registry import choose_formulation

ROOT = Path(__file__).resolve().parents[2]
FORK = ROOT / "problems" / "fork_min_backlash.toml"
#: One Ipopt start from its declared start converges here with every release allowed (the
#: fork's backlash_rss from its declared start ends locally infeasible with NumPy 1.26).
CRANK = ROOT / "problems" / "cs_min_backlash.toml"
CS = ROOT / "problems" / "cs_min_backlash.toml"
CATALOGUE = ROOT / "problems" / "cs_min_backlash_catalogue.toml"


@pytest.fixture
def single(monkeypatch):
    from formulation_example import SingleStart

    monkeypatch.setattr(registry, "FORMULATIONS", dict(registry.FORMULATIONS))
    formulation = SingleStart()
    od.register_formulation(formulation)  # the one registration line
    return formulation


def test_the_built_in_formulations_in_the_order_auto_tries_them():
    assert od.formulation_names() == ["catalogue", "robust", "gp", "nlp"]


def test_a_users_formulation_is_one_object_and_one_registration_line(single):
    assert od.formulation_names() == ["catalogue", "robust", "gp", "single", "nlp"]
    crank = od.load(CRANK)
    result = od.solve(crank, "single", objective="backlash_rss", seed=7, ranges=False)
    (request,) = single.seen
    assert (request.formulation, request.objective, request.seed) == ("single", "backlash_rss", 7)
    assert result.formulation == "single" and result.status == "optimal"
    nlp = od.solve(crank, "nlp", objective="backlash_rss", starts=1, ranges=False)
    assert result.objective == pytest.approx(nlp.objective, rel=1e-9)
    assert result.objective_name == "backlash_rss"


def test_a_users_formulation_brings_its_own_evidence_and_record(single):
    """The pipeline asks the formulation for its sensitivities and its diagnosis, and
    result.json writes its typed record; no line outside it names it."""
    crank = od.load(CRANK)
    result = od.solve(crank, "single", objective="backlash_rss", ranges=False)
    assert single.evidence == [("sensitivities", "optimal")]
    assert result.sensitivities  # its own: the NLP's would skip a result labelled "single"
    start = dict(zip([v.name for v in crank.free], crank.start(), strict=True))
    assert result.details["single"].start == pytest.approx(start)
    assert result.details.single is result.details["single"]
    assert result.to_dict()["extra"]["single_start"] == pytest.approx(start)
    # a result with no feasible design: its own diagnosis
    solve = single.solve

    def failed(problem, request):
        out = solve(problem, request)
        out.status, out.verified = "infeasible", False
        return out

    single.solve = failed
    od.solve(crank, "single", objective="backlash_rss", ranges=False)
    assert single.evidence[-1] == ("diagnose", "infeasible")


def test_a_formulation_without_evidence_of_its_own_gets_the_nlps(monkeypatch):
    """Only name, applies and solve are required: the diagnosis is then the NLP's, and the
    sensitivities the NLP's (which read only an NLP's own result)."""
    from formulation_example import SingleStart

    monkeypatch.setattr(registry, "FORMULATIONS", dict(registry.FORMULATIONS))
    bare = SimpleNamespace(
        name="bare", description="", applies=SingleStart().applies, solve=SingleStart().solve
    )
    od.register_formulation(bare)
    result = od.solve(CRANK, "bare", objective="backlash_rss", ranges=False)
    assert result.status == "optimal" and result.formulation == "single"
    assert result.sensitivities == [] and result.ranges == {}


def test_auto_takes_a_users_formulation_after_the_built_ins_and_before_nlp(single):
    # the fork is a GP in backlash: gp comes first; the crank-slider is not
    assert choose_formulation(od.load(FORK), "auto") == "gp"
    cs = od.load(CS)
    assert choose_formulation(cs, "auto") == "single"
    # ... and it decides with the request: four starts are not its to run
    request = od.SolveRequest.for_problem(cs, starts=4)
    assert registry.pick_formulation(cs, request).name == "nlp"
    assert choose_formulation(od.load(CATALOGUE), "auto") == "catalogue"


def test_a_named_formulation_that_does_not_apply_is_refused_with_its_reason(single):
    with pytest.raises(ProblemError, match=r"^formulation='single': runs one start, 4 asked$"):
        od.solve(CS, "single", starts=4)
    assert single.seen == []  # refused before any work
    with pytest.raises(
        ProblemError, match="formulation='single': a catalogue variable needs the catalogue"
    ):
        od.solve(CATALOGUE, "single")
    with pytest.raises(ProblemError, match=r"formulation='robust': robust design needs a \["):
        od.solve(CS, "robust")
    with pytest.raises(ProblemError, match="formulation='catalogue': no variable takes catalogue"):
        od.solve(CS, "catalogue")


def test_the_names_checked_are_the_registered_ones(single):
    with pytest.raises(InputError, match=r"formulation: unknown formulation 'singel'"):
        od.solve(CS, "singel")
    with pytest.raises(InputError, match="registered already"):
        od.register_formulation(single)
    with pytest.raises(InputError, match=r"register_formulation\.solve: .* has no solve"):
        od.register_formulation(SimpleNamespace(name="half", applies=lambda p, r: True))
    assert "half" not in od.formulation_names()
