"""Graphviz diagram of the system model for the assurance report.

The system model (paper section "System Model", lines 437-461) is a directed
graph: each node of the contract set is a box, each connection from an output
variable to an input variable is an edge labelled with the variable, and every
input nobody produces is fed by an environment source.  Connections on a loop
(handled by rule R4, paper lines 714-768) are drawn bold.

:func:`system_dot` renders the graph as DOT text from the ``system`` part of
the report dict (template ``templates/system.dot.j2``); :func:`dot_to_svg`
lays it out with the Graphviz ``dot`` program when it is installed.
"""
from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Iterable, Mapping, Sequence

import jinja2

from rclverify.records.summary_rows import SystemView
from rclverify.report import layoutcache

#: Fill and border colour of a node box, by (normalised) status.
_NODE_COLOURS: Mapping[str, tuple[str, str]] = {
    "discharged": ("#dafbe1", "#1a7f37"),
    "pending": ("#eaeef2", "#6e7781"),
    "unverified": ("#fff1e5", "#bc4c00"),
    "inconclusive": ("#fff8c5", "#9a6700"),
    "stale": ("#fbefff", "#8250df"),
    "error": ("#ffebe9", "#82071e"),
    "failed": ("#ffebe9", "#cf222e"),
}
_OTHER_COLOURS = ("#ffffff", "#24292f")
#: Public name of the status colours, shared with the argument diagram.
NODE_COLOURS = _NODE_COLOURS
OTHER_COLOURS = _OTHER_COLOURS

#: Seconds the ``dot`` program may run before the diagram is given up.
DOT_TIMEOUT_S = 30.0

#: The largest system diagram (nodes, connections and environment inputs) the report lays out.
#: ``dot``'s time grows faster than the size: on a system shaped like bench/system_scale.py's (a
#: chain with joins and loops), 0.3 s at 500 nodes, 1.7 s at 1,000, 10 s at 2,000, 39 s at 3,000
#:; a drawing of thousands of boxes is not legible, and past
#: :data:`DOT_TIMEOUT_S` whether a diagram appeared would depend on the machine's speed.
MAX_SYSTEM_LAYOUT_ELEMENTS = 2500

INSTALL_HINT = "install graphviz for the diagram (the `dot` program was not found)"


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("rclverify.report", "templates"),
        autoescape=False,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )


def _escape(text: str) -> str:
    """Escape ``text`` for the inside of a DOT double-quoted string."""
    return (
        text.replace("\\", "\\\\")
        .replace('"', '\\"')
        .replace("\r\n", "\n")
        .replace("\n", " ")
    )


def dot_string(*lines: str) -> str:
    """A DOT double-quoted string whose label shows ``lines`` one per line.

    Backslashes and quotes are escaped, so user text (node names, variable
    names, types) cannot end the string or inject Graphviz escapes.
    """
    return '"' + "\\n".join(_escape(line) for line in lines) + '"'


def _loop_edges(loops: Sequence[Sequence[str]]) -> set[tuple[str, str]]:
    """Consecutive node pairs of every loop, closing each cycle."""
    pairs: set[tuple[str, str]] = set()
    for loop in loops:
        cycle = list(loop)
        if len(cycle) > 1 and cycle[0] == cycle[-1]:
            cycle = cycle[:-1]
        for k, name in enumerate(cycle):
            pairs.add((name, cycle[(k + 1) % len(cycle)]))
    return pairs


def system_dot(system: SystemView | Mapping[str, Any], title: str = "system model", culprits: Iterable[str] = (),
               failing: Iterable[tuple[str, str]] = ()) -> str:
    """Graphviz DOT text of the system model.

    ``system`` is the report's ``system`` (:class:`~rclverify.records.summary_rows.SystemView`, or its
    JSON object, decoded here: ``ValidationError`` for one of another shape): ``nodes`` (name, status),
    ``connections`` (``[{"from_node", "from_var", "to_node", "to_var",
    "via"}]``), ``environment_inputs`` (``[{"node", "var", "type"}]``) and
    ``loops`` (``[[node, ...]]``, each a cycle in order).  ``title`` names the
    source in the header comment.

    Nodes are boxes labelled with their name and overall status and coloured
    by it; edges are labelled with the variable (``out -> in`` when the two
    names differ); environment inputs are plain-text sources ``env: <var>``
    with a dashed edge; connections on a loop (R4, paper lines 714-768) are
    bold.  A node in ``culprits`` (a problem blames its guarantee or
    contract, :mod:`.culprits`) has a thick red border and "culprit" in its
    label; a connection in ``failing`` (``(producer, consumer)`` of a side
    condition that is not discharged) is drawn red and dashed: the failing
    edge (the diagram blames the culprit, not only its victims).
    Everything is sorted, so equal inputs give byte-equal output.
    Raises ``KeyError`` when a connection or environment input lacks a key.
    """
    system = SystemView.of(system)
    blamed, bad = set(culprits), set(failing)
    loop_pairs = _loop_edges(system.loops)
    names = {n.name for n in system.nodes}
    status: dict[str, str] = {n.name: n.status for n in system.nodes}
    for c in system.connections:  # the model's links (model/system/model.py ``Link``)
        names.update((c["from_node"], c["to_node"]))
    for e in system.environment_inputs:
        names.add(e["node"])

    nodes = []
    for name in sorted(names):
        st = status.get(name)
        fill, border = _NODE_COLOURS.get(st or "", _OTHER_COLOURS)
        label = dot_string(name, *([st] if st else []), *(["\u2691 culprit"] if name in blamed else []))
        nodes.append({"id": dot_string(name), "label": label, "fill": fill, "border": border,
                      "culprit": name in blamed})

    edges = []
    conns = sorted(
        system.connections,
        key=lambda c: (c["from_node"], c["from_var"], c["to_node"], c["to_var"], str(c.get("via") or "")),
    )
    for c in conns:
        var = c["from_var"] if c["from_var"] == c["to_var"] else f"{c['from_var']} -> {c['to_var']}"
        via = str(c.get("via") or "")
        tip = f"{c['from_node']}.{c['from_var']} -> {c['to_node']}.{c['to_var']}" + (f" ({via})" if via else "")
        edges.append({
            "src": dot_string(c["from_node"]),
            "dst": dot_string(c["to_node"]),
            "label": dot_string(var),
            "tooltip": dot_string(tip),
            "loop": (c["from_node"], c["to_node"]) in loop_pairs,
            "failing": (c["from_node"], c["to_node"]) in bad,
        })

    sources = []
    for e in sorted(system.environment_inputs, key=lambda e: (e["node"], e["var"])):
        typ = str(e.get("type") or "")
        sources.append({
            "id": dot_string(f"env:{e['node']}.{e['var']}"),
            "label": dot_string(f"env: {e['var']}"),
            "tooltip": dot_string(f"{e['node']}.{e['var']}" + (f" : {typ}" if typ else "")),
            "dst": dot_string(e["node"]),
        })

    return _environment().get_template("system.dot.j2").render(
        title=title.replace("\n", " "), nodes=nodes, edges=edges, sources=sources,
    )


