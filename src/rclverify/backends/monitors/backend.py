"""The ``monitors`` backend: export RML + ROSMonitoring config, run = check the plan's traces.

* ``export`` renders ``artifacts/monitors/<Node>/<Node>.rml`` (the node's
  guarantees in RML, :mod:`.rml`) and ``artifacts/monitors/config.yaml``
  (ROSMonitoring's configuration for every node with topics), and returns one
  obligation per trace the plan entry names: "the recorded run satisfies the
  node's contract" (guarantee index 0: the whole contract);
* ``run`` streams the trace through the node's monitor (:mod:`.check`):
  a violation -> ``failed`` (first violation, its time, the guarantee in
  RCL); undecided formulas or obligations still open at the end ->
  ``inconclusive``; no obligation at all -> ``pending``; otherwise
  ``discharged`` (assumption violations are counted and blamed on the
  environment or the upstream node, not on this node).  An unreadable trace
  is ``error`` with the located message.

One read of a run feeds every monitor of a node (:mod:`.run_read`).
"""
from __future__ import annotations

import functools
from pathlib import Path
from typing import Any, Mapping

import jinja2
import msgspec

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces import TraceError
from rclverify.traces.bag import custom_types
from rclverify.traces.files import trace_files, trace_sha256
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.monitors.run_origin import unseen_links
from rclverify.backends.monitors.payload import MonitorsPayload
from rclverify.backends.monitors.shapes import DeadlinesPart
from rclverify.backends.monitors.config import ConfigError, MonitorConfig, load_mapping
from rclverify.backends.monitors.deadline_records import DeadlineResult
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.declarations import add_periods, with_declarations
from rclverify.backends.monitors.judged import Heard, explain, not_judged
from rclverify.backends.monitors.lifecycle import with_lifecycle
from rclverify.backends.monitors.instances import instance_target, per_instance
from rclverify.backends.monitors.recorded import decided_of
from rclverify.backends.monitors.log_calls import merge_deadlines
from rclverify.backends.monitors.periods import with_periods
from rclverify.targets.rml import Spec, rml_id, translate
from rclverify.backends.monitors.widths import carried_fields, float_widths
from rclverify.backends.monitors.stamp_order import second_read, unless_stale
from rclverify.backends.monitors.runset import run_counts, run_runset, runset_obligations
from rclverify.backends.monitors.summary import monitoring_details, summary_line, tool_versions, verdict_status
from rclverify.backends.monitors.run_read import read_run

#: this backend's name and evidence kind, as its declaration.yaml states them
_DECLARED = declared_in(__file__)
NAME, KIND = _DECLARED.name, _DECLARED.evidence_kind
#: The reorder window ROSMonitoring's monitors are configured with (ms); the
#: same default as ``rclverify monitor --live --reorder-window``.
REORDER_WINDOW_MS = 50


def _implementation(target: NodeTarget) -> str:
    """The entry's ``implementation`` (``<file>.py:<function>``: a function of a workspace Python file
    that, called without arguments, makes the robot's rclpy nodes; docs/plan.md), ``""`` when it names
    none.  Raises :class:`PlanError` located at the key for a value of another shape or a file that
    defines no such top-level function (the file's existence is the plan's path check)."""
    import ast  # deferred: only an entry that names its implementation parses it
    value = target.config.get("implementation")
    if value is None:
        return ""
    file, _, name = value.rpartition(":") if isinstance(value, str) else ("", "", "")
    if not file.endswith(".py") or not name.isidentifier():
        raise target.config_error("implementation is '<file>.py:<function>', the function that makes the "
                                  f"robot's rclpy nodes, not {value!r}", "implementation")
    try:
        tree = ast.parse((target.root / file).read_text(encoding="utf-8"), file)
    except (OSError, UnicodeDecodeError, SyntaxError, ValueError) as exc:
        raise target.config_error(f"implementation {file} cannot be read as Python: {exc}", "implementation") from None
    if not any(isinstance(d, (ast.FunctionDef, ast.AsyncFunctionDef)) and d.name == name for d in tree.body):
        raise target.config_error(f"implementation {file} defines no top-level function {name!r}", "implementation")
    return str(value)


@functools.lru_cache(maxsize=1)  # one environment: each template compiled once per process, not once per trace
def _templates() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.monitors", "templates"),
                              undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True,
                              trim_blocks=True, lstrip_blocks=True)


def msg_fields(root: Path, cfg: MonitorConfig) -> dict[str, list[tuple[str, str]]]:
    """``pkg/msg/Type`` -> ``[(field, ros type)]`` from the workspace's ``.msg`` files."""
    types = custom_types([root / d for d in cfg.msg_dirs])
    out: dict[str, list[tuple[str, str]]] = {}
    for name, (_, fields) in types.items():
        out[name] = [(f, str(t[1][0]) if isinstance(t[1], tuple) else str(t[1])) for f, t in fields]
    return out


