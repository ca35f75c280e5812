"""The backend plug-in interface (shared/DESIGN.md, steps 5 and 6).

A backend turns one node's guarantees into :class:`Obligation` records
(``export``) and produces one :class:`Evidence` record per obligation
(``run``).  Backends are registered by name in :mod:`rclverify.backends`;
the verification plan names them per node.

Rules every backend keeps:

* ``export`` is deterministic: same inputs, same obligations and byte-for-byte
  the same rendered artifacts (no timestamps inside artifacts).
* ``run`` never raises for a user-caused problem: a missing tool is
  ``pending`` (with the reason and the command to run), a tool crash is
  ``error``, a refutation is ``failed`` with a counterexample when there is one,
  a timeout/unknown is ``inconclusive``.  Nothing unchecked is ``discharged``.
* Every file the result depends on is listed in ``Obligation.inputs``
  (workspace-relative); :func:`make_evidence` hashes them for staleness.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping, Protocol

from rclverify.records.records import Evidence, Obligation, hash_inputs
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.load import KEY
from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.backends.timing_scope import scope


@dataclass(frozen=True)
class NodeTarget:
    """Everything a backend needs to know about one node of the system.

    ``root``            workspace root (absolute);
    ``checked``         the whole type-checked system (environment + nodes);
    ``node``            the node this target is about;
    ``config``          the plan's evidence entry for this node and backend
                        (the mapping under ``nodes.<Node>.evidence[k]``,
                        including its ``backend`` key);
    ``facts``           the plan's environment facts for this node, parsed;
    ``contract_files``  workspace-relative RCL files of the system;
    ``plan_file``       workspace-relative path of the plan;
    ``artifacts``       absolute directory ``artifacts/<backend>/<node>/``
                        where the backend renders its files;
    ``index``           position of this entry among the node's evidence
                        entries (distinguishes two entries of one backend);
    ``plan_locs``       the plan's value locations (see :meth:`config_loc`);
    ``mapping``         the workspace-relative trace mapping file the plan names
                        for this entry (:func:`~rclverify.model.plan.mapping_file.plan_mapping`;
                        ``None``: none, the default path if present), where every
                        backend reads what a field carries;
    ``instances``       the nodes the plan runs this contract as
                        (:class:`~rclverify.model.plan.instances.Instance`; empty: it
                        runs once, as written), which the monitors judge one by one.
    """

    root: Path
    checked: Checked
    node: CheckedNode
    config: Mapping[str, Any]
    facts: tuple[ast.Expr, ...] = ()
    contract_files: tuple[str, ...] = ()
    plan_file: str = "contracts/plan.yaml"
    artifacts: Path = field(default_factory=Path)
    index: int = 0
    plan_locs: Mapping[tuple[Any, ...], ast.Loc] = field(default_factory=dict)
    mapping: str | None = None
    instances: tuple[Any, ...] = ()

    def config_loc(self, *path: Any, key: bool = False) -> ast.Loc:
        """Where ``nodes.<Node>.evidence[index].<path...>`` is written in the plan.

        ``key=True`` gives the position of the last key itself rather than its
        value.  Falls back to the deepest part of the path the plan has, then
        to the plan's first line.
        """
        full = ("nodes", self.node.name, "evidence", self.index) + tuple(path)
        if key and full + (KEY,) in self.plan_locs:
            return self.plan_locs[full + (KEY,)]
        while full:
            if full in self.plan_locs:
                return self.plan_locs[full]
            full = full[:-1]
        return ast.Loc(self.plan_file, 1, 1)

    def config_error(self, message: str, *path: Any, key: bool = False, code: str = "E-plan",
                     col_offset: int = 0) -> PlanError:
        """A :class:`PlanError` located at :meth:`config_loc` (plus ``col_offset`` columns)."""
        loc = self.config_loc(*path, key=key)
        return plan_error(loc.file, loc.line, loc.col + col_offset, message, code)

    def rel(self, path: Path) -> str:
        """``path`` relative to the workspace root, with forward slashes.  A
        path under :attr:`artifacts` (what the backends pass) is related by
        its text when neither it nor the artifact directory names ``..``;
        anything else is resolved first (symbolic links, ``..``)."""
        a = str(self.artifacts)
        p = str(path)
        if p.startswith(a + "/") and ".." not in path.parts and ".." not in self.artifacts.parts:
            return f"{self._artifacts_rel}/{p[len(a) + 1:]}"
        return path.resolve().relative_to(self.root.resolve()).as_posix()

    @cached_property
    def _artifacts_rel(self) -> str:
        return self.artifacts.resolve().relative_to(self.root.resolve()).as_posix()


class Backend(Protocol):
    """A verification backend.  ``name`` is the plan's ``backend:`` value."""

    name: str
    kind: str

    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render the node's obligations under ``target.artifacts`` and return them.

        Raises :class:`rclverify.model.plan.errors.PlanError` for a configuration
        the user got wrong (missing file, unmappable type ...).
        """
        ...

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Check one exported obligation and return its evidence record."""
        ...


def utc_now() -> str:
    """ISO-8601 UTC timestamp with second precision (evidence records only)."""
    return datetime.now(timezone.utc).replace(microsecond=0).isoformat()


class Stopwatch:
    """Measures a run: ``started`` (ISO UTC) and ``elapsed()`` in seconds."""

    def __init__(self) -> None:
        self.started = utc_now()
        self._t0 = time.perf_counter()

    def elapsed(self) -> float:
        return round(time.perf_counter() - self._t0, 4)


def make_evidence(
    target: NodeTarget,
    obligation: Obligation,
    status: str,
    *,
    tool: str,
    tool_version: str,
    clock: Stopwatch,
    explanation: str = "",
    log: str = "",
    artifacts: tuple[str, ...] = (),
    counterexample: Mapping[str, object] | None = None,
    details: Mapping[str, object] | None = None,
) -> Evidence:
    """Build an :class:`Evidence` record for ``obligation``, hashing its inputs now.

    ``status`` must be one of the statuses in :mod:`rclverify.records.records`.
    For a timed guarantee a backend that does not check time says so in the
    explanation and ``details["timing"]`` (:mod:`.timing_scope`).
    """
    explanation, details = scope(obligation.backend, target.node, obligation.guarantee, explanation, details or {})
    return Evidence(
        obligation=obligation.id, backend=obligation.backend, kind=obligation.kind, status=status,
        tool=tool, tool_version=tool_version, started=clock.started, duration_s=clock.elapsed(),
        input_hashes=hash_inputs(target.root, obligation.inputs), artifacts=artifacts,
        log=log[-20000:], counterexample=dict(counterexample) if counterexample is not None else None,
        explanation=explanation, details=dict(details or {}),
    )
