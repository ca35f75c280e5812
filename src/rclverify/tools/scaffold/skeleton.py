"""``rclverify init DIR --from-ros PATH``: one contract skeleton per node of
the scanned graph, a plan with the ``ros:`` section, and a copy of the
scanned packages under ``DIR/ros`` (docs/ros.md).

From ROS field types to RCL (the paper's Scalar, Collection and Function
rules, lines 535-548), for a topic's message:

* one base field: a scalar -- ``float32``/``float64`` REAL, signed integers
  INTEGER, unsigned integers (``uint*``, ``byte``, ``char``) NATURAL,
  ``bool`` BOOL, ``string`` STRING;
* one integer field with constants of its type (``uint8 RED=2``): an
  enumeration of the constants' names in lower case (Collection rule);
* several base fields (nested messages flattened to five levels, arrays,
  ``time``/``duration`` and ``header`` left out): a predicate over them,
  ``T1 x ... x Tn --> BOOL`` (Function rule: the message asserts the tuple);
  a message with no other field reads its times' ``sec``/``nanosec`` and its
  fixed-size arrays' elements (``kp[0]`` ...), so a present type is not ``{}``;
* no base field: the empty type ``{}``.

Which fields are read is :mod:`.fields`'s; every field left out is listed,
with its type and why, in a comment of the node's skeleton, and ``init
--from-ros`` prints one line per node that has any.  A topic, service or
action is named by its whole name as the code writes it, each ``/`` written
``_`` (:func:`_identifier`).  A type of an absent interface package
(``ros/graph/absent.py``) keeps its name and is ``{}``, said in the comment.

The fields chosen are written to the plan's ``ros.fields`` so the grounding
check and the reader agree: keyed by the topic's field name when every
contract using that name reads one message type, else by
``Contract.topic`` for each contract (the types differ, so do the paths).  Every guarantee is ``TRUE``, a placeholder the
health check reports (a tautology promises nothing) and the argument shows
undeveloped (no evidence).
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import jinja2

from rclverify.records.store import atomic_write_text
from rclverify.ros.graph.scan import ScanResult
from rclverify.ros.extract.interfaces import ABSENT, TypeTable
from rclverify.ros.extract.model import LIBRARY_TOPICS, GraphEdge, GraphNode, library_of, short_type
from rclverify.tools.scaffold.fields import SIGNED, UNSIGNED, read_fields, rcl_scalar
from rclverify.tools.scaffold.safecopy import copy_package
from rclverify.tools.scaffold import EMPTY_DIRS, _env as scaffold_env

__all__ = ["TYPES_FILE", "build_skeletons", "ident", "rcl_scalar", "write_from_ros"]

_ENV = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.tools.scaffold", "templates"), autoescape=False,
                          undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                          keep_trailing_newline=True)
_RCL_WORDS = {"node", "context", "inputs", "outputs", "topics", "assume", "guarantee", "forall", "exists",
              "exists_unique", "and", "or", "not", "in", "out", "TRUE", "FALSE", "REAL", "INTEGER", "NATURAL",
              "BOOL", "STRING", "matches", "set", "seq"}
#: the context declarations shared by every skeleton (one RCL type per message type)
TYPES_FILE = "contracts/ros_types.rcl"


def ident(text: str, camel: bool = False) -> str:
    """An RCL identifier from a ROS name (``radiation_sensor`` -> ``RadiationSensor`` with ``camel``)."""
    parts = [p for p in re.split(r"[^A-Za-z0-9]+", text) if p]
    if not parts:
        parts = ["x"]
    if camel:
        s = "".join(p[:1].upper() + p[1:] for p in parts)
    else:
        s = parts[0][:1].lower() + parts[0][1:] + "".join(p[:1].upper() + p[1:] for p in parts[1:])
    if s[0].isdigit():
        s = "n" + s
    return s + "_" if s in _RCL_WORDS else s


def _contract_file(cname: str, nodes: list["_Node"]) -> str:
    """``contracts/battery_monitor.rcl`` for node ``BatteryMonitor``: snake
    case, as ``rclverify init`` names contract files; ``_`` appended while
    another node already has the name (``ABc`` and ``Abc``)."""
    stem = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", cname).lower()
    taken = {n.file for n in nodes}
    while f"contracts/{stem}.rcl" in taken or f"contracts/{stem}.rcl" == TYPES_FILE:
        stem += "_"
    return f"contracts/{stem}.rcl"


@dataclass
class _Node:
    name: str
    ros_name: str
    package: str | None
    executable: str | None
    sources: list[str]
    file: str
    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    topics: list[str] = field(default_factory=list)
    context: list[dict[str, str]] = field(default_factory=list)
    services: list[str] = field(default_factory=list)
    actions: list[str] = field(default_factory=list)
    apart: list[str] = field(default_factory=list)  # endpoints left out, each with its reason
    # message (pkg/Type) -> (the variables reading it, its fields left out: (path, ROS type, why))
    left: dict[str, tuple[list[str], list[tuple[str, str, str]]]] = field(default_factory=dict)
    named: dict[str, str] = field(default_factory=dict)  # RCL name of a topic, service or action -> its ROS name
    lifecycle: bool = False  # a managed node: its transition topic named, its guarantee scoped `while active`

    def left_groups(self) -> list[tuple[str, list[str], list[tuple[str, str, str]]]]:
        """``(message, variables, fields left out)`` for the skeleton's comment, in order of use."""
        return [(msg, refs, fields) for msg, (refs, fields) in self.left.items()]

    def left_count(self) -> int:
        """How many message fields (counted once per message) the node's RCL types leave out."""
        return sum(len(fields) for _refs, fields in self.left.values())