def render_rml(checked: Checked, node: CheckedNode, spec: Spec, source: str) -> str:
    """Text of a node's ``.rml`` file (deterministic)."""
    return _templates().get_template("spec.rml.j2").render(
        header=f"{node.name}: from {source}; generated by rclverify", node=node.name, terms=spec.terms,
        event_types=spec.event_types, main=spec.main)


def render_config(checked: Checked, ros_version: str, ros_nodes: Mapping[str, Mapping[str, str]] | None = None) -> str:
    """ROSMonitoring's ``config.yaml`` for every node with topics (deterministic).

    ``ros_nodes`` (the mapping file's, contract node -> ``{name, package,
    path}``) fills ROSMonitoring's ``nodes`` list, in contract order; a node
    it does not name is left out (the launch files are not in the contracts)."""
    monitors = []
    for k, node in enumerate(checked.nodes.values()):
        topics = []
        seen = set()
        for t in node.node.topics:
            name = "/" + t.field.lstrip("/")
            if name in seen:
                continue
            seen.add(name)
            pkg, _, typ = t.msg_type.partition("/")
            topics.append({"name": name, "type": f"{pkg}.msg.{typ}"})
        if not topics:
            continue
        ident = "monitor_" + rml_id(node.name).lower()
        monitors.append({"id": ident, "log": f"./{ident}_log.txt", "port": 8080 + k, "topics": topics,
                         "node": node.name})
    named = [dict(ros_nodes[n]) for n in checked.nodes if ros_nodes and n in ros_nodes]
    return _templates().get_template("config.yaml.j2").render(
        header="generated by rclverify from the contracts", ros_version=ros_version, monitors=monitors,
        max_delay_ms=REORDER_WINDOW_MS, nodes=named)