@dataclass(frozen=True)
class Rendering:
    """Outcome of laying out a DOT graph.

    ``svg`` is inline-ready SVG (no XML prolog) or ``None``; ``note`` says
    why there is no SVG ('' when there is one).
    """

    svg: str | None
    note: str


def system_elements(system: SystemView) -> int:
    """How many elements the diagram of the report's ``system`` draws: its
    nodes, connections and environment inputs."""
    return len(system.nodes) + len(system.connections) + len(system.environment_inputs)


def system_too_large(system: SystemView) -> bool:
    """More than :data:`MAX_SYSTEM_LAYOUT_ELEMENTS` elements: the report does not lay the system out."""
    return system_elements(system) > MAX_SYSTEM_LAYOUT_ELEMENTS


def system_layout(system: SystemView, dot: str) -> Rendering:
    """The SVG of the system diagram's DOT text ``dot`` (:func:`render_dot`)
    for the report's ``system``, or, for a system of more than
    :data:`MAX_SYSTEM_LAYOUT_ELEMENTS` elements, no SVG and a note saying
    why and how to draw it anyway (``dot`` is then not run).  Never raises
    for Graphviz trouble."""
    if not system_too_large(system):
        return render_dot(dot)
    return Rendering(None, f"the system has {len(system.nodes)} nodes, {len(system.connections)} connections "
                           f"and {len(system.environment_inputs)} environment inputs, more than the "
                           f"{MAX_SYSTEM_LAYOUT_ELEMENTS} elements the report lays out (Graphviz needs minutes for "
                           "a few thousand, and a diagram of that size is not legible); its nodes, connections "
                           "and loops are in the tables below, its Graphviz source in assurance.md; to draw it "
                           "anyway, run `doit graph` (artifacts/system/model.dot) and "
                           "dot -Tsvg artifacts/system/model.dot")


def render_dot(dot: str, timeout_s: float = DOT_TIMEOUT_S) -> Rendering:
    """Run ``dot -Tsvg`` on ``dot`` (no shell) and explain any failure.

    ``timeout_s`` is in seconds.  Never raises for a missing, failing or
    hanging ``dot``: the reason is in :attr:`Rendering.note`.  A layout
    already made for the same text by the same ``dot`` is reused
    (:mod:`.layoutcache`; the SVG is the same byte for byte).
    """
    exe = shutil.which("dot")
    if exe is None:
        return Rendering(None, INSTALL_HINT)
    failures: list[Rendering] = []

    def compute() -> str | None:
        drawn = _run_dot(exe, dot, timeout_s)
        if drawn.svg is None:
            failures.append(drawn)
        return drawn.svg

    svg = layoutcache.lookup(dot, exe, compute)
    return Rendering(svg, "") if svg is not None else failures[0]


def _run_dot(exe: str, dot: str, timeout_s: float) -> Rendering:
    """Run the ``dot`` program at ``exe`` on ``dot`` (see :func:`render_dot`)."""
    try:
        proc = subprocess.run(
            [exe, "-Tsvg"], input=dot.encode("utf-8"), capture_output=True,
            timeout=timeout_s, check=False,
        )
    except subprocess.TimeoutExpired:
        return Rendering(None, f"graphviz `dot` did not finish within {timeout_s:g} s")
    except OSError as exc:
        return Rendering(None, f"graphviz `dot` could not be run: {exc.strerror or exc}")
    out = proc.stdout.decode("utf-8", "replace")
    start = out.find("<svg")
    if proc.returncode != 0 or start < 0:
        err = proc.stderr.decode("utf-8", "replace").strip().splitlines()
        why = err[0] if err else "no SVG produced"
        return Rendering(None, f"graphviz `dot` failed (exit code {proc.returncode}): {why}")
    return Rendering(out[start:].rstrip() + "\n", "")


def dot_to_svg(dot: str, timeout_s: float = DOT_TIMEOUT_S) -> str | None:
    """SVG text of the DOT graph ``dot``, ready to inline in HTML.

    Runs the Graphviz ``dot`` program (``dot -Tsvg``, no shell, at most
    ``timeout_s`` seconds) and strips the XML prolog, doctype and comments
    that precede the ``<svg`` element.  Returns ``None`` when ``dot`` is not
    installed, fails, or times out (see :func:`render_dot` for the reason).
    """
    return render_dot(dot, timeout_s).svg
