"""Safe output: store identity, torn tails, one writer per folder, overwrite refusal,
atomic files (optdesign.storage, through run_tasks where that is how it is used)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import optdesign as od
from optdesign.runtime.runner import run_tasks
from optdesign.safe_io import UnsafeFileError
from optdesign.storage import (
    STORE_VERSION,
    FolderInUseError,
    StoreError,
    atomic_output,
    atomic_write_bytes,
    atomic_write_text,
    ensure_writable,
    holds_lock,
    lock_folder,
    open_store,
    read_store,
)

ROOT = Path(__file__).resolve().parents[2]


def _double(task, deps):
    return {"value": 2 * task["n"]}


def _tasks(n=6):
    return [{"id": f"t{i}", "n": i} for i in range(n)]


def _lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def _stopped_run(store: Path, after: int, key: str = "k") -> None:
    """A run interrupted after ``after`` records (like Ctrl-C)."""
    seen = []

    def stop(rec):
        seen.append(rec)
        if len(seen) == after:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as info:
        run_tasks(_tasks(), _double, store, key=key, on_record=stop)
    # what the CLI prints from
    assert info.value.run_store == {"path": str(store), "records": after}


# --- identity --------------------------------------------------------------------------
def test_a_new_store_starts_with_its_identity_before_any_record(tmp_path):
    store = tmp_path / "s.jsonl"
    seen_first_line = []

    def peek(rec):  # a record is written: the identity must be on disk before it
        seen_first_line.append(store.read_text().splitlines()[0])

    run_tasks(_tasks(2), _double, store, key="k1", on_record=peek)
    assert {json.loads(x)["key"] for x in seen_first_line} == {"k1"}
    assert _lines(store)[0] == {"__store__": STORE_VERSION, "key": "k1"}


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        ("empty", "is empty"),
        ("identity deleted", "first line is not the identity"),
        ("identity only deleted, nothing left", "no identity"),
        ("foreign key", "belongs to another run"),
        ("binary junk", "binary"),
        ("junk text", "is not JSON"),
        ("two runs interleaved", "appears twice"),
    ],
)
def test_resume_refuses_a_store_that_is_not_this_runs(tmp_path, damage, message):
    store = tmp_path / "s.jsonl"
    _stopped_run(store, 3)
    lines = store.read_bytes().splitlines(keepends=True)
    data = {
        "empty": b"",
        "identity deleted": b"".join(lines[1:]),
        "identity only deleted, nothing left": b"\n",
        "foreign key": json.dumps({"__store__": STORE_VERSION, "key": "other"}).encode()
        + b"\n"
        + b"".join(lines[1:]),
        "binary junk": lines[0] + os.urandom(64).replace(b"\n", b"") + b"\x80\xff\n",
        "junk text": lines[0] + b"{not json\n" + b"".join(lines[1:]),
        "two runs interleaved": b"".join(lines) + lines[1],
    }[damage]
    store.write_bytes(data)
    with pytest.raises(StoreError, match=message) as info:
        run_tasks(_tasks(), _double, store, key="k", resume=True)
    assert str(store) in str(info.value)
    assert "\n" not in str(info.value)  # one line for the CLI
    assert store.read_bytes() == data  # refused, untouched


def test_cli_refuses_resume_from_an_empty_store_with_one_line_and_exit_2(tmp_path, capsys):
    from optdesign.cli import main

    out = tmp_path / "run"
    out.mkdir()
    (out / "epsilon.jsonl").write_text("")
    problem = ROOT / "problems" / "fork_min_backlash.toml"
    code = main(
        [
            "pareto",
            str(problem),
            "--objectives",
            "size,backlash",
            "--points",
            "3",
            "--out",
            str(out),
            "--resume",
            "--workers",
            "1",
            "--no-progress",
            "--no-plot",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "optdesign: error:" in err and "empty" in err
    assert "Traceback" not in err


# --- torn tail -------------------------------------------------------------------------
@pytest.mark.parametrize("cut", [1, 5, "newline only"])
def test_torn_last_line_is_cut_and_no_record_is_lost_or_duplicated(tmp_path, cut):
    store = tmp_path / "s.jsonl"
    _stopped_run(store, 4)
    data = store.read_bytes()
    # killed while writing the 4th record: all but its last bytes on disk
    torn = data[:-1] if cut == "newline only" else data[: -1 - cut]
    store.write_bytes(torn)
    _, before = read_store(store)
    assert len(before) == (4 if cut == "newline only" else 3)
    done = run_tasks(_tasks(), _double, store, key="k", resume=True)
    recs = _lines(store)[1:]  # every line reads (the next record did not glue onto it)
    ids = [r["id"] for r in recs]
    assert sorted(ids) == sorted(t["id"] for t in _tasks())  # each once
    assert {k: r["value"] for k, r in done.items()} == {f"t{i}": 2 * i for i in range(6)}
    for k, rec in before.items():
        assert done[k] == rec


def test_read_store_refuses_a_damaged_middle_line(tmp_path):
    store = tmp_path / "s.jsonl"
    _stopped_run(store, 3)
    lines = store.read_text().splitlines(keepends=True)
    store.write_text(lines[0] + lines[1][:10] + lines[2] + lines[3])  # a glued torn line
    with pytest.raises(StoreError, match="line 2 is not JSON"):
        read_store(store)


# --- overwrite ---------------------------------------------------------------------------
def test_a_new_run_does_not_silently_empty_an_earlier_store(tmp_path):
    store = tmp_path / "s.jsonl"
    _stopped_run(store, 3)
    data = store.read_bytes()
    with pytest.raises(StoreError) as err:
        run_tasks(_tasks(), _double, store, key="k")
    assert str(err.value) == (
        f"{store} holds 3 records of an earlier run; continue it with resume=True, start "
        "over with overwrite=True, or use another output folder"
    )
    assert store.read_bytes() == data
    run_tasks(_tasks(), _double, store, key="new", overwrite=True)
    assert _lines(store)[0]["key"] == "new" and len(_lines(store)) == 7
    # a store holding only its identity has nothing to lose: replaced without a word
    store.write_text(json.dumps({"__store__": STORE_VERSION, "key": "x"}) + "\n")
    run_tasks(_tasks(2), _double, store, key="k")
    assert len(_lines(store)) == 3


def test_cli_overwrite_flag_and_refusal(tmp_path, capsys):
    from optdesign.cli import main

    out = tmp_path / "run"
    out.mkdir()
    store = out / "epsilon.jsonl"
    _stopped_run(store, 2)
    problem = ROOT / "problems" / "fork_min_backlash.toml"
    args = ["pareto", str(problem), "--objectives", "size,backlash", "--out", str(out)]
    assert main([*args, "--workers", "1", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "holds 2 records" in err and err.count("\n") == 1
    assert main([*args, "--resume", "--overwrite"]) == 2
    assert "excludes --resume" in capsys.readouterr().err


# --- one writer per folder -------------------------------------------------------------
_HOLDER = """
import sys, time
from optdesign.storage import lock_folder
with lock_folder(sys.argv[1]):
    print("locked", flush=True)
    time.sleep(60)
