"""Live = log = bag, verdict by verdict: the comparison of bench/_robot_run.py.

Each path's verdicts are the records ``rclverify monitor --verdicts FILE`` writes
(src/rclverify/backends/monitors/verdict_lines.py): the live run's (its log's
verdict lines), and the offline checks' of its log and of its bag.  A verdict is
identified by what every path shares: its node, its item (``guarantee``,
``call``, ``deadline``), the message it judges (topic and event time: the header
stamp, else the source time; a deadline's trigger stamp and guarantee), never
by where it sits in the run (a log's line, a bag's index differ).

Per path, the **final** verdict of each message is its last record (a live
revision, a question heard late, replaces the verdict given before; a
deadline's ``update`` line, a late answer, replaces its first verdict); a
last record ``withdrawn`` (a live ``superseded`` whose answer came late)
leaves the message no verdict.  A
live verdict still ``provisional`` at the end is not final: it is compared,
and a difference is reported apart (``provisional``), never as a final
disagreement.  Two paths **disagree** on a message when their final verdicts
differ or one gave a verdict and the other none; each disagreement names both
sides' verdicts and reasons.

Declarations (``initially``, ``progress``, ``periodic``) are judged once per run, a row each, not
message by message: the live record's rows (``--evidence``, its ``declarations``) are compared with the
offline check's rows of the log and of the bag, by node, declaration and source
(:func:`compare_declarations`).
"""
from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable

#: two paths' times of one message differ by float rounding only (a bag's integer nanoseconds, a log's
#: decimal text); messages of one topic are at least a sensor period (150 ms) apart
TOL_S = 1e-5
#: a record left without a counterpart within :data:`TOL_S` and one of the other path within this many
#: seconds are one message the two paths placed apart (a generated topic's messages are 150 ms or more apart)
APART_S = 0.005
UNDECIDED = ("inconclusive", "incomplete input", "open")
#: a live revision that withdraws the verdict given before, leaving the message none (backends/monitors/late.py)
WITHDRAWN = "withdrawn"
Bucket = tuple[str, str, str, int]  # node, item, topic, guarantee (a deadline's)


def read_records(path: Path) -> list[dict[str, Any]]:
    """The records of a ``--verdicts`` file (one JSON object a line); ``[]`` when there is none."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError:
        return []
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def finals(records: Iterable[dict[str, Any]]) -> dict[Bucket, list[dict[str, Any]]]:
    """Per (node, item, topic, guarantee), each message's final record, by time: the last record of
    each message (equal time: one path gives one message one event time) stands; none where it is
    ``withdrawn``."""
    last: dict[tuple[Bucket, float], dict[str, Any]] = {}
    for r in records:
        b: Bucket = (r["node"], r["item"], r["topic"], int(r.get("guarantee", 0)) if r["item"] == "deadline" else 0)
        last[(b, float(r["time"]))] = r
    out: dict[Bucket, list[dict[str, Any]]] = {}
    for (b, _), r in last.items():
        if r["verdict"] != WITHDRAWN:
            out.setdefault(b, []).append(r)
    for rs in out.values():
        rs.sort(key=lambda r: float(r["time"]))
    return out


@dataclass(frozen=True)
class Disagreement:
    """One message the two paths judged differently: ``a``/``b`` each side's record (``None``: no verdict)."""

    node: str
    item: str
    topic: str
    time: float
    a: dict[str, Any] | None
    b: dict[str, Any] | None
    #: how far apart (s) the two paths placed the message (0: at one time)
    apart: float = 0.0

    @property
    def placed_apart(self) -> bool:
        """One message, one verdict, placed at two times (no disagreement on its verdict)."""
        return self.apart > 0 and self.a is not None and self.b is not None and self.a["verdict"] == self.b["verdict"]

    @property
    def provisional(self) -> bool:
        """Whether a side's verdict is provisional (not final: reported apart)."""
        return any(r is not None and r.get("provisional") for r in (self.a, self.b))

    def text(self, names: tuple[str, str]) -> str:
        def side(name: str, r: dict[str, Any] | None) -> str:
            if r is None:
                return f"{name}: no verdict"
            return (f"{name}: {r['verdict']}" + (" (provisional)" if r.get("provisional") else "")
                    + (f" ({r['reason']})" if r.get("reason") else ""))
        what = f"deadline {self.topic or 'of the trigger'}" if self.item == "deadline" else f"{self.item} {self.topic}"
        apart = (f" ({names[0]} placed it at {float(self.a['time']):.6f}, {names[1]} at {float(self.b['time']):.6f})"
                 if self.apart and self.a is not None and self.b is not None else "")
        return f"{self.node}: {what} at {self.time:.6f}{apart}: {side(names[0], self.a)}; {side(names[1], self.b)}"


