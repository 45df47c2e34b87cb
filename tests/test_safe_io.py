"""Nothing outside the output folder is touched (issue 21, class 2; and class 7's
``bench --update-readme /dev/zero``).

A problem file is untrusted input from a colleague: opening, solving, writing results for
or resuming one never creates, truncates, follows or reads-until-killed a file outside
``--out`` (or the default output folder). Each test plants a sentinel outside the folder
and checks that it keeps its bytes and its modification time, in the default output
mode, with ``--json`` and through the Python API where they apply.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
from pathlib import Path

import casadi as ca
import pytest

import optdesign as od
from optdesign.cli import default_out, main
from optdesign.errors import InputError, OptDesignError
from optdesign.safe_io import UnsafeFileError, read_file, slug
from optdesign.storage import (
    StoreWriter,
    atomic_write_text,
    lock_folder,
    open_store,
    scan_store,
)

ROOT = Path(__file__).resolve().parents[1]
FORK = (ROOT / "problems" / "fork_min_backlash.toml").read_text()
#: A cheap solve on the command line (the NLP through Ipopt, one start).
QUICK = ["--formulation", "nlp", "--starts", "1", "--no-ranges", "--no-diagnosis"]


class Sentinel:
    """A file outside the output folder: same bytes, same mtime, still a regular file."""

    def __init__(self, folder: Path, name: str = "victim.txt"):
        folder.mkdir(parents=True, exist_ok=True)
        self.path = folder / name
        self.path.write_bytes(b"SENTINEL: must never change\n")
        os.utime(self.path, ns=(1_000_000_000_000_000_000, 1_000_000_000_000_000_000))

    def untouched(self) -> bool:
        st = os.lstat(self.path)
        return (
            self.path.read_bytes() == b"SENTINEL: must never change\n"
            and st.st_mtime_ns == 1_000_000_000_000_000_000
            and not self.path.is_symlink()
        )


class _Hang(Exception):
    pass


@contextlib.contextmanager
def within(seconds: int):
    """Fail instead of hanging (a read of /dev/zero or a FIFO would never return)."""

    def alarm(signum, frame):
        raise _Hang(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _problem(folder: Path, name: str | None = None, solver: str = "") -> Path:
    text = FORK
    if name is not None:
        text = text.replace('name = "fork_min_backlash"', f"name = {json.dumps(name)}")
    path = folder / "problem.toml"
    path.write_text(text + (f"\n[solver]\n{solver}\n" if solver else ""))
    return path


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def _tree(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


# --- solver options that name files -----------------------------------------------------
FILE_OPTIONS = [
    ("output_file", "{victim}"),
    ("output_file", "ipopt.log"),
    ("option_file_name", "{victim}"),
    ("hsllib", "{victim}"),
    ("pardisolib", "{victim}"),
    ("file_print_level", 5),
    ("file_append", "yes"),
    ("linear_solver", "ma77"),
]


@pytest.mark.parametrize(("option", "value"), FILE_OPTIONS)
@pytest.mark.parametrize("mode", ["default", "json", "json --out"])
def test_problem_file_options_that_name_files_are_refused(
    tmp_path, monkeypatch, capsys, option, value, mode
):
    victim = Sentinel(tmp_path / "outside")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    shown = value.format(victim=victim.path) if isinstance(value, str) else value
    problem = _problem(work, solver=f"ipopt = {{ {option} = {json.dumps(shown)} }}")
    argv = ["solve", problem, *QUICK]
    if mode != "default":
        argv.append("--json")
    if mode.endswith("--out"):
        argv += ["--out", work / "out"]
    code, out, err = _run(argv, capsys)
    assert code == 2
    assert f"solver.ipopt.{option}: refused: it " in err
    assert err.count("\n") == 1 and out == ""
    assert victim.untouched()
    assert _tree(work) == {"problem.toml"}  # not even the output folder


@pytest.mark.parametrize(("option", "value"), FILE_OPTIONS)
def test_api_refuses_file_options_in_a_problem_dict_and_in_options(tmp_path, option, value):
    victim = Sentinel(tmp_path / "outside")
    shown = value.format(victim=victim.path) if isinstance(value, str) else value
    problem = od.load(_problem(tmp_path))
    data = problem.spec.model_dump(mode="python")
    data["solver"]["ipopt"] = {option: shown}
    with pytest.raises(OptDesignError, match=f"solver.ipopt.{option}: refused"):
        od.load(data)
    for formulation in ("auto", "nlp"):
        with pytest.raises(InputError, match=f"options.{option}: refused: it "):
            od.solve(problem, formulation, options={option: shown}, starts=1, ranges=False)
    assert victim.untouched()


@pytest.mark.parametrize(
    ("solver", "options", "named"),
    [
        ("sqpmethod", {"dump": True, "dump_dir": "{victim_dir}"}, "options.dump"),
        ("sqpmethod", {"dump_in": True}, "options.dump_in"),
        ("sqpmethod", {"jit": True, "compiler": "shell"}, "options.jit"),
        (
            "sqpmethod",
            {"external_transform": [["{victim}", "f", {}]]},
            "options.external_transform",
        ),
        (
            "sqpmethod",
            {
                "qpsol": "nlpsol",
                "qpsol_options": {
                    "nlpsol": "ipopt",
                    "nlpsol_options": {"ipopt": {"output_file": "{victim}"}},
                },
            },
            "options.qpsol_options.nlpsol_options.ipopt.output_file",
        ),
        ("sqpmethod", {"qpsol": "../../{victim}"}, "options.qpsol"),
        ("slsqp", {"logfile": "{victim}"}, "options.logfile"),
        ("ipopt", {"print_level": 0, "output_file": "{victim}"}, "options.output_file"),
    ],
)
def test_api_refuses_back_end_options_that_write_files(
    tmp_path, monkeypatch, solver, options, named
):
    victim = Sentinel(tmp_path / "outside")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    text = json.dumps(options).replace("{victim_dir}", str(victim.path.parent))
    options = json.loads(text.replace("{victim}", str(victim.path)))
    problem = od.load(_problem(tmp_path))
    with pytest.raises(InputError, match=re.escape(named) + ": refused: it "):
        od.solve(problem, "nlp", solver=solver, options=options, starts=1, ranges=False)
    assert victim.untouched()
    assert _tree(work) == set()
    assert _tree(victim.path.parent) == {"victim.txt"}


def test_ipopt_never_reads_an_options_file_from_the_working_directory(
    tmp_path, monkeypatch, capsys
):
    from optdesign.solvers import casadi_nlp

    victim = Sentinel(tmp_path / "outside")
    control = Sentinel(tmp_path / "control")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    (work / "ipopt.opt").write_text(f"output_file {control.path}\nfile_print_level 5\n")
    # The threat is real: Ipopt, as CasADi builds it by default, reads ./ipopt.opt.
    x = ca.MX.sym("x")
    ca.nlpsol("c", "ipopt", {"x": x, "f": x**2}, {"ipopt": {"print_level": 0, "sb": "yes"}})(x0=1)
    assert not control.untouched()
    (work / "ipopt.opt").write_text(f"output_file {victim.path}\nfile_print_level 5\n")
    # The option checks' own probes (cached per process: cleared here) ...
    casadi_nlp.ipopt_option_names.cache_clear()
    casadi_nlp._try_ipopt_option.cache_clear()
    casadi_nlp.check_ipopt_options({"tol": 1e-9, "mu_strategy": "monotone"})
    # ... a solve through the API ...
    result = od.solve(od.load(_problem(tmp_path)), "nlp", starts=1, ranges=False)
    assert result.success
    # ... and the command line, in both output modes.
    for extra in ([], ["--json"]):
        code, _, err = _run(["solve", _problem(tmp_path), *QUICK, *extra], capsys)
        assert code == 0, err
    assert victim.untouched()


# --- names never become paths -------------------------------------------------------------
HOSTILE_NAMES = [
    "../../escaped",
    "../../../../../../tmp/escaped",
    "/etc/passwd",
    "a/../../b",
    "..",
    ".",
    ".hidden",
    "-rf",
    "x" * 400,
    "\x1b[31mred\x1b[0m",
    "line\nbreak\ttab",
    "nul\x00name",
    "Ölpumpe √2",
    "名前",
    "con",
    "a\\..\\..\\b",
]


def test_default_output_folder_is_a_child_of_optdesign_out_for_any_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    root = tmp_path / "optdesign-out"
    seen = set()
    for name in HOSTILE_NAMES:
        for command in ("solve", "pareto"):
            path = default_out(f"{command}-{name}")
            assert path.parent == root, (name, path)
            assert re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", path.name), (name, path.name)
            assert len(path.name) <= 80
            seen.add(path.name)
    assert len(seen) == 2 * len(HOSTILE_NAMES)  # different names, different folders
    assert slug("cs_min_backlash") == "cs_min_backlash"
    assert slug("Ölpumpe").startswith("Olpumpe-")
    assert not list(tmp_path.iterdir())  # default_out only names the folder


@pytest.mark.parametrize("name", ["../../../escaped", "..", "Ölpumpe/../../x", "x" * 300])
def test_solve_with_a_hostile_name_writes_only_into_optdesign_out(
    tmp_path, monkeypatch, capsys, name
):
    work = tmp_path / "a" / "b" / "work"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    problem = _problem(tmp_path, name)
    code, out, err = _run(["solve", problem, *QUICK, "--no-plot", "--no-report"], capsys)
    assert code == 0, err
    made = [p for p in (work / "optdesign-out").iterdir()]
    assert len(made) == 1 and made[0].is_dir()
    assert {p.name for p in made[0].iterdir()} == {".optdesign.lock", "result.json"}
    outside = {p for p in _tree(tmp_path) if not p.startswith("a/b/work/optdesign-out")}
    assert outside == {"problem.toml", "a", "a/b", "a/b/work"}
    assert str(made[0]) in out
    # --json without --out writes no file at all
    code, out, err = _run(["solve", problem, *QUICK, "--json"], capsys)
    assert code == 0, err
    assert json.loads(out)["status"] == "optimal"
    assert len(list((work / "optdesign-out").iterdir())) == 1


@pytest.mark.parametrize("planted", ["link", "file"])
def test_a_planted_optdesign_out_is_refused_before_any_work(tmp_path, monkeypatch, capsys, planted):
    # ./optdesign-out is the program's folder: a link there would send the default output
    # folder elsewhere (the target's tree), a file would fail late
    work = tmp_path / "work"
    work.mkdir()
    target = tmp_path / "elsewhere"
    target.mkdir()
    monkeypatch.chdir(work)
    if planted == "link":
        (work / "optdesign-out").symlink_to(target)
    else:
        (work / "optdesign-out").write_text("not a folder\n")
    problem = _problem(tmp_path, "planted")
    code, _, err = _run(["solve", problem, *QUICK, "--no-plot"], capsys)
    assert code == 2, err
    assert "optdesign-out" in err and ("a link" if planted == "link" else "not a folder") in err
    assert list(target.iterdir()) == []
    code, _, err = _run(
        ["pareto", problem, "--objectives", "size,backlash", "--points", "2"], capsys
    )
    assert code == 2 and "optdesign-out" in err, err
    assert list(target.iterdir()) == []


def test_pareto_with_a_hostile_name_writes_only_into_optdesign_out(tmp_path, monkeypatch, capsys):
    work = tmp_path / "a" / "work"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    problem = _problem(tmp_path, "../../../escaped")
    argv = ["pareto", problem, "--objectives", "size,backlash", "--points", "2", "--starts", "1"]
    code, _, err = _run([*argv, "--workers", "1", "--no-progress", "--no-plot"], capsys)
    assert code == 0, err
    (made,) = list((work / "optdesign-out").iterdir())
    assert made.name.startswith("pareto-escaped-")
    outside = {p for p in _tree(tmp_path) if not p.startswith("a/work/optdesign-out")}
    assert outside == {"problem.toml", "a", "a/work"}


def test_a_method_name_is_never_a_path(tmp_path):
    victim = Sentinel(tmp_path / "outside")
    problem = od.load(_problem(tmp_path))
    for name in ("../outside/victim", "/tmp/x", "..", ".hidden", "a/b"):
        with pytest.raises(InputError, match=r"^name: "):
            od.pareto(problem, ["size", "backlash"], points=2, out=tmp_path / "out", name=name)
    assert victim.untouched()
    assert _tree(tmp_path / "outside") == {"victim.txt"}


# --- the lock file ---------------------------------------------------------------------------
@pytest.mark.parametrize("mode", ["default", "json"])
def test_a_lock_file_planted_as_a_link_is_refused_and_its_target_untouched(tmp_path, capsys, mode):
    victim = Sentinel(tmp_path / "outside")
    out = tmp_path / "out"
    out.mkdir()
    (out / ".optdesign.lock").symlink_to(victim.path)
    argv = ["solve", _problem(tmp_path), *QUICK, "--out", out] + (
        ["--json"] if mode == "json" else []
    )
    code, stdout, err = _run(argv, capsys)
    assert code == 2
    assert f"the lock file {out / '.optdesign.lock'} is a symbolic link" in err
    assert err.count("\n") == 1 and stdout == ""
    assert victim.untouched()
    assert _tree(out) == {".optdesign.lock"}
    with pytest.raises(UnsafeFileError, match="is a symbolic link"):
        od.pareto(od.load(_problem(tmp_path)), ["size", "backlash"], points=2, out=out)
    assert victim.untouched()


def test_a_lock_file_that_is_a_hard_link_a_fifo_or_a_folder_is_refused(tmp_path):
    victim = Sentinel(tmp_path / "outside")
    for k, plant in enumerate(("hard link", "fifo", "folder", "dangling link")):
        out = tmp_path / f"out{k}"
        out.mkdir()
        lock = out / ".optdesign.lock"
        if plant == "hard link":
            os.link(victim.path, lock)
        elif plant == "fifo":
            os.mkfifo(lock)
        elif plant == "folder":
            lock.mkdir()
        else:
            lock.symlink_to(tmp_path / "outside" / "created-by-the-lock")
        with within(20), pytest.raises(UnsafeFileError, match=str(lock)):
            with lock_folder(out):
                pass
    assert victim.untouched()
    assert _tree(tmp_path / "outside") == {"victim.txt"}


def test_the_holder_of_a_lock_is_read_without_following_links(tmp_path):
    out = tmp_path / "out"
    with lock_folder(out):
        lock = out / ".optdesign.lock"
        assert read_file(lock, limit=64) == f"{os.getpid()}\n".encode()


# --- the store -------------------------------------------------------------------------------
PARETO = ["--objectives", "size,backlash", "--points", "2", "--starts", "1", "--workers", "1"]
PARETO_QUIET = ["--no-progress", "--no-plot", "--no-report"]


@pytest.mark.parametrize("resume", [False, True])
def test_a_store_planted_as_a_link_is_refused(tmp_path, capsys, resume):
    victim = Sentinel(tmp_path / "outside")
    out = tmp_path / "out"
    out.mkdir()
    (out / "epsilon.jsonl").symlink_to(victim.path)
    problem = _problem(tmp_path)
    argv = ["pareto", problem, *PARETO, *PARETO_QUIET, "--out", out]
    code, _, err = _run(argv + (["--resume"] if resume else []), capsys)
    assert code == 2
    assert f"the store {out / 'epsilon.jsonl'} is a symbolic link" in err
    assert victim.untouched()
    with pytest.raises(UnsafeFileError, match="is a symbolic link"):
        od.pareto(od.load(problem), ["size", "backlash"], points=2, out=out, resume=resume)
    assert victim.untouched()


@pytest.mark.parametrize("plant", ["/dev/zero link", "fifo", "folder"])
def test_a_store_that_is_not_a_regular_file_is_refused_at_once(tmp_path, capsys, plant):
    out = tmp_path / "out"
    out.mkdir()
    store = out / "epsilon.jsonl"
    if plant == "fifo":
        os.mkfifo(store)
    elif plant == "folder":
        store.mkdir()
    else:
        store.symlink_to("/dev/zero")
    argv = ["pareto", _problem(tmp_path), *PARETO, *PARETO_QUIET, "--out", out]
    for extra in ([], ["--resume"]):
        with within(60):
            code, _, err = _run(argv + extra, capsys)
        assert code == 2
        assert f"the store {store} is " in err, err


def test_a_store_with_another_hard_link_is_never_appended_to(tmp_path):
    victim_dir = tmp_path / "outside"
    victim_dir.mkdir()
    store = tmp_path / "out" / "s.jsonl"
    tasks = [{"id": f"t{i}", "n": i} for i in range(3)]
    from optdesign.runtime.runner import run_tasks

    run_tasks(tasks[:2], _double, store, key="k")
    os.link(store, victim_dir / "linked.jsonl")
    before = (victim_dir / "linked.jsonl").read_bytes()
    with pytest.raises(UnsafeFileError, match="has 2 hard links"):
        run_tasks(tasks, _double, store, key="k", resume=True)
    assert (victim_dir / "linked.jsonl").read_bytes() == before
    with pytest.raises(UnsafeFileError, match="has 2 hard links"):
        StoreWriter(store)


def _double(task, deps):
    return {"value": 2 * task["n"]}


def test_overwrite_replaces_a_planted_store_link_without_touching_its_target(tmp_path):
    victim = Sentinel(tmp_path / "outside")
    store = tmp_path / "out" / "s.jsonl"
    store.parent.mkdir()
    store.symlink_to(victim.path)
    with pytest.raises(UnsafeFileError):
        scan_store(store)
    open_store(store, "k", resume=False, overwrite=True)
    assert not store.is_symlink() and json.loads(store.read_text())["key"] == "k"
    assert victim.untouched()


# --- results written into a folder with planted links -----------------------------------
@pytest.mark.parametrize("mode", ["default", "json"])
def test_solve_results_replace_planted_links_and_never_write_through_them(tmp_path, capsys, mode):
    out = tmp_path / "out"
    out.mkdir()
    names = ["result.json", "solution.png", "report.html"]
    victims = {n: Sentinel(tmp_path / "outside", n + ".victim") for n in names}
    for n in names:
        (out / n).symlink_to(victims[n].path)
    argv = ["solve", _problem(tmp_path), *QUICK, "--out", out]
    code, _, err = _run(argv + (["--json"] if mode == "json" else []), capsys)
    assert code == 0, err
    assert all(v.untouched() for v in victims.values())
    for n in names:
        assert (out / n).is_file() and not (out / n).is_symlink()
    assert json.loads((out / "result.json").read_text())["status"] == "optimal"
    assert not [p for p in out.iterdir() if ".tmp" in p.name]  # no temporary file left


def test_pareto_results_replace_planted_links(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    names = ["front.csv", "front.json", "front.png", "report.html"]
    victims = {n: Sentinel(tmp_path / "outside", n + ".victim") for n in names}
    for n in names:
        (out / n).symlink_to(victims[n].path)
    code, _, err = _run(
        ["pareto", _problem(tmp_path), *PARETO, "--no-progress", "--out", out], capsys
    )
    assert code == 0, err
    assert all(v.untouched() for v in victims.values())
    assert all((out / n).is_file() and not (out / n).is_symlink() for n in names)


def test_bench_outputs_replace_planted_links_and_resume_reads_no_device(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    names = ["bench_runs.csv", "summary.md", "bench_stats.json", "bench_profiles.png"]
    names.append("bench_meta.json")
    victims = {n: Sentinel(tmp_path / "outside", n + ".victim") for n in names}
    for n in names:
        (out / n).symlink_to(victims[n].path)
    problem = od.load(_problem(tmp_path))
    report = od.bench(problems=[problem], solvers=["slsqp"], out=out)
    assert [r.status for r in report.rows] == ["optimal"]
    assert all(v.untouched() for v in victims.values())
    assert all(not (out / n).is_symlink() for n in names)
    # a resume reads bench_meta.json back: planted as /dev/zero, it is not read
    (out / "bench_meta.json").unlink()
    (out / "bench_meta.json").symlink_to("/dev/zero")
    with within(60):
        again = od.bench(problems=[problem], solvers=["slsqp"], out=out, resume=True)
    assert again.rows[0].objective == report.rows[0].objective


def test_reproduce_replaces_a_planted_plot_link(tmp_path, capsys):
    victim = Sentinel(tmp_path / "outside")
    out = tmp_path / "out"
    out.mkdir()
    (out / "yang2016_motor_shaft_moment.png").symlink_to(victim.path)
    code, _, err = _run(["reproduce", "yang2016", "--out", out], capsys)
    assert code == 0, err
    assert victim.untouched()
    assert (out / "yang2016_motor_shaft_moment.png").read_bytes()[:4] == b"\x89PNG"


def test_atomic_writes_replace_a_link_and_use_new_temporary_files(tmp_path, monkeypatch):
    import tempfile

    victim = Sentinel(tmp_path / "outside")
    target = tmp_path / "out" / "front.csv"
    target.parent.mkdir()
    target.symlink_to(victim.path)
    made = []
    real = tempfile.mkstemp

    def spy(*args, **kwargs):  # the temporary file is a new one, made by mkstemp (O_EXCL)
        fd, name = real(*args, **kwargs)
        made.append(name)
        return fd, name

    monkeypatch.setattr(tempfile, "mkstemp", spy)
    atomic_write_text(target, "a,b\n")
    assert victim.untouched() and target.read_text() == "a,b\n" and not target.is_symlink()
    assert len(made) == 1 and Path(made[0]).parent == target.parent
    assert not Path(made[0]).exists()


# --- bench --update-readme -----------------------------------------------------------------
@pytest.mark.parametrize(
    "plant", ["/dev/zero", "fifo", "folder", "too large", "missing", "no markers", "binary"]
)
def test_update_readme_refuses_what_is_not_a_small_regular_file_before_running(
    tmp_path, capsys, plant
):
    readme = tmp_path / "README.md"
    if plant == "/dev/zero":
        readme = Path("/dev/zero")
    elif plant == "fifo":
        os.mkfifo(readme)
    elif plant == "folder":
        readme.mkdir()
    elif plant == "too large":
        with open(readme, "wb") as fh:
            fh.truncate(64 << 20)
    elif plant == "no markers":
        readme.write_text("# no generated block here\n")
    elif plant == "binary":
        readme.write_bytes(b"\xff\xfe\x00junk")
    out = tmp_path / "out"
    with within(60):
        code, _, err = _run(
            ["bench", "--suite", "quick", "--solvers", "slsqp", "--workers", "1", "--out", out,
             "--no-progress", "--update-readme", readme],
            capsys,
        )  # fmt: skip
    assert code == 2
    assert err.startswith("optdesign: error: --update-readme: ") and err.count("\n") == 1
    reason = {
        "/dev/zero": "is a device, not a regular file",
        "fifo": "is a FIFO, not a regular file",
        "folder": "is a folder, not a regular file",
        "too large": "more than the 4194304 it may hold",
        "missing": "does not exist",
        "no markers": "has no generated-block markers",
        "binary": "is not UTF-8 text",
    }[plant]
    assert reason in err
    assert not out.exists()  # refused before the benchmark ran


def test_update_readme_through_a_link_updates_its_target(tmp_path):
    from optdesign.studies.bench.report import README_BEGIN, README_END, update_readme

    real = tmp_path / "docs" / "README.md"
    real.parent.mkdir()
    real.write_text(f"# Bench\n{README_BEGIN}\nold\n{README_END}\ntail\n")
    link = tmp_path / "README.md"
    link.symlink_to(real)
    assert update_readme(link, "new table")
    assert link.is_symlink()
    assert real.read_text() == f"# Bench\n{README_BEGIN}\nnew table{README_END}\ntail\n"


def test_read_file_caps_and_refuses_special_files(tmp_path):
    big = tmp_path / "big"
    big.write_bytes(b"x" * 100)
    with pytest.raises(UnsafeFileError, match="holds 100 bytes, more than the 10"):
        read_file(big, limit=10)
    assert read_file(tmp_path / "missing") is None
    with within(10), pytest.raises(UnsafeFileError, match="is a device"):
        read_file("/dev/zero", follow=True)
    (tmp_path / "s.jsonl").mkdir()
    with pytest.raises(UnsafeFileError, match="is a folder"):
        scan_store(tmp_path / "s.jsonl")


def test_a_refused_run_leaves_no_default_output_folder(
    tmp_path, tmp_path_factory, monkeypatch, capsys
):
    """A run refused after its default folder was made (a [reference] is checked when
    the formulation starts) removes the folder again: nothing in the working directory;
    one line names why. A formulation named that does not apply is refused before any
    folder is made, even one the user named."""
    monkeypatch.chdir(tmp_path)
    cs = ["solve", str(ROOT / "problems" / "cs_min_backlash.toml"), "--formulation", "gp"]
    code = main(cs)
    err = capsys.readouterr().err
    assert code == 2
    assert list(tmp_path.iterdir()) == []
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "\\n" not in lines[0]
    assert "not a geometric program: variable n: not DGP" in lines[0]
    assert main([*cs, "--out", "mine"]) == 2 and list(tmp_path.iterdir()) == []
    assert "not a geometric program" in capsys.readouterr().err
    # the GP formulation checks the file's [reference] once the folder is made
    bad = tmp_path_factory.mktemp("files") / "bad.toml"
    fork = (ROOT / "problems" / "fork_min_backlash.toml").read_text()
    bad.write_text(fork + '\n[reference]\nR = "60 mm"\n')
    code = main(["solve", str(bad)])
    err = capsys.readouterr().err
    assert code == 2 and list(tmp_path.iterdir()) == []
    assert err.strip().splitlines() == [
        "optdesign: error: reference.p: missing (every free variable needs a value)"
    ]
    # a folder the user named is kept, empty or not
    assert main(["solve", str(bad), "--out", "mine"]) == 2 and (tmp_path / "mine").is_dir()
    # a run that writes keeps its default folder
    problem = ROOT / "problems" / "fork_min_backlash.toml"
    assert main(["solve", str(problem), *QUICK, "--no-plot", "--no-report"]) == 0
    [made] = (tmp_path / "optdesign-out").iterdir()
    assert (made / "result.json").is_file()
