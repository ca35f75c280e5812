"""The whole published RCL syntax, and robustness on large and hostile input.

Each construct is checked with the contract text it comes from: it parses,
type-checks, and ``fmt`` round-trips (parse, print, parse gives the same
tree).  Long chains and deep nesting either work or give the located
``too deeply nested`` error; the command line never prints a traceback.
"""
from __future__ import annotations

from pathlib import Path

import pytest
import z3

from rclverify import __version__
from rclverify.cli.commands import main
from rclverify.semantics.encode import Encoder, EncodingError
from rclverify.semantics.evaluate import evaluate
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan
from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError
from rclverify.lang.latex import to_latex
from rclverify.lang.lint import lint
from rclverify.lang.nesting import NESTING_LIMIT
from rclverify.lang.parser import parse_file, parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.typecheck import check
from rclverify.lang.types import INTEGER, NATURAL, STRING, EnumT, SeqT, TupleT
from rclverify.lang.walk import free_names, subexpressions

ROOT = Path(__file__).resolve().parents[2]
ALL_CONTRACTS = sorted(p for p in ROOT.rglob("*.rcl") if ".git" not in p.parts)


def node(body: str, ctx: str = "", io: str = "inputs(a : REAL) outputs(o : REAL)") -> str:
    return (f"context {{ {ctx} }}\n" if ctx else "") + f"node n {{ {io}\n {body} }}\n"


def roundtrip(src: str) -> ast.Spec:
    spec = parse_text(src)
    again = parse_text(to_rcl(spec))
    assert again == spec
    assert to_rcl(again) == to_rcl(spec)
    return spec


def checked(src: str):  # type: ignore[no-untyped-def]
    spec = roundtrip(src)
    return spec, check([spec])


# -- constructs ----------------------------------------------------------------

def test_short_forms_A_and_G() -> None:
    spec, _ = checked(node("A(in.a > 0) G(out.o > in.a)"))
    n = spec.nodes[0]
    assert len(n.assumes) == 1 and len(n.guarantees) == 1
    assert spec == parse_text(node("assume(in.a > 0) guarantee(out.o > in.a)"))


def test_A_and_G_are_still_names_in_formulas() -> None:
    spec, _ = checked(node("guarantee(G > A)", io="inputs(A : REAL) outputs(G : REAL)"))
    assert {v.name for v in subexpressions(spec.nodes[0].guarantees[0].formula) if isinstance(v, ast.Var)} == {"A", "G"}


def test_string_literals_and_the_STRING_type() -> None:
    src = node('guarantee(out.cmd == "stop \\"now\\"" or out.cmd == "go")',
               io="inputs() outputs(cmd : STRING) topics(std_msgs/String data matches(out.cmd))")
    spec, c = checked(src)
    lit = next(e for e in subexpressions(spec.nodes[0].guarantees[0].formula) if isinstance(e, ast.StrLit))
    assert lit.value == 'stop "now"'
    assert c.nodes["n"].outputs["cmd"] == STRING
    with pytest.raises(RclError, match="cannot compare"):
        check([parse_text(node('guarantee(out.o == "x")'))])


def test_sequence_literals_empty_sequence_and_ranges() -> None:
    src = node("guarantee(out.s == <1, 2 + 1, 3> or out.s == <> or out.s == <1 upto in.k>)",
               io="inputs(k : NATURAL) outputs(s : seq(INTEGER))")
    spec, _ = checked(src)
    kinds = {type(e).__name__ for e in subexpressions(spec.nodes[0].guarantees[0].formula)}
    assert {"SeqLit", "SeqRange"} <= kinds
    assert "upto" in to_rcl(spec) and "<>" in to_rcl(spec)


def test_comparisons_still_chain_next_to_angle_brackets() -> None:
    spec, _ = checked(node("guarantee(0 < in.a < 5 and <1> != <2> and in.a > 1)"))
    f = spec.nodes[0].guarantees[0].formula
    assert any(isinstance(e, ast.Compare) and e.ops == ("<", "<") for e in subexpressions(f))


