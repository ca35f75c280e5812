"""Parser: coverage of the RCL syntax of the paper and located syntax errors."""
from __future__ import annotations

from pathlib import Path

import pytest
from lark import Lark

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError
from rclverify.lang.parser import ast_from_tree, grammar_text, parse_file, parse_formula, parse_text

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"


def V(name: str, prefix: str | None = None) -> ast.Var:
    return ast.Var(name, prefix)  # type: ignore[arg-type]


def N(text: str) -> ast.NumLit:
    return ast.NumLit(text)


def syntax_error(text: str, file: str = "f.rcl") -> tuple[ast.Loc, str]:
    with pytest.raises(RclError) as info:
        parse_text(text, file)
    (diag,) = info.value.diagnostics
    assert diag.severity == "error" and diag.code == "E-syntax"
    return diag.loc, diag.message


# ---------------------------------------------------------------------------
# The case study and the paper's listings
# ---------------------------------------------------------------------------

def test_case_study_parses_to_four_nodes() -> None:
    spec = parse_file(CASE_STUDY)
    assert [n.name for n in spec.nodes] == ["Localisation", "Navigation", "Agent", "RadiationSensor"]
    agent = spec.nodes[2]
    assert [v.name for v in agent.inputs] == ["wayP", "at", "radiationStatus", "inspected"]
    assert [v.name for v in agent.outputs] == ["command"]
    assert len(agent.assumes) == 1 and len(agent.guarantees) == 3
    assert agent.topics[0] == ast.Topic("gazebo_radiation_plugin/Snapshot", "command", V("command", "out"))
    assert agent.topics[3].field == "wayPNow"
    sensor = spec.nodes[3]
    assert sensor.topics[0].match == V("r")  # matches(r): bare name
    assert sensor.assumes[0].formula == ast.Compare(("<=",), (N("0"), V("r", "in")))


def test_context_listing_of_the_paper() -> None:
    # Verbatim layout of the paper's context listing (lines 1131-1140).
    src = """context{
 WayP : REAL x REAL --> NATURAL ;
 RadStat : {red, orange, green} ;
 CommandSet : { move(REAL, REAL), inspect(NATURAL) };
 PositionType : REAL x REAL --> BOOL ;
 AtType: REAL x REAL --> BOOL;
 InspectedType :  NATURAL --> BOOL;
 SensorsType : {}; }"""
    (ctx,) = parse_text(src).contexts
    types = {d.name: d.type for d in ctx.decls}
    R, Nat, B = typeexpr.TBase("REAL"), typeexpr.TBase("NATURAL"), typeexpr.TBase("BOOL")
    assert types == {
        "WayP": typeexpr.TFunc((R, R), Nat),
        "RadStat": typeexpr.TEnum(("red", "orange", "green")),
        "CommandSet": typeexpr.TConstructors((typeexpr.Constructor("move", (R, R)), typeexpr.Constructor("inspect", (Nat,)))),
        "PositionType": typeexpr.TFunc((R, R), B),
        "AtType": typeexpr.TFunc((R, R), B),
        "InspectedType": typeexpr.TFunc((Nat,), B),
        "SensorsType": typeexpr.TEmpty(),
    }


def test_agent_listing_of_the_paper_verbatim() -> None:
    # The Agent listing exactly as printed (lines 1143-1171): lower-case node
    # name, irregular spacing, `exists (` with a space.
    src = """node agent{

inputs( wayP : WayP, at : AtType, radiationStatus : RadStat, inspected : InspectedType )

outputs( command : CommandSet  )

topics( gazebo_radiation_plugin/Snapshot command matches(out.command),
gazebo_radiation_plugin/Snapshot inspected matches(in.inspected),
gazebo_radiation_plugin/Snapshot at matches(in.at),
gazebo_radiation_plugin/Snapshot wayPNow matches(in.wayP),
gazebo_radiation_plugin/Snapshot radiationStatus matches(in.radiationStatus) )

assume( in.radiationStatus in {red, orange, green} )

guarantee(forall(x', y' in REAL, i in NATURAL |
  in.at(x', y') == TRUE and in.wayP(x', y') == i and in.inspected(i) == TRUE and in.radiationStatus !in {red, orange} ->
  exists(x, y in REAL | (in.wayP(x, y) == i + 1  or
    (forall( x'', y'' in REAL | in.wayP(x'', y'') != i+1 and in.wayP(x, y) == 0))) and out.command == move(x, y) )) )

guarantee(forall(x', y' in REAL, i in NATURAL |
  in.at(x', y') == TRUE and in.wayP(x', y') == i and in.inspected(i) == FALSE -> out.command == inspect(i) ) )

guarantee(forall(x', y' in REAL, i in NATURAL |
  in.radiationStatus in {red, orange} or not exists( x, y in REAL | in.wayP(x, y) == i + 1 )
  -> exists (x'', y'' in REAL | in.wayP(x'', y'') == 0 and out.command == move(x'', y'') ) ) )
}"""
    (node,) = parse_text(src).nodes
    assert node.name == "agent"
    # Same guarantees as the case-study file (which writes the Agent with its own layout).
    reference = parse_file(CASE_STUDY).nodes[2]
    assert node.guarantees == reference.guarantees
    assert node.assumes == reference.assumes
    g2 = node.guarantees[1].formula
    assert isinstance(g2, ast.Quant) and g2.kind == "forall" and g2.variables == ("x'", "y'", "i")
    body = g2.body
    assert isinstance(body, ast.Binary) and body.op == "->"
    assert body.right == ast.Compare(("==",), (V("command", "out"), ast.Apply(V("inspect"), (V("i"),))))


