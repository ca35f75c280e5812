"""Every verdict of a run as one JSON line (``rclverify monitor --verdicts FILE``).

One record per verdict, the same shape whichever path judged the run, so
that a live run, its log and its bag can be compared verdict by verdict
(docs/monitors.md, "Verdicts one by one"):

* ``node``: the contract node judged;
* ``item``: ``guarantee`` (a message of a topic: an output's answer or an
  input's question), ``call`` (a service call's or an action goal's
  message) or ``deadline`` (a trigger's deadline, a topic's or a call's);
* ``topic`` and ``time``: the message judged, by what every path shares:
  its topic and its header stamp (s), else its event time (the source time;
  docs/semantics.md, "Event time"), which a bag and a log also give a
  message whose stamp the live run did not place it at (another clock); a
  deadline's ``topic`` is ``""``, its ``time`` the trigger's stamp and
  ``guarantee`` its 1-based guarantee;
* ``verdict`` and ``reason``; ``update`` true for a deadline's late answer
  replacing its first verdict; ``provisional`` true for a verdict the live
  run gave before every writer had been heard past it (not final).

A message judged twice (a live revision: a question heard late) has two
records; the later one stands (``withdrawn``: a live ``superseded`` whose
question an answer heard late answered, the message left no verdict).  Where a verdict sits in the run (a log's
line, a bag's message index) differs between the paths and is left out.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable

from rclverify.core.atomic import atomic_write_text
from rclverify.traces.events import header_stamp_ns

#: the ``topic`` of a live log's verdict lines (rclverify.runtime.live writes them)
VERDICT_TOPIC = "rclverify/verdict"
ITEMS = ("guarantee", "call", "deadline")


def verdict_record(item: str, v: Any, stamp: float | None = None) -> dict[str, Any]:
    """The record of verdict ``v`` of ``item`` (:data:`ITEMS`): ``v`` a
    :class:`~.verdicts.Verdict` (``guarantee``, ``call``) or a
    :class:`~.deadline_records.DeadlineVerdict` (``deadline``), or either's
    JSON form (its ``to_json()``, as a live log carries it); ``stamp`` the
    judged message's header stamp (s; ``None``: none, its time stands)."""
    d = v if isinstance(v, dict) else v.to_json()
    if item == "deadline":
        return {"node": str(d["node"]), "item": item, "topic": "", "time": float(d["trigger_stamp"]),
                "guarantee": int(d["guarantee"]), "verdict": str(d["verdict"]), "reason": str(d.get("reason", "")),
                "update": bool(d.get("update")), "provisional": bool(d.get("provisional"))}
    time = float(d["time"]) if stamp is None else stamp
    return {"node": str(d["node"]), "item": item, "topic": str(d["topic"]).strip("/"), "time": time,
            "guarantee": 0, "verdict": str(d["verdict"]), "reason": str(d.get("reason", "")), "update": False,
            "provisional": bool(d.get("provisional"))}


def log_records(path: Path) -> list[dict[str, Any]]:
    """The records of the verdict lines of the live log at ``path``, in the
    log's order.  A verdict on message ``N`` (its ``where``) is on the log's
    N-th message line (0-based; the lines of topics ``rclverify/...`` are no
    messages), whose header stamp, else its time, names the message: the
    time a recorded run gives it, also for a message the live run heard late
    and placed at its watermark.  Lines that are not JSON are passed over (a
    log cut short by a stop ends mid-line).  Raises :class:`OSError` when the
    log cannot be read."""
    messages: list[str] = []
    verdicts: list[tuple[str, dict[str, Any]]] = []
    with path.open(encoding="utf-8", errors="replace") as f:
        for line in f:
            if not line.startswith(_OWN) and not line.startswith(_OWN_COMPACT):
                messages.append(line)
                continue
            if VERDICT_TOPIC not in line:
                continue
            try:
                rec = json.loads(line)
            except ValueError:
                continue
            v = rec.get("verdict") if isinstance(rec, dict) and rec.get("topic") == VERDICT_TOPIC else None
            if isinstance(v, dict):
                verdicts.append(("deadline" if rec.get("kind") == "deadline" else
                                 ("call" if v.get("call") else "guarantee"), v))
    return [verdict_record(item, v, None if item != "guarantee" else _message_time(messages, v))
            for item, v in verdicts]


#: how a log's own lines (``rclverify/verdict``, ``rclverify/call``, ``rclverify/run`` ...) begin
_OWN, _OWN_COMPACT = '{"topic": "rclverify/', '{"topic":"rclverify/'


def _message_time(messages: list[str], v: dict[str, Any]) -> float | None:
    """The header stamp, else the time, of the log's message line verdict ``v`` is on (``where``:
    ``message N``); ``None`` when it names no message line of its topic."""
    where = str(v.get("where", ""))
    n = where.removeprefix("message ")
    if n == where or not n.isdigit() or int(n) >= len(messages):
        return None
    try:
        rec = json.loads(messages[int(n)])
    except ValueError:
        return None
    if not isinstance(rec, dict) or str(rec.get("topic", "")).strip("/") != str(v.get("topic", "")).strip("/"):
        return None
    ns = header_stamp_ns(rec)
    t = rec.get("time")
    return ns / 1e9 if ns is not None else (float(t) if isinstance(t, (int, float)) else None)


def write_records(path: Path, records: Iterable[dict[str, Any]]) -> None:
    """Write ``records`` to ``path``, one JSON object a line, through the
    atomic writer (:mod:`rclverify.core.atomic`)."""
    atomic_write_text(path, "".join(json.dumps(r, sort_keys=True) + "\n" for r in records))


__all__ = ["ITEMS", "VERDICT_TOPIC", "log_records", "verdict_record", "write_records"]