def test_range_bounds_must_be_integers() -> None:
    with pytest.raises(RclError, match="upto"):
        check([parse_text(node("guarantee(in.a in <1.5 upto 3>)"))])


def test_function_type_with_tuple_result() -> None:
    src = node("guarantee(in.pos(in.a) == (1.0, 2.0))", ctx="Pos : REAL --> REAL x REAL ;",
               io="inputs(a : REAL, pos : Pos) outputs(o : REAL)")
    spec, c = checked(src)
    decl = spec.contexts[0].decls[0]
    assert isinstance(decl, ast.TypeDecl) and isinstance(decl.type, typeexpr.TFunc)
    assert isinstance(decl.type.result, typeexpr.TTuple)
    assert str(c.env.types["Pos"]).endswith("(REAL, REAL)")


def test_tuple_binders_in_every_quantifier() -> None:
    ctx = "Wayp = {wayA, wayB} ; Pair : (Wayp, Wayp) ;"
    io = "inputs(p : set(Pair)) outputs(o : BOOL)"
    for q in ("forall", "exists", "exists_unique"):
        spec, _ = checked(node(f"guarantee(out.o <=> {q}((u, v) in in.p | u != v))", ctx=ctx, io=io))
        tq = spec.nodes[0].guarantees[0].formula.right  # type: ignore[union-attr]
        assert isinstance(tq, ast.TupleQuant) and tq.kind == q and tq.names == ("u", "v")
        assert free_names(tq) == set()
    with pytest.raises(RclError, match="takes apart tuples of 3"):
        check([parse_text(node("guarantee(forall((u, v, w) in in.p | u == v))", ctx=ctx, io=io))])


def test_constant_set_used_as_type_and_tuple_and_sequence_types() -> None:
    ctx = "Wayp = {wayA, wayB, wayC} ; Pair : (Wayp, Wayp) ; Route : <Wayp> ;"
    src = node("guarantee(in.w in Wayp and in.r == <wayA, wayC> and in.p == (in.w, wayB))", ctx=ctx,
               io="inputs(w : Wayp, r : Route, p : Pair) outputs(o : BOOL)")
    _, c = checked(src)
    assert isinstance(c.env.types["Wayp"], EnumT) and c.env.types["Wayp"].values == ("wayA", "wayB", "wayC")
    assert c.env.types["Route"] == SeqT(c.env.types["Wayp"])
    assert isinstance(c.env.types["Pair"], TupleT)


def test_contract_with_every_construct_checks_and_renders() -> None:
    spec = parse_file(ROOT / "tests" / "data" / "rcl_language.rcl")
    c = check([spec])
    assert "\\langle" in to_latex(spec)
    assert c.nodes["n"].inputs["name"] == STRING


@pytest.mark.parametrize("path", ALL_CONTRACTS, ids=lambda p: p.name)
def test_fmt_round_trips_every_contract_in_the_repository(path: Path) -> None:
    spec = parse_file(path)
    assert parse_text(to_rcl(spec), str(path)) == spec


# -- Z3 meaning of the new constructs ---------------------------------------------

def _z3(src: str, k: int = 0) -> z3.CheckSatResult:
    spec = parse_text(src)
    c = check([spec])
    f = Encoder(c.env).formula(spec.nodes[0].guarantees[k].formula, c.nodes["n"])
    s = z3.Solver()
    s.add(z3.Not(f))
    return s.check()


def test_z3_meaning_of_strings_ranges_and_tuple_binders() -> None:
    assert _z3(node('guarantee("ab" == "ab" and "a" != "b")')) == z3.unsat  # valid
    assert _z3(node("guarantee(<1 upto 3> == <1, 2, 3>)")) == z3.unsat
    assert _z3(node("guarantee(in.k in <2 upto 4> -> in.k >= 2)", io="inputs(k : INTEGER) outputs(o : REAL)")) == z3.unsat
    ctx = "Wayp = {wayA, wayB} ; Pair : (Wayp, Wayp) ;"
    io = "inputs(p : set(Pair)) outputs(o : BOOL)"
    assert _z3(node("guarantee(forall((u, v) in Pair | u == v or u != v))", ctx=ctx, io=io)) == z3.unsat
    # Not valid: a set of pairs may hold a pair with distinct components.
    assert _z3(node("guarantee(forall((u, v) in in.p | u == v))", ctx=ctx, io=io)) == z3.sat


