"""Offline monitoring against its peers: rclverify, RTAMT, Reelay and mstlo on the same trace and property.

The property is a three-band classifier (the case study's Radiation Sensor
without its command): a reading ``r`` is answered by a status, ``green``
below 120, ``orange`` from 120 to below 250, ``red`` from 250 on.  The trace
has ``--samples`` samples, 10 ms apart; a sample is one reading (uniform in
[0, 400), full double precision) and the status that answers it, wrong with
probability ``--wrong`` (another band), so there are violations to agree on.

Each tool checks every sample, each in a process of its own on the same
samples (made from ``--seed``), the monitoring loop timed in CPU seconds:

* **rclverify engine** (monitor only): the contract below through
  ``check_trace`` (the offline verdict engine), the events made as it reads
  them, the mapping's rules, horizon 5 ms: the reading is the input event,
  the status (same stamp, logged after it) its answer (docs/monitors.md); a
  sample's verdict is its input event's (``satisfied`` or ``violated``).
  The horizon is half the sample period, so only a reading's own status can
  answer it (a later status fitting its band would satisfy it within a
  longer horizon), as each peer judges a sample on its own.  A last event
  past every horizon ends the run so no obligation is left open;
* **rclverify batch**: the same through ``check_trace``'s offline batch
  path (backends/monitors/batch.py: the answer pairs surely satisfied
  judged over numpy columns, every other event by the engine), which the
  command takes; its verdicts compared with the streaming engine's on
  every sample (issue 51: at least Reelay's samples per second);
* **rclverify batch, columns**: the same samples as a run held in columns
  (traces/table.py: the readings a float64 array, the statuses a string
  array, made from the samples with numpy inside the timing), read by the
  batch path without a Python object a sample (issue 67: at least twice
  Reelay's and mstlo's samples per second);
* **rclverify monitor**: the command on a workspace holding the contract,
  the mapping and the trace as a ROSMonitoring log (two lines a sample):
  the whole process's CPU (start, reading the log, checking, printing);
  and (unless ``--no-bags``) on the same samples in a sqlite3 and an MCAP
  ROS 2 bag (``std_msgs/msg/Float64`` readings, ``std_msgs/msg/String``
  statuses; traces/bag_blocks.py), whose counts must be the log's;
* **reading the log** (figures only): the log's blocks as the batch path
  takes them (traces/jsonl_blocks.py) and the ``data`` values of every
  row, in a process of its own after a warm-up on ten samples, without
  judging anything: the part of the command no monitor can skip (issue 67);
  the same for the two bags (traces/bag_blocks.py, a block's float column
  as the batch path takes it, after a warm-up reading the whole bag once,
  which also warms the file cache);
* **RTAMT** 0.4.10 (``pip install rtamt==0.4.10``): the discrete-time STL
  specification of the same property, updated sample by sample
  (robustness >= 0 is satisfied; statuses as 0, 1, 2);
* **Reelay** 25.0.0 (``pip install reelay==25.0.0``, C++ core): the same
  property in its rye syntax, a discrete monitor updated sample by sample;
* **mstlo** 0.2.2 (``pip install mstlo-python==0.2.2``, Rust core, RV
  2026): the same property as an STL formula over the reading and the
  status code (its predicates compare with ``<`` and ``>``: ``status ==
  1`` is ``status > 0.5 && status < 1.5``), qualitative semantics, fed by
  its batch call 16,384 samples at a time (its fastest input), one verdict
  per sample's stamp.

Every tool's set-up (parsing its specification, rclverify's imports and
first use: a first run on ten samples) is outside the timing; the timing
is the monitoring of the samples.

Printed: samples per CPU second, each as a ratio to the rclverify streaming
engine, the batch path's over Reelay's, the command's CPU over the batch
path's reading events (the reference of issue 67's table, aim: at most
1.2) and over the batch path on columns, and its samples per CPU second
against Reelay's and mstlo's end to end (the start-up included), the
command's start-up (the same command on ten samples) and its figures
without it, peak resident memory (of the largest child so far), and
whether each tool's verdict on every sample agrees with the rclverify
engine's (the bench exits non-zero when one does not) (the verdicts are collected in a second,
untimed run of the engine, so collecting them costs the timing nothing).
A peer that is not installed is skipped with the reason: the peers are
optional bench dependencies (``pip install '.[bench]'``), never rclverify's.

``--repeat K`` runs the command on the log and on the bags, its start-up,
the reading of the log and of the bags and the columns path K times each and keeps each one's least CPU
(the run the machine's other load disturbed least; the ratios between them
are taken from those).

``--compare OLD_SRC`` also runs the rclverify engine and command (on the log
and, unless ``--no-bags``, on the two bags) from an older source tree (e.g. ``git worktree add ../old <commit>``, then
``OLD_SRC=../old/src``) alternately with this one, and prints old, new
and new/old: issue 44's "at least 3x today's samples/s" is that ratio, in
one run on one machine.

``--windowed`` runs only the windowed race (bench/_window_peers.py): the
``rclverify monitor`` command with margins on ``G[0,2](x > 1)``, ``(x > 1)
U[0,3] (y > 4)`` and a ``triggered by ... within`` deadline against RTAMT's,
Reelay's and mstlo's robustness on ``--samples`` samples, every sample's
verdict and margin compared (with ``--smoke``: 2,000 samples); each peer twice: its monitoring loop
on the samples in memory, and as a program of its own reading the same log (bench/_peer_read.py),
timed as the command is (the whole process, its start-up printed apart); with ``--compare OLD_SRC``
the command from the older tree too, on the same logs in the same run (before -> after).

``--margins`` runs only the margins race (bench/_margin_peers.py): the
batch path's space margins of ``G(x > 1)`` as a per-answer guarantee
against RTAMT's, Reelay's and mstlo's robustness on ``--samples`` samples,
samples per CPU second and whether every sample's value agrees; ``--smoke``
ends with it on 1,000 samples.

Usage::

    python3 bench/monitor_peers.py --margins --samples 300000
    python3 bench/monitor_peers.py --windowed --samples 300000 [--repeat K]
    python3 bench/monitor_peers.py [--samples 1000000] [--wrong 0.001] [--compare OLD_SRC] [--no-bags] [--repeat K]
    python3 bench/monitor_peers.py --smoke     # 2,000 samples: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import random
import resource
import subprocess
import sys
import tempfile
import time
from array import array
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from _classifier import CLASSIFIER  # noqa: E402

BANDS = ("green", "orange", "red")
CONTRACT = CLASSIFIER  # tests/_classifier.py: the contract the batch path's tests check runs against
MAPPING = "horizon: 0.005\ntopics:\n  reading: {fields: [data]}\n  status: {fields: [data]}\n"
PLAN = "name: classifier\ncontracts: [contracts/classifier.rcl]\nnodes:\n  Classifier:\n    evidence: []\n"
RTAMT_SPEC = ("((r < 120) -> (status == 0)) and (((r >= 120) and (r < 250)) -> (status == 1)) "
              "and ((r >= 250) -> (status == 2))")
MSTLO_SPEC = ("((r < 120) -> (status < 0.5)) && (((r >= 120) && (r < 250)) -> ((status > 0.5) && (status < 1.5))) "
              "&& ((r >= 250) -> (status > 1.5))")  # statuses as 0, 1, 2: its predicates compare with < and > only
REELAY_SPEC = ("({r < 120} -> {status: green}) and ({r >= 120, r < 250} -> {status: orange}) "
               "and ({r >= 250} -> {status: red})")
PERIOD = 0.01  # s between samples
HORIZON = 0.005  # s: half the sample period, so a reading is answered by its own status only


def samples(n: int, seed: int, wrong: float) -> tuple[array, bytes]:
    """The readings (doubles) and the status answering each (0 green, 1 orange, 2 red)."""
    rnd = random.Random(seed)
    rs = array("d")
    st = bytearray()
    for _ in range(n):
        r = rnd.uniform(0.0, 400.0)
        band = 0 if r < 120 else 1 if r < 250 else 2
        if rnd.random() < wrong:
            band = (band + rnd.choice((1, 2))) % 3
        rs.append(r)
        st.append(band)
    return rs, bytes(st)


# -- children: one tool each, timed in their own process --------------------------------------------

def _columns(n: int, rs: array, st: bytes) -> Any:
    """The samples as a run held in columns (traces/table.py): the rows a reading and its status
    taking turns, then the last tick; made from the arrays with numpy, no Python object a sample."""
    import numpy as np
    from rclverify.traces.table import ColumnTrace
    topic = np.empty(2 * n + 1, dtype=np.int8)  # indices into the names below
    topic[0:2 * n:2], topic[1:2 * n:2], topic[-1] = 0, 1, 2
    t = np.arange(n, dtype=np.float64) * PERIOD  # the same doubles as i * PERIOD
    times = np.empty(2 * n + 1)
    times[0:2 * n:2], times[1:2 * n:2], times[-1] = t, t, n * PERIOD + 10 * HORIZON
    status = np.array(BANDS)[np.frombuffer(st, dtype=np.uint8)]
    return ColumnTrace(topic, times, {"reading": {"data": np.frombuffer(rs, dtype=np.float64)},
                                      "status": {"data": status}}, "synthetic", ["reading", "status", "tick"])


def _rclverify_engine(n: int, rs: array, st: bytes, verdicts: bool, batch: bool = False, columns: bool = False
                      ) -> tuple[float, bytes, dict[str, int]]:
    from rclverify.backends.monitors.check import check_trace
    from rclverify.lang.typecheck import load
    from rclverify.traces.events import Event
    from rclverify.traces.mapping import load_rules
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "classifier.rcl").write_text(CONTRACT)
        checked = load([Path(tmp) / "classifier.rcl"])
    rules = load_rules({"reading": {"fields": ["data"]}, "status": {"fields": ["data"]}})
    if type(rules) is not dict:  # an older tree's rules are a plain dict, with no skew
        rules.skew = 0.02  # the mapping's default transport skew, as the command runs it

    def events(n: int = n) -> Iterator[Any]:
        k = 0
        for i in range(n):
            t = i * PERIOD
            yield Event(k, t, "reading", {"data": rs[i]}, "synthetic")
            yield Event(k + 1, t, "status", {"data": BANDS[st[i]]}, "synthetic")
            k += 2
        yield Event(k, n * PERIOD + 10 * HORIZON, "tick", {}, "synthetic")  # past every horizon
    out = bytearray(b"\x02" * n)

    def seen(v: Any) -> None:
        out[v.event // 2] = {"satisfied": 1, "violated": 0}.get(v.verdict, 2)
    import inspect
    # the streaming engine alone, or the batch path (an older tree has no batch path: always streaming)
    extra = {"batch": batch} if "batch" in inspect.signature(check_trace).parameters else {}
    # a first run on ten samples: the imports and first-use set-up, outside the timing (as the peers' set-up)
    check_trace(checked, [checked.nodes["Classifier"]], _columns(10, rs[:10], st[:10]) if columns else events(10),
                rules, HORIZON, **extra)
    t0 = time.process_time()
    source = _columns(n, rs, st) if columns else events()
    _, (res,) = check_trace(checked, [checked.nodes["Classifier"]], source, rules, HORIZON,
                            seen if verdicts else None, **extra)
    counts = dict(res.counts)
    counts["evaluation"] = getattr(res, "evaluation", {})  # how the formulas ran (an older tree has no such field)
    return time.process_time() - t0, bytes(out), counts


def _rtamt(n: int, rs: array, st: bytes) -> tuple[float, bytes]:
    import rtamt  # type: ignore[import-not-found]
    spec = rtamt.StlDiscreteTimeSpecification()
    spec.declare_var("r", "float")
    spec.declare_var("status", "float")
    spec.spec = RTAMT_SPEC
    spec.parse()
    out = bytearray(n)
    update = spec.update
    codes = (0.0, 1.0, 2.0)
    t0 = time.process_time()
    for i in range(n):
        out[i] = update(i, [("r", rs[i]), ("status", codes[st[i]])]) >= 0
    return time.process_time() - t0, bytes(out)


def _reelay(n: int, rs: array, st: bytes) -> tuple[float, bytes]:
    import reelay  # type: ignore[import-not-found]
    m = reelay.discrete_timed_monitor(pattern=REELAY_SPEC, condense=False)
    out = bytearray(n)
    update = m.update
    t0 = time.process_time()
    for i in range(n):
        out[i] = update({"time": i, "r": rs[i], "status": BANDS[st[i]]})["value"]
    return time.process_time() - t0, bytes(out)


def _mstlo(n: int, rs: array, st: bytes) -> tuple[float, bytes]:
    """mstlo's Rust monitor, qualitative (true/false) semantics, fed by its batch call a chunk of samples at
    a time (its fastest input path: one call per 16,384 samples), one verdict per sample's time stamp."""
    import mstlo_python  # type: ignore[import-not-found]
    mon = mstlo_python.Monitor(mstlo_python.parse_formula(MSTLO_SPEC), semantics="DelayedQualitative")
    out = bytearray(n)
    codes = (0.0, 1.0, 2.0)
    step = 16384
    t0 = time.process_time()
    for a in range(0, n, step):
        b = min(n, a + step)
        ts = [i * PERIOD for i in range(a, b)]
        got = mon.update_batch({"r": list(zip(rs[a:b], ts)), "status": [(codes[s], t) for s, t in zip(st[a:b], ts)]})
        vs = got.verdicts()
        if len(vs) != b - a:
            raise SystemExit(f"mstlo: {len(vs)} verdicts for samples {a}..{b - 1}, one a sample expected")
        out[a:b] = bytes(bool(v) for _, v in vs)
    return time.process_time() - t0, bytes(out)


