"""The windowed race of bench/monitor_peers.py (``--windowed``): the ``rclverify monitor`` command against
RTAMT, Reelay and mstlo on windowed formulas, each reading the same samples.

Three formulas over ``--samples`` samples 10 ms apart (``x`` uniform in
[1, 4.5), below 1 with probability ``--wrong``; ``y`` uniform in [0, 8);
a trigger at a sample with probability 1/2, an answer with probability
0.7):

* ``G[0,2](x > 1)``;
* ``(x > 1) U[0,3] (y > 4)`` (RTAMT's and Reelay's until, ``x > 1`` on
  ``[t, t')`` before ``y > 4`` at ``t'``; mstlo's closed until,
  ``[t, t']``, is raced against its own RCL formula);
* a deadline, ``G(trig -> F[0,3] ans)``: every trigger answered within
  30 ms, RCL's ``triggered by in.a within 30 ms``.

In RCL a time window is a value a message carries (docs/semantics.md,
"Against the peers"): the log (a ROSMonitoring log, the command's input)
holds, for every sample ``t`` whose window lies in the trace, a question
and its answer, the answer's ``data`` the window ``[x(t), ..., x(t+h)]``
(mapped to ``NATURAL --> REAL``: traces/mapping.py, the window rule), and
STL's bounded ``G`` and ``F`` are ``forall`` and ``exists`` over ``<0 upto
h>``.  The deadline's log holds the triggers and answers as they come, one
message each.  The ``h`` last samples, whose window runs past the end of
the trace, are not compared: RCL has no message for them (each message
carries its whole window), and the peers give them partial or delayed
figures.

Timed (CPU seconds, the least of ``--repeat`` runs): the command, ``rclverify monitor --json --margins``, a
process of its own reading the log (start, reading, judging, printing the
JSON: the command's whole CPU; its start-up, the same command on ten
samples, printed apart), and each peer judging the samples in this process
after a first run on ten samples (RTAMT 0.4.10's offline ``evaluate`` on
the whole signal, Reelay 25's discrete robustness monitor updated sample
by sample, read past-time as test_margins_peers.py reads it, mstlo 0.2.2's
``DelayedQuantitative`` monitor by its batch call 16,384 samples at a
time: bench/_peer_read.py).  Beside each peer's row, a second one times
the peer as the command is timed: a process of its own
(bench/_peer_read.py) that reads the same log (one read, msgspec's
typed ``decode_lines``, the samples rebuilt from the lines) and monitors
them, its whole CPU (start-up included; the same on the ten-sample log
printed apart), its robustness compared as the in-memory run's.
Compared, untimed: every window's verdict and margin as the engine
gives them (``check_trace`` with margins and a verdict callback on the same
log; the deadline's per-trigger verdicts from its deadline monitor) against
each peer's robustness at that sample within 1e-9 (the deadline: the sign,
the met or missed trigger; its time margin, ``30 ms`` less the answer's
delay, against the samples themselves: space robustness has no time
margin), and the command's counts and smallest margin against them.  A
disagreement exits 1.
"""
from __future__ import annotations

import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from array import array
from dataclasses import dataclass
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _peer_read import RUNS  # noqa: E402  (bench/_peer_read.py: the peers' monitoring, and a peer reading the log)

PERIOD = 0.01  # s between samples
TOLERANCE = 1e-9


@dataclass(frozen=True)
class Formula:
    """One windowed formula: the window ``h`` (samples), RCL's node, the peers' specifications, and how
    Reelay reads it (``shift``: past time at t + h; ``reverse``: on the samples read backwards)."""

    name: str
    h: int
    rcl: str
    rtamt: str
    reelay: str
    reelay_read: str
    mstlo: str
    signals: tuple[str, ...]


