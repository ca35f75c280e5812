"""Windowed formulas in the offline batch path (backends/monitors/batch_window.py,
targets/column_windows.py) against the streaming engine and a brute-force
enumeration of the window, its oracle.

A window is a message's array mapped to ``NATURAL --> REAL`` (``out.x(k)``
the sample at offset ``k``); STL's ``G[0,2]``, ``F[0,2]`` and ``U[0,3]``
are ``forall``/``exists`` over ``<0 upto h>`` (docs/semantics.md, "Against
the peers").  On small random traces (right and wrong windows, samples on
the bound itself, windows of another length, NaN, an integer, a string
among the samples, answers missing, late, duplicated, stamped back; skew
on and off; chunks of 2 events up), with margins, the batch path must give
exactly the streaming engine's verdict list (verdicts, order, reasons,
margins) and result; each satisfied or violated answer's margin must equal
the window's own figure computed here by enumerating it (min and max over
the offsets, nothing of rclverify's); a control shows that a formula
differing at one offset (until's ``i <= j`` for ``i < j``) is caught.
"""
from __future__ import annotations

import math
import random
from typing import Any, Callable

import pytest

from rclverify.backends.monitors.batch import check_batch
from rclverify.backends.monitors.batch_window import answer_only, window_column
from rclverify.backends.monitors.check import check_trace
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event
from rclverify.traces.mapping import load_rules

NODES = """
node G {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
node F {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( exists(k in <0 upto 2> | out.x(k) >= in.r + 0.1) and out.x(0) < 4 )
}
node U {
  inputs( x : NATURAL --> REAL )
  outputs( y : NATURAL --> REAL )
  topics( std_msgs/Float64MultiArray limit matches(in.x), std_msgs/Float64MultiArray window matches(out.y) )
  guarantee( exists(j in <0 upto 3> | out.y(j) > 4 and forall(i in <0 upto 3> | i < j -> in.x(i) > 1)) )
}
"""
CHECKED = check([parse_text(NODES)])
RULES = {"limit": {"fields": ["data"]}, "window": {"fields": ["data"]}}
WIDTH = {"G": 3, "F": 3, "U": 4}
NEAR = [1.0, 1.0000000000000002, 0.9999999999999999, 4.0, 1.1, 3.9999999999999996]


def _g(r: float, x: list[float]) -> float:
    return min(v - r for v in x)


def _f(r: float, x: list[float]) -> float:
    return min(max(v - (r + 0.1) for v in x), 4 - x[0])


def _until(strict: bool) -> Callable[[list[float], list[float]], float]:
    def margin(x: list[float], y: list[float]) -> float:
        best = -math.inf
        for j in range(4):
            before = [x[i] - 1 for i in range(4) if (i < j if strict else i <= j)]
            best = max(best, min([y[j] - 4] + before))
        return best
    return margin


#: node -> the window's margin, enumerated here (the question's value, the answer's)
BRUTE: dict[str, Callable[[Any, list[float]], float]] = {"G": _g, "F": _f, "U": _until(True)}


def _sample(rnd: random.Random) -> float:
    return rnd.choice(NEAR) if rnd.random() < 0.15 else round(rnd.uniform(0.0, 8.0), rnd.choice([1, 3, 17]))


def _trace(rnd: random.Random, node: str, horizon: float) -> list[Event]:
    """A random run: mostly a question and its window answer at the same time, every irregularity now and then."""
    events: list[Event] = []
    w = WIDTH[node]
    t = 0.0

    def add(topic: str, value: Any, time: float, stamp: float | None = None) -> None:
        events.append(Event(len(events), time, topic, {"data": value}, f"run.jsonl:{len(events) + 1}", stamp))

    for _ in range(rnd.randint(5, 90)):
        t += rnd.choice([0.0, 0.001, 0.01, 0.01, 0.01, 0.05])
        kind = rnd.choices(["pair", "lone", "dup", "late", "back", "short", "bad", "int"], [70, 4, 4, 4, 4, 5, 5, 4])[0]
        q: Any = [_sample(rnd) for _ in range(w)] if node == "U" else rnd.choice([1.0, 1.0, 0.5, 2.0])
        add("limit", q, t)
        a: Any = [_sample(rnd) for _ in range(w)]
        if kind == "short":
            a = a[:rnd.choice([0, 1, w - 1])] + ([] if rnd.random() < 0.5 else [1.5, 2.5])
        if kind == "bad":
            a[rnd.randrange(w)] = rnd.choice([math.nan, math.inf, "2.0", None, True])
        if kind == "int":
            a[rnd.randrange(w)] = rnd.choice([2, 5])
        if kind in ("pair", "dup", "short", "bad", "int"):
            add("window", a, t + rnd.choice([0.0, 0.0, horizon / 2]))
        if kind == "dup":
            add("window", [_sample(rnd) for _ in range(w)], t + 0.001)
        if kind == "late":
            add("window", a, t + 2 * horizon + 0.01)
        if kind == "back":
            add("window", a, t - rnd.choice([0.002, 0.03]))
    return events