def test_appendix_matches_colon_form() -> None:
    # Appendix A writes topics as "matches: x" (lines 1890-1983).
    src = """node RadiationSensor {
  inputs( r : REAL, command : CommandSet )
  outputs( radiationStatus : RadStat, inspected : InspectedType )
  topics( gazebo_radiation_plugin/Snapshot r matches: r,
          gazebo_radiation_plugin/Snapshot command matches: in.command,
          gazebo_radiation_plugin/Snapshot inspected matches: inspected,
          gazebo_radiation_plugin/Snapshot radiationStatus matches: out.radiationStatus )
  assume( 0 <= in.r )
  guarantee( TRUE ) }"""
    (node,) = parse_text(src).nodes
    assert [t.match for t in node.topics] == [V("r"), V("command", "in"), V("inspected"),
                                             V("radiationStatus", "out")]


def test_topic_without_matches_and_nested_ros_type() -> None:
    src = "node n { inputs() outputs(o : REAL) topics(geometry_msgs/msg/Twist linear, Float64 data) guarantee(o > 0) }"
    (node,) = parse_text(src).nodes
    assert node.topics == (ast.Topic("geometry_msgs/msg/Twist", "linear", None),
                           ast.Topic("Float64", "data", None))
    assert node.inputs == ()


def test_node_without_topics_and_with_several_clauses() -> None:
    src = """node n { inputs(a : INTEGER) outputs(o : INTEGER)
      assume(a > 0) guarantee(o >= a) assume(a < 10) guarantee(o <= 2 * a) }"""
    (node,) = parse_text(src).nodes
    assert node.topics == ()
    assert len(node.assumes) == 2 and len(node.guarantees) == 2


def test_context_constants_and_collection_types() -> None:
    src = """context {
      MaxLevel = 250 ;
      Low : REAL = 120.5 ;
      Ids : set(NATURAL) ;
      Route : seq((REAL, REAL)) ;
      Pair : (REAL, BOOL) ;
      Speed : REAL x REAL x INTEGER --> REAL ;
      Higher : (REAL --> REAL) --> BOOL ;
      Mode : {go, stop} ;
      Cmd : {move(REAL, REAL), stop} ;
      Waypoints = {0, 1, 2} ;
    }"""
    decls = {d.name: d for d in parse_text(src).contexts[0].decls}
    R = typeexpr.TBase("REAL")
    assert decls["MaxLevel"] == ast.ConstDecl("MaxLevel", N("250"), None)
    assert decls["Low"] == ast.ConstDecl("Low", N("120.5"), R)
    assert decls["Ids"].type == typeexpr.TSet(typeexpr.TBase("NATURAL"))
    assert decls["Route"].type == typeexpr.TSeq(typeexpr.TTuple((R, R)))
    assert decls["Pair"].type == typeexpr.TTuple((R, typeexpr.TBase("BOOL")))
    assert decls["Speed"].type == typeexpr.TFunc((R, R, typeexpr.TBase("INTEGER")), R)
    assert decls["Higher"].type == typeexpr.TFunc((typeexpr.TFunc((R,), R),), typeexpr.TBase("BOOL"))
    assert decls["Mode"].type == typeexpr.TEnum(("go", "stop"))
    assert decls["Cmd"].type == typeexpr.TConstructors(
        (typeexpr.Constructor("move", (R, R)), typeexpr.Constructor("stop", ())))
    assert decls["Waypoints"].value == ast.SetLit((N("0"), N("1"), N("2")))  # type: ignore[union-attr]


