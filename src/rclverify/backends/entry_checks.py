"""Check-time validation of the plan's ``experiment``, ``review``, ``monitors`` and ``ajpf`` entries.

Called by :attr:`rclverify.app.pipeline.Workspace.checked` right after
:func:`rclverify.model.plan.load.resolve` (the layer above both the plan and the
backends: the plan imports no backend code), so ``rclverify``/``doit
check`` reports a missing data or record file, a malformed record, a bad
criterion, a reviewed file or message directory outside the workspace, or a
bad trace mapping at once, located in the plan or in the file that names
it, before any evidence is touched.

A node has at most one ``ajpf`` entry: its obligations are named
``<Node>.g<k>.ajpf.p<n>_...`` and its files are ``artifacts/ajpf/<Node>/``,
so a second entry would give the same obligations (doit refuses the
duplicated task names) and overwrite the first's artifacts.  The second is
refused at its ``backend`` key; extra properties belong in the first
entry's ``properties:`` list.
"""
from __future__ import annotations

from typing import Any

from rclverify.model.plan.mapping_file import plan_mapping
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.load import KEY, Plan
from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic
from rclverify.lang.types import Checked
import json


def check_entries(plan: Plan, checked: Checked) -> list[Diagnostic]:
    """Diagnostics for every experiment/review entry of ``plan`` that does not check.
    (The two backends are imported only for a plan that has such entries:
    the experiment backend brings Z3 and matplotlib's helpers, a tenth of a
    second of every run that loads the plan.)"""
    out: list[Diagnostic] = []
    for node, entries in plan.evidence.items():
        if node not in checked.nodes:
            continue
        out.extend(_one_ajpf_entry(plan, node, entries))
        out.extend(_no_repeated_entry(plan, node, entries))
        for e in entries:
            if e.backend not in ("experiment", "review", "monitors"):
                continue

            def loc(*path: Any, key: bool = False, _e: Any = e) -> ast.Loc:
                full = ("nodes", node, "evidence", _e.index) + tuple(path)
                if key and full + (KEY,) in plan.locs:
                    return plan.locs[full + (KEY,)]
                while full and full not in plan.locs:
                    full = full[:-1]
                return plan.locs.get(full, _e.loc)
            try:
                if e.backend == "experiment":
                    from rclverify.backends.experiment.config import read_config  # deferred: optional or conditional (inside a block)
                    read_config(plan.root, e.config, len(checked.nodes[node].node.guarantees), loc)
                elif e.backend == "review":
                    from rclverify.backends.review.backend import read_record  # deferred: optional or conditional (inside a block)
                    read_record(plan.root, e.config, loc)
                else:
                    _check_monitors(plan, e.config, loc, checked, node)
                    out.extend(d for d in _shared_topics(plan, e.config, checked, node) if d not in out)
            except PlanError as exc:  # once each: entries sharing a mapping file share its errors
                out.extend(d for d in exc.diagnostics if d not in out)
    return out


def _one_ajpf_entry(plan: Plan, node: str, entries: Any) -> list[Diagnostic]:
    """An error at the ``backend`` key of every ``ajpf`` entry of ``node`` after the first."""
    first: ast.Loc | None = None
    out = []
    for e in entries:
        if e.backend != "ajpf":
            continue
        path = ("nodes", node, "evidence", e.index, "backend")
        loc = plan.locs.get(path, e.loc)
        if first is None:
            first = loc
            continue
        out.append(plan_error(loc.file, loc.line, loc.col,
                              f"node {node} has a second ajpf entry (the first is at {first.file}:{first.line}:"
                              f"{first.col}): both would give the same obligations and write artifacts/ajpf/{node}/; "
                              "keep one entry and list further property files under its 'properties'").diagnostics[0])
    return out


def _no_repeated_entry(plan: Plan, node: str, entries: Any) -> list[Diagnostic]:
    """An error at the ``backend`` key of an entry of ``node`` that repeats an
    earlier one (same backend, same configuration): it would give the same
    obligations, which doit refuses as duplicated task names.  (Entries that
    differ but still name their obligations alike are caught when the
    obligations are exported, :func:`rclverify.app.pipeline.stage_export`.)"""
    seen: dict[str, ast.Loc] = {}
    out = []
    for e in entries:
        if e.backend == "ajpf":
            continue  # _one_ajpf_entry
        key = e.backend + json.dumps(e.config, sort_keys=True, default=str)
        loc = plan.locs.get(("nodes", node, "evidence", e.index, "backend"), e.loc)
        if key in seen:
            first = seen[key]
            out.append(plan_error(loc.file, loc.line, loc.col,
                                  f"node {node} has this {e.backend} entry twice (the first is at {first.file}:"
                                  f"{first.line}:{first.col}): both would give the same obligations; keep one"
                                  ).diagnostics[0])
        else:
            seen[key] = loc
    return out