_ROLE_WORDS = {"pub": "publishes", "sub": "subscribes to", "service_servers": "serves",
               "service_clients": "calls", "action_servers": "serves action", "action_clients": "calls action"}


def _left_out(n: _Node, role: str, e: GraphEdge, reason: str) -> None:
    """Record that endpoint ``e`` (of ``role``) is not in ``n``'s contract, and why."""
    at = f" ({e.src.file}:{e.src.line})" if e.src else ""
    line = f"{_ROLE_WORDS.get(role, role)} {e.topic} ({short_type(e.msg_type) if e.msg_type else 'type unknown'}){at}: " \
           f"{reason}"
    if line not in n.apart:
        n.apart.append(line)


def _kept(n: _Node, role: str, edges: list[GraphEdge], table: TypeTable, library: bool) -> list[GraphEdge]:
    """The endpoints of ``edges`` the contract takes: its own, with a type the scan
    read; a library's (tf, bond, diagnostics, ...; :func:`model.library_of`) only
    with ``library``; each one left out is listed in ``n.apart`` with the reason."""
    out = []
    for e in edges:
        lib = library_of(e.topic, e.msg_type)
        if lib == "client library" or (lib is not None and not library):
            _left_out(n, role, e, f"made by the {lib}{'' if lib == 'client library' else ' library'}, not the "
                                  f"node's own code" + (
                "" if lib == "client library" else " (`init --from-ros --library-endpoints` takes it in)"))
        elif not e.msg_type:
            _left_out(n, role, e, "its type is not read statically (the scan's note at that line says why)")
        else:
            info = table.get(e.msg_type if role in ("pub", "sub") else f"{e.msg_type}_Request" if role.startswith(
                "service") else f"{e.msg_type}_Goal")
            if info is None:
                _left_out(n, role, e, f"kept, but {short_type(e.msg_type)} is defined by no scanned or standard "
                                      f"package: its values are {{}}")
            elif info.origin == ABSENT:
                _left_out(n, role, e, f"kept with its type name, untyped: its interface package "
                                      f"{e.msg_type.split('/')[0]} is in neither the scanned tree nor an installed "
                                      f"ROS (the scan's ROS-INTERFACE-ABSENT warning): its values are {{}}")
            out.append(e)
    return out


