"""Report hygiene (issue 64): no raw Markdown in the HTML report or in an SVG
drawing, every list of assurance.md well-formed, and a command whose reader
leaves (``rclverify explain ID | head``) ends quietly."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from rclverify.report.argument.export import to_dot
from rclverify.report.argument.model import Argument, Element
from rclverify.cli.commands import BROKEN_PIPE_EXIT, main
from rclverify.report.textfmt import code_spans, plain, prose

from _grip_ws import make


class _RawMarkup(HTMLParser):
    """Backticks shown as text: in text outside code, preformatted text and
    scripts, and in attribute values (tooltips)."""

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.raw: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag not in ("br", "img", "meta", "link", "input", "hr", "col", "wbr"):
            self.stack.append(tag)
        self.raw += [f"{tag}@{k}: {v}" for k, v in attrs if v and "`" in v]

    def handle_startendtag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.raw += [f"{tag}@{k}: {v}" for k, v in attrs if v and "`" in v]

    def handle_endtag(self, tag: str) -> None:
        if tag in self.stack:
            while self.stack and self.stack.pop() != tag:
                pass

    def handle_data(self, data: str) -> None:
        if "`" in data and not {"code", "pre", "script", "style"} & set(self.stack):
            self.raw.append(data)


def raw_markup(text: str) -> list[str]:
    p = _RawMarkup()
    p.feed(text)
    return p.raw


_ITEM = re.compile(r"^\s*(?:[-*+]|\d+[.)])\s")


def glued_items(md: str) -> list[str]:
    """List items run together: a second item on an item's line, or a
    paragraph line that Markdown would read as the item's lazy continuation."""
    lines = md.split("\n")
    out = [l for l in lines if _ITEM.match(l) and re.search(r"\S {2,}(?:[-*+]|\d+\.) \S", l.split("`")[0])]
    fence = False
    for a, b in zip(lines, lines[1:]):
        fence ^= a.startswith("```")
        if not fence and _ITEM.match(a) and b.strip() and not _ITEM.match(b) and not b.startswith((" ", "|", "<")):
            out.append(f"{a!r} then {b!r}")
    return out


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = make(tmp_path_factory.mktemp("hygiene") / "ws")
    assert main(["verify", "-w", str(root)]) == 0
    return root


def test_html_and_svg_show_no_raw_markup(ws: Path) -> None:
    html = (ws / "reports" / "assurance.html").read_text(encoding="utf-8")
    assert "<code>" in html  # the problems' sentences carry code spans: rendered, not dropped
    assert raw_markup(html) == []
    assert raw_markup((ws / "reports" / "argument.svg").read_text(encoding="utf-8")) == []


def test_markdown_lists_are_well_formed(ws: Path) -> None:
    md = (ws / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert "\n  - assuming `GripperDriver.in.force <= 10`" in md  # the nested item on a line of its own
    assert glued_items(md) == []


def test_the_checkers_see_what_they_look_for() -> None:
    assert raw_markup('<p>a `x` b</p><svg><a title="t `y`"><text>z</text></a></svg>') == \
        ["a `x` b", "a@title: t `y`"]
    assert raw_markup("<p><code>`kept`</code></p>") == []
    assert glued_items("- **REQ1** proved.  - used: `x`\n") != []
    assert glued_items("- item\nLog excerpt:\n") != []
    assert glued_items("- item\n  - nested\n\nText\n") == []


def test_code_spans_plain_and_prose() -> None:
    assert code_spans("maps `a < b` to `T`") == [(False, "maps "), (True, "a < b"), (False, " to "), (True, "T")]
    assert str(prose("maps `a < b`")) == "maps <code>a &lt; b</code>"
    assert plain("maps `a < b` to `T`") == "maps a < b to T"
    assert plain("cut short: `forall(x") == "cut short: forall(x"  # a span a length limit cut
    assert str(prose("a `` b`c `` d")) == "a <code>b`c</code> d"


def test_argument_drawing_strips_code_spans() -> None:
    text = "PARTIAL COVERAGE: mapping row 8 maps `forall(x in REAL | in.p(x) != i)` to the constant F " * 4
    els = {"G1": Element("G1", "goal", "top", supported_by=("Sn1",)),
           "Sn1": Element("Sn1", "solution", text, status="inconclusive", ref="A.g1.ajpf")}
    dot = to_dot(Argument("G1", els))
    assert "`" not in dot and "mapping row 8 maps forall(x in REAL" in dot


def _closed_pipe_run(args: list[str], cwd: Path) -> subprocess.CompletedProcess[bytes]:
    r, w = os.pipe()
    os.close(r)  # the reader left before the first line
    try:
        return subprocess.run([sys.executable, "-c", "import sys; from rclverify.cli.commands import main; "
                               "sys.exit(main(sys.argv[1:]))", *args], stdout=w, stderr=subprocess.PIPE,
                              cwd=cwd, timeout=120, check=False)
    finally:
        os.close(w)


def test_a_closed_pipe_ends_quietly(ws: Path) -> None:
    for args in (["explain", "REQ-FORCE", "-w", str(ws)], ["fmt", str(ws / "contracts" / "cell.rcl")]):
        done = _closed_pipe_run(args, ws)
        assert done.stderr == b"", done.stderr.decode()
        assert done.returncode == BROKEN_PIPE_EXIT
