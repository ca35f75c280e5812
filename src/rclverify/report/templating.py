"""The report templates' jinja2 environment and filters: status badges and ranks, fragment ids,
Markdown escaping, durations, links and clipped values.

The status words are those of records/statuses.py; a word outside them
ranks as an error (the report cannot vouch for what it does not
understand).  Markdown escaping follows CommonMark's backslash escapes of
ASCII punctuation and GitHub-flavoured tables' ``|``; HTML escaping is
markupsafe's.  Nothing here depends on the time of rendering.
"""
from __future__ import annotations

import re
from functools import lru_cache, partial
from pathlib import Path
from typing import Any, Callable, Mapping
from urllib.parse import quote

import jinja2
from markupsafe import Markup, escape

from rclverify.records.deadline_rows import DeadlineHop, DeadlineRow
from rclverify.records.derived_rows import DerivedPropertyRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.lint_rows import LintRow
from rclverify.records.margin_rows import MarginRow, NearMissRow
from rclverify.records.node_rows import GuaranteeRow, NodeRow, UnverifiedRow
from rclverify.records.problem_rows import DiagnosisRow, rows_of as problem_rows_of
from rclverify.records.row import decode_rows
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.verdict_rows import PendingRow
from rclverify.records.requirement_rows import rows_of as requirement_rows_of
from rclverify.records.statistics_rows import rows_of as statistics_rows_of
from rclverify.records.standards_rows import rows_of as standard_rows_of
from rclverify.records.findings import rows_of
from rclverify.records.obligations import ObligationRow
from rclverify.records.records import SEVERITY
from rclverify.report import htmlfilters
from rclverify.report.textfmt import breakable, formula_html, formula_lines

#: Status word -> badge style.  Evidence statuses map to themselves; contract
#: health and solver words map to the evidence status they stand for.
STATUS_STYLE: Mapping[str, str] = {
    "discharged": "discharged",
    "pending": "pending",
    "unverified": "unverified",
    "inconclusive": "inconclusive",
    "stale": "stale",
    "error": "error",
    "failed": "failed",
    "ok": "discharged",
    "problem": "failed",
    "proved": "discharged",
    "refuted": "failed",
    "unknown": "inconclusive",
    # derivation status of a derived property (report/build.py)
    "derived": "discharged",
    "not derived": "failed",
    "undecided": "inconclusive",
    "warning": "warning",  # a health warning: its own colour, never a pass (report/severity.py)
}

#: Severity of a status word for ordering the attention list (larger is
#: worse).  A word outside the vocabulary ranks as an error: the report cannot
#: vouch for what it does not understand.
_RANK: Mapping[str, int] = {**SEVERITY, "ok": 0, "proved": 0, "problem": SEVERITY["failed"],
                            "refuted": SEVERITY["failed"], "unknown": SEVERITY["inconclusive"], "derived": 0,
                            "not derived": SEVERITY["failed"], "undecided": SEVERITY["inconclusive"], "warning": 1}
_UNKNOWN_RANK = SEVERITY["error"]

#: Marker shown in Markdown next to a status (no colours there).
_MD_MARK: Mapping[str, str] = {
    "discharged": "\u2705",
    "pending": "\u23f3",
    "unverified": "\u2754",
    "inconclusive": "\u26a0\ufe0f",
    "stale": "\U0001f7e3",
    "error": "\u26d4",
    "failed": "\u274c",
}

#: Order in which status counts are listed: worst first, then any other key.
COUNT_ORDER = sorted(SEVERITY, key=lambda s: -SEVERITY[s])


def rank(status: str) -> int:
    """Severity of ``status`` (0 = fine ... ``SEVERITY["failed"]`` = failed/problem)."""
    return _RANK.get(status, _UNKNOWN_RANK)


def style(status: str) -> str:
    """CSS class suffix for ``status`` (``other`` for an unknown word)."""
    return STATUS_STYLE.get(status, "other")



_ANCHOR_BAD = re.compile(r"[^A-Za-z0-9_.\-]")