def test_comments_are_ignored() -> None:
    src = """// a line comment
    /* a block
       comment */ node n { // trailing
      inputs(a : REAL) /* inline */ outputs(o : REAL)
      guarantee(o == /* in a formula */ a) }"""
    (node,) = parse_text(src).nodes
    assert node.guarantees[0].formula == ast.Compare(("==",), (V("o"), V("a")))


# ---------------------------------------------------------------------------
# Formulas
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("text,kind,sep", [
    ("forall(x in REAL | x == x)", "forall", "|"),
    ("forall(x in REAL; x == x)", "forall", ";"),
    ("exists(x in REAL | x == x)", "exists", "|"),
    ("exists_unique(x in REAL | x == x)", "exists_unique", "|"),
    ("exists!(x in REAL ; x == x)", "exists_unique", ";"),
    ("exists !(x in REAL | x == x)", None, None),
])
def test_quantifier_forms(text: str, kind: str | None, sep: str | None) -> None:
    if kind is None:
        with pytest.raises(RclError):
            parse_formula(text)
        return
    q = parse_formula(text)
    assert q == ast.Quant(kind, (ast.Binding(("x",), typeexpr.TBase("REAL")),),  # type: ignore[arg-type]
                          ast.Compare(("==",), (V("x"), V("x"))))


def test_quantifier_domains() -> None:
    q = parse_formula("forall(x, y in REAL, i in NATURAL, c in RadStat, s in {1, 2}, q in set(REAL), "
                      "w in seq(INTEGER), v in in.points | TRUE)")
    assert isinstance(q, ast.Quant)
    assert [b.names for b in q.bindings] == [("x", "y"), ("i",), ("c",), ("s",), ("q",), ("w",), ("v",)]
    assert [b.domain for b in q.bindings] == [
        typeexpr.TBase("REAL"), typeexpr.TBase("NATURAL"), typeexpr.TName("RadStat"), ast.SetLit((N("1"), N("2"))),
        typeexpr.TSet(typeexpr.TBase("REAL")), typeexpr.TSeq(typeexpr.TBase("INTEGER")), V("points", "in")]


def test_precedence_loosest_first() -> None:
    # <=> looser than ->, looser than or, looser than and, looser than not,
    # looser than comparison, looser than + -, looser than * /, looser than unary -.
    e = parse_formula("a <=> b -> c or d and not e == -f + g * h")
    a, b, c, d, e_, f, g, h = (V(n) for n in "abcdefgh")
    expected = ast.Binary("<=>", a, ast.Binary("->", b, ast.Binary("or", c, ast.Binary(
        "and", d, ast.Unary("not", ast.Compare(("==",), (e_, ast.Binary(
            "+", ast.Unary("-", f), ast.Binary("*", g, h)))))))))
    assert e == expected


def test_associativity() -> None:
    a, b, c = V("a"), V("b"), V("c")
    assert parse_formula("a -> b -> c") == ast.Binary("->", a, ast.Binary("->", b, c))
    assert parse_formula("a or b or c") == ast.Binary("or", ast.Binary("or", a, b), c)
    assert parse_formula("a - b - c") == ast.Binary("-", ast.Binary("-", a, b), c)
    assert parse_formula("a / b * c") == ast.Binary("*", ast.Binary("/", a, b), c)
    assert parse_formula("a <=> b <=> c") == ast.Binary("<=>", ast.Binary("<=>", a, b), c)


def test_parentheses_are_recorded_for_lint_but_not_compared() -> None:
    plain = parse_formula("a and b -> c")
    paren = parse_formula("(a and b) -> c")
    assert plain == paren
    assert isinstance(plain, ast.Binary) and isinstance(paren, ast.Binary)
    assert not plain.left.parenthesised  # type: ignore[union-attr]
    assert paren.left.parenthesised  # type: ignore[union-attr]


@pytest.mark.parametrize("text,ops", [
    ("0 <= in.r < 120", ("<=", "<")),
    ("a == b != c", ("==", "!=")),
    ("a > b >= c <= d", (">", ">=", "<=")),
])
def test_chained_comparisons(text: str, ops: tuple[str, ...]) -> None:
    e = parse_formula(text)
    assert isinstance(e, ast.Compare) and e.ops == ops and len(e.operands) == len(ops) + 1


