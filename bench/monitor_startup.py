"""The ``rclverify monitor`` command's start-up and its reading of a JSON-lines log (issue 106).

Printed, each the least CPU (user + system) of ``--repeat`` runs:

* **start-up**: ``rclverify monitor --help`` and ``rclverify monitor
  --json --margins`` on a ten-line log (five windowed samples of
  ``G[0,2](x > 1)``, bench/_window_peers.py's workspace), each a process
  of its own (``rclverify.cli:main``, the console script's entry), the
  CPU of the waited child;
* **modules**: what the ten-line run imported (in a process of its own:
  the command run in-process, then ``sys.modules`` read): the count of
  modules, of rclverify's, and which of the named heavy libraries
  (:data:`HEAVY`) were loaded;
* **reading**: CPU seconds per 100,000 lines to read a log as the
  command's batch path reads it (``JsonlLog.blocks``, a block's ``data``
  at every row, the collector off as the batch path runs it), in a child
  after a warm-up on its first twenty lines, for a windowed log (each
  answer's ``data`` an array of three floats) and a scalar one (each
  ``data`` one float), ``--lines`` lines each.

The children run with bytecode caching on (``PYTHONDONTWRITEBYTECODE``
removed from their environment) and one warm-up of each command before
the timing, as an installed rclverify runs; they share a user cache
(``XDG_CACHE_HOME``) in the temporary folder, warmed by that first run,
so the start-up measured is the one after the first run on a workspace.

``--compare OLD_SRC`` runs the same from an older source tree (e.g. ``git
worktree add ../old <commit>``, then ``OLD_SRC=../old/src``) and prints old,
new and new/old; the start-up runs of the two trees alternate (new, old,
new, ...), so that a load that comes and goes on a shared machine falls on
both.

Usage::

    python3 bench/monitor_startup.py [--lines 600000] [--repeat 3] [--compare OLD_SRC]
    python3 bench/monitor_startup.py --smoke     # 2,000 lines, one run: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[1]
#: Libraries the command needs only for some runs: their import on a plain log is start-up spent for nothing.
#: (``rosbags.typesys.stores``: its standard type store; ``numpy``, ``yaml`` and ``msgspec`` a run on a large log needs.)
HEAVY = ("z3", "cvc5", "lark", "jinja2", "jsonschema", "rosbags.typesys.stores", "numpy", "yaml", "msgspec", "networkx",
         "rich", "hypothesis", "doit", "websockets", "pygls", "cyclonedds", "rclpy", "rospy", "importlib.metadata")
ENTRY = "import sys; from rclverify.cli import main; sys.exit(main())"


def _env(src: str, cache: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = os.pathsep.join([src] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))
    env["XDG_CACHE_HOME"] = str(cache)
    return env


def _cpu(argv: list[str], env: dict[str, str]) -> float:
    """CPU seconds (user + system) of the child ``argv``, which must exit 0 or 1 and print something."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(argv, capture_output=True, text=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode not in (0, 1) or not p.stdout:
        raise SystemExit(f"{' '.join(argv[3:])} exited {p.returncode}:\n{p.stderr[-3000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _logs(tmp: Path, lines: int) -> tuple[Path, Path, Path]:
    """(the ten-line workspace, a windowed log of ``lines`` lines, a scalar log of ``lines`` lines)."""
    sys.path.insert(0, str(ROOT / "bench"))
    from _window_peers import FORMULAS, signals, workspace
    samples = max(lines // 2, 10)
    s = signals(samples + 3, 44, 0.001)
    tiny = tmp / "tiny"
    workspace(tiny, FORMULAS[0], s, 7)  # 5 samples whose window lies in the trace: 10 lines and the tick
    windowed = workspace(tmp / "windowed", FORMULAS[0], s, samples + 2)
    scalar = tmp / "scalar.jsonl"
    with scalar.open("w") as out:
        for i, x in enumerate(s["x"][:samples].tolist()):
            t = round(i * 0.01, 6)
            out.write(f'{{"topic": "limit", "time": {t!r}, "data": 1.0}}\n'
                      f'{{"topic": "window", "time": {t!r}, "data": {x!r}}}\n')
    return tiny, windowed, scalar


def startups(trees: list[tuple[str, str]], tmp: Path, tiny: Path, repeat: int) -> dict[str, dict[str, Any]]:
    """Per tree label, the least CPU of ``repeat`` runs of ``monitor --help`` (``help``) and of the
    ten-line run (``tiny``), the trees' runs alternating; each tree's user cache is ``tmp/<label>/cache``."""
    help_argv = [sys.executable, "-c", ENTRY, "monitor", "--help"]
    run_argv = [sys.executable, "-c", ENTRY, "monitor", "--json", "--margins", "-w", str(tiny), str(tiny / "run.jsonl")]
    envs = {label: _env(src, tmp / label / "cache") for label, src in trees}
    for env in envs.values():
        _cpu(help_argv, env)  # warm-up: bytecode and the user cache written
        _cpu(run_argv, env)
    runs: dict[str, dict[str, list[float]]] = {label: {"help": [], "tiny": []} for label in envs}
    for _ in range(repeat):
        for label, env in envs.items():
            runs[label]["help"].append(_cpu(help_argv, env))
            runs[label]["tiny"].append(_cpu(run_argv, env))
    return {label: {k: min(v) for k, v in r.items()} for label, r in runs.items()}


def measure(src: str, tmp: Path, tiny: Path, logs: list[Path], repeat: int) -> dict[str, Any]:
    """The figures of the tree ``src`` but its start-up (module docstring; :func:`startups`)."""
    env = _env(src, tmp / "cache")
    run_argv = [sys.executable, "-c", ENTRY, "monitor", "--json", "--margins", "-w", str(tiny), str(tiny / "run.jsonl")]
    _cpu(run_argv, env)  # warm-up: bytecode and the user cache written, as the modules child finds them
    out: dict[str, Any] = {}
    p = subprocess.run([sys.executable, __file__, "--child", "modules", "--", *run_argv[3:]], env=env,
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"modules child exited {p.returncode}:\n{p.stderr[-3000:]}")
    out["modules"] = json.loads(p.stdout.strip().splitlines()[-1])
    for log in logs:
        runs = []
        for _ in range(repeat):
            p = subprocess.run([sys.executable, __file__, "--child", "read", "--", str(log)], env=env,
                               capture_output=True, text=True)
            if p.returncode != 0:
                raise SystemExit(f"read child exited {p.returncode}:\n{p.stderr[-3000:]}")
            runs.append(json.loads(p.stdout.strip().splitlines()[-1]))
        out[log.parent.name if log.name == "run.jsonl" else log.stem] = min(runs, key=lambda r: float(r["cpu"]))
    return out


def _child_modules(argv: list[str]) -> int:
    import contextlib
    import io
    from rclverify.cli import main
    with contextlib.redirect_stdout(io.StringIO()):
        main(argv)
    names = list(sys.modules)
    print(json.dumps({"modules": len(names), "rclverify": sum(n.split(".")[0] == "rclverify" for n in names),
                      "heavy": [h for h in HEAVY if h in sys.modules]}))
    return 0


def _child_read(log: Path) -> int:
    import gc
    import time
    import numpy as np
    from rclverify.traces.jsonl_blocks import JsonlLog

    def read(path: Path) -> int:
        rows = 0
        for block in JsonlLog(path).blocks(["data"], 16384) or ():
            rows += len(block)
            if not isinstance(block, list):  # the column as the batch path takes it
                block.values(np.arange(len(block)), "data")
        return rows
    with tempfile.TemporaryDirectory() as tmp:
        head = Path(tmp) / "head.jsonl"
        with log.open("rb") as f:
            head.write_bytes(b"".join(f.readline() for _ in range(20)))
        read(head)
    gc.disable()  # as the batch path reads (backends/monitors/batch.py)
    t0 = time.process_time()
    rows = read(log)
    cpu = time.process_time() - t0
    print(json.dumps({"cpu": cpu, "lines": rows, "per_100k": cpu / max(rows, 1) * 1e5}))
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=600_000, help="lines of each log read (default 600,000)")
    ap.add_argument("--repeat", type=int, default=3, metavar="K", help="keep each figure's least CPU of K runs")
    ap.add_argument("--compare", metavar="OLD_SRC", help="also measure this older source tree, alternately")
    ap.add_argument("--smoke", action="store_true", help="2,000 lines, one run")
    ap.add_argument("--child", choices=("modules", "read"), help=argparse.SUPPRESS)
    ap.add_argument("rest", nargs="*", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child == "modules":
        return _child_modules(args.rest)
    if args.child == "read":
        return _child_read(Path(args.rest[0]))
    if args.smoke:
        args.lines, args.repeat = 2_000, 1
    trees = [("new", str(ROOT / "src"))] + ([("old", str(Path(args.compare).resolve()))] if args.compare else [])
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        tiny, windowed, scalar = _logs(base, args.lines)
        got = {label: measure(src, base / label, tiny, [windowed, scalar], args.repeat) for label, src in trees}
        for label, figures in startups(trees, base, tiny, args.repeat).items():
            got[label].update(figures)
    print(f"rclverify monitor: start-up and reading; CPU s the least of {args.repeat} run(s)")
    rows: list[tuple[str, Callable[[dict[str, Any]], float], str]] = [
        ("start-up: monitor --help", lambda r: r["help"], "{:.3f} s"),
        ("start-up: monitor --json --margins, 10 lines", lambda r: r["tiny"], "{:.3f} s"),
        ("reading, windowed log, per 100k lines", lambda r: r["windowed"]["per_100k"], "{:.3f} s"),
        ("reading, scalar log, per 100k lines", lambda r: r["scalar"]["per_100k"], "{:.3f} s")]
    head = f"{'':<46} {'new':>9}" + (f" {'old':>9} {'new/old':>8}" if "old" in got else "")
    print(head)
    for name, pick, fmt in rows:
        line = f"{name:<46} {fmt.format(pick(got['new'])):>9}"
        if "old" in got:
            line += f" {fmt.format(pick(got['old'])):>9} {pick(got['new']) / max(pick(got['old']), 1e-9):>8.2f}"
        print(line)
    for label, r in got.items():
        m = r["modules"]
        print(f"modules imported by the 10-line run ({label}): {m['modules']} ({m['rclverify']} of rclverify); "
              f"heavy: {', '.join(m['heavy']) or 'none'}")
    print(f"logs read: {got['new']['windowed']['lines']} windowed and {got['new']['scalar']['lines']} scalar lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
