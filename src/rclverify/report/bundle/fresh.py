"""Is the written report the one the recorded artifacts give now?

An assessor's bundle never holds a report that says something else than the
evidence it is packed with.  The report is built again in memory from the
recorded artifacts (every evidence record's inputs hashed anew against the
current contracts and files, docs/integrity.md) and compared with
``reports/assurance.json``:

* ``meta.inputs_sha256`` (:func:`rclverify.report.records.inputs_sha256`):
  the report was built from other inputs, e.g. a contract edited and the
  evidence produced again by a ``doit verify`` that then failed at the
  report stage, so every status may be the same while the report describes
  the old contract;
* each obligation's status: stale or altered evidence called anything else.
"""
from __future__ import annotations

import json
from typing import Any

from rclverify.lang.errors import RclError

_RUN = "run `rclverify report` (or `doit verify`) first"


def report_out_of_date(ws: Any) -> list[str]:
    """Why ``reports/assurance.json`` of the workspace ``ws`` no longer says
    what the recorded artifacts say, one sentence each (empty when it does,
    when there is no report yet, or when the workspace does not check: the
    bundle then packs what there is)."""
    from rclverify.report.build import build_report  # deferred: start-up (loads jinja2, lark and more only when called)
    try:
        written = json.loads(ws.path("reports/assurance.json").read_text(encoding="utf-8"))
        was = {o["id"]: o["status"] for o in written["obligations"]}
        was_inputs = written.get("meta", {}).get("inputs_sha256")
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return []
    try:
        report = build_report(ws)
    except RclError:
        return []
    now: dict[str, str] = {o.id: o.status for o in report.obligations}
    changed = sorted(k for k in now if was.get(k) != now[k])
    if changed:
        shown = ", ".join(f"{k} ({was.get(k, 'absent')} -> {now[k]})" for k in changed[:5])
        return [f"reports/assurance.json is out of date: {len(changed)} obligation(s) have another status now: "
                f"{shown}{' ...' if len(changed) > 5 else ''}; {_RUN}"]
    if was_inputs != report.meta.inputs_sha256:
        why = ("it records no input hashes (written by an earlier rclverify)" if was_inputs is None else
               "it was built from other inputs than the recorded evidence, requirement checks, contracts and plan "
               f"(inputs sha256 {str(was_inputs)[:12]}..., now {report.meta.inputs_sha256[:12]}...)")
        return [f"reports/assurance.json is out of date: {why}; {_RUN}"]
    return []
