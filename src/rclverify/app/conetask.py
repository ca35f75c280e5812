"""When a node's ``compose`` stage must run again because its upstream cone changed.

A node's calculus reads its own snapshot and its producers' (the local side
conditions), the environment conjuncts of its whole upstream cone (the
derived property), and, only when a side condition failed locally and was
decided in context, every contract and fact of the cone (docs/calculus.md).
``check`` writes each node's cone digest, ``artifacts/cones/<Node>.sha256``:
a line ``env <sha256>`` for the first and ``cone <sha256>`` for the second
(:func:`rclverify.stages.cone_digests.cone_digests`).

Making the digest file a file dependency of every node task would re-run the
``compose`` stage of every node downstream of an edit: after editing the
middle node of a 1000-node chain, 500 stages whose side conditions all hold
locally and cannot change (docs/scale.md's one-contract edit).  Instead the
node task has the doit ``uptodate`` check :class:`ConeUnchanged`: after the
task ran it saves, with doit's task values, the part of the digest file its
last ``compose`` depended on (the whole file when its provenance record
lists the file, i.e. a side condition was decided in context; the ``env``
line otherwise), and on the next run the task is up to date only while that
part is unchanged.  An unreadable or altered provenance record counts as
"decided in context" (the whole file): the check errs towards running.
Incremental equals clean: a composition that read the cone is made again
whenever any contract or fact of the cone changes.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from rclverify.app.task_checks import UPTODATE_SIGNATURE


def _relevant(text: str, whole: bool) -> str:
    """The part of a cone digest file a composition depended on."""
    return text if whole else (text.splitlines()[0] + "\n" if text else "")


class ConeUnchanged:
    """doit ``uptodate`` check of a node task (module docstring).

    ``cone``: the absolute path of the node's cone digest file;
    ``provenance``: the absolute path of its provenance record
    (``artifacts/provenance/compose/<Node>.json``); ``cone_rel``: the digest file's
    workspace-relative path, as the provenance record names it."""

    KEY = "_cone"
    __signature__ = UPTODATE_SIGNATURE

    def __init__(self, cone: str, provenance: str, cone_rel: str) -> None:
        self.cone, self.provenance, self.cone_rel = cone, provenance, cone_rel

    def _read(self) -> str:
        try:
            return Path(self.cone).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return ""

    def _used_cone(self) -> bool:
        from rclverify.records.sealed import read_sealed  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
        rec, altered = read_sealed(Path(self.provenance))
        if altered or not isinstance(rec, dict) or not isinstance(rec.get("compose"), dict):
            return True
        return self.cone_rel in rec["compose"]

    def _save(self) -> dict[str, str]:
        return {self.KEY: _relevant(self._read(), self._used_cone())}

    def __call__(self, task: Any, values: Mapping[str, object]) -> bool:
        task.value_savers.append(self._save)
        saved = values.get(self.KEY)
        if not isinstance(saved, str):
            return True  # never ran (its targets are missing then) or ran before this check existed (the code changed)
        whole = not (saved.startswith("env ") and saved.count("\n") == 1)
        return _relevant(self._read(), whole) == saved
