"""The house's layers, drawn from the code's own imports (issue 22): every ``import`` of
an optdesign module in optdesign/ - at module top or inside a function - is an arrow, and
the arrows form no circle and never point up the layers of the architecture:

shared utilities -> models -> mechanisms -> problem -> programs -> solvers -> runtime ->
search -> formulations -> views -> studies -> api -> cli, commands, plots, reports,
reproduce.

The programs (the NLP with its bounds, starts and targets; the GP's data) are what the
solvers take, so they sit below them. The formulations (one package each: nlp, gp,
catalogue, robust, with their solve, diagnosis, sensitivities and typed record, and the
registry that chooses among them) use the solvers, the execution engine and the global
search, so they sit above them and below the studies (pareto, sweep, bench, the solve
pipeline) that use them. The views (what a page or a figure shows of a design,
evaluated: its objectives, binding and violated rows, curves over the stroke, sketch
frames and facts) read the problem and the solvers' rows, so they sit above them; the
reports and plots format and draw the views' records and evaluate no model themselves
(:func:`test_reports_and_plots_evaluate_no_model`).

Imports under ``if TYPE_CHECKING:`` are annotations, not arrows, and are left out.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "optdesign"

#: the layers from the bottom up, by the first name under ``optdesign.``.
LAYERS: list[tuple[str, ...]] = [
    # shared utilities: no knowledge of a mechanism, a problem or a solver
    (
        "errors",
        "units",
        "unit_grammar",
        "math",
        "text",
        "tolerances",
        "argument_checks",
        "safe_io",
        "interrupts",
        "pipes",
        "user_code",
        "data",
        "store_identity",
        "storage",
        "display",  # numbers, tables, limits and figures in the user's units
    ),
    ("models", "fits"),  # optdesign.fits: the public entry to the ISO 286 models
    ("mechanisms",),
    ("problem",),
    ("programs",),  # the mathematical programs the solvers take: NLP, GP
    ("solvers",),
    ("runtime",),  # the execution engine: tasks, worker processes, stores' identity
    ("search",),  # the global search: starts, stopping rule, odds
    ("formulations",),  # one package per formulation: solve, diagnose, sensitivities
    ("views",),  # what a page or a figure shows of a design, evaluated
    ("studies",),
    ("api", "validation"),
    ("cli", "__main__", "commands", "plots", "reports", "reproduce"),
]

#: the one arrow allowed upwards: a result's and a front's methods (``result.summary()``,
#: ``front.plot()``) are the public API's entry points to the reports and plots that read
#: them; they import on call, and nothing they reach imports the record back.
ENTRY_POINTS = {
    ("optdesign.solvers.result", "optdesign.reports.solve_text"),
    ("optdesign.solvers.result", "optdesign.display.frames"),
    ("optdesign.solvers.result", "optdesign.plots.solution"),
    ("optdesign.studies.pareto.front", "optdesign.reports.front_text"),
    ("optdesign.studies.pareto.front", "optdesign.display.frames"),
    ("optdesign.studies.pareto.front", "optdesign.plots.front"),
    ("optdesign.studies.sweep", "optdesign.reports.sweep_text"),
    ("optdesign.studies.sweep", "optdesign.plots.sweep"),
    # od.report(result_or_front_or_sweep, path): the public API's entry point to the pages
    ("optdesign.api", "optdesign.reports.html"),
    ("optdesign.api", "optdesign.reports.sweep_html"),
    # od.pareto(..., out=DIR) writes the files optdesign pareto writes
    ("optdesign.api", "optdesign.reports.front_files"),
    # od.sweep(..., out=DIR) writes the files optdesign sweep writes
    ("optdesign.api", "optdesign.reports.sweep_files"),
}


def _modules() -> dict[str, tuple[Path, bool]]:
    modules = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        modules[".".join(parts)] = (path, is_package)
    return modules


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                skip.update(id(n) for n in ast.walk(child))
    return skip


def import_graph() -> dict[str, dict[str, int]]:
    """module -> {imported optdesign module: line of the first such import}."""
    modules = _modules()

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, dict[str, int]] = {}
    for module, (path, is_package) in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        skip = _type_checking_nodes(tree)
        base = module if is_package else module.rpartition(".")[0]
        arrows: dict[str, int] = {}
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            targets = []
            if isinstance(node, ast.Import):
                targets = [resolve(a.name) for a in node.names if a.name.startswith("optdesign")]
            elif isinstance(node, ast.ImportFrom):
                source = node.module or ""
                if node.level:
                    root = base
                    for _ in range(node.level - 1):
                        root = root.rpartition(".")[0]
                    source = root + ("." + source if source else "")
                if source == "optdesign" or source.startswith("optdesign."):
                    for alias in node.names:
                        full = f"{source}.{alias.name}"
                        targets.append(full if full in modules else resolve(source))
            for target in targets:
                if target and target != module:
                    arrows.setdefault(target, node.lineno)
        graph[module] = arrows
    return graph


#: the package root: a version and lazily exported names, no import of its own
ROOT = "optdesign"


def layer(module: str) -> int:
    if module == ROOT:
        return 0
    parts = module.split(".")
    top = parts[1]
    for k, names in enumerate(LAYERS):
        if top in names:
            return k
    raise AssertionError(f"{module}: in no layer of tests/test_layers.py (add it to LAYERS)")


def circles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_graph_sees_imports_inside_functions():
    # the reader itself: a module-top import and one inside a function are both arrows
    graph = import_graph()
    assert "optdesign.errors" in graph["optdesign.argument_checks"]
    assert "optdesign.studies.solve" in graph["optdesign.api"]
    assert graph["optdesign.solvers.result"]["optdesign.reports.solve_text"] > 1


def test_every_module_has_a_layer():
    for module in import_graph():
        layer(module)


def without_entry_points(graph: dict[str, dict[str, int]]) -> dict[str, dict[str, int]]:
    """The graph without the allowed upward arrows (they import on call, so a report
    reading the record it was called from is no circle at import)."""
    return {m: {t: n for t, n in a.items() if (m, t) not in ENTRY_POINTS} for m, a in graph.items()}


def test_no_import_circle():
    found = circles(without_entry_points(import_graph()))
    assert found == [], "import circles:\n" + "\n".join(" <-> ".join(c) for c in found)


def test_no_import_points_up_the_layers():
    graph = import_graph()
    upward = [
        f"{m}:{line} imports {t} (layer {layer(m)} -> {layer(t)})"
        for m, arrows in sorted(graph.items())
        for t, line in sorted(arrows.items())
        if layer(t) > layer(m) and (m, t) not in ENTRY_POINTS
    ]
    assert upward == [], "upward imports:\n" + "\n".join(upward)


def test_the_commands_enter_through_the_public_api():
    """A command (optdesign/commands/*, cli.py) reaches the studies through optdesign.api
    and optdesign.validation only (the checks and the computations ``od.solve``,
    ``od.pareto``, ``od.bench`` run), never by importing a study itself; the reports and
    plots it writes read the results."""
    graph = import_graph()
    direct = [
        f"{m}:{line} imports {t}"
        for m, arrows in sorted(graph.items())
        if m == "optdesign.cli" or m.startswith("optdesign.commands")
        for t, line in sorted(arrows.items())
        if t.startswith("optdesign.studies")
    ]
    assert direct == [], "commands importing a study:\n" + "\n".join(direct)
    assert "optdesign.api" in graph["optdesign.commands.pareto"]
    assert "optdesign.api" in graph["optdesign.commands.bench"]


def test_reports_and_plots_import_no_study():
    """The reports and plots read records (a result, a front, a sweep) and the display
    primitives below the studies: none imports a study, the global search or a
    formulation (at module top or inside a function) to work out what a page shows."""
    graph = import_graph()
    above = ("optdesign.studies", "optdesign.search", "optdesign.formulations")
    found = [
        f"{m}:{line} imports {t}"
        for m, arrows in sorted(graph.items())
        if m.partition(".")[2].split(".")[0] in ("reports", "plots")
        for t, line in sorted(arrows.items())
        if t.startswith(above)
    ]
    assert found == [], "reports or plots importing a study:\n" + "\n".join(found)


#: the calls that evaluate a model: a problem's ``quantities`` and ``evaluate``, its
#: constraint rows, a mechanism's ``sketch`` (called directly or through ``call_method``)
MODEL_CALLS = {"quantities", "evaluate", "constraint_rows", "sketch"}


def model_calls(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, name) of every call in ``tree`` that evaluates a model (:data:`MODEL_CALLS`),
    ``call_method(obj, "sketch", ...)`` counted as a call of ``sketch``."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
        if name == "call_method" and len(node.args) > 1:
            method = node.args[1]
            name = method.value if isinstance(method, ast.Constant) else ""
        if name in MODEL_CALLS:
            found.append((node.lineno, str(name)))
    return sorted(found)


def test_the_model_call_finder_sees_every_form():
    source = (
        "q = problem.quantities(design)\n"
        "def f(p, x):\n"
        "    return p.evaluate(x), constraint_rows(p, x)\n"
        "sk = call_method(mech, 'sketch', 0.0, doing='drawing')\n"
        "mech.sketch(0.1)\n"
        "draw_panel(ax, panel)\n"
    )
    assert model_calls(ast.parse(source)) == [
        (1, "quantities"),
        (3, "constraint_rows"),
        (3, "evaluate"),
        (4, "sketch"),
        (5, "sketch"),
    ]


def test_reports_and_plots_evaluate_no_model():
    """The reports and plots format and draw records: what a page or a figure shows of a
    design is evaluated by :mod:`optdesign.views`, and no module of reports/ or plots/
    calls a problem's ``quantities`` or ``evaluate``, its ``constraint_rows`` or a
    mechanism's ``sketch``."""
    found = [
        f"{path.relative_to(PACKAGE)}:{line} calls {name}"
        for folder in ("reports", "plots")
        for path in sorted((PACKAGE / folder).rglob("*.py"))
        for line, name in model_calls(ast.parse(path.read_text(), str(path)))
    ]
    assert found == [], "reports or plots evaluating a model:\n" + "\n".join(found)


def test_the_entry_points_are_still_there():
    # an allowed arrow that no longer exists is a stale exception: remove it from the list
    graph = import_graph()
    assert sorted(e for e in ENTRY_POINTS if e[1] not in graph[e[0]]) == []


def test_feasibility_and_ties_compare_with_the_named_tolerances():
    """No comparison in the package against a bare 1e-6: the feasibility and tie
    tolerances are optdesign.tolerances' (one name each, one value)."""
    from optdesign import tolerances

    assert tolerances.FEASIBILITY_TOL == 1e-6 and tolerances.OBJECTIVE_TIE_TOL == 1e-6
    bare = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare):
                for sub in ast.walk(node):
                    if isinstance(sub, ast.Constant) and sub.value == 1e-6:
                        bare.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert bare == []
