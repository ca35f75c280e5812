"""A run is what the contracts read (issue 106; docs/statistics.md, "A run's identity"): with the entry's
topic rules, a run's identity reads only the fields they name, so a copy of a run with a field added that
no rule reads is the same run, and a run with a read value changed is another; a topic whose rule names
no field keeps every field."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors.run_identity import read_fields, run_digest
from rclverify.traces.mapping import load_rules

RULES = load_rules({"dist": {"fields": ["data"]}, "scan": {"fields": ["ranges[0]", "header.frame_id"]},
                    "pose": {"fields": {"x": ["position.x"], "y": ["position.y"]}}, "free": {}})


def _log(path: Path, rows: list[dict[str, Any]]) -> str:
    path.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    return path.name


RUN = [{"topic": "dist", "time": 1.0, "data": 2.5}, {"topic": "free", "time": 1.5, "data": 1.0},
       {"topic": "scan", "time": 2.0, "header": {"frame_id": "laser", "seq": 4}, "ranges": [1.0, 2.0]},
       {"topic": "pose", "time": 3.0, "position": {"x": 1.0, "y": 2.0, "z": 0.0}}]


def test_the_fields_a_mapping_reads() -> None:
    assert read_fields(RULES) == {"dist": ("data",), "scan": ("header.frame_id", "ranges"),
                                  "pose": ("position.x", "position.y")}
    assert read_fields(None) == {} and read_fields(load_rules({"a": {"fields": []}})) == {}


def test_an_unread_field_added_is_the_same_run_and_a_read_value_changed_another(tmp_path: Path) -> None:
    read = read_fields(RULES)
    base = run_digest(tmp_path, _log(tmp_path / "base.jsonl", RUN), read)
    noted = [{**r, "note": f"copy {k}"} for k, r in enumerate(RUN[:1])] + RUN[1:]  # dist gets a field no rule reads
    deeper = RUN[:2] + [{**RUN[2], "header": {"frame_id": "laser", "seq": 9}},  # scan: an unread header field
                        {**RUN[3], "position": {"x": 1.0, "y": 2.0, "z": 7.0}}]  # pose: z is read by no variable
    for name, rows in (("noted", noted), ("deeper", deeper)):
        copy = _log(tmp_path / f"{name}.jsonl", rows)
        assert run_digest(tmp_path, copy, read) == base, name
        assert run_digest(tmp_path, copy) != run_digest(tmp_path, "base.jsonl")  # every field read: not the same
    # the controls: a read value changed, a read item of an array changed, a field of a topic whose rule
    # names none (every field of it read), a time changed
    changed = {"value": [{**RUN[0], "data": 2.0}] + RUN[1:],
               "array": RUN[:2] + [{**RUN[2], "ranges": [1.5, 2.0]}] + RUN[3:],
               "free": [RUN[0], {**RUN[1], "note": "x"}] + RUN[2:],
               "time": [{**RUN[0], "time": 1.1}] + RUN[1:]}
    for name, rows in changed.items():
        assert run_digest(tmp_path, _log(tmp_path / f"{name}.jsonl", rows), read) != base, name