def _run(node: str, events: list[Event], skew: float, chunk: int) -> tuple[Any, Any, dict[str, int]]:
    rules = load_rules(RULES)
    rules.skew = skew
    seen_s: list[Any] = []
    streamed = check_trace(CHECKED, [CHECKED.nodes[node]], iter(events), rules, 0.005, seen_s.append, batch=False,
                           margins=True)
    seen_b: list[Any] = []
    stats: dict[str, int] = {}
    done = check_batch(CHECKED, CHECKED.nodes[node], iter(events), rules, 0.005, seen_b.append, chunk=chunk,
                       stats=stats, margins=True)
    assert done is not None, f"{node} should be eligible"
    return (streamed[0], streamed[1][0], seen_s), (done[0], done[1], seen_b), stats


def _brute(node: str, events: list[Event], verdicts: list[Any], margin: Callable[[Any, list[float]], float]
           ) -> tuple[int, int]:
    """(answers compared, equal): each margin against the window's own figure, the question the latest input
    at or before the answer (the traces' questions are answered at their own time)."""
    by_index = {ev.index: ev for ev in events}
    compared = same = 0
    for v in verdicts:
        if v.margin is None or v.verdict not in ("satisfied", "violated"):
            continue
        ans = by_index[v.event]
        q = next(ev for ev in reversed(events[:v.event]) if ev.topic == "limit")
        if q.time != ans.time or ans.fields["data"] is None:  # only the plain pairs: a question and its own answer
            continue
        compared += 1
        w = WIDTH["U" if isinstance(q.fields["data"], list) else "G"]
        want = margin(q.fields["data"][:w] if w == 4 else q.fields["data"], ans.fields["data"][:w])  # offsets read
        same += want == v.margin and (want > 0) == (v.verdict == "satisfied")
    return compared, same


@pytest.mark.parametrize("node", sorted(WIDTH))
def test_batch_equals_streaming_and_the_enumerated_window(node: str) -> None:
    rnd = random.Random(f"window-{node}")
    batched = compared = 0
    for case in range(6):
        events = _trace(rnd, node, 0.005)
        skew = (0.0, 0.02)[case % 2]
        chunk = rnd.choice([2, 3, 7, 64, 4096])
        s, b, stats = _run(node, events, skew, chunk)
        where = f"case {case}: skew {skew}, chunk {chunk}, {len(events)} events"
        assert b[2] == s[2], where  # the verdict list: verdicts, order, reasons, margins
        assert b[1] == s[1], where  # the result: counts, records, smallest margins
        assert b[0] == s[0], where
        if not skew:  # with a skew a held violated answer is judged against the questions after it too
            n, same = _brute(node, events, b[2], BRUTE[node])
            assert same == n, where
            compared += n
        batched += stats["batched"]
    assert batched > 30 and compared > 30  # the batch path judged most answers, the enumeration checked them


def test_control_a_formula_differing_at_one_offset_is_caught() -> None:
    """Closed until (``i <= j``) enumerated against the batch path's strict until: they differ on
    these traces, so the enumeration above tells the two apart."""
    rnd = random.Random("window-U")
    events = _trace(rnd, "U", 0.005)
    _, b, _ = _run("U", events, 0.0, 4096)
    n, same = _brute("U", events, b[2], _until(False))
    assert n > 10 and same < n
    n, same = _brute("U", events, b[2], _until(True))
    assert same == n


def test_windows_the_columns_hold() -> None:
    """A row is a list of ``width`` finite floats; anything else is the engine's (a float subclass too:
    numpy's float64, whose type is read as not a float, wherever it stands)."""
    import numpy as np
    mixed = [[1.0, 2.0], [1.0], [1.0, math.nan], [1, 2.0], [True, 1.0], "ab", [3.5, -0.0]]
    good, col = window_column(mixed, 2)
    assert good.tolist() == [True, False, False, False, False, False, True]
    assert col[0].tolist() == [1.0, 2.0] and col[6].tolist() == [3.5, -0.0]
    good, col = window_column([[1.0, 2.0], [math.inf, 0.5], [3.5, -0.0]], 2)  # every row a list of floats
    assert good.tolist() == [True, False, True] and col[2].tolist() == [3.5, -0.0]
    for odd in (2, True, "2.5", None, [2.5], np.float64(2.5)):  # every row of width entries, one not a float
        good, _ = window_column([[1.0, 2.0], [3.0, odd], [3.5, 1.5]], 2)
        assert good.tolist() == [True, False, True]
    good, _ = window_column([[1.0, 2.0], [1.0], [3.0, np.float64(2.5)], [3.5, 1.5]], 2)  # the row-by-row path
    assert good.tolist() == [True, False, False, True]