def test_membership_and_literals() -> None:
    assert parse_formula("x !in {red, orange}") == ast.Member(V("x"), ast.SetLit((V("red"), V("orange"))), True)
    assert parse_formula("x in {}") == ast.Member(V("x"), ast.SetLit(()), False)
    assert parse_formula("[1, 2.5, 3e2] == s") == ast.Compare(
        ("==",), (ast.SeqLit((N("1"), N("2.5"), N("3e2"))), V("s")))
    assert parse_formula("(a, b + 1) == out.p") == ast.Compare(
        ("==",), (ast.TupleLit((V("a"), ast.Binary("+", V("b"), N("1")))), V("p", "out")))
    assert parse_formula("[] == s") == ast.Compare(("==",), (ast.SeqLit(()), V("s")))
    assert parse_formula("TRUE and not FALSE") == ast.Binary("and", ast.BoolLit(True),
                                                             ast.Unary("not", ast.BoolLit(False)))


def test_names_prefixes_primes_and_applications() -> None:
    e = parse_formula("out.command == move(x'', in.y') and in.at(x', y') == TRUE")
    assert e == ast.Binary(
        "and",
        ast.Compare(("==",), (V("command", "out"), ast.Apply(V("move"), (V("x''"), V("y'", "in"))))),
        ast.Compare(("==",), (ast.Apply(V("at", "in"), (V("x'"), V("y'"))), ast.BoolLit(True))))
    assert parse_formula("f()") == ast.Apply(V("f"), ())


def test_keywords_of_other_contexts_are_names_in_formulas() -> None:
    # "x" is the product sign in types, but an ordinary variable in formulas.
    e = parse_formula("forall(x in REAL | x * x >= 0)")
    assert isinstance(e, ast.Quant) and e.variables == ("x",)
    assert parse_formula("node == inputs") == ast.Compare(("==",), (V("node"), V("inputs")))


# ---------------------------------------------------------------------------
# Locations
# ---------------------------------------------------------------------------

def test_locations_point_into_the_file() -> None:
    spec = parse_file(CASE_STUDY)
    lines = CASE_STUDY.read_text(encoding="utf-8").splitlines()
    agent = spec.nodes[2]
    assert lines[agent.loc.line - 1].startswith("node Agent")
    g3 = agent.guarantees[2]
    assert lines[g3.loc.line - 1][g3.loc.col - 1:].startswith("guarantee(")
    q = g3.formula
    assert isinstance(q, ast.Quant)
    b = q.bindings[0]
    for name, loc in zip(b.names, b.name_locs):
        assert lines[loc.line - 1][loc.col - 1:].startswith(name)
    assert str(agent.loc).startswith(str(CASE_STUDY) + ":")


def test_parse_formula_locations_are_offset_into_the_plan() -> None:
    # A formula that starts at plan.yaml line 12, column 9.
    e = parse_formula("in.r >= 0 and\n  out.level < 250", "plan.yaml", line=12, col=9)
    assert isinstance(e, ast.Binary)
    left, right = e.left, e.right
    assert isinstance(left, ast.Compare) and isinstance(right, ast.Compare)
    r = left.operands[0]
    assert (r.loc.file, r.loc.line, r.loc.col) == ("plan.yaml", 12, 9)
    assert (left.operands[1].loc.line, left.operands[1].loc.col) == (12, 17)
    level = right.operands[0]
    # Second line of the formula: the column is not shifted.
    assert (level.loc.line, level.loc.col) == (13, 3)


# ---------------------------------------------------------------------------
# Syntax errors
# ---------------------------------------------------------------------------

def test_missing_parenthesis() -> None:
    loc, msg = syntax_error("node n { inputs(a : REAL outputs(o : REAL) guarantee(o > a) }")
    assert (loc.file, loc.line, loc.col) == ("f.rcl", 1, 26)
    assert msg == "unexpected 'outputs'; expected one of ')', ',', '-->', 'x', a unit such as [m]"


def test_missing_closing_parenthesis_of_a_quantifier() -> None:
    loc, msg = syntax_error("node n { inputs() outputs(o : REAL)\n  guarantee(forall(x in REAL | x > o) }")
    assert (loc.line, loc.col) == (2, 39)
    assert msg == "unexpected '}'; expected one of ')', '<=>'"


def test_bad_character() -> None:
    loc, msg = syntax_error("node n { inputs(a : REAL) outputs(o : REAL) guarantee(o > a $ 1) }")
    assert (loc.line, loc.col) == (1, 61)
    assert msg.startswith("unexpected character '$'; expected one of ")
    for alt in ("')'", "'->'", "'and'", "'or'", "'+'", "a comparison"):
        assert alt in msg


def test_single_equals_gets_a_hint() -> None:
    loc, msg = syntax_error("node n { inputs(a : REAL) outputs(o : REAL) guarantee(o = a) }")
    assert (loc.line, loc.col) == (1, 57)
    assert msg.startswith("unexpected '='") and msg.endswith("(equality is written '==')")


