"""The HTML report's text helpers (issue 30, item 6): Markdown code spans as
``<code>``, natural order of ids, a large drawing at a readable size, a
requirement's proof and evidence as two badges."""
from __future__ import annotations

import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.records.requirement_rows import RequirementRow
from rclverify.report.render import environment
from rclverify.report.svgfit import readable_svg, smallest_font
from rclverify.report.textfmt import natural_key, natural_sorted, natural_within, prose


def test_code_spans_become_code_and_everything_is_escaped() -> None:
    assert prose("guard it with `i + 1 <= 12`: done") == "guard it with <code>i + 1 &lt;= 12</code>: done"
    assert prose("a `x` and ``y ` z`` b") == "a <code>x</code> and <code>y ` z</code> b"
    assert prose("`` `tick` ``") == "<code>`tick`</code>"  # one space stripped at each end
    assert prose("<b>no</b> `<i>`") == "&lt;b&gt;no&lt;/b&gt; <code>&lt;i&gt;</code>"
    assert prose("an odd ` tick stays") == "an odd ` tick stays"
    assert prose("no ticks & more") == "no ticks &amp; more"


def test_natural_order_compares_digit_runs_as_numbers() -> None:
    ids = ["A.g1.ajpf.p10_i9", "A.g1.ajpf.p1_i0", "A.g1.ajpf.p2_i1", "A.g10.x", "A.g2.x", "A.g1.ajpf.p01_i0"]
    assert natural_sorted(ids) == ["A.g1.ajpf.p01_i0", "A.g1.ajpf.p1_i0", "A.g1.ajpf.p2_i1", "A.g1.ajpf.p10_i9",
                                   "A.g2.x", "A.g10.x"]
    assert natural_key("p9") < natural_key("p10") < natural_key("q1") and natural_key("") < natural_key("1")
    rows = [("Loc", "Loc.g1"), ("Agent", "Agent.g10"), ("Agent", "Agent.g2"), ("Loc", "Loc.g0")]
    # groups keep the order of their first row; ids are natural within a group
    assert natural_within(rows, lambda r: r[0], lambda r: r[1]) == [
        ("Loc", "Loc.g0"), ("Loc", "Loc.g1"), ("Agent", "Agent.g2"), ("Agent", "Agent.g10")]


SVG = ('<?xml version="1.0"?>\n<svg width="2514pt" height="3771pt"\n viewBox="0.00 0.00 2514.11 3770.60" '
       'xmlns="http://www.w3.org/2000/svg">\n<g><text font-size="14.00">a</text><text font-size="9.00">b</text></g></svg>')


def test_a_drawing_gets_the_size_at_which_its_smallest_text_is_readable() -> None:
    assert smallest_font(SVG) == 9.0
    out = str(readable_svg(SVG, min_px=10))
    root = re.search(r"<svg[^>]*>", out).group(0)  # type: ignore[union-attr]
    assert 'class="fixed"' in root and 'width="2793px"' in root and 'height="4190px"' in root
    assert "pt\"" not in root and out.count("<svg") == 1 and out.endswith("</svg>")
    # 10 px text: the drawing's width over its viewBox width times the smallest font size
    assert abs(2793 / 2514.11 * 9 - 10) < 0.01
    assert str(readable_svg("<svg><g/></svg>")) == "<svg><g/></svg>"  # no text: unchanged


def _req(status: str, verdict: str, note: str = "") -> RequirementRow:
    return RequirementRow(id="R1", text="r", verdict=verdict, status=status, note=note,
                          support=[], check={})


def _badges(req: RequirementRow) -> list[tuple[str, str]]:
    html = environment().from_string("{{ req|reqbadges }}").render(req=req)
    return re.findall(r'<span class="badge st-([a-z]+)"[^>]*>([^<]*)</span>', html)


def test_a_requirement_shows_its_proof_and_its_evidence_apart() -> None:
    assert _badges(_req("failed", "proved, evidence outstanding")) == [
        ("discharged", "proved"), ("failed", "evidence: failed")]
    assert _badges(_req("discharged", "met")) == [
        ("discharged", "proved"), ("discharged", "evidence: discharged")]
    assert _badges(_req("failed", "proved vacuously", "its premise <never> holds")) == [
        ("warning", "proved vacuously")]
    assert _badges(_req("failed", "refuted")) == [("failed", "refuted")]
    assert _badges(_req("pending", "informal")) == [("pending", "informal")]
    html = environment().from_string("{{ req|reqbadges }}").render(
        req=_req("failed", "proved vacuously", "its premise <never> holds"))
    assert 'title="status: failed; its premise &lt;never&gt; holds"' in html


def test_the_badges_read_a_decoded_row_only() -> None:
    """The filter is typed on the row: a requirement's JSON object is refused in one sentence (the view
    decodes what it hands the templates); the control, the same requirement decoded, renders."""
    with pytest.raises(TypeError, match="reads a RequirementRow, not a dict"):
        environment().from_string("{{ req|reqbadges }}").render(req=_req("failed", "refuted").to_json())
    assert "refuted" in environment().from_string("{{ req|reqbadges }}").render(
        req=RequirementRow.of(_req("failed", "refuted").to_json()))


_ITEMS = st.lists(st.one_of(st.text(alphabet="ab <=>&|`*_\n(x)", max_size=160), st.integers()), max_size=5)


@settings(max_examples=150, deadline=None)
@given(_ITEMS)
def test_the_list_filters_equal_the_loops_they_replace(items) -> None:
    """``formulas`` and ``codes`` (a side condition's hypotheses, each text's markup made once per
    process: issue 67) give the text of the per-item loops they replaced, in the HTML templates'
    autoescaped environment and the Markdown ones' plain one; twice, so the cached texts are read."""
    html, md = environment(), environment().overlay(autoescape=False)
    html_loop = "{% for h in xs %}{{ h|formula }}{% if not loop.last %}<br>{% endif %}{% else %}none{% endfor %}"
    md_loop = "{% for h in xs %}{{ h|code }}{% if not loop.last %}<br>{% endif %}{% else %}none{% endfor %}"
    for _ in range(2):
        assert html.from_string("{{ xs|formulas }}").render(xs=items) == html.from_string(html_loop).render(xs=items)
        assert md.from_string("{{ xs|codes }}").render(xs=items) == md.from_string(md_loop).render(xs=items)