_G = """node Window {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
"""
_U = """node Window {
  inputs( x : NATURAL --> REAL )
  outputs( y : NATURAL --> REAL )
  topics( std_msgs/Float64MultiArray limit matches(in.x), std_msgs/Float64MultiArray window matches(out.y) )
  guarantee( exists(j in <0 upto 3> | out.y(j) > 4 and forall(i in <0 upto 3> | i %s j -> in.x(i) > 1)) )
}
"""
_D = """node Window {
  inputs( a : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
}
"""
FORMULAS = [
    Formula("G[0,2](x > 1)", 2, _G, "always[0,2](x > 1)", "historically[0:2]{x > 1}", "shift", "G[0,2](x > 1)",
            ("x",)),
    Formula("(x > 1) U[0,3] (y > 4)", 3, _U % "<", "(x > 1) until[0,3] (y > 4)", "{x > 1} since[0:3] {y > 4}",
            "reverse", "", ("x", "y")),
    Formula("(x > 1) U[0,3] (y > 4), closed", 3, _U % "<=", "", "", "", "(x > 1) U[0,3] (y > 4)", ("x", "y")),
    Formula("G(trig -> F[0,3] ans)", 3, _D, "(trig > 0.5) implies (eventually[0,3](ans > 0.5))",
            "{trig > 0.5} implies once[0:3]{ans > 0.5}", "reverse", "trig > 0.5 -> F[0,3](ans > 0.5)", ("trig", "ans")),
]


def signals(n: int, seed: int, wrong: float) -> dict[str, Any]:
    """The samples: ``x``, ``y`` (float64) and ``trig``, ``ans`` (0.0 or 1.0)."""
    import numpy as np
    rng = np.random.default_rng(seed)
    x = rng.uniform(1.0, 4.5, n)
    low = rng.random(n) < wrong
    x[low] = rng.uniform(0.0, 1.0, int(low.sum()))
    y = rng.uniform(0.0, 8.0, n)
    trig = (rng.random(n) < 0.5).astype(np.float64)
    ans = (rng.random(n) < 0.7).astype(np.float64)
    return {"x": x, "y": y, "trig": trig, "ans": ans}


def workspace(ws: Path, f: Formula, s: dict[str, Any], n: int) -> Path:
    """The contract, plan, mapping and log of ``f`` on the first ``n`` samples, in ``ws``; returns the log."""
    (ws / "contracts").mkdir(parents=True)
    (ws / "backends/monitors").mkdir(parents=True)
    (ws / "contracts/w.rcl").write_text(f.rcl)
    (ws / "contracts/plan.yaml").write_text("name: w\ncontracts: [contracts/w.rcl]\nnodes:\n  Window:\n"
                                            "    evidence: []\n")
    deadline = f.name.startswith("G(trig")
    topics = ("trig", "ans") if deadline else ("limit", "window")
    (ws / "backends/monitors/mapping.yaml").write_text(
        f"horizon: 0.005\ntopics:\n  {topics[0]}: {{fields: [data]}}\n  {topics[1]}: {{fields: [data]}}\n")
    log = ws / "run.jsonl"
    h = f.h
    with log.open("w") as out:
        if deadline:
            trig, ans = s["trig"][:n].tolist(), s["ans"][:n].tolist()
            for i in range(n):
                t = round(i * PERIOD, 6)
                if trig[i]:
                    out.write(f'{{"topic": "trig", "time": {t!r}, "data": 0.0}}\n')
                if ans[i]:
                    out.write(f'{{"topic": "ans", "time": {t!r}, "data": 1.0}}\n')
        else:
            x, y = s["x"][:n].tolist(), s["y"][:n].tolist()
            until = "y" in f.signals
            for i in range(n - h):
                t = round(i * PERIOD, 6)
                q = x[i:i + h + 1] if until else 1.0
                a = y[i:i + h + 1] if until else x[i:i + h + 1]
                out.write(f'{{"topic": "limit", "time": {t!r}, "data": {q!r}}}\n'
                          f'{{"topic": "window", "time": {t!r}, "data": {a!r}}}\n')
        out.write(f'{{"topic": "tick", "time": {round(n * PERIOD + 1.0, 6)!r}}}\n')
    return log