def _type_name(msg: str, taken: dict[str, str]) -> str:
    """A context type name for message ``msg`` (``rover_msgs/msg/Status`` -> ``Status``,
    ``PkgStatus`` when another package's ``Status`` has it already)."""
    pkg, base = msg.split("/")[0], msg.split("/")[-1]
    name = ident(base, camel=True)
    if name in _RCL_WORDS or taken.get(name, msg) != msg:
        name = ident(pkg, camel=True) + name
    taken[name] = msg
    return name


def _value(tname: str, const: str, taken: dict[str, str]) -> str:
    """An enumeration value for constant ``const`` of type ``tname``: ``on`` for ``ON``,
    qualified with the type (``soundValueOn``) when another enumeration has ``on``
    already (RCL values are global: two messages' ``ON`` constants must not clash;
    the grounding reads either form, :func:`rclverify.ros.ground.ground`).  ``taken`` records
    values as ``"=value"`` -> type name."""
    v = ident(const.lower())
    if taken.setdefault("=" + v, tname) != tname:
        v = ident(f"{tname} {const.lower()}")
        taken["=" + v] = tname
    return v


def _var_type(n: _Node, table: TypeTable, msg: str | None, ref: str,
              taken: dict[str, str]) -> tuple[str, list[str], dict[str, str] | None]:
    """(RCL type text, field paths, context declaration or None) of variable ``ref``
    (``out.odom``) reading message ``msg``; types are named after their message
    (:func:`_type_name`), so one message has one RCL type.  The fields the type
    leaves out are recorded in ``n.left`` (:func:`fields.read_fields`)."""
    info = table.get(msg)
    if msg is None or info is None:
        return "{}", [], None
    reading = read_fields(table, msg)
    fields = reading.kept
    if reading.left:
        n.left.setdefault(short_type(msg), ([], reading.left))[0].append(ref)
    if len(fields) == 1:
        path, t = fields[0]
        consts = [c for c, ct, _ in info.consts if ct == t] if "." not in path else []
        if consts and t in UNSIGNED | SIGNED:
            tname = _type_name(msg, taken) + ident(path, camel=True)
            return tname, [path], {"name": tname, "type": "{" + ", ".join(_value(tname, c, taken) for c in consts) + "}"}
        return rcl_scalar(t) or "{}", [path], None
    if not fields:
        return "{}", [], None
    tname = _type_name(msg, taken)
    sig = " x ".join(rcl_scalar(t) or "REAL" for _, t in fields) + " --> BOOL"
    return tname, [p for p, _ in fields], {"name": tname, "type": sig}


def _identifier(n: _Node, e: GraphEdge, group: str) -> str:
    """The RCL name a contract gives endpoint ``e`` of node ``n``: the whole name as
    the code writes it, each ``/`` written ``_`` (an RCL name holds no ``/``), a
    leading ``/`` or ``~`` dropped (``/robot/arm/cmd`` -> ``robot_arm_cmd``,
    ``~/status`` -> ``status``): the form the grounding matches (docs/ros.md,
    "Names in skeletons").  Two ROS names of the node that read alike
    (``a/b_c``, ``a_b/c``) as the same ``group`` (``topic``, ``service``, ``action``)
    are said in ``n.apart``: the grounding cannot tell them apart."""
    written = e.written or e.topic
    base = written.strip("/~").replace("/", "_").replace("~", "")
    name = base if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", base) and base not in _RCL_WORDS else ident(base)
    first = n.named.setdefault(f"{group} {name}", e.topic)
    if first != e.topic:
        line = (f"{e.topic} and {first} both read `{name}` (an RCL name holds no /: each / is written _): "
                f"the grounding cannot tell them apart and reports one undocumented; rename one in the code")
        if line not in n.apart:
            n.apart.append(line)
    return name


