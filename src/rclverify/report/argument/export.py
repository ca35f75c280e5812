"""Write the assurance argument: JSON, gsn2x YAML, Graphviz DOT and SVG.

* JSON (:func:`to_json_text`): :meth:`Argument.to_json`, sorted keys.
* YAML (:func:`to_gsn_yaml`): the input format of gsn2x (jonasthewolf/gsn2x,
  "Syntax in YAML"): one top-level key per element whose prefix gives its
  type (``G``, ``S``, ``Sn``, ``C``, ``A``, ``J``), with ``text``, and
  optionally ``supportedBy``, ``inContextOf`` (lists of ids),
  ``undeveloped: true`` and ``url``; the dialectic extension's
  ``challenges`` and ``defeated`` and the confidence extension's ``acp``
  (assurance claim points, :mod:`.claim_points`).  The status is appended to the text of
  goals, strategies and solutions (gsn2x has no status attribute).
* DOT (:func:`to_dot`): GSN shapes (goal box, strategy parallelogram,
  solution ellipse, context rounded box, assumption and justification ovals
  marked A/J, undeveloped goals marked with a diamond), supportedBy as solid
  arrows, inContextOf as dashed arrows with hollow heads, coloured by status
  like the system diagram; laid out left to right so the many solutions
  stack vertically.
* SVG with Graphviz ``dot`` (:func:`rclverify.report.diagram.render_dot`);
  without it the DOT source stands in, as for the system diagram.  An
  argument of more than :data:`MAX_LAYOUT_ELEMENTS` elements is not laid
  out (:func:`layout`), and its tooltips are clipped to
  :data:`MAX_TOOLTIP_CHARS` so that ``dot`` accepts the file.

Everything is deterministic: the element order is the builder's, nothing
depends on the time.
"""
from __future__ import annotations

import json
import textwrap
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

import jinja2

from rclverify.records.report_record import AssuranceReport
from rclverify.records.published import write_published
from rclverify.records.store import dumps
from rclverify.core.cache.memo import last_call
from rclverify.report import diagram
from rclverify.core.cache import fingerprint
from rclverify.report.fragments import FragmentCache
from rclverify.report.textfmt import plain
from rclverify.report.view import ReportIn, decoded_parts
from rclverify.report.argument.build import build_argument
from rclverify.report.argument.model import Argument, Element

#: File names written by :func:`write_argument` (in this order).
FILES = ("argument.json", "argument.gsn.yaml", "argument.dot", "argument.svg")

_SHAPES = {"goal": ("box", ""), "strategy": ("parallelogram", ""), "solution": ("ellipse", ""),
           "context": ("box", "rounded,filled"), "assumption": ("oval", ""), "justification": ("oval", ""),
           "counter_solution": ("ellipse", "dashed,filled")}


def _yq(value: Any) -> str:
    """A YAML double-quoted scalar (JSON string syntax, which YAML reads)."""
    return json.dumps(str(value), ensure_ascii=False)


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    env = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.report.argument", "templates"), autoescape=False,
                             undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                             keep_trailing_newline=True)
    env.filters["yq"] = _yq
    return env


def _with_status(e: Element) -> str:
    return f"{e.text} [{e.status}]" if e.status is not None else e.text


def to_json_text(arg: Argument, fragments: FragmentCache | None = None, link_prefix: str = "../") -> str:
    """The argument as deterministic JSON text: :func:`rclverify.records.store.dumps`
    of :meth:`Argument.to_json` (sorted keys, two-space indent, final
    newline).  ``fragments`` keeps each element's text between runs, keyed
    like its DOT and YAML pieces (:func:`_pieces`; ``link_prefix`` is part
    of that key only): the same text."""
    if fragments is None or not arg.elements:
        return dumps(arg.to_json())
    # each element as the standard encoder indents it two levels down: {"elements": [ <here> ], "top": ...}
    elements = _pieces(arg, fragments, None, link_prefix,
                       lambda e: json.dumps(e.to_json(), sort_keys=True, indent=2, ensure_ascii=False).replace(
                           "\n", "\n    "))
    return ('{\n  "elements": [\n    ' + ",\n    ".join(elements) + '\n  ],\n  "top": '
            + json.dumps(arg.top, ensure_ascii=False) + "\n}\n")