def test_a_log_read_in_blocks_gives_the_engines_verdicts(tmp_path: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """The command's reading: a ROSMonitoring log in blocks, its windows decoded JSON and read as columns,
    the batch path's verdicts and result the streaming engine's on the same log, now and then an entry
    that is an integer, a boolean or a string: the engine's (the control: a column that does not read the
    entries' types is caught)."""
    import json
    from rclverify.backends.monitors import batch as batch_module
    from rclverify.backends.monitors import batch_window
    from rclverify.traces import read_trace
    from rclverify.traces.jsonl import read_jsonl
    from rclverify.traces.mapping import MappingError
    passes: list[int] = []
    real = window_column

    def counted(vals: list[Any], width: int) -> Any:
        passes.append(len(vals))
        return real(vals, width)
    monkeypatch.setattr(batch_module, "window_column", counted)
    real_floats = batch_window._floats
    rnd = random.Random("window-log")
    for node in ("G", "U"):
        log = tmp_path / f"{node}.jsonl"
        with log.open("w") as out:
            for i in range(600):
                t = round(0.01 * i, 6)
                q: Any = [_sample(rnd) for _ in range(4)] if node == "U" else rnd.choice([1.0, 0.5, 2.0])
                a: Any = [_sample(rnd) for _ in range(WIDTH[node])]
                if rnd.random() < 0.04:  # (numpy would convert each to a float: the column reads their types)
                    a[rnd.randrange(len(a))] = rnd.choice([2, True, "2.5"])
                out.write(json.dumps({"topic": "limit", "time": t, "data": q}) + "\n")
                out.write(json.dumps({"topic": "window", "time": t, "data": a}) + "\n")
        rules = load_rules(RULES)
        seen_s: list[Any] = []
        streamed = check_trace(CHECKED, [CHECKED.nodes[node]], read_jsonl(log), rules, 0.005, seen_s.append,
                               batch=False, margins=True)
        seen_b: list[Any] = []
        batched = check_trace(CHECKED, [CHECKED.nodes[node]], read_trace(log, streams=True), rules, 0.005,
                              seen_b.append, margins=True)
        assert seen_b == seen_s and batched == streamed
        assert sum(v.verdict == "inconclusive" for v in seen_b) > 10  # the odd windows: the engine's
        if node == "G":  # the control: a column whose entries' types are not read takes the odd ones
            monkeypatch.setattr(batch_window, "_floats", lambda entries: True)
            seen_f: list[Any] = []
            try:
                check_trace(CHECKED, [CHECKED.nodes[node]], read_trace(log, streams=True), rules, 0.005,
                            seen_f.append, margins=True)
            except MappingError:  # the engine's mapper meets the odd entry where the columns took it
                seen_f = []
            assert seen_f != seen_s
            monkeypatch.setattr(batch_window, "_floats", real_floats)
    assert passes and max(passes) > 100  # the windows read as columns, not one at a time


def test_the_types_counted_are_the_types_gathered() -> None:
    """The window's and a ``REAL`` column's types are counted (``list.count``, ``operator.countOf``) where
    they were gathered into a set: the same rows held on every mix of types, empty lists included (the
    control: a set of the types, as before, on the same values)."""
    import numpy as np
    from itertools import chain
    from rclverify.backends.monitors.batch_window import _floats
    from rclverify.targets.columns import column
    odd: list[Any] = [1.0, -0.0, math.inf, 2, True, "2.5", None, np.float64(2.5), [1.0]]
    rnd = random.Random("types")
    for _ in range(300):
        entries = [rnd.choice(odd[:2]) if rnd.random() < 0.8 else rnd.choice(odd) for _ in range(rnd.randint(0, 6))]
        assert _floats(entries) == (set(map(type, entries)) == {float})
        good, col = column(entries, "real", {})
        want = [type(v) is float and math.isfinite(v) for v in entries]
        assert good.tolist() == want and [c for c, w in zip(col.tolist(), want) if w] == \
            [v for v, w in zip(entries, want) if w]
        rows = [entries[i:i + 2] for i in range(0, len(entries) - 1, 2)] + ([1.0] if rnd.random() < 0.2 else [])
        if rows:
            held, _ = window_column(rows, 2)
            assert held.tolist() == [type(r) is list and len(r) == 2 and set(map(type, r)) == {float} and
                                     all(map(math.isfinite, r)) for r in rows]
    assert not _floats([]) and _floats([1.0]) and not _floats(list(chain([1.0], [2])))
