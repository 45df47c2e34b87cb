"""A child process that runs cases in-process, and the parent's client of it.

Importing optdesign and its solver libraries costs a second or two; a child that stays
up runs hundreds of cases at the price of one. Each run gets its own working directory,
its stdout and stderr redirected at the file-descriptor level (so that a C library's
output and a forked worker's are captured too), a time limit (SIGALRM, and a hard one in
the parent for a hang inside C code) and, for the whole child, a limit on its address
space (``starts=10**9`` or ``--update-readme /dev/zero`` must not take the machine's
memory). A crash (a segfault, an abort) kills only the child: the parent records it
against the running case and starts a new one.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import select
import signal
import subprocess
import sys
import time
import tomllib
import traceback
from pathlib import Path
from typing import Any

from hostile_classes import workspace

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
#: Address-space limit of the child (bytes): far above what a case needs (~1.5 GB with
#: the solver libraries), far below the machine's memory.
MEMORY_LIMIT = 6 << 30
#: Seconds the parent waits past a case's own time limit before killing the child.
GRACE = 20.0


def child_env(extra: dict[str, str] | None = None, one_thread: bool = True) -> dict[str, str]:
    """The environment of a run: the repository and tests importable, Agg, no
    OPTDESIGN_DEBUG unless a case sets it; ``one_thread``: one BLAS / OpenMP thread (the
    machine is shared). The determinism cases run with the user's default threads: the
    front of ``pareto --deterministic`` depends on them."""
    env = {k: v for k, v in os.environ.items() if k != "OPTDESIGN_DEBUG"}
    path = env.get("PYTHONPATH")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), str(HERE.parent), *([path] if path else [])])
    env["MPLBACKEND"] = "Agg"
    if one_thread:
        env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    else:
        for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            env.pop(k, None)
    env.update(extra or {})
    return env


class Ctx:
    """What an API case sees: its folders and its problem file."""

    def __init__(self, root: Path, text: str | bytes | None):
        self.root = root
        p = workspace.paths(root)
        self.cwd, self.out, self.outside, self.file = (
            p["@CWD@"],
            p["@OUT@"],
            p["@OUTSIDE@"],
            p["@FILE@"],
        )
        self._text = text

    def text(self) -> str:
        assert isinstance(self._text, str)
        return workspace.fill(self._text, self.root)

    def data(self) -> dict[str, Any]:
        """The problem file parsed (the dict form a script gives ``od.load``)."""
        return tomllib.loads(self.text())

    def module(self, name: str):
        """Import the user's own file ``cwd/name.py`` (written with the case's folder)."""
        path = self.cwd / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
        return mod


# --- the child --------------------------------------------------------------------------------
class _Hang(BaseException):
    """The run's time limit (not an Exception: no handler of the code under test takes it)."""


def _on_alarm(signum, frame):
    raise _Hang


def _run_cli(argv: list[str]) -> Any:
    from optdesign.cli import main

    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except _Hang:
        return "hang"
    except BaseException:
        traceback.print_exc()
        return "exception"


def _run_api(case: Any, root: Path) -> dict[str, Any]:
    from hostile_classes.verify import failure_text, value_problems
    from optdesign.errors import OptDesignError

    ctx = Ctx(root, case.text)
    try:
        value = case.api(ctx)
    except _Hang:
        return {"api": "hang"}
    except BaseException as exc:
        return {
            "api": "raised",
            "optdesign": isinstance(exc, OptDesignError),
            "type": type(exc).__name__,
            "message": str(exc)[:4000],
            "traceback": "".join(traceback.format_exception(exc))[-6000:],
        }
    failed = type(value).__name__ in ("Result", "Front") and (
        not getattr(value, "success", True) or not getattr(value, "points", True)
    )
    problems: list[str] = []
    try:
        if not failed:
            problems = value_problems(value)
            if case.check is not None and not problems:
                problems += case.check(value, ctx)
    except _Hang:
        return {"api": "hang"}
    except BaseException as exc:
        problems.append(f"verifying it raised {type(exc).__name__}: {exc}"[:2000])
    return {
        "api": "returned",
        "kind": type(value).__name__,
        "failed": failed,
        "problems": problems,
        "text": failure_text(value) if failed else "",
    }


