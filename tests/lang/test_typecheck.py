"""Type checker: resolved types of the case study and located, useful errors."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check, domain_type, infer, load
from rclverify.lang.types import (BOOL, INTEGER, NATURAL, REAL, DataT, EmptyT, EnumT, FuncT, SetT)

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"

CTX = """context {
  RadStat : {red, orange, green} ;
  CommandSet : { move(REAL, REAL), inspect(NATURAL) } ;
  WayP : REAL x REAL --> NATURAL ;
}
"""


def node(body: str, inputs: str = "r : REAL, s : RadStat, c : CommandSet, w : WayP",
         outputs: str = "y : REAL", name: str = "N") -> str:
    return f"node {name} {{\n  inputs({inputs})\n  outputs({outputs})\n{body}\n}}\n"


def errors(text: str, file: str = "t.rcl") -> list[Diagnostic]:
    with pytest.raises(RclError) as info:
        check([parse_text(text, file)])
    diags = list(info.value.diagnostics)
    assert diags and all(d.severity == "error" for d in diags)
    return diags


def one_error(text: str, file: str = "t.rcl") -> Diagnostic:
    diags = errors(text, file)
    assert len(diags) == 1, [str(d) for d in diags]
    return diags[0]


def where(text: str, needle: str, occurrence: int = 1) -> tuple[int, int]:
    """1-based (line, col) of the ``occurrence``-th ``needle`` in ``text``."""
    pos = -1
    for _ in range(occurrence):
        pos = text.index(needle, pos + 1)
    line = text.count("\n", 0, pos) + 1
    col = pos - (text.rfind("\n", 0, pos) + 1) + 1
    return line, col


def at(d: Diagnostic) -> tuple[int, int]:
    return d.loc.line, d.loc.col


# ---------------------------------------------------------------------------
# The case study
# ---------------------------------------------------------------------------

def test_case_study_checks_with_resolved_types() -> None:
    checked = load([CASE_STUDY])
    assert list(checked.nodes) == ["Localisation", "Navigation", "Agent", "RadiationSensor"]
    agent = checked.nodes["Agent"]
    assert agent.inputs["wayP"] == FuncT((REAL, REAL), NATURAL)
    assert agent.inputs["at"] == FuncT((REAL, REAL), BOOL)
    assert agent.inputs["inspected"] == FuncT((NATURAL,), BOOL)
    assert agent.inputs["radiationStatus"] == EnumT("RadStat", ("red", "orange", "green"))
    command = agent.outputs["command"]
    assert isinstance(command, DataT) and command.name == "CommandSet"
    assert [c for c, _ in command.ctors] == ["move", "inspect"]
    assert command.ctor("move") == (REAL, REAL)
    assert command.ctor("inspect") == (NATURAL,)
    # The same constructor set everywhere it is used; the empty type for hardware.
    assert checked.nodes["Navigation"].inputs["command"] == command
    assert checked.nodes["Localisation"].inputs["sensors"] == EmptyT("SensorsType")
    assert checked.env.ctors["move"] is checked.env.ctors["inspect"]
    assert checked.env.enum_values["green"].name == "RadStat"
    assert checked.nodes["RadiationSensor"].inputs["r"] == REAL


def test_infer_and_domain_type_on_the_case_study() -> None:
    checked = load([CASE_STUDY])
    agent = checked.nodes["Agent"]
    env = checked.env
    assert infer(parse_formula("in.wayP(1, 2.5) + 1"), agent, env) == NATURAL
    assert infer(parse_formula("in.wayP(1, 2) - 1"), agent, env) == INTEGER  # NATURAL - NATURAL may be negative
    assert infer(parse_formula("in.wayP(1, 2) / 2"), agent, env) == REAL
    assert infer(parse_formula("move(1, 2)"), agent, env) == env.ctors["move"]
    assert infer(parse_formula("out.command == inspect(3)"), agent, env) == BOOL
    assert infer(parse_formula("i + 1"), agent, env, {"i": NATURAL}) == NATURAL
    q = parse_formula("forall(i in NATURAL, s in RadStat, k in {1, 2.5} | TRUE)")
    assert isinstance(q, ast.Quant)
    assert [domain_type(b, agent, env) for b in q.bindings] == [NATURAL, env.types["RadStat"], REAL]


def test_infer_reports_located_errors_for_plan_formulas() -> None:
    checked = load([CASE_STUDY])
    expr = parse_formula("in.wayP(green, 2) == 0", "plan.yaml", 10, 5)
    with pytest.raises(RclError) as info:
        infer(expr, checked.nodes["Agent"], checked.env)
    (d,) = info.value.diagnostics
    assert str(d) == "plan.yaml:10:13: error: argument of in.wayP must be REAL, found RadStat"


# ---------------------------------------------------------------------------
# Names
# ---------------------------------------------------------------------------

def test_unknown_bare_name_suggests_the_close_ones() -> None:
    text = CTX + node("  guarantee(statu == red)", inputs="status : RadStat")
    d = one_error(text)
    assert d.code == "E-name"
    assert at(d) == where(text, "statu ==")
    assert "unknown name 'statu'" in d.message and "did you mean 'status'" in d.message


def test_unknown_enum_value_suggests_the_values() -> None:
    text = CTX + node("  guarantee(in.s == gren)")
    d = one_error(text)
    assert str(d).startswith(f"t.rcl:{where(text, 'gren')[0]}:{where(text, 'gren')[1]}: error: unknown name 'gren'")
    assert "did you mean 'green'" in d.message


def test_unknown_prefixed_input_lists_candidates() -> None:
    text = CTX + node("  guarantee(out.y == in.rr)")
    d = one_error(text)
    assert d.code == "E-name" and at(d) == where(text, "in.rr")
    assert "node N has no input named 'rr'" in d.message and "did you mean 'r'" in d.message


def test_wrong_prefix_is_an_error_naming_the_inputs() -> None:
    # y is an output of N, so in.y names nothing.
    text = CTX + node("  guarantee(in.y == 1)")
    d = one_error(text)
    assert d.code == "E-name" and at(d) == where(text, "in.y")
    assert "node N has no input named 'y'" in d.message
    assert "r, s, c, w" in d.message


def test_wrong_prefix_points_at_the_other_prefix() -> None:
    text = CTX + node("  guarantee(in.y == 1)")
    d = one_error(text)
    assert "out.y" in d.message


def test_ambiguous_bare_name() -> None:
    text = node("  guarantee(x == 1)", inputs="x : REAL", outputs="x : REAL")
    d = one_error(text)
    assert d.code == "E-ambiguous" and at(d) == where(text, "x == 1")
    assert "'x' is both an input and an output of N; write in.x or out.x" in d.message
    # With prefixes the same contract is fine.
    check([parse_text(node("  guarantee(out.x == in.x)", inputs="x : REAL", outputs="x : REAL"))])


def test_bound_variable_shadows_an_input() -> None:
    # r is a REAL input; the bound r is BOOL, so 'r' alone is a formula.
    check([parse_text(CTX + node("  guarantee(forall(r in BOOL | r or not r))"))])


def test_unknown_type_suggests_declared_types() -> None:
    text = CTX + node("  guarantee(TRUE)", inputs="s : RadSta")
    d = one_error(text)
    assert d.code == "E-name" and at(d) == where(text, "RadSta)")
    assert "unknown type 'RadSta'" in d.message and "did you mean 'RadStat'" in d.message


def test_unknown_quantifier_domain_suggests_types() -> None:
    text = CTX + node("  guarantee(forall(k in RadSta | k == red))")
    d = one_error(text)
    assert "did you mean 'RadStat'" in d.message


def test_a_type_is_not_a_value() -> None:
    text = CTX + node("  guarantee(in.s == RadStat)")
    d = one_error(text)
    assert at(d) == where(text, "RadStat)") and "'RadStat' is a type, not a value" in d.message


# ---------------------------------------------------------------------------
# Applications and constructors
# ---------------------------------------------------------------------------

def test_function_arity() -> None:
    text = CTX + node("  guarantee(in.w(1) == 0)")
    d = one_error(text)
    assert d.code == "E-arity" and at(d) == where(text, "in.w(1)")
    assert d.message == "in.w takes 2 argument(s) (REAL, REAL), given 1"


def test_constructor_arity() -> None:
    text = CTX + node("  guarantee(in.c == move(1))")
    d = one_error(text)
    assert d.code == "E-arity" and at(d) == where(text, "move(1)")
    assert d.message == "constructor move takes 2 argument(s) (REAL, REAL), given 1"


def test_constructor_used_without_arguments() -> None:
    text = CTX + node("  guarantee(in.c == move)")
    d = one_error(text)
    assert d.code == "E-arity" and "write move(...)" in d.message


def test_argument_type_mismatch_is_located_at_the_argument() -> None:
    text = CTX + node("  guarantee(in.c == inspect(1.5))")
    d = one_error(text)
    assert at(d) == where(text, "1.5")
    assert d.message == "argument of constructor inspect must be NATURAL, found REAL"
    text = CTX + node("  guarantee(in.w(in.s, 0) == 0)")
    d = one_error(text)
    assert at(d) == where(text, "in.s, 0") and "argument of in.w must be REAL, found RadStat" in d.message


def test_applying_a_non_function() -> None:
    text = CTX + node("  guarantee(in.r(1) == 2)")
    d = one_error(text)
    assert "in.r has type REAL and cannot be applied to arguments" in d.message


def test_numeric_widening_is_accepted() -> None:
    ctx = "context { F : INTEGER x REAL --> BOOL ; G : REAL --> BOOL ; }\n"
    text = ctx + node(
        "  guarantee(out.y == in.n and out.y == in.i + in.n and in.f(in.n, in.i) and in.g(in.n) and in.g(in.i)"
        " and in.i < in.y)",
        inputs="n : NATURAL, i : INTEGER, f : F, g : G, y : REAL")
    check([parse_text(text)])


def test_narrowing_is_rejected() -> None:
    ctx = "context { F : NATURAL --> BOOL ; }\n"
    text = ctx + node("  guarantee(in.f(in.i))", inputs="i : INTEGER, f : F")
    d = one_error(text)
    assert at(d) == where(text, "in.i))") and d.message == "argument of in.f must be NATURAL, found INTEGER"


# ---------------------------------------------------------------------------
# Operators
# ---------------------------------------------------------------------------

def test_comparing_an_enum_with_a_number() -> None:
    text = CTX + node("  guarantee(in.s == 1)")
    d = one_error(text)
    assert at(d) == where(text, "1)") and d.message == "cannot compare RadStat with NATURAL using '=='"


def test_order_on_booleans() -> None:
    text = CTX + node("  guarantee(in.b < TRUE)", inputs="b : BOOL")
    d = one_error(text)
    assert at(d) == where(text, "in.b <") and d.message == "'<' needs numbers, found BOOL"


def test_connective_on_a_number() -> None:
    text = CTX + node("  guarantee(not in.r)")
    d = one_error(text)
    assert at(d) == where(text, "in.r)") and "'not' needs a formula (BOOL), found REAL" in d.message


def test_clause_that_is_not_a_formula() -> None:
    text = CTX + node("  guarantee(out.y + 1)")
    d = one_error(text)
    assert at(d) == where(text, "out.y + 1")
    assert d.message == "a contract clause must be a formula (BOOL), found REAL"


def test_membership_of_the_wrong_type() -> None:
    text = CTX + node("  guarantee(in.s in {1, 2})")
    d = one_error(text)
    assert at(d) == where(text, "{1, 2}") and "membership of a RadStat in a collection of NATURAL" in d.message


def test_membership_in_a_type_name_and_in_an_enum_literal() -> None:
    check([parse_text(CTX + node("  guarantee(in.s in RadStat and in.s !in {red, orange})"))])


def test_chained_comparison_types() -> None:
    check([parse_text(CTX + node("  guarantee(0 <= in.r < 120 <= out.y)"))])
    text = CTX + node("  guarantee(0 <= in.r < in.s)")
    d = one_error(text)
    assert at(d) == where(text, "in.s)") and d.message == "'<' needs numbers, found RadStat"


# ---------------------------------------------------------------------------
# Declarations
# ---------------------------------------------------------------------------

def test_node_without_guarantee() -> None:
    text = CTX + node("  assume(TRUE)")
    d = one_error(text)
    assert d.code == "E-contract" and at(d) == where(text, "node N")
    assert "node N has no guarantee" in d.message


def test_duplicate_node_names_the_first_definition() -> None:
    first = node("  guarantee(TRUE)", inputs="a : REAL")
    text = first + node("  guarantee(TRUE)", inputs="a : REAL")
    d = one_error(text)
    line2, col2 = where(text, "node N", 2)
    assert d.code == "E-duplicate" and at(d) == (line2, col2)
    assert d.message == "node 'N' is already defined at t.rcl:1:1"


def test_duplicate_node_across_files() -> None:
    a = parse_text(CTX + node("  guarantee(TRUE)"), "a.rcl")
    b = parse_text(node("  guarantee(TRUE)"), "b.rcl")
    with pytest.raises(RclError) as info:
        check([a, b])
    (d,) = info.value.diagnostics
    assert str(d).startswith("b.rcl:1:1: error: node 'N' is already defined at a.rcl:")


def test_duplicate_io_declaration() -> None:
    text = node("  guarantee(TRUE)", inputs="b : BOOL, b : REAL")
    d = one_error(text)
    assert d.code == "E-duplicate" and at(d) == where(text, "b : REAL")
    assert d.message == "'b' is declared twice in node N"


def test_duplicate_context_declaration() -> None:
    text = "context { C : {lo, hi} ; C : REAL ; }\n" + node("  guarantee(TRUE)", inputs="a : REAL")
    d = one_error(text)
    assert d.code == "E-duplicate" and at(d) == where(text, "C : REAL")
    assert d.message == "'C' is already declared at t.rcl:1:11"


def test_enum_value_declared_in_two_enumerations() -> None:
    text = "context { C : {red, green} ; D : {red, blue} ; }\n" + node("  guarantee(TRUE)", inputs="a : REAL")
    d = one_error(text)
    assert d.code == "E-duplicate" and at(d) == where(text, "{red, blue}")
    assert d.message == "'red' is already a value of C"


def test_enum_value_repeated_in_one_enumeration() -> None:
    text = "context { C : {red, green, red} ; }\n" + node("  guarantee(TRUE)", inputs="a : REAL")
    diags = errors(text)
    assert any(d.message == "enumeration value 'red' appears twice in C" and at(d) == where(text, "{red")
               for d in diags)


def test_enum_value_repeated_is_reported_once() -> None:
    text = "context { C : {red, green, red} ; }\n" + node("  guarantee(TRUE)", inputs="a : REAL")
    assert len(errors(text)) == 1


def test_direct_type_cycle() -> None:
    text = "context { A : A x REAL --> BOOL ; }\n" + node("  guarantee(TRUE)", inputs="a : REAL")
    d = one_error(text)
    assert d.code == "E-type-cycle" and at(d) == where(text, "A x")
    assert d.message == "type 'A' is defined in terms of itself"


def test_mutual_type_cycle_is_an_error_at_both_references() -> None:
    text = "context { A : B ; B : A ; }\n" + node("  guarantee(TRUE)", inputs="x : A")
    diags = errors(text)
    assert {d.code for d in diags} == {"E-type-cycle"}
    assert {at(d) for d in diags} == {where(text, "B ;"), where(text, "A ;")}


def test_mutual_type_cycle_has_no_duplicate_diagnostics() -> None:
    text = "context { A : B ; B : A ; }\n" + node("  guarantee(TRUE)", inputs="x : A")
    diags = errors(text)
    assert len({str(d) for d in diags}) == len(diags)


def test_constants_are_typed_and_checked() -> None:
    ctx = "context { Max : REAL = 250 ; Lim = 120 ; }\n"
    checked = check([parse_text(ctx + node("  guarantee(Lim < in.r and in.r < Max)", inputs="r : REAL"))])
    assert checked.env.constants["Max"][0] == REAL
    assert checked.env.constants["Lim"][0] == NATURAL
    text = "context { Bad : BOOL = 3 ; }\n" + node("  guarantee(TRUE)", inputs="r : REAL")
    d = one_error(text)
    assert at(d) == where(text, "3 ;") and d.message == "constant Bad is declared BOOL but its value has type NATURAL"


def test_set_typed_input() -> None:
    checked = check([parse_text(node("  guarantee(in.k in in.ks)", inputs="k : NATURAL, ks : set(INTEGER)"))])
    assert checked.nodes["N"].inputs["ks"] == SetT(INTEGER)


# ---------------------------------------------------------------------------
# Several errors at once
# ---------------------------------------------------------------------------

def test_several_errors_are_reported_together_and_sorted() -> None:
    text = CTX + "\n".join([
        node("  assume(in.zz > 0)\n  guarantee(out.y < TRUE)", name="M"),
        node("  guarantee(out.q == 1)", name="K"),
    ])
    diags = errors(text)
    lines = [str(d) for d in diags]
    assert len(diags) == 3
    assert [at(d) for d in diags] == sorted(at(d) for d in diags)
    assert "no input named 'zz'" in lines[0]
    assert "'<' needs numbers, found BOOL" in lines[1]
    assert "no output named 'q'" in lines[2]
    assert all(line.startswith("t.rcl:") and ": error: " in line for line in lines)


def test_errors_of_several_files_are_sorted_by_file() -> None:
    b = parse_text(CTX + node("  guarantee(in.nope)", name="B"), "b.rcl")
    a = parse_text(node("  guarantee(in.also_nope)", name="A"), "a.rcl")
    with pytest.raises(RclError) as info:
        check([b, a])  # contexts are shared: A may use RadStat declared in b.rcl
    assert [d.loc.file for d in info.value.diagnostics] == ["a.rcl", "b.rcl"]


def test_context_of_another_file_is_visible() -> None:
    b = parse_text(CTX, "ctx.rcl")
    a = parse_text(node("  guarantee(in.s == green)", inputs="s : RadStat"), "a.rcl")
    checked = check([a, b])
    assert checked.nodes["N"].inputs["s"] == EnumT("RadStat", ("red", "orange", "green"))
