"""A flattened Autoware System Designer design written as a workspace, and a workspace written as a design
(``rclverify import autoware-design``, ``rclverify export autoware-design``; docs/nodl.md, "Autoware System
Designer").

Import (:func:`workspace_texts`): per node of :class:`~rclverify.model.nodl.design.Design` one
contract skeleton in ``contracts/design.rcl`` (template ``design.rcl.j2``) and one NoDL document
``nodl/<Node>.nodl.yaml``; the plan (``design_plan.yaml.j2``) names the contracts and declares each
wire between a publisher and a subscriber as a connection.  A contract's inputs are the node's
subscribers, its outputs its publishers (``BOOL``: a skeleton; each named as its port, ``/`` read
``_``), its topics the ports' resolved names and types.  Its guarantees are the processes: each
``on_input X`` of a process (``and``/``or`` alike) starts the outputs the process reaches (its
``to_output``, and those of the processes it triggers: ``to_trigger``, ``on_trigger``), as
``guarantee( out.Y == out.Y ... ) triggered by in.X within T`` with ``T`` that trigger's
``timeout``; each ``periodic: f`` of a process is ``periodic( out.Y, 1/f )`` for the outputs it
reaches.  ``once`` starts nothing (an initialisation).  The outputs no ``on_input`` starts (a
periodic one) have one untriggered guarantee ``out.Y == out.Y`` (published, unconstrained); a node
with no output guarantees ``TRUE``.  Durations are written in ``ms`` when exact there, else ``us``, else in whole ``ns``
(rounded to the nearest).  Services and actions are in the NoDL documents only (an RCL service
entry needs request and response variables the design does not have).

Export (:func:`design_files`): per contract node one ``<Node>.node.yaml`` whose ports are the
contract's topic entries (each with its resolved name as ``global``, its QoS and its services from
the node's NoDL document when there is one) and whose processes are its triggered guarantees
(``on_input`` with the deadline as ``timeout``) and its ``periodic`` declarations; one
``<name>.system.yaml`` with one component per node and the plan's connections (the system model's
links when the plan declares none) as connections.
An untriggered guarantee has no process (the format's processes all have a trigger) and is not
exported.  Importing the export gives the same workspace (tests/model/test_design.py).
"""
from __future__ import annotations

import json
import re
from fractions import Fraction
from functools import lru_cache
from typing import Any, Mapping, Sequence

import jinja2
import yaml

from rclverify.lang import ast
from rclverify.lang.timing import parse_duration, seconds
from rclverify.lang.types import Checked
from rclverify.lang.walk import subexpressions
from rclverify.model.nodl.contract import GENERATED_QOS, full_type, rcl_name_of, type_key, yaml_text
from rclverify.model.nodl.design import Design, DesignNode
from rclverify.model.nodl.design_read import Process
from rclverify.model.nodl.document import Document
from rclverify.model.plan.model import Connection
from rclverify.model.system.model import Link

#: The format version written by export.
FORMAT = "0.3.0"
#: Where import writes the contracts (relative to the workspace).
CONTRACTS = "contracts/design.rcl"
#: The NoDL list of each design port role (services and actions told apart by their type).
_NODL = {"publisher": "publishers", "subscriber": "subscriptions", "server": "service_servers",
         "client": "service_clients"}


@lru_cache(maxsize=1)
def _env() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.model.nodl", "templates"), autoescape=False,
                              keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True)


def duration(s: Fraction) -> str:
    """``s`` seconds as RCL writes a duration: ``ms`` when exact, else ``us``, else whole ``ns`` (rounded)."""
    for unit, scale in (("ms", 1000), ("us", 1_000_000)):
        v = s * scale
        if v.denominator == 1:
            return f"{v.numerator} {unit}"
    return f"{max(1, round(s * 1_000_000_000))} ns"


def var_of(port: str) -> str:
    """The contract variable of design port ``port``: its name as a contract reads a ROS name (:func:`rcl_name_of`:
    ``concatenated/pointcloud`` is ``concatenated_pointcloud``), any other character no RCL name has read ``_``."""
    return re.sub(r"\W", "_", rcl_name_of(port))


def _reach(node: DesignNode, proc: Process, seen: frozenset[str] = frozenset()) -> list[str]:
    """The publisher ports ``proc`` reaches: its ``to_output``s and those of the processes it triggers."""
    by_name = {p.name: p for p in node.processes}
    out = [v for k, v, _ in proc.outcomes if k == "to_output"]
    nxt = [v for k, v, _ in proc.outcomes if k == "to_trigger"]
    nxt += [q.name for q in node.processes if any(t.kind == "on_trigger" and t.value == proc.name for t in q.triggers)]
    for name in nxt:
        if name not in seen and name != proc.name:
            out += _reach(node, by_name[name], seen | {proc.name})
    return list(dict.fromkeys(out))