def _links(n: "_Node", gn: GraphNode, table: TypeTable, taken: dict[str, str], context: dict[str, dict[str, str]],
           seen: set[str], library: bool = False) -> None:
    """The node's service and action links (``services(...)``, ``actions(...)``): a
    server reads the request (goal) and writes the response (feedback, result), a
    client the mirror image; each part an input or output typed from the
    ``.srv``/``.action`` definition."""
    for kind, parts in (("service", (("Request", "Req"), ("Response", "Res"))),
                        ("action", (("Goal", "Goal"), ("Feedback", "Feedback"), ("Result", "Result")))):
        for role in ("servers", "clients"):
            edges = _kept(n, f"{kind}_{role}", gn.edges_of(f"{kind}_{role}"), table, library)
            done: set[str] = set()
            for e in sorted(edges, key=lambda e: e.topic):
                if e.topic in done or not e.msg_type:
                    continue
                done.add(e.topic)
                name = _identifier(n, e, kind)
                refs = []
                for k, (part, suffix) in enumerate(parts):
                    var = ident(name) + suffix
                    while var in seen:
                        var += "_"
                    seen.add(var)
                    incoming = (k == 0) == (role == "servers")
                    refs.append(f"{'in' if incoming else 'out'}.{var}")
                    typ, _paths, ctx = _var_type(n, table, f"{e.msg_type}_{part}", refs[-1], taken)
                    if ctx is not None:
                        context.setdefault(ctx["name"], ctx)
                    (n.inputs if incoming else n.outputs).append(f"{var} : {typ}")
                verb = "serves" if role == "servers" else "calls"
                getattr(n, f"{kind}s").append(f"{short_type(e.msg_type)} {name} {verb}({', '.join(refs)})")


def build_skeletons(res: ScanResult, library: bool = False
                    ) -> tuple[list[_Node], dict[str, list[str]], list[str], list[dict[str, str]]]:
    """Contract skeletons (one per graph node), the plan's ``fields``, the ``external``
    topics and the shared context declarations (one per message type used).  A
    topic the node's code creates at several call sites is one input or output.
    Library endpoints (:func:`model.library_of`) are inputs and outputs only with
    ``library``; every endpoint left out is in the node's ``apart`` list with why."""
    g, table = res.graph, res.table
    taken: dict[str, str] = {}
    context: dict[str, dict[str, str]] = {}
    nodes: list[_Node] = []
    fields: dict[str, list[str]] = {}
    uses: dict[str, list[tuple[str, str | None, list[str]]]] = {}  # topic field -> (contract, type, paths)
    used_names: set[str] = set()
    for gname in sorted(g.nodes):
        gn: GraphNode = g.nodes[gname]
        cname = ident(gname.rsplit("/", 1)[-1], camel=True)
        while cname in used_names:
            cname += "_"
        used_names.add(cname)
        n = _Node(cname, gname, gn.package, gn.executable, gn.sources, _contract_file(cname, nodes))
        seen: set[str] = set()
        # the client library's own topics (/parameter_events, /rosout) are no contract's
        pubs, subs = (_kept(n, role, es, table, library) for role, es in (("pub", gn.publishes),
                                                                            ("sub", gn.subscribes)))
        for kind, edges in (("in", subs), ("out", pubs)):
            done: set[str] = set()
            for e in sorted(edges, key=lambda e: e.topic):
                if e.topic in done:
                    continue
                done.add(e.topic)
                topic_name = _identifier(n, e, "topic")
                var = ident(topic_name)
                while var in seen:
                    var += "_"
                seen.add(var)
                typ, paths, ctx = _var_type(n, table, e.msg_type, f"{kind}.{var}", taken)
                if ctx is not None:
                    context.setdefault(ctx["name"], ctx)
                (n.inputs if kind == "in" else n.outputs).append(f"{var} : {typ}")
                n.topics.append(f"{short_type(e.msg_type) if e.msg_type else 'std_msgs/Empty'} {topic_name} "
                                f"matches({kind}.{var})")
                uses.setdefault(topic_name, []).append((cname, e.msg_type, paths))
        if gn.lifecycle:  # a managed node (docs/rcl-language.md, "Lifecycle nodes"): its ~/transition_event,
            n.lifecycle = True  # written relative as the skeleton's other names (resolved in the node's namespace)
            n.topics.append(f"lifecycle_msgs/TransitionEvent {gname.rsplit('/', 1)[-1]}/transition_event")
        _links(n, gn, table, taken, context, seen, library)
        nodes.append(n)
    for topic_name, got in uses.items():
        # one message type wherever the name is used: one entry by the topic's name; types
        # that differ (JoyFeedback and JoyFeedbackArray on set_feedback): one per contract
        shared = len({t for _c, t, _p in got}) == 1
        for cname, _t, paths in got:
            if paths:
                fields.setdefault(topic_name if shared else f"{cname}.{topic_name}", paths)
    published = {e.topic for n in g.nodes.values() for e in n.publishes}
    external = sorted({e.topic for n in g.nodes.values() for e in n.subscribes
                       if e.msg_type and (library and library_of(e.topic, e.msg_type) != "client library"
                                          or library_of(e.topic, e.msg_type) is None)} - published - LIBRARY_TOPICS)
    for kind in ("service", "action"):  # called, served by no scanned node: another system's
        served = {e.topic for n in g.nodes.values() for e in n.edges_of(f"{kind}_servers")}
        external += sorted({e.topic for n in g.nodes.values() for e in n.edges_of(f"{kind}_clients")
                            if e.msg_type and library_of(e.topic, e.msg_type) is None} - served - set(external))
    return nodes, fields, external, list(context.values())