class MonitorsBackend:
    """Runtime monitors (RML for ROSMonitoring) and offline trace checking.

    ``name`` ``"monitors"``, ``kind`` ``"monitoring"``.  Paper lines 791-980.
    """

    name = NAME
    kind = KIND

    def _config(self, target: NodeTarget) -> MonitorConfig:
        c = target.config
        try:
            # the entry's mapping, else the one the plan names for it (model/plan/mapping_file.py)
            rel = target.mapping if c.get("mapping") is None else c.get("mapping")
            return load_mapping(target.root, rel, c.get("horizon"), c.get("traces", ()),
                                c.get("tolerance"))
        except ConfigError as exc:
            if exc.located:  # an error inside the mapping file: located there
                from rclverify.model.plan.errors import plan_error  # deferred: optional or conditional (inside a block)
                raise plan_error(*exc.located) from None
            if exc.path:
                raise target.config_error(str(exc), *exc.path) from None
            raise target.config_error(str(exc)) from None

    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render the node's RML and the system's ROSMonitoring config; one
        obligation per trace.  Raises :class:`PlanError` (located) for a bad entry."""
        cfg = self._config(target)
        made_by = _implementation(target)  # the code that made the runs: the diagnosis re-runs it (docs/plan.md)
        node = target.node
        try:
            fields = msg_fields(target.root, cfg)
        except TraceError as exc:
            raise target.config_error(str(exc), "mapping") from None
        carried = carried_fields(node, cfg.rules, [target.root / d for d in cfg.msg_dirs])
        spec = translate(target.checked, node, cfg.rules, fields, float_widths(node, carried))
        src = node.node.loc
        source = f"{_rel(target, src.file)}:{src.line}:{src.col}"
        rml = target.artifacts / f"{node.name}.rml"
        atomic_write_text(rml, render_rml(target.checked, node, spec, source))
        atomic_write_text(target.artifacts.parent / "config.yaml", render_config(target.checked, cfg.ros_version, cfg.ros_nodes))
        out = []
        names = [Path(t).name for t in cfg.traces]
        for trace in cfg.traces:
            # the file's name, or its whole path where two traces share a name
            stem = (Path(trace).name if names.count(Path(trace).name) == 1 else trace).replace(".", "_").replace("/", "_")
            oid = make_obligation_id(node.name, 0, NAME, stem)
            statement = (f"the run recorded in {trace} satisfies the contract of {node.name}: every input event "
                         f"meeting the assumption is answered within {cfg.horizon} s by outputs meeting every "
                         f"guarantee")
            if cfg.tolerance:
                statement += f" (recorded numbers equal within {cfg.tolerance.text()})"
            artifact = target.artifacts / f"{stem}.txt"
            atomic_write_text(artifact, _templates().get_template("obligation.txt.j2").render(
                header=f"{oid}: generated by rclverify", id=oid, statement=statement, trace=trace,
                mapping=cfg.mapping or "(default rules)", horizon=cfg.horizon, rml=target.rel(rml),
                guarantees=[{"k": k, "rcl": expr_to_rcl(c.formula)} for k, c in enumerate(node.node.guarantees, 1)],
                assumptions=[expr_to_rcl(c.formula) for c in node.node.assumes]))
            inputs = sorted({*trace_files(target.root, trace), *([cfg.mapping] if cfg.mapping else []),
                             *cfg.msg_files(target.root), *target.contract_files, target.plan_file,
                             *([made_by.rpartition(":")[0]] if made_by else [])})
            out.append(Obligation(
                id=oid, node=node.name, guarantee=0, backend=NAME, kind=KIND, statement=statement,
                source=SourceRef(_rel(target, src.file), src.line, src.col), instance=stem,
                artifact=target.rel(artifact), inputs=tuple(inputs),
                data={"trace": trace, "horizon": cfg.horizon, "mapping": cfg.mapping, "rml": target.rel(rml),
                      **({"tolerance": cfg.tolerance.to_json()} if cfg.tolerance else {}),
                      "config": target.rel(target.artifacts.parent / "config.yaml"),
                      **({"implementation": made_by} if made_by else {}),
                      "not_expressible": [{"guarantee": t.guarantee, "part": t.part, "why": t.why}
                                          for t in spec.terms if not t.text]}))
        # a contract the plan runs as instances: each trace judged once per instance (instances.py)
        return per_instance(target, out) + runset_obligations(target, list(cfg.traces), out)

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Check the obligation's trace against the node's contract (never raises
        for a user-caused problem)."""
        if obligation.data.get("run_set") is not None:  # the entry's target over all its runs (runset.py)
            return run_runset(self.run, obligation, target, tool_versions())
        clock = Stopwatch()
        versions = tool_versions()

        def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="rclverify monitor", tool_version=versions,
                                 clock=clock, explanation=explanation, **kw)
        try:
            cfg = self._config(target)
        except Exception as exc:
            return evidence("error", f"the plan entry no longer loads: {exc}")
        trace = str(obligation.data.get("trace", ""))
        try:
            target = instance_target(target, obligation)  # an instance's run: its names resolved (instances.py)
            read = read_run(target, cfg, trace, None)
            lag, note, stale = second_read(read.watch, trace, True)  # one clock, the stamps (stamp_order.py)
            if lag is not None:
                read = read_run(target, cfg, trace, lag)
        except TraceError as exc:
            return evidence("error", f"the trace could not be read: {exc}", log=str(exc))
        except Exception as exc:  # a recorded run is user input: whatever the checker meets is this record's error
            return evidence("error", f"the trace could not be checked: {type(exc).__name__}: {exc}", log=str(exc))
        beside, calls, span, heard = read.beside, read.calls, read.span, read.heard
        events, results, summary = read.events, read.results, read.summary
        res = results[0]
        details = monitoring_details(res, trace, events, trace_sha256(target.root, trace), versions, cfg.horizon,
                                     cfg.tolerance, duration_s=span.seconds)
        status, explanation = verdict_status(res, trace)
        status, explanation, extra = with_lifecycle(read.gate, res.node, status, explanation)  # managed: lifecycle.py
        finished = beside.finish()
        for name in ("deadlines", "periods", "declarations"):  # as above: the record's error, never a crash
            err = beside.errors.get(name)
            if err is not None:
                return evidence("error", f"the {name} could not be checked: {type(err).__name__}: {err}",
                                log=str(err))
        if summary is not None:  # the node's calls beside its topics; their deadlines with its topics' ones
            status, explanation, extra = with_calls(calls.entries(), summary, status, explanation)
            if extra["calls"].get("first_violation") and not details.get("first_violation"):
                # a call's violation is the node's first one: the report's row names its guarantee
                details["first_violation"] = extra["calls"]["first_violation"]
            (cdl,) = calls.deadlines() or (None,)
            merged = merge_deadlines(finished.get("deadlines"), cdl)
            if merged is not None:
                finished["deadlines"] = merged
        if "deadlines" in finished:
            status, explanation, dpart = with_deadlines(target, finished["deadlines"], trace, status, explanation)
            extra.update(dpart)
        if "periods" in finished:
            status, explanation, ppart = with_periods(finished["periods"], trace, status, explanation)
            extra.update(ppart)
        if "declarations" in finished:
            status, explanation, cpart = with_declarations(
                add_periods(finished["declarations"], target.node, finished.get("periods")), trace, status, explanation)
            extra.update(cpart)
        dl = finished.get("deadlines")
        # silence is never green: what the run did not judge, with the reason, beside the status
        extra["not_judged"] = items = not_judged([target.node], Heard({**heard, **calls.messages},
                                                                      dict(calls.orphans),
                                                                      unseen=unseen_links(read.origin)),
                                                 {res.node: [(status, explanation)]}, *_deadline_counts(dl, trace,
                                                 decided_of([res], calls.entries() if summary is not None else [])))
        if read.bag is not None:  # a bag without a link's call topics: say what it lacks (bag_calls.py)
            read.bag.explain(items)
        entry = {"node": res.node, "status": status, "explanation": explanation}
        explain(entry, items)  # a pending record says why itself
        status, explanation = unless_stale((status, entry["explanation"] + (f"; {note}" if note else "")), stale)
        if note:
            details["stamp_order"] = note
        if read.origin is not None:
            details["source"] = read.origin
        stats = run_counts(target.root, target.config, trace, details["sha256"], res, status, span.seconds,
                           calls=extra.get("calls"), rules=cfg.rules)
        return evidence(status, explanation, details=run_payload(details, stats, extra).details(),
                        artifacts=(str(obligation.data.get("rml", "")), str(obligation.data.get("config", ""))),
                        log=summary_line(res))


