"""The margins race of bench/monitor_peers.py (``--margins``): rclverify's batch path with margins
against RTAMT's, Reelay's and mstlo's robustness on the same samples of ``G(x > 1)``.

STL's ``G(x > 1)`` judged at time 0 has the robustness ``min_t (x(t) - 1)``
(Donzé and Maler): the least of the per-sample robustness of ``x > 1``.
RCL states it as a per-answer guarantee, ``guarantee( out.x > in.r )`` of a
node answering each reading ``r`` (the limit, 1 in every sample) with ``x``:
every answer's margin is that sample's ``x - 1`` and the run's smallest
margin is ``G``'s robustness (docs/semantics.md, "Margins").  The same bound
as an output-only guarantee, ``guarantee( out.x > 1 )``, reads no input and
is judged on each answer as the outputs stand (the batch path too): its row
gives that figure and its smallest margin (which must be the same).  Each tool gives the per-sample robustness of
``x > 1`` (RTAMT 0.4.10's discrete-time specification updated sample by
sample, Reelay 25's discrete robustness monitor sample by sample, mstlo
0.2.2's ``DelayedQuantitative`` monitor by its batch call 16,384 samples at a
time), rclverify its answers' margins: the bench compares every sample and
the minimum, within 1e-9.

rclverify is timed on the samples held in columns (traces/table.py, the
readings and the answers as float64 arrays), judged by ``check_trace`` with
``margins=True`` (the batch path: every answer's margin over the columns, the
smallest kept per guarantee); its per-answer margins are collected in a
second, untimed run through the verdict callback.  Every tool's set-up
(imports, parsing, a first run on ten samples) is outside the timing, CPU
seconds of this one process, the least of :data:`REPEAT` runs.  A peer that
is not installed is skipped with the reason.
"""
from __future__ import annotations

import math
import time
from typing import Any, Callable

NODE = ("node Level {{ inputs( r : REAL ) outputs( x : REAL ) "
        "topics( std_msgs/Float64 raw matches(in.r), std_msgs/Float64 level matches(out.x) ) "
        "guarantee( {} ) }}")
#: The formulas: name -> (RCL's guarantee, RTAMT's, Reelay's, mstlo's specification); ``in.r`` is 1 in every sample.
FORMULAS = {
    "G(x > 1)": ("out.x > in.r", "x > 1", "{x > 1}", "x > 1"),
    "G(x > 1 and x < 4.5)": ("out.x > in.r and out.x < in.r + 3.5", "(x > 1) and (x < 4.5)", "{x > 1} and {x < 4.5}",
                             "x > 1 && x < 4.5"),
}
CONTRACT = NODE.format(FORMULAS["G(x > 1)"][0])
#: The first bound as an output-only guarantee (it reads no input), judged on each answer as the outputs stand.
ALONE = NODE.format("out.x > 1")
#: Each tool is timed this many times on the samples; its least CPU is kept (the run the machine's other
#: load disturbed least).
REPEAT = 3
PERIOD = 0.01  # s between samples
HORIZON = 0.005  # s: a reading is answered by its own sample's x only


def samples(n: int, seed: int, wrong: float) -> Any:
    """``x`` (float64, n): uniform in [1, 4.5), below 1 (uniform in [0, 1)) with probability ``wrong``: every
    formula violated on the same samples."""
    import numpy as np
    rng = np.random.default_rng(seed)
    x = rng.uniform(1.0, 4.5, n)
    low = rng.random(n) < wrong
    x[low] = rng.uniform(0.0, 1.0, int(low.sum()))
    return x


def _columns(x: Any) -> Any:
    import numpy as np
    from rclverify.traces.table import ColumnTrace
    n = len(x)
    topic = np.empty(2 * n + 1, dtype=np.int8)
    topic[0:2 * n:2], topic[1:2 * n:2], topic[-1] = 0, 1, 2
    t = np.arange(n, dtype=np.float64) * PERIOD
    limit = np.ones(n)  # every reading states the limit 1
    times = np.empty(2 * n + 1)
    times[0:2 * n:2], times[1:2 * n:2], times[-1] = t, t, n * PERIOD + 10 * HORIZON
    return ColumnTrace(topic, times, {"raw": {"data": limit}, "level": {"data": x}}, "synthetic", ["raw", "level", "tick"])