"""


def _holder(folder: Path) -> subprocess.Popen:
    proc = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, str(folder)],
        stdout=subprocess.PIPE,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert proc.stdout.readline().strip() == b"locked"
    return proc


def test_a_second_process_is_refused_and_the_lock_dies_with_the_first(tmp_path):
    proc = _holder(tmp_path)
    try:
        with pytest.raises(
            FolderInUseError, match=rf"in use by another optdesign run \(pid {proc.pid}\)"
        ):
            run_tasks(_tasks(), _double, tmp_path / "s.jsonl", key="k")
        assert not (tmp_path / "s.jsonl").exists()
    finally:
        proc.kill()  # SIGKILL: no cleanup code runs, the kernel drops the lock
        proc.wait()
    run_tasks(_tasks(), _double, tmp_path / "s.jsonl", key="k")  # no stale lock
    assert len(_lines(tmp_path / "s.jsonl")) == 7


def test_two_concurrent_cli_runs_into_one_folder(tmp_path):
    # The second run of two racing into one --out is refused with one line, exit 2.
    proc = _holder(tmp_path)
    try:
        res = subprocess.run(
            [
                sys.executable,
                "-m",
                "optdesign",
                "bench",
                "--suite",
                "quick",
                "--solvers",
                "debug-crash",
                "--out",
                str(tmp_path),
                "--no-progress",
            ],
            capture_output=True,
            text=True,
            timeout=60,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )
    finally:
        proc.kill()
        proc.wait()
    assert res.returncode == 2
    assert res.stderr.strip() == (
        f"optdesign: error: folder {tmp_path} is in use by another optdesign run "
        f"(pid {proc.pid}); wait for it to finish or use another output folder"
    )


def test_lock_is_reentrant_in_a_process_and_not_inherited_by_a_fork(tmp_path):
    with lock_folder(tmp_path):
        with lock_folder(tmp_path):  # a command holds it, the runner takes it again
            assert holds_lock(tmp_path)
        assert holds_lock(tmp_path)
        pid = os.fork()
        if pid == 0:  # pragma: no cover - child
            os._exit(0 if not holds_lock(tmp_path) else 1)
        assert os.waitpid(pid, 0)[1] == 0
    assert not holds_lock(tmp_path)
    run_tasks(_tasks(1), _double, tmp_path / "s.jsonl")


def test_unwritable_folder_is_reported_up_front(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(StoreError, match=r"cannot create the output folder .*file/out"):
        ensure_writable(tmp_path / "file" / "out")
    with pytest.raises(StoreError, match="cannot create the output folder"):
        run_tasks(_tasks(1), _double, tmp_path / "file" / "out" / "s.jsonl")
    if os.geteuid() == 0:
        return  # root writes anywhere
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(StoreError, match="cannot write to the output folder"):
            ensure_writable(ro)
        with pytest.raises(StoreError, match="cannot"):
            run_tasks(_tasks(1), _double, ro / "s.jsonl")
    finally:
        ro.chmod(0o700)


# --- atomic files ----------------------------------------------------------------------
def test_atomic_write_replaces_whole_or_not_at_all(tmp_path):
    path = tmp_path / "front.json"
    atomic_write_text(path, "old")
    assert path.read_text() == "old"
    assert oct(path.stat().st_mode & 0o777) != oct(0o600)  # not mkstemp's private mode
    with pytest.raises(RuntimeError), atomic_output(path) as tmp:
        tmp.write_text("half of the new")
        raise RuntimeError("killed while writing")
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["front.json"]  # no temp file left
    with atomic_output(tmp_path / "plot.png") as tmp:
        assert tmp.suffix == ".png"  # writers choosing the format by extension
        tmp.write_bytes(b"png")
    assert (tmp_path / "plot.png").read_bytes() == b"png"


_WRITER = """
import sys
from optdesign.storage import atomic_write_bytes
i = 0
print("go", flush=True)
while True:
    atomic_write_bytes(sys.argv[1], bytes([i % 251]) * 1_000_000)
    i += 1