def command(ws: Path, log: Path, src: str) -> dict[str, Any]:
    """``rclverify monitor --json --margins`` on ``log``: its CPU (user + system, of the waited child) and JSON."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src] + ([os.environ["PYTHONPATH"]]
                                                                if os.environ.get("PYTHONPATH") else []))}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, "-c", "import sys; from rclverify.cli.commands import main; sys.exit(main())",
                        "monitor", "--json", "--margins", "-w", str(ws), str(log)], capture_output=True, text=True,
                       env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode not in (0, 1) or not p.stdout:
        raise SystemExit(f"rclverify monitor exited {p.returncode}:\n{p.stderr[-3000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"cpu": cpu, "json": json.loads(p.stdout)}


def engine(ws: Path, log: Path, f: Formula, n: int) -> tuple[list[float | None], dict[str, Any]]:
    """Untimed: each sample's margin as the engine gives it (``None``: no verdict there; the deadline: the
    time margin of each trigger, ``-inf`` when it was missed) and the result's counts, from the same log."""
    from rclverify.backends.monitors.check import check_trace
    from rclverify.backends.monitors.deadlines import DeadlineMonitor
    from rclverify.lang.typecheck import load
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.traces.jsonl import read_jsonl
    checked = load([ws / "contracts/w.rcl"])
    node = checked.nodes["Window"]
    rules = load_mapping(ws, None).rules  # as the command reads the mapping (its default transport skew too)
    got: list[float | None] = [None] * n
    if f.name.startswith("G(trig"):
        late: list[float] = []  # the time margins of answers past their trigger's deadline (an update, or a false)

        def timed(v: Any) -> None:
            if v.verdict == "undecided":  # no verdict either way (the transport skew): not compared
                return
            if v.update:
                late.append(v.time_margin)
            else:
                got[round(v.trigger_stamp / PERIOD)] = v.time_margin if v.verdict == "true" else -math.inf
                if v.verdict == "false" and v.time_margin is not None:  # answered, after the deadline
                    late.append(v.time_margin)
        d = DeadlineMonitor(checked, node, rules, timed)
        for ev in read_jsonl(log):
            d.feed(ev)
        d.advance(n * PERIOD + 1.0)
        d.finish()
        return got, {"late": late}

    def seen(v: Any) -> None:
        if v.margin is not None:
            got[v.event // 2] = v.margin  # two lines a sample: the question, its answer
    _, (res,) = check_trace(checked, [node], read_jsonl(log), rules, 0.005, seen, margins=True)
    return got, dict(res.counts)


#: A peer's name -> the Formula field of its specification (empty: the peer has no row for that formula).
PEERS = {"RTAMT": "rtamt", "Reelay": "reelay", "mstlo": "mstlo"}


def _lists(s: dict[str, Any], n: int) -> dict[str, list[float]]:
    """The first ``n`` samples of each signal as a list of floats (what the peers take)."""
    return {v: c[:n].tolist() for v, c in s.items()}


def _peer(name: str, f: Formula, s: dict[str, Any], n: int, repeat: int) -> tuple[float, list[float]] | str:
    """(least CPU s of ``repeat`` runs, the robustness at each sample), or why the peer is skipped."""
    attr = PEERS[name]
    if not getattr(f, attr):
        return ""
    run = RUNS[attr]
    try:
        run(f, _lists(s, 20), 20)  # the set-up and first use, outside the timing
    except ImportError as exc:
        return f"not installed ({exc}); pip install '.[bench]'"
    best, out = math.inf, []
    for _ in range(max(repeat, 1)):
        t0 = time.process_time()
        out = run(f, _lists(s, n), n)
        best = min(best, time.process_time() - t0)
    return best, out


def _peer_process(peer: str, f: Formula, log: Path, out: Path) -> float:
    """CPU s (user + system, of the waited child) of ``peer`` (``rtamt``, ``reelay`` or ``mstlo``) as a
    program of its own (bench/_peer_read.py) reading ``log`` and monitoring ``f``, its robustness at each
    sample written to ``out``."""
    spec = json.dumps({k: getattr(f, k) for k in ("name", "h", "rtamt", "reelay", "reelay_read", "mstlo",
                                                  "signals")})
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, str(Path(__file__).resolve().parent / "_peer_read.py"), peer, spec, str(log),
                        str(out)], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"{peer} reading {log} exited {p.returncode}:\n{p.stderr[-3000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _agree(f: Formula, mine: list[float | None], theirs: list[float], n: int) -> tuple[int, int, str]:
    """(samples compared, agreeing, the first difference) over the samples whose window lies in the trace."""
    deadline = f.name.startswith("G(trig")
    same, total, first = 0, 0, ""
    for t in range(n - f.h):
        a = mine[t]
        if deadline and a is None:
            continue  # no trigger here (the peers' vacuous truth has no RCL verdict), or an undecided one
        b = theirs[t] if t < len(theirs) else math.nan
        total += 1
        if a is None:
            ok = False
        elif deadline:
            ok = (a >= 0) == (b >= 0)
        else:
            ok = abs(a - b) <= TOLERANCE * max(1.0, abs(a)) or a == b
        same += ok
        if not ok and not first:
            first = f" (first difference at sample {t}: {a!r} against {b!r})"
    return total, same, first