def rclverify(x: Any, contract: str = CONTRACT, collect: bool = True, skew: float = 0.0) -> tuple[float, list[float],
                                                                                               float]:
    """CPU s of ``check_trace`` with margins on ``contract`` (``skew``: the mapping's transport skew, s), every
    answer's margin (an untimed run; none unless ``collect``), the smallest kept."""
    from rclverify.backends.monitors.check import check_trace
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.traces.mapping import load_rules
    checked = check([parse_text(contract)])
    node = checked.nodes["Level"]
    rules = load_rules({"raw": {"fields": ["data"]}, "level": {"fields": ["data"]}})
    rules.skew = skew
    check_trace(checked, [node], _columns(x[:10]), rules, HORIZON, margins=True)
    cpu = math.inf
    for _ in range(REPEAT):
        t0 = time.process_time()
        _, (res,) = check_trace(checked, [node], _columns(x), rules, HORIZON, margins=True)
        cpu = min(cpu, time.process_time() - t0)
    got: list[float] = [math.nan] * len(x)
    if not collect:
        return cpu, got, res.margins[1].value

    def seen(v: Any) -> None:
        if v.margin is not None:
            got[v.event // 2] = v.margin
    check_trace(checked, [node], _columns(x), rules, HORIZON, seen, margins=True)
    return cpu, got, res.margins[1].value


def rtamt(x: Any, formula: str) -> tuple[float, list[float]]:
    import rtamt as rt  # type: ignore[import-not-found]
    spec = rt.StlDiscreteTimeSpecification()
    spec.declare_var("x", "float")
    spec.spec = FORMULAS[formula][1]
    spec.parse()
    xs = x.tolist()
    update = spec.update
    t0 = time.process_time()
    out = [update(i, [("x", v)]) for i, v in enumerate(xs)]
    return time.process_time() - t0, [float(r) for r in out]


def reelay(x: Any, formula: str) -> tuple[float, list[float]]:
    import reelay as rl  # type: ignore[import-not-found]
    mon = rl.discrete_timed_monitor(pattern=FORMULAS[formula][2], semantics="robustness", condense=False)
    xs = x.tolist()
    update = mon.update
    t0 = time.process_time()
    out = [update({"time": i, "x": v})["value"] for i, v in enumerate(xs)]
    return time.process_time() - t0, [float(r) for r in out]


def mstlo(x: Any, formula: str) -> tuple[float, list[float]]:
    import mstlo_python  # type: ignore[import-not-found]
    mon = mstlo_python.Monitor(mstlo_python.parse_formula(FORMULAS[formula][3]), semantics="DelayedQuantitative")
    xs = x.tolist()
    out: list[float] = []
    step = 16384
    t0 = time.process_time()
    for a in range(0, len(xs), step):
        got = mon.update_batch({"x": [(v, i * PERIOD) for i, v in enumerate(xs[a:a + step], start=a)]}).verdicts()
        out += [r for _, r in got]
    return time.process_time() - t0, [float(r) for r in out]


PEERS: dict[str, Callable[[Any, str], tuple[float, list[float]]]] = {"RTAMT": rtamt, "Reelay": reelay, "mstlo": mstlo}


def _agree(mine: list[float], theirs: list[float]) -> str:
    if len(theirs) != len(mine):
        return f"{len(theirs)} values for {len(mine)} samples"
    bad = [i for i, (a, b) in enumerate(zip(mine, theirs)) if not abs(a - b) <= 1e-9 * max(1.0, abs(a))]
    return f"{len(mine) - len(bad)}/{len(mine)}" + (f" (first difference at sample {bad[0]})" if bad else "")


def race(n: int, seed: int, wrong: float, skew: float = 0.0) -> bool:
    """Print each tool's samples per CPU second and whether its robustness agrees, formula by formula
    (``skew``: rclverify's transport skew, s); True when all agree."""
    x = samples(n, seed, wrong)
    ok = True
    print(f"margins against robustness: {n} samples, {wrong:g} of them below 1, seed {seed}, skew {skew:g} s")
    print(f"{'formula, tool':<40} {'samples/s':>11}  per-sample robustness agrees with rclverify's margins; min")
    for formula, (guarantee, *_) in FORMULAS.items():
        cpu, mine, least = rclverify(x, NODE.format(guarantee), skew=skew)
        print(f"{formula + ', rclverify batch':<40} {n / cpu:>11.0f}  -; smallest margin {least:.12g} "
              f"(of every answer's: {min(mine):.12g})")
        ok = ok and least == min(mine)
        if formula == "G(x > 1)":
            ok = ok and least == float(x.min()) - 1.0
            acpu, _, aleast = rclverify(x, ALONE, collect=False, skew=skew)
            ok = ok and aleast == least
            print(f"{formula + ', rclverify output-only':<40} {n / acpu:>11.0f}  -; smallest margin {aleast:.12g} "
                  f"(out.x > 1, reading no input)")
        for name, peer in PEERS.items():
            try:
                peer(x[:10], formula)  # the set-up and first use, outside the timing
            except ImportError as exc:
                print(f"{formula + ', ' + name:<40} skipped: not installed ({exc}); pip install '.[bench]'")
                continue
            pcpu, theirs = min((peer(x, formula) for _ in range(REPEAT)), key=lambda r: r[0])
            agree = _agree(mine, theirs)
            ok = ok and agree == f"{n}/{n}" and min(theirs) == least
            print(f"{formula + ', ' + name:<40} {n / pcpu:>11.0f}  {agree}; min {min(theirs):.12g}; "
                  f"rclverify / {name} samples/s: {pcpu / cpu:.2f}")
    return ok


__all__ = ["race"]