def _clauses(node: DesignNode) -> tuple[list[dict[str, str]], list[str]]:
    """The guarantees (each its formula and what follows it) and periodic declarations of ``node``'s contract
    (module docstring)."""
    guarantees: list[dict[str, str]] = []
    periods: dict[str, Fraction] = {}
    for proc in node.processes:
        outs = [var_of(o) for o in _reach(node, proc)]
        if not outs:
            continue
        for t in proc.triggers:
            if t.kind == "on_input":
                timeout = next((v for k, v, _ in t.fields if k == "timeout"), None)
                within = f" within {duration(Fraction(str(timeout)))}" if timeout is not None else ""
                g = {"formula": " and ".join(f"out.{o} == out.{o}" for o in outs),
                     "tail": f" triggered by in.{var_of(t.value)}{within}"}
                if g not in guarantees:
                    guarantees.append(g)
            elif t.kind == "periodic":
                period = 1 / Fraction(str(t.value))
                for o in outs:
                    periods[o] = min(periods.get(o, period), period)
    periodic = [f"out.{o}, {duration(p)}" for o, p in sorted(periods.items())]
    answered = {o for p in node.processes for t in p.triggers if t.kind == "on_input" for o in _reach(node, p)}
    rest = [var_of(p.name) for p in node.ports if p.role == "publisher" and p.name not in answered]
    if rest:  # an output no input starts (a periodic one, one never reached): published, unconstrained
        guarantees.append({"formula": " and ".join(f"out.{o} == out.{o}" for o in rest), "tail": ""})
    return guarantees or [{"formula": "TRUE", "tail": ""}], periodic


def _contract_view(node: DesignNode) -> dict[str, Any]:
    ins = [p for p in node.ports if p.role == "subscriber"]
    outs = [p for p in node.ports if p.role == "publisher"]
    topics = [f"{type_key(p.type)[0]}/{type_key(p.type)[1]} {node.topics[(p.role, p.name)]} "
              f"matches({'in' if p.role == 'subscriber' else 'out'}.{var_of(p.name)})" for p in ins + outs]
    guarantees, periodic = _clauses(node)
    return {"name": node.name, "inputs": [f"{var_of(p.name)} : BOOL" for p in ins],
            "outputs": [f"{var_of(p.name)} : BOOL" for p in outs], "topics": topics,
            "guarantees": guarantees,
            "periodic": periodic}


def _document(node: DesignNode) -> dict[str, object]:
    lists: dict[str, list[dict[str, object]]] = {}
    for p in node.ports:
        kind = _NODL[p.role]
        if p.type.split("/")[1] == "action":
            kind = kind.replace("service_", "action_")
        entry: dict[str, object] = {"name": node.topics[(p.role, p.name)], "type": p.type}
        if p.role in ("publisher", "subscriber"):
            qos = dict(GENERATED_QOS)
            qos.update({k: v.upper() for k, v in p.qos})
            entry["qos"] = qos
        lists.setdefault(kind, []).append(entry)
    return {"nodl_version": 2, "description": "imported from an Autoware System Designer design",
            **{k: lists[k] for k in sorted(lists)}}


def workspace_texts(design: Design, folder: str = "design") -> dict[str, str]:
    """The workspace files of ``design``, by path relative to the workspace: the contracts, the plan (its
    ``design`` key ``folder``: where the design lies in the workspace), and one NoDL document per node
    (module docstring)."""
    nodes = [_contract_view(n) for n in design.nodes.values()]
    files = {CONTRACTS: _env().get_template("design.rcl.j2").render(name=design.name, nodes=nodes)}
    wires = sorted({(f"{w.writer}.{var_of(w.writer_port)}", f"{w.reader}.{var_of(w.reader_port)}")
                    for w in design.wires if w.role == "publisher"})
    files["contracts/plan.yaml"] = _env().get_template("design_plan.yaml.j2").render(
        name=json.dumps(design.name), contracts=CONTRACTS, connections=wires, design=json.dumps(folder))
    for n in design.nodes.values():
        files[f"nodl/{n.name}.nodl.yaml"] = yaml_text(_document(n))
    return files


def with_design_key(plan: str, folder: str) -> str:
    """The text of plan ``plan`` with its top-level ``design`` key set to ``folder`` (replaced where the plan has
    one, appended where not), every other line kept as it is."""
    lines = plan.splitlines(keepends=True)
    out, skipping, done = [], False, False
    for line in lines:
        top = bool(line[:1].strip()) and not line.startswith("#")
        if top:
            skipping = False
        if top and re.match(r"design\s*:", line):
            out.append(f"design: {json.dumps(folder)}\n")
            skipping, done = True, True
            continue
        if skipping and not top:
            continue  # the old value's continuation lines
        out.append(line)
    if not done:
        if out and not out[-1].endswith("\n"):
            out[-1] += "\n"
        out.append(f"design: {json.dumps(folder)}\n")
    return "".join(out)