def _time_margins(mine: list[float | None], s: dict[str, Any], n: int, h: int) -> tuple[int, int, int]:
    """(triggers with a verdict, those whose time margin is 30 ms less the delay of the first answer at or
    after them, from the samples, ``-inf`` where none comes within 3 samples; triggers with none: undecided,
    an answer stamped within the transport skew before them, docs/semantics.md "Deadlines")."""
    trig, ans = s["trig"], s["ans"]
    right = total = undecided = 0
    for t in range(n - h):
        if not trig[t]:
            continue
        if mine[t] is None:
            undecided += 1
            continue
        total += 1
        k = next((k for k in range(h + 1) if ans[t + k]), None)
        want = -math.inf if k is None else round((h - k) * PERIOD, 9)
        got = mine[t]
        right += got is not None and (got == want or (want != -math.inf and abs(got - want) < 1e-9))
    return total, right, undecided


def _counts(out: list[dict[str, Any]]) -> list[Any]:
    """What the command said of a run, its counts, margins and deadlines (the parts both trees print)."""
    return [(r.get("counts"), r.get("margins"), r.get("deadlines")) for r in out]


def race(n: int, seed: int, wrong: float, repeat: int = 1, src: str | None = None, old: str | None = None) -> bool:
    """Print, formula by formula, the command's and each peer's samples per CPU second and whether every
    sample agrees; True when all agree.  ``old``: an older source tree whose command is run too (its own
    row: before -> after in one run)."""
    root = Path(__file__).resolve().parents[1]
    src = src or str(root / "src")
    sys.path.insert(0, src)
    s = signals(n, seed, wrong)
    ok = True
    print(f"windowed formulas: {n} samples 10 ms apart, {wrong:g} of x below 1, seed {seed}; CPU s the least of "
          f"{max(repeat, 1)} run(s)")
    print(f"{'formula, tool':<52} {'samples/s':>10} {'CPU s':>7}  every sample's verdict and margin agree")
    with tempfile.TemporaryDirectory() as tmp:
        for k, f in enumerate(FORMULAS):
            ws = Path(tmp) / f"w{k}"
            log = workspace(ws, f, s, n)
            tiny = Path(tmp) / f"t{k}"
            tiny_log = workspace(tiny, f, s, 10)  # the start-up: the least of as many runs as the command's own
            start = min(float(command(tiny, tiny_log, src)["cpu"]) for _ in range(max(repeat, 1)))
            runs = [command(ws, log, src) for _ in range(max(repeat, 1))]
            cmd = min(runs, key=lambda r: float(r["cpu"]))
            mine, counts = engine(ws, log, f, n)
            res = next(r for r in cmd["json"] if "counts" in r)
            said = res.get("counts", {})
            judged = [m for m in mine if m is not None]
            if "late" not in counts:  # the command's counts and smallest margin are the engine's
                agree_cmd = said == counts and res["margins"][0]["margin"] == min(judged)
            else:  # the deadline's: its met and missed triggers and smallest time margin
                dl = next(r["deadlines"] for r in cmd["json"] if "deadlines" in r)
                met = [m for m in judged if m != -math.inf]
                late = counts["late"]
                counts = {"true": len(met), "false": len(judged) - len(met)}
                agree_cmd = {k: dl["counts"][k] for k in counts} == counts and \
                    abs(dl["time_margins"][0]["margin"] - min(met + late)) < 1e-9
            print(f"{f.name + ', rclverify monitor':<52} {n / cmd['cpu']:>10.0f} {cmd['cpu']:>7.2f}  "
                  f"(start-up {start:.2f} s; {n / max(cmd['cpu'] - start, 1e-3):.0f} samples/s without it); "
                  f"command = engine: {'yes' if agree_cmd else 'NO'}; "
                  + ", ".join(f"{v} {key}" for key, v in (counts or {}).items() if v))
            ok = ok and agree_cmd
            if old:  # the same command from the older tree, its counts the engine's too
                was = min((command(ws, log, old) for _ in range(max(repeat, 1))), key=lambda r: float(r["cpu"]))
                same = _counts(was["json"]) == _counts(cmd["json"])
                print(f"{f.name + ', rclverify monitor (old)':<52} {n / was['cpu']:>10.0f} {was['cpu']:>7.2f}  "
                      f"new / old samples/s: {was['cpu'] / cmd['cpu']:.2f}; the same counts and margins: "
                      f"{'yes' if same else 'NO'}")
                ok = ok and same
            if f.name.startswith("G(trig"):
                total, right, undecided = _time_margins(mine, s, n, f.h)
                print(f"{'':<52} time margins: {right}/{total} triggers equal 30 ms less the first answer's delay; "
                      f"{undecided} trigger(s) undecided (no answer of their own in time, one within the transport "
                      f"skew before them: no verdict, not compared; the peers call them missed)")
                ok = ok and right == total
            for name in PEERS:
                got = _peer(name, f, s, n, repeat)
                if got == "":
                    continue
                if isinstance(got, str):
                    print(f"{f.name + ', ' + name:<52} skipped: {got}")
                    continue
                cpu, theirs = got
                total, agreeing, first = _agree(f, mine, theirs, n)
                ok = ok and agreeing == total and total > 0
                print(f"{f.name + ', ' + name:<52} {n / cpu:>10.0f} {cpu:>7.2f}  {agreeing}/{total}{first}; "
                      f"rclverify / {name} samples/s: {cpu / cmd['cpu']:.2f} ({cpu / max(cmd['cpu'] - start, 1e-3):.2f} "
                      f"without the start-up)")
                # the same peer as a process of its own reading the same log (bench/_peer_read.py), timed as the
                # command is: the whole process's CPU, its start-up (the same on the ten-sample log) printed apart
                out = Path(tmp) / f"peer-{k}-{PEERS[name]}"
                pstart = min(_peer_process(PEERS[name], f, tiny / "run.jsonl", out) for _ in range(max(repeat, 1)))
                pcpu = min(_peer_process(PEERS[name], f, log, out) for _ in range(max(repeat, 1)))
                read = array("d")
                with out.open("rb") as fh:
                    read.frombytes(fh.read())
                total, agreeing, first = _agree(f, mine, read.tolist(), n)
                ok = ok and agreeing == total and total > 0
                print(f"{f.name + ', ' + name + ' reading the log':<52} {n / pcpu:>10.0f} {pcpu:>7.2f}  "
                      f"{agreeing}/{total}{first}; (start-up {pstart:.2f} s; {n / max(pcpu - pstart, 1e-3):.0f} "
                      f"samples/s without it); rclverify / {name} reading the log, samples/s: "
                      f"{pcpu / cmd['cpu']:.2f} ({max(pcpu - pstart, 1e-3) / max(cmd['cpu'] - start, 1e-3):.2f} "
                      f"without either start-up)")
    print(f"not compared: the last 2-3 samples of each formula, whose window runs past the end of the trace "
          f"(no RCL message carries them; the peers give partial or delayed figures)")
    return ok


__all__ = ["FORMULAS", "race"]