#: Ends each element's text in a batch render (JSON-quoted YAML and DOT strings escape control characters).
_SEP = "\x00"


@last_call
def _element_keys(arg: Argument, link_prefix: str) -> list[bytes]:
    """The fingerprint of each element of ``arg`` with ``link_prefix``: the
    key of its pieces of every kind."""
    return [fingerprint({"e": e.to_json(), "link_prefix": link_prefix}) for e in arg.elements.values()]


def _pieces(arg: Argument, fragments: FragmentCache | None, template: str | None, link_prefix: str,
            data: Callable[[Element], Any]) -> list[str]:
    """The text of every element in order by ``template`` (which renders
    ``items``, each followed by ``sep``), from ``fragments`` when the element
    (its JSON form) and ``link_prefix`` were rendered before.  The elements
    not kept are rendered in one call (a template call per element cost more
    than the rendering); the fingerprint of each element is computed once
    per argument for the four kinds of piece (DOT node, DOT edges, YAML,
    JSON).  With no ``template``, ``data`` gives an element's text itself
    (the JSON kind)."""
    cache = fragments if fragments is not None else FragmentCache()
    keys = _element_keys(arg, link_prefix)
    kind = template or "argument.json-element"
    texts = [cache.lookup(kind, k) for k in keys]
    missing = [i for i, t in enumerate(texts) if t is None]
    if not missing:
        return [t for t in texts if t is not None]
    elements = list(arg.elements.values())
    if template is None:
        made = [data(elements[i]) for i in missing]
    else:
        rendered = _environment().get_template(template).render(items=[data(elements[i]) for i in missing], sep=_SEP)
        made = rendered.split(_SEP)
        if len(made) != len(missing) + 1 or made[-1]:
            raise ValueError(f"{template}: an element's text contains the separator")  # not from escaped text
    for i, text in zip(missing, made):
        cache.store(kind, keys[i], text)
        texts[i] = text
    return [t for t in texts if t is not None]


def to_gsn_yaml(arg: Argument, title: str = "assurance argument", link_prefix: str = "../",
                fragments: FragmentCache | None = None) -> str:
    """The argument in gsn2x's YAML input format (see the module docstring).

    ``link_prefix`` (the path from the YAML file's directory to the
    workspace root) is prepended to each element's ``url``; ``fragments``
    keeps each element's text between runs (same text)."""
    def element(e: Element) -> dict[str, object]:
        return {"id": e.id, "text": _with_status(e), "supported_by": e.supported_by,
                "in_context_of": e.in_context_of, "undeveloped": e.undeveloped,
                "challenges": e.challenges, "defeated": e.defeated, "acp": e.acp,
                "url": link_prefix + e.url if e.url else ""}
    elements = _pieces(arg, fragments, "argument.gsn-elements.yaml.j2", link_prefix, element)
    return _environment().get_template("argument.gsn.yaml.j2").render(title=title.replace("\n", " "), elements=elements)


#: The largest argument (in elements) laid out with Graphviz.  ``dot``'s time grows faster than
#: the size: 1,218 elements (a 100-node system) take 0.6 s, 11,968 (1000 nodes) nearly two minutes,
#: and a diagram of thousands of boxes is not legible anyway (docs/scale.md).
MAX_LAYOUT_ELEMENTS = 2500
#: Longest tooltip kept in the DOT text: Graphviz rejects a quoted string over 16,384 characters
#: (the plan's context element lists every contract file).
MAX_TOOLTIP_CHARS = 1000