def test_qualified_builtin_terms_are_products_of_base_types() -> None:
    # The original tool's localisation contract: `(x, y) in REAL.REAL` is the
    # pair (x, y) ranging over REAL x REAL.
    ctx = "Pos : REAL x REAL --> BOOL ;"
    io = "inputs() outputs(position : Pos)"
    src = node("guarantee(exists_unique((x, y) in REAL.REAL | out.position(x, y) == TRUE))\n"
               "guarantee(forall(p in NATURAL.INTEGER | p in INTEGER.INTEGER))\n"
               "guarantee(forall(a, b in REAL | (a, b) in REAL.REAL and (1, -1) !in NATURAL.NATURAL))",
               ctx=ctx, io=io)
    spec, c = checked(src)
    assert "REAL.REAL" in to_rcl(spec) and "NATURAL.INTEGER" in to_rcl(spec)
    assert r"\mathbb{N} \times \mathbb{Z}" in to_latex(spec)
    assert _z3(src, 1) == z3.unsat  # every (NATURAL, INTEGER) pair is a pair of integers
    assert _z3(src, 2) == z3.unsat  # (1, -1) has a negative component
    # Not valid the other way round: (0, -1) is an integer pair, not a natural one.
    assert _z3(node("guarantee(forall(p in INTEGER.INTEGER | p in NATURAL.NATURAL))")) == z3.sat
    assert _z3(node("guarantee(forall((u, v) in NATURAL.REAL | u >= 0))")) == z3.unsat


def test_qualified_builtin_terms_must_name_base_types_and_fit_the_element() -> None:
    with pytest.raises(RclError, match=r"<string>:2:28: error: unexpected character '\.'"):
        parse_text(node("guarantee(forall(p in REAL.FOO | TRUE))"))
    with pytest.raises(RclError, match=r"2:25: error: membership of a \(NATURAL, NATURAL, NATURAL\) in a collection of \(REAL, REAL\)"):
        check([parse_text(node("guarantee((1, 2, 3) in REAL.REAL)"))])


def test_monitor_evaluates_builtin_terms_on_the_right_of_in() -> None:
    src = node("guarantee((in.a, in.a) in NATURAL.INTEGER and in.a in NATURAL)")
    spec, c = checked(src)
    f = spec.nodes[0].guarantees[0].formula
    assert evaluate(f, c, c.nodes["n"], {"in.a": 3, "out.o": 0}) is True
    assert evaluate(f, c, c.nodes["n"], {"in.a": -3, "out.o": 0}) is False
    assert evaluate(f, c, c.nodes["n"], {"in.a": 0.5, "out.o": 0}) is False


def test_z3_meaning_of_tuple_literals_and_empty_literals() -> None:
    io = "inputs(p : (REAL, REAL), s : set((NATURAL, NATURAL)), q : <NATURAL>) outputs(o : <NATURAL>)"
    assert _z3(node("guarantee((1, 2) == (1, 2) and (1, 2) != (2, 1))", io=io)) == z3.unsat
    # Tuple literals of integers compare with tuples of reals component by component.
    assert _z3(node("guarantee(in.p == (1, 2) -> in.p != (1.5, 2))", io=io)) == z3.unsat
    assert _z3(node("guarantee(in.p == (1, 2) -> in.p == (1.5, 2))", io=io)) == z3.sat
    assert _z3(node("guarantee((1, 2) in {(1, 2), (3, 4)} and (2, 1) !in {(1, 2), (3, 4)})", io=io)) == z3.unsat
    assert _z3(node("guarantee(in.s == {(0, 0)} -> (0, 0) in in.s)", io=io)) == z3.unsat
    # The empty literal takes the sort of the other side of the comparison.
    assert _z3(node("guarantee(out.o == <> -> not (3 in out.o))", io=io)) == z3.unsat
    assert _z3(node("guarantee(in.q != <> or in.s == {})", io=io)) == z3.sat
    assert _z3(node("guarantee(<> == <> and {} == {})", io=io)) == z3.unsat