def _shared_topics(plan: Plan, config: Any, checked: Checked, node: str) -> list[Diagnostic]:
    """Located errors of ``node``'s variables that share a topic and would
    read one field (:mod:`.monitors.shared_topics`), under the entry's
    mapping file's rules (none when it does not exist yet)."""
    from rclverify.backends.monitors.config import DEFAULT_MAPPING, ConfigError, load_mapping  # deferred: start-up (loads lark, z3 and more only when called)
    from rclverify.backends.monitors.shared_topics import shared_topic_errors  # deferred: start-up (loads rclverify.backends.monitors, rclverify.semantics and more only when called)
    rel = config.get("mapping")
    rel = plan_mapping(plan, node, config) if rel is None else rel  # the mapping the plan names for the entry
    rules: Any = {}
    if isinstance(rel, (str, type(None))) and (plan.root / (rel or DEFAULT_MAPPING)).is_file():
        try:
            rules = load_mapping(plan.root, rel, config.get("horizon"), (), config.get("tolerance")).rules
        except ConfigError:
            return []  # the mapping's own error is reported by _check_monitors
    return shared_topic_errors(checked, node, rules, rel or DEFAULT_MAPPING)


def _check_monitors(plan: Plan, config: Any, loc: Any, checked: Checked | None = None, node: str | None = None) -> None:
    """Read the monitors entry's ``near_miss`` threshold
    (:mod:`.monitors.near_miss`), its trace mapping when it exists (its
    YAML, its ``msg_dirs``, which must lie inside the workspace, and its
    field paths against the message definitions the contracts' topics name,
    :mod:`.monitors.fieldpaths`) and the entry's ``tolerance``.  A missing
    mapping or trace is left to the export stage (a workspace may record its
    traces after writing the plan).  Raises :class:`PlanError`."""
    from rclverify.backends.monitors.near_miss import NearMissError, guarantee_units, parse_near_miss, value_fault  # deferred: start-up (loads rclverify.lang.timing only when called)
    try:
        t = parse_near_miss(config.get("near_miss"))
        if t is not None and t.value is not None and checked is not None and node in checked.nodes:
            why = value_fault(t, guarantee_units(checked, str(node)), str(node))  # one reading on every guarantee
            if why:
                raise NearMissError(why, ("value",))
    except NearMissError as exc:
        l = loc("near_miss", *exc.key)
        raise plan_error(l.file, l.line, l.col, str(exc)) from None
    from rclverify.semantics.floatsem import ToleranceError, parse_tolerance  # deferred: start-up (loads lark, z3 and more only when called)
    from rclverify.backends.monitors.config import DEFAULT_MAPPING, ConfigError, load_mapping  # deferred: start-up (loads lark, z3 and more only when called)
    rel = config.get("mapping")
    rel = plan_mapping(plan, node, config) if rel is None else rel  # the mapping the plan names for the entry
    if not isinstance(rel, (str, type(None))) or not (plan.root / (rel or DEFAULT_MAPPING)).is_file():
        try:
            parse_tolerance(config.get("tolerance"))
        except ToleranceError as exc:
            l = loc("tolerance", *exc.key)
            raise plan_error(l.file, l.line, l.col, str(exc)) from None
        return
    try:
        cfg = load_mapping(plan.root, rel, config.get("horizon"), (), config.get("tolerance"))
    except ConfigError as exc:
        if exc.located:  # an error inside the mapping file: located there
            raise plan_error(*exc.located) from None
        l = loc(*exc.path)
        raise plan_error(l.file, l.line, l.col, str(exc)) from None
    if checked is not None and cfg.mapping:
        from rclverify.backends.monitors.fieldpaths import check_field_paths  # deferred: optional or conditional (inside a block)
        diags = check_field_paths(plan.root, cfg.mapping, cfg.msg_dirs, checked)
        if diags:
            raise PlanError(diags)