def layout(arg: Argument, dot: str | None) -> diagram.Rendering:
    """The SVG of the argument's DOT text ``dot`` (:func:`rclverify.report.diagram.render_dot`),
    or, for an argument of more than :data:`MAX_LAYOUT_ELEMENTS` elements, no SVG and a
    note saying how to lay it out (``dot`` may then be ``None``: it is not read).  Raises
    ``ValueError`` for a ``None`` ``dot`` of an argument that is laid out (a caller's
    mistake); never for Graphviz trouble."""
    n = len(arg.elements)
    if n > MAX_LAYOUT_ELEMENTS:
        return diagram.Rendering(None, f"the argument has {n} elements, more than the {MAX_LAYOUT_ELEMENTS} the report "
                                       "lays out (Graphviz needs minutes for it, and a diagram of that size is not "
                                       "legible); its structure is in the tables above and in argument.json; "
                                       "to draw it anyway, run: dot -Tsvg reports/argument.dot")
    if dot is None:
        raise ValueError("layout: the DOT text of an argument that is laid out is needed")
    return diagram.render_dot(dot)


def _clip(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _label(e: Element) -> str:
    head = e.id if e.type != "solution" else e.ref or e.id
    width = 28 if e.type == "solution" else 44
    text = plain(e.text)  # an SVG shows no Markdown: code spans as their text
    body = text if len(text) <= 180 else text[:177] + "..."
    lines = [head] + (textwrap.wrap(body, width) if e.type != "solution" else [])
    if e.type in ("assumption", "justification"):
        lines.append("A" if e.type == "assumption" else "J")
    if e.status is not None:
        lines.append(e.status)
    if e.undeveloped:
        lines.append("\u25c7 undeveloped")
    return diagram.dot_string(*lines)


def to_dot(arg: Argument, title: str = "assurance argument", link_prefix: str = "../",
           fragments: FragmentCache | None = None) -> str:
    """Graphviz DOT text of the argument; ``link_prefix`` is prepended to the
    workspace-relative ``url`` of an element (its record) to make a link.
    ``fragments`` keeps each element's node and edge lines between runs
    (same text)."""
    def node(e: Element) -> dict[str, object]:
        shape, style = _SHAPES[e.type]
        fill, border = diagram.NODE_COLOURS.get(e.status or "", diagram.OTHER_COLOURS)
        return {"id": diagram.dot_string(e.id), "label": _label(e), "tooltip": diagram.dot_string(_clip(plain(e.text), MAX_TOOLTIP_CHARS)),
                "shape": shape, "style": style, "fill": fill, "border": border,
                "url": diagram.dot_string(link_prefix + e.url) if e.url else ""}

    def edges(e: Element) -> list[dict[str, object]]:
        out = [{"src": diagram.dot_string(e.id), "dst": diagram.dot_string(x), "context": False} for x in e.supported_by]
        out += [{"src": diagram.dot_string(e.id), "dst": diagram.dot_string(x), "context": True} for x in e.in_context_of]
        out += [{"src": diagram.dot_string(e.id), "dst": diagram.dot_string(x), "context": False, "challenges": True}
                for x in e.challenges]
        return out
    return _environment().get_template("argument.dot.j2").render(
        title=title.replace("\n", " "), nodes=_pieces(arg, fragments, "argument.dot-nodes.j2", link_prefix, node),
        edges=_pieces(arg, fragments, "argument.dot-edges.j2", link_prefix, edges))


@last_call
def _typed(report: ReportIn) -> AssuranceReport:
    """``report`` decoded once when it is a JSON object (:func:`rclverify.report.view.decoded_parts`)."""
    return decoded_parts(report)


@last_call
def _built(report: ReportIn) -> Argument:
    """The argument of ``report``.  One report run shows the argument several
    times (HTML, Markdown, ``reports/argument.*``) from the same report,
    which no renderer changes; it is built once for that report."""
    return build_argument(_typed(report))


def _title(report: ReportIn) -> str:
    """The argument's title: ``assurance argument of <workspace>``."""
    return f"assurance argument of {_typed(report).meta.workspace}"


def too_large(arg: Argument) -> bool:
    """More than :data:`MAX_LAYOUT_ELEMENTS` elements: the argument is not laid out."""
    return len(arg.elements) > MAX_LAYOUT_ELEMENTS


def argument_dot(report: ReportIn, fragments: FragmentCache | None = None) -> str:
    """The DOT text of ``report``'s argument, made once per report dict
    (``fragments`` as for :func:`to_dot`)."""
    return _dot_text(report, fragments=fragments)


@last_call
def _dot_text(report: ReportIn, *, fragments: FragmentCache | None) -> str:
    return to_dot(_built(report), _title(report), fragments=fragments)


def argument_layout(report: ReportIn, fragments: FragmentCache | None = None) -> Callable[[], diagram.Rendering]:
    """What lays the argument of ``report`` out: a call that returns
    :func:`layout`'s rendering.  The DOT text is made now, by the caller
    (the fragment cache is not shared between threads), and only when the
    argument is laid out at all; the call itself only waits for Graphviz,
    so it can run in a thread (``fragments`` as for :func:`to_dot`)."""
    arg = _built(report)
    dot = None if too_large(arg) else argument_dot(report, fragments)
    return lambda: layout(arg, dot)


def argument_view(report: ReportIn, rendering: diagram.Rendering | None = None,
                  fragments: FragmentCache | None = None) -> dict[str, Any]:
    """What the report templates show of the argument: ``dot`` (``None``
    when the argument is too large to lay out: no report shows it then),
    ``svg`` (``None`` without Graphviz), ``note`` (why
    there is no SVG), ``too_large`` (more than :data:`MAX_LAYOUT_ELEMENTS`
    elements: not laid out, and the report links to the DOT file instead
    of inlining it) and ``goals`` (the requirement and contract goals with
    their statuses, for the tables).  ``rendering`` replaces running ``dot``;
    ``fragments`` as for :func:`to_dot`."""
    arg = _built(report)
    large = too_large(arg)
    dot = None if large else argument_dot(report, fragments)
    drawn = layout(arg, dot) if rendering is None or large else rendering
    top = arg.elements[arg.top]
    goals = [top] + [arg.elements[g] for s in top.supported_by for g in arg.elements[s].supported_by]
    return {"dot": dot, "svg": drawn.svg, "note": drawn.note, "too_large": large,
            "goals": [{"id": g.id, "text": g.text, "status": g.status, "undeveloped": g.undeveloped} for g in goals]}


def write_argument(report: ReportIn, out_dir: Path, fragments: FragmentCache | None = None,
                   files: tuple[str, ...] = FILES, rendering: diagram.Rendering | None = None,
                   within: Path | None = None) -> list[Path]:
    """Write the :data:`FILES` named in ``files`` for ``report`` into ``out_dir`` (``reports/``).

    Everything is rendered before anything is written; each file is written
    atomically and only when changed.  When the argument is not laid out
    (no Graphviz, or too large), ``argument.svg`` is removed (so no stale
    diagram remains) and not returned.  ``fragments`` keeps rendered pieces
    between runs (:mod:`rclverify.report.fragments`; the files are the same
    without it); ``rendering`` is the argument's layout when already made
    (:func:`argument_layout`); ``within`` (the workspace) bounds where the
    files may lead (:func:`rclverify.records.published.write_published`).
    Returns the paths written, in :data:`FILES` order.  Raises
    :class:`msgspec.ValidationError` for a malformed report and ``OSError`` when ``out_dir`` cannot be
    written (:class:`~rclverify.core.within.Refused` for a special file or
    a link out of ``within`` at a file's place).
    """
    arg = _built(report)
    title = _title(report)
    texts: dict[str, str] = {}
    if FILES[0] in files:
        texts[FILES[0]] = to_json_text(arg, fragments)
    if FILES[1] in files:
        texts[FILES[1]] = to_gsn_yaml(arg, title, fragments=fragments)
    if FILES[2] in files:
        texts[FILES[2]] = argument_dot(report, fragments)
    svg = None
    if FILES[3] in files:
        svg = (rendering if rendering is not None else argument_layout(report, fragments)()).svg
    paths = []
    for name, text in texts.items():
        write_published(out_dir / name, text, within)
        paths.append(out_dir / name)
    if FILES[3] not in files:
        return paths
    svg_path = out_dir / FILES[3]
    if svg is None:
        svg_path.unlink(missing_ok=True)
    else:
        write_published(svg_path, svg, within)
        paths.append(svg_path)
    return paths