def write_from_ros(root: Path, res: ScanResult, scanned: list[Path], launch: list[Path],
                   library: bool = False) -> list[Path]:
    """Write the workspace: ``dodo.py``, ``contracts/*.rcl``, ``contracts/plan.yaml``,
    ``ros/`` (a copy of each scanned package directory), ``nodl/<Node>.nodl.yaml`` for each node
    whose package registers a NoDL document (:func:`.nodl.from_ros_documents`) and empty ``backends``,
    ``artifacts``, ``reports``.  Returns the paths written.  Raises ``OSError``.
    ``library``: library endpoints become inputs and outputs too (:func:`build_skeletons`)."""
    nodes, fields, external, context = build_skeletons(res, library)
    for n in nodes:
        for line in n.apart:
            print(f"{n.file}: {line}", file=sys.stderr)
        if n.left:
            print(f"{n.file}: its RCL types leave out {n.left_count()} message field(s), each listed in its "
                  f"comment with why", file=sys.stderr)
    written: list[Path] = []
    name = root.resolve().name or "workspace"
    ros_dir = root / "ros"
    launch_rel: list[str] = []
    for pkg in sorted(res.packages.values(), key=lambda p: p.name):
        dst = ros_dir / pkg.name
        for w in copy_package(pkg.root, dst):
            print(f"{pkg.name}/{w}", file=sys.stderr)
        written.append(dst)
        for lf in launch:
            try:
                inside = lf.resolve().relative_to(pkg.root.resolve())
            except ValueError:
                continue
            launch_rel.append(f"ros/{pkg.name}/{inside.as_posix()}")
    files: dict[str, str] = {"dodo.py": scaffold_env().get_template("dodo.py.j2").render(name=name)}
    for n in nodes:
        files[n.file] = _ENV.get_template("skeleton.rcl.j2").render(node=n)
    files[TYPES_FILE] = _ENV.get_template("skeleton-types.rcl.j2").render(context=context)
    files["contracts/plan.yaml"] = _ENV.get_template("skeleton-plan.yaml.j2").render(
        name=name, nodes=nodes, types=TYPES_FILE, launch=launch_rel, external=external, fields=sorted(fields.items()))
    from rclverify.tools.scaffold.nodl import from_ros_documents  # deferred: start-up (loads yaml and more only when called)
    files.update(from_ros_documents([(n.name, n.package, n.executable) for n in nodes],
                                    {p.name: p.root for p in res.packages.values()}))
    for rel, text in files.items():
        atomic_write_text(root / rel, text)
        written.append(root / rel)
    for d in EMPTY_DIRS:
        (root / d).mkdir(parents=True, exist_ok=True)
    return written