"""


def test_atomic_write_killed_at_random_moments_never_leaves_a_partial_file(tmp_path):
    path = tmp_path / "big.bin"
    atomic_write_bytes(path, b"\x07" * 1_000_000)
    seen = set()
    for delay in (0.05, 0.13, 0.21):
        proc = subprocess.Popen(
            [sys.executable, "-c", _WRITER, str(path)],
            stdout=subprocess.PIPE,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )
        proc.stdout.readline()
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        data = path.read_bytes()
        assert len(data) == 1_000_000 and data == data[:1] * len(data)
        seen.add(data[0])
    assert seen - {7}  # the writer did replace the file meanwhile


def test_an_atomic_write_gives_the_file_the_mode_of_a_plain_open(tmp_path):
    """mkstemp makes its file 0600; the finished file has the mode ``open`` would give
    it under the process's umask (0666 minus the umask: never executable)."""
    old = os.umask(0o022)
    os.umask(old)
    path = atomic_write_text(tmp_path / "r.json", "{}")
    assert path.read_text() == "{}"
    assert path.stat().st_mode & 0o777 == 0o666 & ~old
    with open(tmp_path / "plain", "w") as fh:
        fh.write("x")
    assert (tmp_path / "plain").stat().st_mode & 0o777 == path.stat().st_mode & 0o777


