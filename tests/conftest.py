import os
import signal
import tempfile

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

os.environ.setdefault("MPLBACKEND", "Agg")

# A run started in the background by a non-interactive shell (`pytest &`, nohup, a
# mutation run) inherits SIGINT ignored, and so would the commands it starts; the signal
# tests check what a user at a terminal gets, Python's own handler, so the run starts
# from it (a handled signal is reset to its default in a child, which Python then takes).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# Property tests find a bug every run or never, not by luck: by default (the README's test
# command, CI) Hypothesis draws the same examples on every run - seeded from each test's
# own code - and replays no example database. OPTDESIGN_HYPOTHESIS=explore (or pytest's
# --hypothesis-profile=explore) draws new random examples each run and keeps the failing
# ones in .hypothesis/, to hunt for new bugs; a bug found so becomes a fixed example or a
# case of the deterministic run. Generation time is no test (a loaded machine is slow).
settings.register_profile(
    "deterministic",
    derandomize=True,
    database=None,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "explore",
    derandomize=False,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("OPTDESIGN_HYPOTHESIS") or "deterministic")


@pytest.fixture(scope="session", autouse=True)
def _temporary_folders_kept_by_pytest(tmp_path_factory):
    """A study without ``out`` keeps its store in a new temporary folder (nothing computed
    is lost); the suite's thousands of such folders (and those of the commands it starts)
    go under pytest's own temporary folder, which pytest prunes, never straight to /tmp."""
    folder = tmp_path_factory.mktemp("tempfile")
    saved_dir, saved_env = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir = str(folder)
    os.environ["TMPDIR"] = str(folder)
    yield folder
    tempfile.tempdir = saved_dir
    if saved_env is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = saved_env


@pytest.fixture
def paper_phi():
    """The paper's stroke, -30...+30 deg, on a dense grid (rad)."""
    return np.radians(np.linspace(-30.0, 30.0, 6001))


@pytest.fixture(autouse=True)
def _registries_restored():
    """A solver back-end or benchmark configuration a test registers is gone after it:
    the lists of known names (in refusals' messages, in the benchmark's default suite)
    never depend on which tests ran before."""
    from optdesign.solvers import registry
    from optdesign.studies.bench import configs

    registry.solver_names()  # the built-ins are registered at first use: before the copy
    configs.default_configs()
    solvers, bench = dict(registry._SOLVERS), dict(configs.CONFIGS)
    yield
    registry._SOLVERS.clear()
    registry._SOLVERS.update(solvers)
    configs.CONFIGS.clear()
    configs.CONFIGS.update(bench)


@pytest.fixture(scope="session")
def fin_lug_optimum():
    """The shipped fin_actuator with 5 mm lug cheeks (the inputs of Huth's model; its
    optimum is the file's, the lug entering no objective) solved once with the pin contact
    models' spread: (problem, result), shared by the tests that read the spread there."""
    import tomllib
    from pathlib import Path

    import optdesign as od

    path = Path(__file__).resolve().parents[1] / "problems" / "fin_actuator.toml"
    data = tomllib.loads(path.read_text())
    data.setdefault("materials", {})["lug"] = {"cheek_thickness": "5 mm"}
    problem = od.load(data)
    return problem, od.solve(problem, contact_models=True, ranges=False)