def child(args: argparse.Namespace) -> int:
    """Run one tool (``--child``) and print its figures as one JSON line."""
    if args.src:
        sys.path.insert(0, args.src)
    rs, st = samples(args.samples, args.seed, args.wrong)
    report: dict[str, Any] = {}
    try:
        if args.child == "read":
            cpu = _read_log(Path(args.log))
            print(json.dumps({"cpu": cpu, "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
            return 0
        if args.child in ("rclverify", "batch", "columns"):
            batch, cols = args.child != "rclverify", args.child == "columns"
            cpu, _, counts = _rclverify_engine(args.samples, rs, st, verdicts=False, batch=batch, columns=cols)
            report["counts"] = counts
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            if args.verdicts:
                _, out, counts2 = _rclverify_engine(args.samples, rs, st, verdicts=True, batch=batch, columns=cols)
                assert counts2 == counts, (counts, counts2)
                Path(args.verdicts).write_bytes(out)
        else:
            cpu, out = {"rtamt": _rtamt, "reelay": _reelay, "mstlo": _mstlo}[args.child](args.samples, rs, st)
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            if args.verdicts:
                Path(args.verdicts).write_bytes(out)
    except ImportError as exc:
        print(json.dumps({"skipped": f"{args.child} is not installed ({exc}); pip install '.[bench]'"}))
        return 0
    print(json.dumps({"cpu": cpu, "rss": rss, **report}))
    return 0


def _read_log(log: Path) -> float:
    """CPU seconds to read the log (or, a directory, the bag) at ``log`` as the batch path does
    (its blocks, a block's ``data`` at every row), after the same on the log's first ten samples
    (a bag: on the whole bag; the imports, outside)."""
    import numpy as np
    from rclverify.traces.bag_blocks import BagTrace
    from rclverify.traces.jsonl_blocks import JsonlLog

    def read(path: Path) -> int:
        rows = 0
        for block in (BagTrace(path) if path.is_dir() else JsonlLog(path)).blocks(["data"], 16384) or ():
            rows += len(block)
            if not isinstance(block, list):  # the column as the batch path takes it (rows.py: typed, else values)
                at = np.arange(len(block))
                if getattr(block, "typed", None) is None or block.typed(at, "data", "real", {}) is None:
                    block.values(at, "data")
        return rows
    with tempfile.TemporaryDirectory() as tmp:
        head = Path(tmp) / "head.jsonl"
        if log.is_dir():
            head = log
        else:
            with log.open("rb") as f:
                head.write_bytes(b"".join(f.readline() for _ in range(20)))
        read(head)
    t0 = time.process_time()
    read(log)
    return time.process_time() - t0


# -- the parent: runs the children, the command, and compares -----------------------------------------

def _best(k: int, run: Any) -> dict[str, Any]:
    """The figures of ``run()`` (a child's) with the least CPU of ``k`` runs."""
    return min((run() for _ in range(max(k, 1))), key=lambda r: float(r.get("cpu", 0.0)))


def _run_child(tool: str, args: argparse.Namespace, verdicts: Path | None, src: str | None,
               log: Path | None = None) -> dict[str, Any]:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", tool, "--samples", str(args.samples),
           "--seed", str(args.seed), "--wrong", str(args.wrong), "--src", src or str(ROOT / "src")]
    if log is not None:
        cmd += ["--log", str(log)]
    if verdicts is not None:
        cmd += ["--verdicts", str(verdicts)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{tool}: exited {p.returncode}:\n{p.stderr[-3000:]}")
    return dict(json.loads(p.stdout.strip().splitlines()[-1]))


def _workspace(tmp: Path, args: argparse.Namespace) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "backends/monitors").mkdir(parents=True)
    (tmp / "contracts/classifier.rcl").write_text(CONTRACT)
    (tmp / "contracts/plan.yaml").write_text(PLAN)
    (tmp / "backends/monitors/mapping.yaml").write_text(MAPPING)
    rs, st = samples(args.samples, args.seed, args.wrong)
    with (tmp / "run.jsonl").open("w") as f:
        for i in range(args.samples):
            t = round(i * PERIOD, 6)
            f.write(f'{{"topic": "reading", "time": {t!r}, "data": {rs[i]!r}}}\n'
                    f'{{"topic": "status", "time": {t!r}, "data": "{BANDS[st[i]]}"}}\n')
        f.write(f'{{"topic": "tick", "time": {args.samples * PERIOD + 10 * HORIZON!r}}}\n')
    return tmp


def _bags(ws: Path, args: argparse.Namespace) -> None:
    """The same samples as ROS 2 bags beside the log: ``run_sqlite3`` and ``run_mcap`` (rosbags' writer),
    the readings ``std_msgs/msg/Float64``, the statuses ``std_msgs/msg/String`` (their CDR bytes made here),
    the recording stamps the log's times in nanoseconds."""
    import struct
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rclverify.traces.bag import typestore
    store = typestore([])
    rs, st = samples(args.samples, args.seed, args.wrong)
    status = [b"\x00\x01\x00\x00" + struct.pack("<I", len(b) + 1) + b.encode() + b"\x00" for b in BANDS]
    for storage, plugin in (("sqlite3", StoragePlugin.SQLITE3), ("mcap", StoragePlugin.MCAP)):
        with Writer(ws / f"run_{storage}", version=9, storage_plugin=plugin) as w:
            cr = w.add_connection("/reading", "std_msgs/msg/Float64", typestore=store)
            cs = w.add_connection("/status", "std_msgs/msg/String", typestore=store)
            ct = w.add_connection("/tick", "std_msgs/msg/Float64", typestore=store)
            for i in range(args.samples):
                t = round(i * PERIOD * 1e9)
                w.write(cr, t, struct.pack("<4sd", b"\x00\x01\x00\x00", rs[i]))
                w.write(cs, t, status[st[i]])
            w.write(ct, round((args.samples * PERIOD + 10 * HORIZON) * 1e9), struct.pack("<4sd", b"\x00\x01\x00\x00", 0.0))


def _run_command(ws: Path, src: str, trace: str = "run.jsonl") -> dict[str, Any]:
    """``rclverify monitor`` on the workspace's log: the child's CPU (user +
    system) and peak RSS, from the rusage of the waited child."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src] + ([os.environ["PYTHONPATH"]]
                                                                if os.environ.get("PYTHONPATH") else []))}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, "-c", "import sys; from rclverify.cli.commands import main; sys.exit(main())",
                        "monitor", "-w", str(ws), str(ws / trace)], capture_output=True, text=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode not in (0, 1) or not p.stdout:
        raise SystemExit(f"rclverify monitor exited {p.returncode}:\n{p.stderr[-3000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"cpu": cpu, "rss": after.ru_maxrss / 1024, "out": p.stdout.strip().splitlines()[0] if p.stdout else ""}


def _agree(a: bytes, b: bytes) -> str:
    same = sum(1 for x, y in zip(a, b) if x == y)
    first = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), None)
    return f"{same}/{len(a)}" + ("" if first is None else f" (first difference at sample {first})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--wrong", type=float, default=0.001, help="probability of a wrong status (a violation)")
    ap.add_argument("--seed", type=int, default=44)
    ap.add_argument("--compare", metavar="OLD_SRC", help="also run the engine and the command from this source tree")
    ap.add_argument("--smoke", action="store_true", help="2,000 samples (CI); then the margins race on 1,000")
    ap.add_argument("--margins", action="store_true",
                    help="only the margins race: G(x > 1) on --samples (bench/_margin_peers.py)")
    ap.add_argument("--windowed", action="store_true",
                    help="only the windowed race: G[0,2], U[0,3] and a deadline, the command against the peers "
                         "(bench/_window_peers.py)")
    ap.add_argument("--skew", type=float, default=0.0, metavar="S",
                    help="with --margins: the mapping's transport skew for rclverify, s (the command's default: 0.02)")
    ap.add_argument("--no-bags", action="store_true", help="leave out the command on the sqlite3 and MCAP bags")
    ap.add_argument("--repeat", type=int, default=1, metavar="K",
                    help="run the command on the log and the bags, its start-up, the readings and the columns path K times; keep "
                         "each one's least CPU")
    ap.add_argument("--child", choices=("rclverify", "batch", "columns", "read", "rtamt", "reelay", "mstlo"),
                    help=argparse.SUPPRESS)
    ap.add_argument("--log", help=argparse.SUPPRESS)
    ap.add_argument("--src", help=argparse.SUPPRESS)
    ap.add_argument("--verdicts", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args)
    if args.windowed:  # bench/_window_peers.py: the command on windowed formulas against the peers
        from _window_peers import race as windowed
        return 0 if windowed(2_000 if args.smoke else args.samples, args.seed, args.wrong, args.repeat,
                             old=args.compare) else 1
    if args.margins:  # bench/_margin_peers.py: rclverify's margins against the peers' robustness
        from _margin_peers import race
        return 0 if race(1_000 if args.smoke else args.samples, args.seed, args.wrong, args.skew) else 1
    if args.smoke:
        args.samples = 2_000
    print(f"{args.samples} samples (a reading and its answer each), {args.wrong:g} of the answers wrong, "
          f"seed {args.seed}")
    rows, verdicts = _measure(args)
    _print(rows, verdicts, args)
    if args.smoke:
        from _margin_peers import race
        return 0 if race(1_000, args.seed, args.wrong) else 1
    return 0


def _measure(args: argparse.Namespace) -> tuple[dict[str, dict[str, Any]], dict[str, bytes]]:
    """Every tool's figures (row name -> the child's JSON) and verdicts (row -> a byte a sample)."""
    trees = [("new", str(ROOT / "src"))] + ([("old", str(Path(args.compare).resolve()))] if args.compare else [])
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        (base / "ws").mkdir()
        ws = _workspace(base / "ws", args)
        rows: dict[str, dict[str, Any]] = {}
        verdicts: dict[str, bytes] = {}
        for label, src in trees:  # alternately: the machine's load moves both alike
            r = _run_child("rclverify", args, base / f"v-{label}", src)
            rows[f"rclverify engine ({label})"] = r
            verdicts[label] = (base / f"v-{label}").read_bytes()
            if label == "new":
                for kind, row in (("batch", "rclverify batch"), ("columns", "rclverify batch, columns")):
                    rows[row] = _run_child(kind, args, base / f"v-{kind}", src)
                    verdicts[row] = (base / f"v-{kind}").read_bytes()
                if args.repeat > 1:
                    rows["rclverify batch, columns"] = _best(args.repeat, lambda: _run_child("columns", args, None, src))
                rows["reading the log (new)"] = _best(args.repeat, lambda: _run_child("read", args, None, src,
                                                                                      ws / "run.jsonl"))
            rows[f"rclverify monitor ({label})"] = _best(args.repeat, lambda: _run_command(ws, src))
            if label == "new" and not args.no_bags:  # the same samples in ROS 2 bags
                _bags(ws, args)
                for storage in ("sqlite3", "mcap"):
                    rows[f"rclverify monitor, {storage}"] = _best(args.repeat, lambda s=storage: _run_command(
                        ws, src, f"run_{s}"))
                    rows[f"reading the {storage} bag"] = _best(args.repeat, lambda s=storage: _run_child(
                        "read", args, None, src, ws / f"run_{s}"))
            if label == "old" and not args.no_bags:  # the older tree's command on the same bags
                for storage in ("sqlite3", "mcap"):
                    rows[f"rclverify monitor, {storage} (old)"] = _best(args.repeat, lambda s=storage: _run_command(
                        ws, src, f"run_{s}"))
            if label == "new":  # the command's start-up: the same command on a log of ten samples
                tiny = argparse.Namespace(**{**vars(args), "samples": 10})
                (base / "tiny").mkdir()
                small = _workspace(base / "tiny", tiny)
                rows["rclverify monitor, 10 samples"] = _best(args.repeat, lambda: _run_command(small, src))
        for tool in ("rtamt", "reelay", "mstlo"):
            r = _run_child(tool, args, base / f"v-{tool}", None)
            rows[tool] = r
            if "skipped" not in r:
                verdicts[tool] = (base / f"v-{tool}").read_bytes()
    return rows, verdicts


def _print(rows: dict[str, dict[str, Any]], verdicts: dict[str, bytes], args: argparse.Namespace) -> None:
    """The table and the ratios; exits 1 (SystemExit) when a verdict or the command's counts differ."""
    n = args.samples
    engine = rows["rclverify engine (new)"]["cpu"]
    batch = rows["rclverify batch"]
    print(f"{'tool':<33} {'samples/s':>11} {'x engine':>9} {'peak RSS MiB':>13}  verdicts agree with the streaming engine")
    for name, r in rows.items():
        if "skipped" in r:
            print(f"{name:<33} skipped: {r['skipped']}")
            continue
        if name.endswith("10 samples"):
            print(f"{name:<33} {'':>11} {'':>9} {r['rss']:>13.1f}  (its CPU: {r['cpu']:.2f} s, the start-up)")
            continue
        key = name.split("(")[-1].rstrip(")") if name.startswith("rclverify engine") else name
        agree = _agree(verdicts[key], verdicts["new"]) if key in verdicts else "-"
        print(f"{name:<33} {n / r['cpu']:>11.0f} {engine / r['cpu']:>9.2f} {r['rss']:>13.1f}  {agree}")
    counts = dict(rows["rclverify engine (new)"]["counts"])
    evaluation = counts.pop("evaluation", {})
    bcounts = dict(batch["counts"])
    bcounts.pop("evaluation", None)
    print("rclverify engine verdicts: " + ", ".join(f"{v} {k}" for k, v in counts.items() if v)
          + "; formulas: " + ", ".join(f"{k} {v}" for k, v in evaluation.items())
          + ("; the batch path's counts: the same" if bcounts == counts else f"; the batch path's DIFFER: {bcounts}"))
    cols = rows["rclverify batch, columns"]
    for peer in ("reelay", "mstlo"):
        if peer in rows and "skipped" not in rows[peer]:
            print(f"rclverify batch / {peer} samples/s: {rows[peer]['cpu'] / cols['cpu']:.2f} reading columns, "
                  f"{rows[peer]['cpu'] / batch['cpu']:.2f} reading events (aim: at least 2)")
    start = rows["rclverify monitor, 10 samples"]["cpu"]
    said = set()
    for name in ("rclverify monitor (new)", "rclverify monitor, sqlite3", "rclverify monitor, mcap"):
        if name not in rows:
            continue
        cmd = rows[name]
        peers = "; ".join(f"samples/s end to end over {peer}'s: {rows[peer]['cpu'] / cmd['cpu']:.2f}"
                          for peer in ("reelay", "mstlo") if peer in rows and "skipped" not in rows[peer])
        print(f"{name}: {n / cmd['cpu']:.0f} samples per CPU second, the start-up ({start:.2f} s) included; "
              f"{n / max(cmd['cpu'] - start, 1e-3):.0f} without it; command / batch path reading events (the "
              f"reference of issue 67's table): {cmd['cpu'] / batch['cpu']:.2f} (aim: at most 1.2); command / "
              f"batch path on columns: {cmd['cpu'] / cols['cpu']:.2f}, {(cmd['cpu'] - start) / cols['cpu']:.2f} "
              f"without the start-up; {peers}; printed: {cmd['out']}")
        said.add(cmd["out"].split(": ", 1)[-1])
    for name, what in (("reading the log (new)", "the log"), ("reading the sqlite3 bag", "the sqlite3 bag"),
                       ("reading the mcap bag", "the MCAP bag")):
        if name in rows:
            read = rows[name]["cpu"]
            print(f"reading {what} alone (blocks and values, nothing judged): {read:.2f} CPU s, "
                  f"{read / cols['cpu']:.2f}x the batch path on columns")
    if len(said) != 1:  # the log and the two bags hold the same samples: the same counts
        raise SystemExit(f"the command's counts differ between the log and the bags: {sorted(said)}")
    wrong = [k for k, v in verdicts.items() if v != verdicts["new"]]
    if wrong:  # a figure of a tool that judged otherwise compares nothing
        raise SystemExit(f"verdicts differ from the streaming engine's: {', '.join(wrong)}")
    if args.compare:
        old = rows["rclverify engine (old)"]["cpu"]
        old_cmd = rows["rclverify monitor (old)"]["cpu"]
        new_cmd = rows["rclverify monitor (new)"]["cpu"]
        print(f"engine samples/s new/old: {old / engine:.2f} (aim: at least 3); "
              f"command new/old: {old_cmd / new_cmd:.2f}; old command / old engine: {old_cmd / old:.2f}")
        for storage in ("sqlite3", "mcap"):
            if f"rclverify monitor, {storage} (old)" in rows:
                print(f"command on the {storage} bag, CPU s old / new: "
                      f"{rows[f'rclverify monitor, {storage} (old)']['cpu']:.2f} / "
                      f"{rows[f'rclverify monitor, {storage}']['cpu']:.2f}")


if __name__ == "__main__":
    sys.exit(main())