def compare(a: dict[Bucket, list[dict[str, Any]]], b: dict[Bucket, list[dict[str, Any]]]) -> list[Disagreement]:
    """The messages on which the final verdicts ``a`` and ``b`` (:func:`finals`) differ, in time order,
    and those the two placed apart (:attr:`Disagreement.placed_apart`: a record of each left without a
    counterpart, within :data:`APART_S` of each other)."""
    out: list[Disagreement] = []
    for d in _matched(a, b):
        if d.a is None or d.b is None:
            near = [e for e in out if e.b is None and d.a is None and e.a is not None and d.b is not None
                    and (e.node, e.item, e.topic) == (d.node, d.item, d.topic)
                    and abs(float(e.a["time"]) - float(d.b["time"])) <= APART_S]
            near += [e for e in out if e.a is None and d.b is None and e.b is not None and d.a is not None
                     and (e.node, e.item, e.topic) == (d.node, d.item, d.topic)
                     and abs(float(e.b["time"]) - float(d.a["time"])) <= APART_S]
            if near:
                e = near[0]
                out.remove(e)
                x, y = e.a or d.a, e.b or d.b
                assert x is not None and y is not None
                out.append(Disagreement(d.node, d.item, d.topic, min(e.time, d.time), x, y,
                                        abs(float(x["time"]) - float(y["time"]))))
                continue
        out.append(d)
    return sorted(out, key=lambda d: (d.time, d.node))


def _matched(a: dict[Bucket, list[dict[str, Any]]], b: dict[Bucket, list[dict[str, Any]]]) -> list[Disagreement]:
    """The records of ``a`` and ``b`` matched within :data:`TOL_S`, each pair whose verdicts differ and
    each record left without a counterpart, in time order."""
    out: list[Disagreement] = []
    for bucket in sorted(set(a) | set(b)):
        xs, ys = a.get(bucket, []), b.get(bucket, [])
        i = j = 0
        while i < len(xs) or j < len(ys):
            tx = float(xs[i]["time"]) if i < len(xs) else float("inf")
            ty = float(ys[j]["time"]) if j < len(ys) else float("inf")
            x = y = None
            if abs(tx - ty) <= TOL_S:
                x, y = xs[i], ys[j]
                i, j = i + 1, j + 1
                if x["verdict"] == y["verdict"]:
                    continue
            elif tx < ty:
                x, i = xs[i], i + 1
            else:
                y, j = ys[j], j + 1
            topic = bucket[2] if bucket[1] != "deadline" else f"(guarantee {bucket[3]})"
            out.append(Disagreement(bucket[0], bucket[1], topic, min(tx, ty), x, y))
    return sorted(out, key=lambda d: (d.time, d.node))


def tally(f: dict[Bucket, list[dict[str, Any]]]) -> dict[str, Counter[str]]:
    """Per node, its final verdicts counted: ``satisfied``, ``violated``, ``undecided`` (inconclusive,
    incomplete input, open; and each as ``undecided <verdict>``) answers of topics and calls, other
    question verdicts by name, ``deadline
    <verdict>``, and ``provisional`` (final verdicts still provisional)."""
    out: dict[str, Counter[str]] = {}
    for (node, item, _, _), rs in f.items():
        c = out.setdefault(node, Counter())
        for r in rs:
            v = r["verdict"]
            c[f"deadline {v}" if item == "deadline" else ("undecided" if v in UNDECIDED else v)] += 1
            if item != "deadline" and v in UNDECIDED:
                c[f"undecided {v}"] += 1
            c["provisional"] += bool(r.get("provisional"))
            if item == "call":
                c["call " + ("undecided" if v in UNDECIDED else v)] += 1
    return out