def _hz(period: Fraction) -> float | int:
    f = 1 / period
    return f.numerator if f.denominator == 1 else float(f)


def _node_yaml(name: str, checked: Checked, doc: Document | None) -> dict[str, Any]:
    """The ``<name>.node.yaml`` data of contract node ``name`` (module docstring)."""
    node = checked.nodes[name].node
    qos = {(e.kind, e.name): e.qos for e in (doc.endpoints if doc else ()) if e.qos is not None}
    ports: dict[str, list[dict[str, Any]]] = {"subscribers": [], "publishers": [], "servers": [], "clients": []}
    for t in node.topics:
        if t.match is None or t.match.prefix not in ("in", "out"):
            continue
        key, kind = ("subscribers", "subscriptions") if t.match.prefix == "in" else ("publishers", "publishers")
        entry: dict[str, Any] = {"name": t.match.name, "message_type": full_type(t.msg_type, kind), "global": t.field}
        q = qos.get((kind, t.field))
        entry["qos"] = {"reliability": (q.reliability if q else "RELIABLE").lower(),
                        "durability": ((q.durability if q else None) or "VOLATILE").lower()}
        ports[key].append(entry)
    for e in doc.endpoints if doc else ():
        if e.kind in ("service_servers", "service_clients", "action_servers", "action_clients"):
            key = "servers" if e.kind.endswith("servers") else "clients"
            ports[key].append({"name": e.name.strip("/~").replace("/", "_"),
                               "message_type": full_type(e.type, e.kind), "global": e.name})
    processes: list[dict[str, Any]] = []
    for i, cl in enumerate(node.guarantees, 1):
        outs = list(dict.fromkeys(v.name for v in _outputs(cl.formula)))
        if cl.trigger is None or not outs:
            continue
        trig: dict[str, Any] = {"on_input": cl.trigger.name}
        bound = seconds(cl.deadline) if cl.deadline is not None else None
        if bound is not None:
            trig["timeout"] = bound.numerator if bound.denominator == 1 else float(bound)
        processes.append({"name": f"guarantee_{i}", "trigger_conditions": [trig],
                          "outcomes": [{"to_output": o} for o in outs]})
    for p in node.periodic:
        period = parse_duration(f"{p.amount} {p.unit}")
        if period is not None:
            processes.append({"name": f"periodic_{p.output.name}", "trigger_conditions": [{"periodic": _hz(period)}],
                              "outcomes": [{"to_output": p.output.name}]})
    return {"autoware_system_design_format": FORMAT, "name": f"{name}.node",
            "package": {"name": name.lower(), "provider": "rclverify"}, "launch": {"plugin": name},
            **ports, "param_files": [], "param_values": [], "processes": processes}


def _outputs(expr: ast.Expr) -> list[ast.Var]:
    return [e for e in subexpressions(expr) if isinstance(e, ast.Var) and e.prefix == "out"]


def _dump(data: dict[str, Any]) -> str:
    return str(yaml.safe_dump(data, sort_keys=False, default_flow_style=False, width=120))


def design_files(name: str, checked: Checked, links: Sequence[Link | Connection],
                 documents: Mapping[str, Document]) -> dict[str, str]:
    """The design of a workspace (module docstring), by path relative to the design folder: ``node/<Node>.node.yaml``
    per node of ``checked`` (its NoDL document from ``documents`` by node, when there is one) and
    ``system/<name>.system.yaml`` with ``links`` (the plan's connections, or the system model's links) as
    connections."""
    files = {f"node/{n}.node.yaml": _dump(_node_yaml(n, checked, documents.get(n))) for n in checked.nodes}
    system = {"autoware_system_design_format": FORMAT, "name": f"{name}.system", "variables": [],
              "modes": [{"name": "default", "default": True}],
              "components": [{"name": n, "entity": f"{n}.node", "path": f"/{n}"} for n in checked.nodes],
              "connections": [[f"{lk.from_node}.publisher.{lk.from_var}", f"{lk.to_node}.subscriber.{lk.to_var}"]
                              for lk in sorted(links, key=lambda lk: (lk.from_node, lk.from_var, lk.to_node, lk.to_var))]}
    files[f"system/{name}.system.yaml"] = _dump(system)
    return files


__all__ = ["CONTRACTS", "FORMAT", "design_files", "duration", "var_of", "workspace_texts"]