def anchor(*parts: Any) -> str:
    """A fragment id built from ``parts`` joined by ``-``.

    Characters other than letters, digits, ``_ . -`` are hex-encoded as
    ``_xx``, so any user text gives a valid, quote-free HTML id.
    """
    text = "-".join(str(p) for p in parts)
    return _ANCHOR_BAD.sub(lambda m: "".join(f"_{b:02x}" for b in m.group(0).encode("utf-8")), text)


def html_badge(status: Any) -> Markup:
    """``<span class="badge st-...">status</span>`` (status text escaped)."""
    s = str(status)
    return Markup('<span class="badge st-%s">%s</span>') % (style(s), escape(s))


_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>|&#])")
_WS = re.compile(r"\s*[\r\n]+\s*")


def md_text(value: Any) -> str:
    """Escape ``value`` for inline Markdown (also inside a table cell).

    Markdown punctuation, ``<``, ``>``, ``&`` and ``|`` are backslash-escaped,
    so no HTML or table structure can come from user text; line breaks
    become spaces.
    """
    return _MD_SPECIAL.sub(r"\\\1", _WS.sub(" ", str(value)).strip())


def md_code(value: Any, cell: bool = True) -> str:
    """``value`` as an inline code span.

    The fence is longer than any backtick run inside; with ``cell`` (the
    default) ``|`` is escaped so the span can sit in a table cell.  An empty
    value gives ``''``.
    """
    text = _WS.sub(" ", str(value)).strip()
    if not text:
        return ""
    runs = [len(m) for m in re.findall(r"`+", text)]
    fence = "`" * (max(runs, default=0) + 1)
    if text.startswith("`") or text.endswith("`"):
        text = f" {text} "
    if cell:
        text = text.replace("|", "\\|")
    return f"{fence}{text}{fence}"


@lru_cache(maxsize=1 << 16)
def _md_code_cell(text: str) -> str:
    return md_code(text)


@lru_cache(maxsize=1 << 16)
def _formula_html_of(text: str) -> Markup:
    return formula_html(text)


def md_code_list(values: Any, sep: str = "<br>", empty: str = "none") -> str:
    """The items of ``values`` each as a table-cell code span (:func:`md_code`),
    joined by ``sep``; ``empty`` when there is none: the text of the loop
    ``{% for h in values %}{{ h|code }}{% if not loop.last %}<br>{% endif
    %}{% else %}none{% endfor %}``.  A side condition in context lists every
    premise of its upstream cone, so along a chain the lists add up to N*N/2
    items, most of them the same texts (docs/scale.md): each
    text's span is made once per process (a pure function of the text)."""
    items = [str(v) for v in values]
    return sep.join(_md_code_cell(t) for t in items) if items else empty


def formula_html_list(values: Any, sep: str = "<br>", empty: str = "none") -> Markup:
    """The items of ``values`` each as :func:`formula_html` (HTML-escaped),
    joined by ``sep`` (markup); ``empty`` (escaped) when there is none: the
    text of ``{% for h in values %}{{ h|formula }}{% if not loop.last
    %}<br>{% endif %}{% else %}none{% endfor %}`` in an autoescaped
    template, each text's HTML made once per process (:func:`md_code_list`)."""
    items = [str(v) for v in values]
    return Markup(sep).join(_formula_html_of(t) for t in items) if items else Markup(escape(empty))


def md_fence(value: Any, lang: str = "") -> str:
    """``value`` as a fenced code block (fence longer than any backtick run)."""
    text = str(value).rstrip("\n")
    runs = [len(m) for m in re.findall(r"`{3,}", text)]
    fence = "`" * max(3, max(runs, default=0) + 1)
    return f"{fence}{lang}\n{text}\n{fence}"


def md_badge(status: Any) -> str:
    """A status for Markdown: a marker and the word, bold unless fine."""
    s = str(status)
    mark = _MD_MARK.get(style(s), "\u2753")
    word = md_text(s)
    return f"{mark} {word}" if rank(s) == 0 else f"{mark} **{word}**"


def seconds(value: Any) -> str:
    """A duration in seconds as ``'1.23 s'`` (``'-'`` when absent)."""
    if value is None or value == "":
        return "-"
    return f"{float(value):.2f} s"


def comment_safe(value: Any) -> str:
    """Text safe inside an HTML comment (no ``--``, one line)."""
    text = _WS.sub(" ", str(value))
    while "--" in text:
        text = text.replace("--", "- -")
    return text