def test_unsupported_encodings_are_located_errors() -> None:
    with pytest.raises(EncodingError, match=r":1:|:2:"):
        _z3(node("guarantee(in.k in <1 upto 3> or <in.k upto 3> == <1>)", io="inputs(k : INTEGER) outputs(o : REAL)"))


def test_range_on_the_right_of_in_is_integral() -> None:
    assert _z3(node("guarantee(not (in.a in <0 upto 2> and in.a == 0.5))")) == z3.unsat


# -- errors ---------------------------------------------------------------------------

def test_unknown_type_reported_once_without_knock_on_messages() -> None:
    src = node("guarantee(out.o > in.a and in.a > 0)", io="inputs(a : Foo) outputs(o : Foo)")
    with pytest.raises(RclError) as e:
        check([parse_text(src)])
    msgs = [d.message for d in e.value.diagnostics]
    assert len(msgs) == 1 and "unknown type 'Foo'" in msgs[0], msgs
    assert (e.value.diagnostics[0].loc.line, e.value.diagnostics[0].loc.col) == (1, 21)


def test_unknown_type_used_as_a_domain_too_is_reported_once_with_the_case_hint() -> None:
    # A contract in the style of the original tool's examples: `String` for a string topic.
    src = node("guarantee(not forall(x in String | in.c == x and out.n != 10))",
               io="inputs(c : String) outputs(n : INTEGER)")
    with pytest.raises(RclError) as e:
        check([parse_text(src)])
    msgs = [str(d) for d in e.value.diagnostics]
    assert len(msgs) == 1, msgs
    assert "1:21: error: unknown type 'String'; did you mean 'STRING'?" in msgs[0]


def test_empty_file_warns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "empty.rcl"
    f.write_text("// nothing here\n")
    assert main(["check", str(f)]) == 0
    out = capsys.readouterr().out
    assert f"{f}:1:1: warning: empty contract file" in out and "1 warning(s)" in out


# -- size and depth -------------------------------------------------------------------

@pytest.mark.parametrize("op", ["and", "or"])
def test_5000_long_chains_go_through_every_stage(op: str) -> None:
    n = 5000
    src = node("guarantee(" + f" {op} ".join(f"out.b != {i}" for i in range(n)) + ")",
               io="inputs() outputs(b : INTEGER)")
    spec = parse_text(src)
    f = spec.nodes[0].guarantees[0].formula
    assert sum(1 for e in subexpressions(f) if isinstance(e, ast.Compare)) == n
    c = check([spec])
    hash(spec)
    text = to_rcl(spec)
    assert text.count(f" {op} ") == n - 1 and "(" not in text.split("guarantee(")[1][:-4]
    assert parse_text(text) == spec
    to_latex(spec)
    lint(spec)
    Encoder(c.env).formula(f, c.nodes["n"])


def test_left_nested_chain_built_by_a_program_prints_and_encodes() -> None:
    f: ast.Expr = ast.Compare(("!=",), (ast.Var("b", "out"), ast.NumLit("0")))
    for i in range(1, 3000):
        f = ast.Binary("and", f, ast.Compare(("!=",), (ast.Var("b", "out"), ast.NumLit(str(i)))))
    spec = parse_text(node("guarantee(out.b != 0)", io="inputs() outputs(b : INTEGER)"))
    c = check([spec])
    from rclverify.lang.printer import expr_to_rcl
    assert expr_to_rcl(f).count(" and ") == 2999
    Encoder(c.env).formula(f, c.nodes["n"])


DEEP = {
    "not": lambda d: "not (" * d + "out.o" + ")" * d,
    "plus": lambda d: "(" * d + "in.a" + " + 1)" * d + " > 0",
    "set": lambda d: "in.a in " + "{" * d + "1" + "}" * d,
    "tuple": lambda d: "(" * d + "1, " + "1), " * (d - 1) + "1) == in.t",
    "quant": lambda d: "".join(f"forall(x{i} in INTEGER | " for i in range(d)) + "out.o" + ")" * d,
    "implies": lambda d: "out.o -> " * d + "out.o",
}


