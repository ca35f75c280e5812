"""Triples an ``export`` prepared and rendered, kept for the ``run`` of the same process.

doit runs a node's ``export`` task and later its obligations' ``evidence``
tasks, in one process when it runs serially (and the pipeline's workspace is
loaded once per process, :func:`rclverify.tasks._ws`).  Without this memo
every run would rebuild what the export of the same inputs has just built --
parse and check the program, encode the triple, compute its weakest
precondition and VCs -- and render the same obligation artifact again
(docs/scale.md, "Hoare backend: export and run share their work").

An entry is served to a run only when the run's inputs are the ones the
export saw:

* the same loaded system: the run's :class:`~rclverify.backends.base.NodeTarget`
  holds the *same objects* (identity) for the checked contracts, the node and
  the plan's value locations, and equal values for every other field (root,
  plan entry, artifact directory, entry index, plan file, contract files,
  facts); a workspace loaded again (an edited contract or plan) gives new
  objects, so nothing prepared from the old one is served;
* the same program: the bytes of the plan entry's program file, read again
  at the run, equal those the export read.

Each entry is served once (a run takes it out), and at most
:data:`MAX_TRIPLES` are kept (the oldest dropped first): a miss only costs
the rebuild the run would do anyway.  A run in another process (``doit -n``,
a cluster worker, the CLI) finds nothing here and rebuilds.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

from ...logic.world import on_fresh
from ..base import NodeTarget

#: Most triples kept at once (each holds its Z3 terms and rendered texts, some 10 kB).
MAX_TRIPLES = 10_000


@dataclass(frozen=True)
class _Inputs:
    """What a prepared triple was derived from (see the module text)."""

    checked: Any
    node: Any
    plan_locs: Any
    same: tuple[Any, ...]
    program: bytes | None

    def serves(self, other: _Inputs) -> bool:
        return (self.checked is other.checked and self.node is other.node and self.plan_locs is other.plan_locs
                and self.program is not None and self.program == other.program and self.same == other.same)


def _inputs(target: NodeTarget) -> _Inputs:
    """The inputs of ``target``'s triples now: the program file is read again."""
    prog = target.config.get("program")
    data: bytes | None = None
    if isinstance(prog, str) and prog:
        try:
            data = (target.root / prog).read_bytes()
        except OSError:
            data = None
    same = (target.root, copy.deepcopy(dict(target.config)), target.artifacts, target.index, target.plan_file,
            tuple(target.contract_files), tuple(target.facts))
    return _Inputs(target.checked, target.node, target.plan_locs, same, data)


_KEPT: dict[tuple[str, str, int, str], tuple[_Inputs, Any]] = {}
on_fresh(_KEPT.clear)  # its triples hold Z3 terms of the context they were made in (rclverify.logic.world)


def _key(target: NodeTarget, obligation_id: str) -> tuple[str, str, int, str]:
    return (str(target.root), target.node.name, target.index, obligation_id)


def keep(target: NodeTarget, items: list[tuple[str, Any]]) -> None:
    """Keep ``(obligation id, value)`` pairs an export of ``target`` computed,
    replacing what an earlier export of the same entry kept."""
    inputs = _inputs(target)
    for oid, value in items:
        k = _key(target, oid)
        _KEPT.pop(k, None)  # re-inserted last: the newest are dropped last
        _KEPT[k] = (inputs, value)
    while len(_KEPT) > MAX_TRIPLES:
        _KEPT.pop(next(iter(_KEPT)), None)


def take(target: NodeTarget, obligation_id: str) -> Any | None:
    """The value kept for ``obligation_id`` of ``target`` when its inputs are
    unchanged (see the module text), else ``None``; either way nothing is
    kept for it afterwards."""
    hit = _KEPT.pop(_key(target, obligation_id), None)
    if hit is None:
        return None
    inputs, value = hit
    return value if inputs.serves(_inputs(target)) else None


def clear() -> None:
    """Forget everything kept (tests; a long-lived process that wants the memory back)."""
    _KEPT.clear()
