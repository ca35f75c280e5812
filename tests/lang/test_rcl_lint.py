"""Lint: implication precedence, unused bound variables, unconstrained outputs."""
from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

from rclverify.lang.lint import lint
from rclverify.lang.walk import free_names
from rclverify.lang.parser import parse_file, parse_formula, parse_text

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"


def node(guarantees: list[str], assumes: list[str] = (), inputs: str = "a : REAL, b : REAL",  # type: ignore[assignment]
         outputs: str = "o : REAL") -> str:
    clauses = "".join(f"\n  assume({a})" for a in assumes) + "".join(f"\n  guarantee({g})" for g in guarantees)
    return f"node n {{\n  inputs({inputs})\n  outputs({outputs}){clauses}\n}}\n"


def codes(text: str) -> list[str]:
    return [d.code for d in lint(parse_text(text, "t.rcl"))]


# ---------------------------------------------------------------------------
# (a) W-implication-precedence
# ---------------------------------------------------------------------------

def test_conventional_forms_get_no_warning() -> None:
    # (A and B) -> C, A or B -> C, A -> B and C, A and B <=> C: every reader
    # takes and/or to bind tighter than -> and <=>; no warning.
    assert codes(node(["a > 0 and b > 0 -> o > 0", "a > 0 or b > 0 -> o > 0", "a > 0 -> o > 0 or o < b",
                       "a > 0 and b > 0 <=> o > 0"])) == []


def test_parentheses_silence_the_warning() -> None:
    assert codes(node(["(a > 0 and b > 0) -> o > 0", "a > 0 -> (o > 0 or o < b)",
                       "a > 0 -> o > 0", "a > 0 and (b > 0 -> o > 0)", "(a > 0 -> b > 0) -> o > 0"])) == []


def test_a_chain_gets_one_warning_with_the_full_parse_at_its_start() -> None:
    diags = lint(parse_text(node(["a > 0 -> b > 0 and o > 0 -> o > 1"]), "t.rcl"))
    assert [d.code for d in diags] == ["W-implication-precedence"]
    d = diags[0]
    assert d.severity == "warning"
    assert (d.loc.file, d.loc.line, d.loc.col) == ("t.rcl", 4, 13)
    assert "(a > 0 -> ((b > 0 and o > 0) -> o > 1))" in d.message
    assert d.message.startswith("guarantee 1 of n: a chain of")


def test_mixed_and_or_and_biconditional_chains_in_assumptions() -> None:
    diags = lint(parse_text(node(["o > 0"], assumes=["a > 0 -> b > 0 <=> a > b", "a > 0 and b > 0 or a > b"]),
                            "t.rcl"))
    assert [d.code for d in diags] == ["W-implication-precedence"] * 2
    assert "((a > 0 -> b > 0) <=> a > b)" in diags[0].message
    assert diags[0].message.startswith("assumption 1 of n: ")
    assert "((a > 0 and b > 0) or a > b)" in diags[1].message
    assert diags[1].message.startswith("assumption 2 of n: ")


# ---------------------------------------------------------------------------
# (b) W-unused-bound
# ---------------------------------------------------------------------------

def test_unused_bound_variable_is_located_at_its_binding() -> None:
    text = node(["forall(x, y in REAL | o >= x)"])
    diags = lint(parse_text(text, "t.rcl"))
    assert [d.code for d in diags] == ["W-unused-bound"]
    d = diags[0]
    line = text.splitlines()[d.loc.line - 1]
    assert d.loc.line == 4 and line[d.loc.col - 1:].startswith("y in REAL")
    assert "bound variable y of 'forall' is never used" in d.message


def test_use_in_a_later_domain_counts_and_shadowing_does_not() -> None:
    assert codes(node(["forall(s in in.sets, x in s | o >= x)"], inputs="sets : set(REAL)")) == []
    # The inner exists rebinds x; the outer x is never used.
    diags = lint(parse_text(node(["forall(x in REAL | exists(x in REAL | o == x))"]), "t.rcl"))
    assert [d.code for d in diags] == ["W-unused-bound"]
    assert diags[0].loc.col == 20  # the outer x
    # A bare name used as a function or a constructor argument is a use.
    assert codes(node(["forall(f in Fs, i in NATURAL | f(o) == i)"])) == []


def test_free_names_respects_shadowing() -> None:
    e = parse_formula("forall(x in REAL | x == y and exists(y in S | y == z)) or x == in.w")
    assert free_names(e) == {"y", "z", "x", "S"}  # S: a domain written as a name


# ---------------------------------------------------------------------------
# (c) W-unconstrained-output, (d) inputs are not reported
# ---------------------------------------------------------------------------

def test_unconstrained_output() -> None:
    text = node(["out.o >= in.a"], outputs="o : REAL, spare : BOOL")
    diags = lint(parse_text(text, "t.rcl"))
    assert [d.code for d in diags] == ["W-unconstrained-output"]
    d = diags[0]
    assert (d.loc.line, d.loc.col) == (3, 21)
    assert text.splitlines()[2][d.loc.col - 1:].startswith("spare : BOOL")
    assert "output spare of n is not mentioned by any guarantee" in d.message


def test_output_mentioned_only_in_an_assumption_or_as_a_bound_name_is_unconstrained() -> None:
    assert codes(node(["a >= 0"], assumes=["out.o > 0"])) == ["W-unconstrained-output"]
    assert codes(node(["forall(o in REAL | o > a)"])) == ["W-unconstrained-output"]
    # Bare name and application both count as mentions.
    assert codes(node(["o > a"])) == []
    assert codes(node(["exists(x in REAL | o(x))"], outputs="o : REAL --> BOOL")) == []


def test_unused_inputs_are_not_reported() -> None:
    assert codes(node(["out.o == 1"], inputs="a : REAL, b : REAL, c : {}")) == []


# ---------------------------------------------------------------------------
# The case study
# ---------------------------------------------------------------------------

def _agent_guarantee_lines(text: str) -> list[int]:
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("node Agent"))
    end = next(i for i in range(start + 1, len(lines)) if lines[i].startswith("}"))
    return [i + 1 for i in range(start, end) if lines[i].lstrip().startswith("guarantee(")]


def test_case_study_warnings() -> None:
    text = CASE_STUDY.read_text(encoding="utf-8")
    diags = lint(parse_file(CASE_STUDY))
    assert all(d.severity == "warning" for d in diags)
    counts = Counter(d.code for d in diags)
    # no precedence warning: the case study only uses the conventional forms
    assert counts == {"W-unused-bound": 2}

    # (b): the Agent's third guarantee binds x', y' and never uses them,
    # reported on the line of that guarantee at the columns of the names.
    g3_line = _agent_guarantee_lines(text)[2]
    unused = [d for d in diags if d.code == "W-unused-bound"]
    line_text = text.splitlines()[g3_line - 1]
    assert [(d.loc.line, d.loc.col) for d in unused] == [
        (g3_line, line_text.index("x'") + 1), (g3_line, line_text.index("y'") + 1)]
    assert all("guarantee 3 of Agent" in d.message for d in unused)
    assert "x'" in unused[0].message and "y'" in unused[1].message

    # Every output of the case study is mentioned by a guarantee.
    assert counts["W-unconstrained-output"] == 0