@contextlib.contextmanager
def captured(req: dict[str, Any], env: dict[str, str], pythonpath: bool = False):
    """Inside: fd 1 and 2 go to the request's files, the working directory is the case's,
    its environment set (OPTDESIGN_DEBUG only if it asks), the time limit armed."""
    root = Path(req["root"])
    out_fd = os.open(req["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    err_fd = os.open(req["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    os.dup2(out_fd, 1)
    os.dup2(err_fd, 2)
    os.close(out_fd)
    os.close(err_fd)
    old_cwd = os.getcwd()
    old_env = {k: os.environ.get(k) for k in [*env, "OPTDESIGN_DEBUG"]}
    os.environ.pop("OPTDESIGN_DEBUG", None)
    os.environ.update(env)
    os.chdir(root / "cwd")
    if pythonpath:
        sys.path.insert(0, str(root / "cwd"))
    old_alarm = signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, float(req["timeout"]))
    try:
        yield root
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old_alarm)
        with contextlib.suppress(Exception):
            sys.stdout.flush()
        with contextlib.suppress(Exception):
            sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])
        os.chdir(old_cwd)
        if pythonpath:
            sys.path.remove(str(root / "cwd"))
        for k, v in old_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def execute(case: Any, req: dict[str, Any]) -> dict[str, Any]:
    """Run one request (a case in one mode) with its output captured, in its folder."""
    t0 = time.perf_counter()
    try:
        with captured(req, case.env, case.pythonpath) as root:
            if req["mode"] == "api":
                res = _run_api(case, root)
            else:
                res = {"code": _run_cli(req["argv"])}
                if res["code"] == "hang":
                    res = {"hang": True}
    except _Hang:  # the alarm, in the restoring itself
        res = {"hang": True}
    if res.get("api") == "hang":
        res = {"hang": True}
    res["seconds"] = time.perf_counter() - t0
    return res


def execute_fuzz(req: dict[str, Any]) -> dict[str, Any]:
    from hostile_classes.fuzz import run_in_child

    t0 = time.perf_counter()
    try:
        with captured(req, {}):
            outcomes = run_in_child(int(req["fuzz"]), req["home"])
    except _Hang:
        return {"hang": True, "seconds": time.perf_counter() - t0}
    return {"outcomes": outcomes, "seconds": time.perf_counter() - t0}


def serve() -> None:
    """The child's loop: one JSON request a line on stdin, one JSON answer a line."""
    import resource

    sys.dont_write_bytecode = True  # no __pycache__ next to a case's own modules
    chan = os.fdopen(os.dup(1), "w", buffering=1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    import optdesign.cli
    import optdesign.studies.solve
    from hostile_classes.run import case_index

    optdesign.cli.build_parser()
    cases = case_index()
    chan.write("ready\n")
    for line in sys.stdin:
        req = json.loads(line)
        try:
            res = execute_fuzz(req) if "fuzz" in req else execute(cases[req["case"]], req)
        except Exception:  # the corpus's own bug: the parent raises it
            res = {"harness_error": traceback.format_exc()}
        chan.write(json.dumps(res, default=str) + "\n")


# --- the parent's client ------------------------------------------------------------------------
class Server:
    """The parent's handle on the child; restarts it after a crash or a hang."""

    def __init__(self, workdir: Path):
        self.workdir = workdir
        self.proc: subprocess.Popen | None = None
        self._buf = b""
        self.starts = 0

    def start(self) -> None:
        self.workdir.mkdir(parents=True, exist_ok=True)
        log = open(self.workdir / "server.log", "ab")
        self.proc = subprocess.Popen(
            [sys.executable, "-c", "from hostile_classes.server import serve; serve()"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=log,
            env=child_env(),
            cwd=self.workdir,
            start_new_session=True,
        )
        log.close()
        self._buf = b""
        self.starts += 1
        line = self._readline(time.monotonic() + 180)
        if line != "ready":
            raise RuntimeError(f"the corpus server did not start ({line!r}); see server.log")

    def stop(self) -> None:
        if self.proc is None:
            return
        with contextlib.suppress(OSError):
            self.proc.stdin.close()  # type: ignore[union-attr]
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            pass
        self._kill()
        self.proc = None

    def _kill(self) -> None:
        if self.proc is None:
            return
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.proc.pid, signal.SIGKILL)
        with contextlib.suppress(Exception):
            self.proc.wait(10)

    def _readline(self, deadline: float) -> str | None:
        """The child's next line; None once it has died or when ``deadline`` passed."""
        assert self.proc is not None and self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        while b"\n" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([fd], [], [], min(left, 1.0))
            if not ready:
                if self.proc.poll() is not None:
                    return None
                continue
            chunk = os.read(fd, 65536)
            if not chunk:  # the child closed its end: it is dying (a worker may linger)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self.proc.wait(10)
                return None
            self._buf += chunk
        line, _, self._buf = self._buf.partition(b"\n")
        return line.decode()

    def execute(self, req: dict[str, Any], timeout: float) -> dict[str, Any]:
        """Run one request; a dead child is a crash, a silent one past the limit a hang."""
        if self.proc is None or self.proc.poll() is not None:
            self.start()
        assert self.proc is not None and self.proc.stdin is not None
        t0 = time.monotonic()
        self.proc.stdin.write((json.dumps(req) + "\n").encode())
        self.proc.stdin.flush()
        line = self._readline(t0 + timeout + GRACE)
        if line is not None:
            res = json.loads(line)
            if "harness_error" in res:
                raise RuntimeError(f"the corpus itself failed:\n{res['harness_error']}")
            return res
        seconds = time.monotonic() - t0
        code = self.proc.poll()
        if code is not None:
            self._kill()
            self.proc = None
            return {"crash": code, "seconds": seconds}
        self._kill()
        self.proc = None
        return {"hang": True, "seconds": seconds}