def link_maker(prefix: str) -> Callable[[str], str]:
    """Return a function mapping a workspace-relative path to an href.

    ``prefix`` is the path from the report's directory to the workspace root
    (``'../'`` for the standard ``reports/`` folder).  The path is
    percent-encoded, so ``:`` cannot start a URL scheme.
    """
    def href(path: str) -> str:
        return prefix + quote(str(path), safe="/._-~")
    return href


#: Longest model value shown in the reports (characters); the JSON report and
#: the artifacts keep every value whole.
CLIP_CHARS = 2000


def clip(value: Any, limit: int = CLIP_CHARS) -> str:
    """``str(value)``, cut to ``limit`` characters with a note of how much
    was left out: a function-table model of a nested quantifier can run to
    hundreds of thousands of characters, which no reader scrolls through."""
    text = str(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit]} ... ({len(text) - limit} more characters in the JSON report)"


def model_text(model: Mapping[str, Any] | None) -> str:
    """``name = value, ...`` of a model or counterexample, sorted by name,
    each value clipped (:func:`clip`); ``""`` for none.  For the one-line
    messages of SARIF and JUnit."""
    return ", ".join(f"{k} = {clip(v)}" for k, v in sorted((model or {}).items()))


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    """The report's jinja2 environment.

    ``*.html.j2`` templates are autoescaped, ``*.md.j2``/``*.dot.j2`` are
    not; undefined names raise (``StrictUndefined``).
    """
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("rclverify.report", "templates"),
        autoescape=jinja2.select_autoescape(
            enabled_extensions=("html.j2", "html"),
            disabled_extensions=("md.j2", "dot.j2"),
            default_for_string=True,
            default=True,
        ),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters.update(
        anchor=anchor, badge=html_badge, md=md_text, code=md_code, fence=md_fence,
        mdbadge=md_badge, secs=seconds, comment_safe=comment_safe, style=style, clip=clip,
        formula=formula_html, lines=formula_lines, wbr=breakable, codes=md_code_list,
        formulas=formula_html_list,
        # the rows defined once, decoded so that a template reads declared fields only (an undeclared
        # attribute raises under StrictUndefined, an undeclared key msgspec.ValidationError; every field is
        # held to a renderer or its record's INTERNAL by tests/records/test_record_shapes.py)
        findings=rows_of, obligation_row=ObligationRow.of, evidence_row=EvidenceRow.of,
        requirement_rows=requirement_rows_of, statistics_rows=statistics_rows_of, standard_rows=standard_rows_of,
        node_rows=partial(decode_rows, NodeRow), guarantee_rows=partial(decode_rows, GuaranteeRow),
        side_condition_rows=partial(decode_rows, SideConditionRow), derived_rows=partial(decode_rows, DerivedPropertyRow),
        deadline_rows=partial(decode_rows, DeadlineRow), hop_rows=partial(decode_rows, DeadlineHop),
        lint_rows=partial(decode_rows, LintRow), unverified_rows=partial(decode_rows, UnverifiedRow),
        pending_rows=partial(decode_rows, PendingRow), near_miss_rows=partial(decode_rows, NearMissRow),
        margin_rows=partial(decode_rows, MarginRow), problem_rows=problem_rows_of,
        diagnosis_rows=partial(decode_rows, DiagnosisRow),
    )
    env.globals.update(anchor=anchor, rank=rank)
    htmlfilters.register(env)  # prose, natsort, readable_svg, reqbadges, latex_frame
    return env


def use_bytecode_cache(directory: Path | None) -> None:
    """Keep the report's compiled templates in ``directory`` (jinja2's
    ``FileSystemBytecodeCache``, keyed by template name and source checksum;
    ``None``: compile in memory only).  Compiling the report's templates is
    about 0.3 s of every report run.  The files are code: the report run
    keeps them in the user's cache, never in a workspace
    (:func:`rclverify.core.cache.keys.user_cache_dir`).  Raises ``OSError`` when
    ``directory`` cannot be created."""
    if directory is None:
        environment().bytecode_cache = None
        return
    Path(directory).mkdir(parents=True, exist_ok=True)
    environment().bytecode_cache = jinja2.FileSystemBytecodeCache(str(directory))