def _deadline_counts(dl: DeadlineResult | None, trace: str, decided: dict[str, int]) -> \
        tuple[dict[str, dict[str, int]], str, dict[str, int], dict[str, str] | None]:
    """The deadline part of :func:`.judged.not_judged`'s arguments for one node's deadlines ``dl`` on
    ``trace``: its counts with the undecided triggers, where, ``decided``, and why the first undecided was."""
    if dl is None:
        return {}, f"in {trace}", decided, None
    first = dl.first_unaccepted
    why = {dl.node: str(first["reason"])} if first is not None and first["why"] == "undecided" else None
    return {dl.node: {**dl.counts, "undecided": dl.unaccepted.get("undecided", 0)}}, f"in {trace}", decided, why


def run_payload(monitoring: Mapping[str, Any], stats: Mapping[str, Any], extra: Mapping[str, Any]) -> MonitorsPayload:
    """One run's evidence payload: the ``monitoring`` block (:func:`.summary.monitoring_details`, the shape
    ``rclverify monitor`` and the live run print too), the run's ``stats`` (:func:`.runset.run_counts`) and
    the parts the other monitors added (``extra``: ``calls``, ``lifecycle``, ``deadlines``, ``periods``,
    ``declarations``, ``not_judged``), each part converted once into its Struct.  Raises
    :class:`msgspec.ValidationError` for a part the payload does not declare or one of another shape (a
    monitor's bug: the record's payload would not decode)."""
    return msgspec.convert({**extra, "monitoring": monitoring, "statistics": stats}, MonitorsPayload)


def with_calls(entries: list[dict[str, Any]], summary: dict[str, Any], status: str,
               explanation: str) -> tuple[str, str, dict[str, Any]]:
    """The untimed verdict on the node's topics combined with its calls'
    (``entries``: :meth:`~.log_calls.LogCalls.entries`, at most one for one
    node): a ``pending`` side leaves the verdict to the other, else the worse
    status wins; returns ``(status, explanation, {"calls": ...})`` (the
    node's call result and the log's call counts)."""
    if not entries:
        return status, explanation, {"calls": {"counts": summary["counts"]}}
    (e,) = entries
    rank = {"discharged": 0, "pending": 1, "inconclusive": 2, "failed": 3}
    worse = (e["status"] if status == "pending" else status if e["status"] == "pending" else
             max(status, e["status"], key=lambda s: rank.get(s, 0)))
    return worse, f"calls: {e['explanation']}; topics: {explanation}", {
        "calls": {"counts": summary["counts"], **e["calls"], "status": e["status"]}}


def with_deadlines(target: NodeTarget, res: DeadlineResult, trace: str, status: str,
                   explanation: str) -> tuple[str, str, DeadlinesPart]:
    """The untimed verdict combined with the node's deadline verdicts ``res``
    on the same trace (:mod:`.deadlines`): the worse status wins; returns
    ``(status, explanation, {"deadlines": ...})``."""
    dstatus, dexpl = deadline_status(res, trace)
    rank = {"discharged": 0, "pending": 1, "inconclusive": 2, "failed": 3}
    # An untimed check that saw nothing (pending) leaves the verdict to the deadline monitor only when every
    # guarantee is timed (it then evaluated each one on each answer); else the worse of the two wins.
    all_timed = all(c.trigger is not None for c in target.node.node.guarantees)
    worse = dstatus if (status == "pending" and all_timed) or rank.get(dstatus, 0) > rank.get(status, 0) else status
    said = (f"untimed: {explanation}; deadlines: {dexpl}" if worse == status != dstatus else
            f"deadlines: {dexpl}; untimed: {explanation}")  # what decided the status first
    return worse, said, {"deadlines": res.to_json()}


def _rel(target: NodeTarget, file: str) -> str:
    p = Path(file)
    if p.is_absolute():
        try:
            return p.resolve().relative_to(target.root.resolve()).as_posix()
        except ValueError:
            return file
    return file