def false_verdicts(f: dict[Bucket, list[dict[str, Any]]], correct: set[str]) -> list[dict[str, Any]]:
    """The final, not provisional, ``violated`` answers and ``false`` deadlines of the nodes ``correct``."""
    return [r for (node, item, _, _), rs in f.items() if node in correct for r in rs
            if not r.get("provisional") and r["verdict"] in ("violated", "false")]


def three_way(paths: dict[str, list[dict[str, Any]]]) -> tuple[dict[str, Any], list[str]]:
    """``paths`` ``{"live", "log", "bag"}`` -> records: the finals of each and the lines of every
    disagreement of live with log and with bag (one on a provisional verdict begins ``provisional: ``,
    one message with one verdict placed at two times ``placed apart: ``)."""
    f = {name: finals(rs) for name, rs in paths.items()}
    lines: list[str] = []
    for other in ("log", "bag"):
        for d in compare(f["live"], f[other]):
            lines.append(("placed apart: " if d.placed_apart else "provisional: " if d.provisional else "")
                         + f"live != {other}: " + d.text(("live", other)))
    return f, lines


#: one declaration of one node: its node, its row's name (``progress``, ``initially 1``, ``periodic out.x``)
#: and its source (``contracts/robot.rcl:21:3``)
DeclKey = tuple[str, str, str]


def declaration_verdicts(parts: Iterable[dict[str, Any]]) -> dict[DeclKey, dict[str, Any]]:
    """The declaration rows of one path by :data:`DeclKey`: ``parts`` are the live record's
    ``declarations`` items, or the rows of ``rclverify monitor --json``; each part with a
    ``declarations`` list ``[{"declaration", "source", "verdict", "reason", ...}]``
    (docs/monitors.md, "Declarations on recorded and live runs") gives its rows."""
    out: dict[DeclKey, dict[str, Any]] = {}
    for part in parts:
        rows = part.get("declarations")
        if not isinstance(rows, list):
            continue
        for row in rows:
            out[(str(part["node"]), str(row["declaration"]), str(row.get("source", "")))] = row
    return out


def compare_declarations(paths: dict[str, dict[DeclKey, dict[str, Any]]],
                         calls_only: Iterable[str] = ()) -> tuple[list[str], list[str]]:
    """``(disagreements, bag_pending)``: each declaration the live path (``paths["live"]``) and the log's
    or the bag's judged differently, or that one judged and the other did not, named with both sides'
    verdicts and reasons; apart from them, each declaration of a node whose steps are all calls
    (``calls_only``: servers) that the bag leaves ``pending``, the live run and its log judging it: a
    bag's reader gives calls to the call checks only (docs/monitors.md, "Declarations on recorded and live
    runs"), so that ``pending`` is the bag's documented limit, said apart, never a disagreement (any other
    difference at such a node still is one)."""
    out: list[str] = []
    apart: list[str] = []
    servers = set(calls_only)
    live = paths["live"]
    for other in ("log", "bag"):
        them = paths.get(other, {})
        for key in sorted(set(live) | set(them)):
            a, b = live.get(key), them.get(key)
            if a is not None and b is not None and a["verdict"] == b["verdict"]:
                continue
            line = f"{key[0]}: declaration {key[1]} ({key[2]}): {_side('live', a)}; {_side(other, b)}"
            if other == "bag" and key[0] in servers and b is not None and b["verdict"] == "pending":
                apart.append(f"pending on the bag (its calls go to the call checks only): {line}")
            else:
                out.append(f"live != {other}: {line}")
    return out, apart


def _side(name: str, row: dict[str, Any] | None) -> str:
    return f"{name}: no verdict" if row is None else f"{name}: {row['verdict']} ({row.get('reason', '')})"


def tally_declarations(d: dict[DeclKey, dict[str, Any]]) -> dict[str, Counter[str]]:
    """Per node, its declarations counted by verdict (``declaration true``, ``declaration false`` ...)."""
    out: dict[str, Counter[str]] = {}
    for (node, _, _), row in d.items():
        out.setdefault(node, Counter())[f"declaration {row['verdict']}"] += 1
    return out


__all__ = ["DeclKey", "Disagreement", "compare", "compare_declarations", "declaration_verdicts", "false_verdicts",
           "finals", "read_records", "tally", "tally_declarations", "three_way"]
