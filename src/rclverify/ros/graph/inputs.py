"""The files a grounding is made from (docs/ros.md, docs/integrity.md).

The ``ground`` stage hashes them into ``artifacts/ros/grounding.json``
(``inputs``); the report hashes them again and shows a grounding made from
other files ``stale``.
"""
from __future__ import annotations

from typing import Any

from rclverify.model.plan.ros_section import RosSection
from rclverify.ros.extract import safefs


def input_files(ws: Any) -> list[str]:
    """Workspace-relative files a grounding is made from: the plan, its
    contract files, and every file under the ``ros:`` section's
    ``workspaces``, ``launch``, ``bags`` and its ``mapping`` (hashed into the
    grounding record, ``inputs``: the report shows a grounding made from
    other files ``stale``)."""
    ros = RosSection.of(ws.plan.ros)
    out = {ws.plan.file, *ws.plan.contracts}
    for rel in (*ros.workspaces, *ros.launch, *ros.bags, *([ros.mapping] if ros.mapping else [])):
        top = ws.root / rel
        if top.is_file():
            out.add(rel)
        elif top.is_dir():
            # regular files only, no links, names valid UTF-8: what the scan reads (docs/ros.md)
            out.update(p.relative_to(ws.root).as_posix() for p in top.rglob("*")
                       if not p.is_symlink() and p.is_file() and safefs.utf8_name(str(p)))
    return sorted(out)