@pytest.mark.parametrize("writer", ["atomic_write_text", "atomic_output", "store"])
def test_a_full_disk_names_the_file_being_written(tmp_path, monkeypatch, capsys, writer):
    """optdesign.storage.WriteError: "[Errno 28] No space left on device" named no file;
    a failed write now names the file (an OSError still, with its errno), leaves the
    old file and no temporary one, and the command line prints it as one line, exit 2."""
    import errno

    from optdesign.cli import run_guarded
    from optdesign.storage import StoreWriter, WriteError, open_store

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / ("sweep.jsonl" if writer == "store" else "sweep.csv")
    if writer == "store":
        open_store(target, "k", resume=False)
        store = StoreWriter(target)
    else:
        target.write_text("old")
    before = sorted(os.listdir(tmp_path))

    def write():
        if writer == "atomic_write_text":
            atomic_write_text(target, "new")
        elif writer == "atomic_output":  # a writer by name (savefig) fails in its own
            with atomic_output(target) as tmp:  # write, naming no file or the temporary one
                tmp.write_text("n")
                full()
        else:
            store.write({"id": "t0", "value": 1})

    with monkeypatch.context() as m:
        m.setattr(os, "write", full)
        with pytest.raises(WriteError) as err:
            write()
        assert run_guarded(write) == 2
    assert str(err.value).startswith(f"cannot write {target}: No space left on device")
    assert isinstance(err.value, OSError) and isinstance(err.value, StoreError)
    assert (err.value.errno, err.value.filename) == (errno.ENOSPC, str(target))
    assert capsys.readouterr().err == (
        f"optdesign: error: cannot write {target}: No space left on device\n"
    )
    assert sorted(os.listdir(tmp_path)) == before  # no temporary file left
    if writer == "store":
        store.close()
    else:
        assert target.read_text() == "old"


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


def test_resuming_a_store_whose_identity_line_was_torn_says_it_has_none(cs_min_backlash, tmp_path):
    """A store holding only a torn first line (a run stopped while writing its identity)
    is no store of any run: the resume is refused, saying so and how to start over."""
    from optdesign.storage import StoreError

    store = tmp_path / "epsilon.jsonl"
    store.write_text('{"__store__": 2, "identity": {"objec')
    with pytest.raises(StoreError) as caught:
        od.pareto(cs_min_backlash, ["backlash", "size"], 3, out=tmp_path, resume=True, starts=1)
    assert str(caught.value) == (
        f"resume=True: {store} cannot be resumed: it has no identity line; start over with "
        "overwrite=True or use another output folder"
    )
    assert store.read_text() == '{"__store__": 2, "identity": {"objec'


def test_a_torn_store_with_another_hard_link_is_not_repaired_in_place(tmp_path):
    store = tmp_path / "s.jsonl"
    run_tasks([{"id": f"t{i}", "n": i} for i in range(3)], _double, store, key="k")
    torn = store.read_bytes()[:-3]
    store.write_bytes(torn)
    other = tmp_path / "elsewhere.jsonl"
    os.link(store, other)
    with pytest.raises(UnsafeFileError) as caught:
        open_store(store, "k", resume=True)
    assert str(caught.value).startswith(
        f"the store {store} has 2 hard links (changing it would change another file too)"
    )
    assert other.read_bytes() == torn  # the file the other link names is untouched


def test_a_store_left_open_never_keeps_the_process_alive(tmp_path):
    """A store writer's fsync thread is a daemon: a program that exits (or dies) with a
    store still open ends all the same, its records on disk."""
    import subprocess
    import sys
    import textwrap

    store = tmp_path / "s.jsonl"
    store.write_text("")
    code = textwrap.dedent(
        f"""
        from optdesign.storage.store import StoreWriter
        w = StoreWriter({str(store)!r})
        w.write({{"id": "a", "value": 1}})
        """
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert store.read_text() == '{"id": "a", "value": 1}\n'