@pytest.mark.parametrize("kind", sorted(DEEP))
def test_1000_deep_nesting_is_a_located_error(kind: str) -> None:
    src = node("guarantee(" + DEEP[kind](1000) + ")", io="inputs(a : REAL, t : REAL) outputs(o : BOOL)")
    with pytest.raises(RclError) as e:
        parse_text(src)
    d = e.value.diagnostics[0]
    assert d.code == "E-depth" and d.message == f"too deeply nested (limit {NESTING_LIMIT})"
    assert d.loc.line == 2 and d.loc.col > 1


@pytest.mark.parametrize("kind", ["not", "plus", "quant", "implies"])
def test_nesting_just_under_the_limit_goes_through_every_stage(kind: str) -> None:
    d = NESTING_LIMIT - 5 if kind != "quant" else (NESTING_LIMIT - 5) // 2
    src = node("guarantee(" + DEEP[kind](d) + ")", io="inputs(a : REAL, t : REAL) outputs(o : BOOL)")
    spec = roundtrip(src)
    c = check([spec])
    hash(spec)
    to_latex(spec)
    lint(spec)
    Encoder(c.env).formula(spec.nodes[0].guarantees[0].formula, c.nodes["n"])


def test_hostile_files_never_print_a_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    files = {
        "chain.rcl": node("guarantee(" + " and ".join(f"out.b != {i}" for i in range(3000)) + ")",
                          io="inputs() outputs(b : INTEGER)"),
        "deep.rcl": node("guarantee(" + "not (" * 800 + "out.b" + ")" * 800 + ")", io="inputs() outputs(b : BOOL)"),
        "empty.rcl": "",
    }
    codes = {}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        codes[name] = main(["check", str(tmp_path / name)])
    out = capsys.readouterr()
    assert "Traceback" not in out.out + out.err
    assert codes == {"chain.rcl": 0, "deep.rcl": 1, "empty.rcl": 0}
    assert "too deeply nested" in out.err


# -- YAML limits -------------------------------------------------------------------

def _plan(tmp_path: Path, text: str) -> Path:
    (tmp_path / "contracts").mkdir(exist_ok=True)
    (tmp_path / "contracts" / "plan.yaml").write_text(text)
    return tmp_path


def test_yaml_alias_bomb_is_refused_quickly(tmp_path: Path) -> None:
    bomb = 'a: &a ["x", "x", "x", "x", "x", "x", "x", "x", "x"]\n'
    prev = "a"
    for c in "bcdefghi":
        bomb += f"{c}: &{c} [" + ", ".join([f"*{prev}"] * 9) + "]\n"
        prev = c
    bomb += "contracts: []\n"
    with pytest.raises(PlanError) as e:
        load_plan(_plan(tmp_path, bomb))
    d = e.value.diagnostics[0]
    assert "alias" in d.message and d.loc.line > 1 and d.code == "E-yaml-limit"


def test_yaml_alias_cycle_and_oversized_file_are_refused(tmp_path: Path) -> None:
    with pytest.raises(PlanError, match="cycle"):
        load_plan(_plan(tmp_path, "contracts: &x [*x]\n"))
    with pytest.raises(PlanError, match="1048576 bytes"):
        load_plan(_plan(tmp_path, "#" + "x" * (1 << 20) + "\ncontracts: []\n"))


# -- command line ------------------------------------------------------------------------

def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0 and capsys.readouterr().out.strip() == f"rclverify {__version__}"


@pytest.mark.parametrize("cmd", ["fmt", "latex"])
def test_output_file(cmd: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = ROOT / "contracts" / "remote_inspection.rcl"
    assert main([cmd, str(src)]) == 0
    stdout = capsys.readouterr().out
    out = tmp_path / f"out.{cmd}"
    assert main([cmd, str(src), "-o", str(out)]) == 0
    assert capsys.readouterr().out == "" and out.read_text() == stdout
    assert main([cmd, str(src), "-o", str(tmp_path / "missing" / "x")]) == 1
    assert "cannot write output file" in capsys.readouterr().err