def test_unexpected_end_of_input() -> None:
    text = "node n { inputs(a : REAL) outputs(o : REAL)\n  guarantee(o > a)\n\n"
    loc, msg = syntax_error(text)
    assert (loc.line, loc.col) == (2, 19)  # just after the last token
    assert msg == ("unexpected end of input; expected one of 'A', 'G', 'assume', 'guarantee', 'initially', 'periodic', "
                   "'progress', 'ready', 'triggered', 'while', 'within', '}'")


def test_keywords_are_listed_as_expected() -> None:
    loc, msg = syntax_error("node n { inputs() outputs(o : REAL) guarantee(o > and) }")
    assert (loc.line, loc.col) == (1, 51)
    for alt in ("'forall'", "'exists'", "'exists_unique'", "'exists!'", "'TRUE'", "a name", "a number",
                "an in./out. name"):
        assert alt in msg


def test_error_on_line_five_reports_line_five() -> None:
    text = ("// header\n"
            "context { T : REAL ; }\n"
            "node n {\n"
            "  inputs(a : T) outputs(o : T)\n"
            "  guarantee(o == == a)\n"
            "}\n")
    loc, msg = syntax_error(text, "sys.rcl")
    assert (loc.file, loc.line, loc.col) == ("sys.rcl", 5, 18)
    assert text.splitlines()[4][loc.col - 1:].startswith("== a")
    assert msg.startswith("unexpected '=='")


def test_trailing_garbage_and_unterminated_comment() -> None:
    loc, msg = syntax_error("node n { inputs() outputs(o : REAL) guarantee(o > 0) } garbage")
    assert (loc.line, loc.col) == (1, 56)
    assert msg == "unexpected 'garbage'; expected one of 'context', 'node', end of file"
    loc, msg = syntax_error("node n { inputs() outputs(o : REAL)\n guarantee(o > 0 /* oops ) }")
    assert (loc.line, loc.col) == (2, 18)
    assert msg.startswith("unterminated /* comment")


def test_parse_formula_errors_are_located_in_the_plan() -> None:
    with pytest.raises(RclError) as info:
        parse_formula("in.r >= 0 and $", "plan.yaml", line=7, col=11)
    (d,) = info.value.diagnostics
    assert (d.loc.file, d.loc.line, d.loc.col) == ("plan.yaml", 7, 25)
    with pytest.raises(RclError) as info:
        parse_formula("in.r >= 0 and\n   (", "plan.yaml", line=7, col=11)
    (d,) = info.value.diagnostics
    assert (d.loc.line, d.loc.col) == (8, 5)
    assert d.message.startswith("unexpected end of input")
    assert str(d).startswith("plan.yaml:8:5: error: ")


def test_unreadable_file_is_a_located_error(tmp_path: Path) -> None:
    with pytest.raises(RclError) as info:
        parse_file(tmp_path / "missing.rcl")
    (d,) = info.value.diagnostics
    assert d.code == "E-io" and d.loc.line == 1


# ---------------------------------------------------------------------------
# The grammar is unambiguous on the case study
# ---------------------------------------------------------------------------

def test_grammar_is_unambiguous_on_the_case_study() -> None:
    """Earley with ambiguity='explicit' over the same grammar finds exactly
    one derivation (no _ambig nodes), and it yields the LALR parser's AST."""
    text = CASE_STUDY.read_text(encoding="utf-8")
    earley = Lark(grammar_text(), parser="earley", ambiguity="explicit", keep_all_tokens=True,
                  maybe_placeholders=True)
    tree = earley.parse(text)
    assert not list(tree.find_data("_ambig"))
    assert ast_from_tree(tree, "case.rcl") == parse_text(text, "case.rcl")


def test_the_lalr_tables_are_cached_per_user_and_rebuilt_from_the_cache(tmp_path: Path,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.lang.parser import _BUILDER, lark_cache_file
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    where = lark_cache_file("rcl")
    assert isinstance(where, str) and where.startswith(str(tmp_path / "cache" / "rclverify"))
    options = dict(parser="lalr", start=["start", "expr"], keep_all_tokens=True, maybe_placeholders=True,
                   transformer=_BUILDER, cache=where)
    built = Lark(grammar_text(), **options)
    assert Path(where).is_file()
    loaded = Lark(grammar_text(), **options)  # from the file
    text = "node A { inputs(x : REAL) outputs(y : REAL) guarantee(out.y >= in.x) }"
    assert loaded.parse(text, start="start") == built.parse(text, start="start")
    (tmp_path / "blocked").write_text("a file, not a directory")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "blocked"))
    assert lark_cache_file("rcl") is False  # no cache rather than an error
