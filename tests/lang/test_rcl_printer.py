"""RCL and LaTeX printers: round trip, minimal parentheses, paper notation."""
from __future__ import annotations

import re
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError
from rclverify.lang.latex import expr_to_latex, to_latex, type_to_latex
from rclverify.lang.parser import parse_file, parse_formula, parse_text
from rclverify.lang.printer import expr_to_rcl, to_rcl, type_to_rcl

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"

# Words that can never be names in RCL formulas (see rcl.lark), plus the
# type keywords set/seq, which are names only where no type may stand.
RESERVED = {"and", "or", "not", "in", "forall", "exists", "exists_unique", "TRUE", "FALSE",
            "REAL", "INTEGER", "NATURAL", "BOOL", "set", "seq"}

# ---------------------------------------------------------------------------
# Strategies: random ASTs
# ---------------------------------------------------------------------------

identifiers = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,5}", fullmatch=True).filter(lambda s: s not in RESERVED)
plain_names = st.one_of(st.sampled_from(["x", "y", "i", "r", "wayP", "node", "inputs", "matches"]), identifiers)
primed = st.builds(lambda n, k: n + "'" * k, plain_names, st.integers(0, 2))
prefixes = st.sampled_from([None, "in", "out"])
variables = st.builds(ast.Var, primed, prefixes)
numbers = st.builds(ast.NumLit, st.from_regex(r"[0-9]{1,3}(\.[0-9]{1,2})?([eE][+-]?[0-9]{1,2})?", fullmatch=True))
bools = st.builds(ast.BoolLit, st.booleans())

base_types = st.builds(typeexpr.TBase, st.sampled_from(["REAL", "INTEGER", "NATURAL", "BOOL"]))
type_names = st.builds(typeexpr.TName, plain_names)


def _extend_types(inner: st.SearchStrategy[typeexpr.TypeExpr]) -> st.SearchStrategy[typeexpr.TypeExpr]:
    ctor = st.builds(typeexpr.Constructor, plain_names, st.lists(inner, max_size=2).map(tuple))
    with_args = st.builds(typeexpr.Constructor, plain_names, st.lists(inner, min_size=1, max_size=2).map(tuple))
    return st.one_of(
        st.builds(typeexpr.TSet, inner),
        st.builds(typeexpr.TSeq, inner),
        st.builds(typeexpr.TTuple, st.lists(inner, min_size=2, max_size=3).map(tuple)),
        st.builds(typeexpr.TFunc, st.lists(inner, min_size=1, max_size=3).map(tuple), inner),
        st.builds(lambda a, rest: typeexpr.TConstructors((a, *rest)), with_args, st.lists(ctor, max_size=2)),
    )


types: st.SearchStrategy[typeexpr.TypeExpr] = st.recursive(
    st.one_of(base_types, type_names, st.just(typeexpr.TEmpty()),
              st.builds(typeexpr.TEnum, st.lists(plain_names, min_size=1, max_size=3).map(tuple))),
    _extend_types, max_leaves=6)


def _domain(children: st.SearchStrategy[ast.Expr]) -> st.SearchStrategy[object]:
    # A bare unprefixed name as domain is a type name (TName), by definition.
    terms = children.filter(lambda e: not (isinstance(e, ast.Var) and e.prefix is None))
    return st.one_of(base_types, type_names, st.builds(typeexpr.TSet, types), st.builds(typeexpr.TSeq, types), terms)


def _extend_exprs(children: st.SearchStrategy[ast.Expr]) -> st.SearchStrategy[ast.Expr]:
    small = st.lists(children, max_size=3).map(tuple)
    binding = st.builds(ast.Binding, st.lists(primed, min_size=1, max_size=2).map(tuple), _domain(children))
    compare = st.integers(1, 3).flatmap(lambda n: st.builds(
        ast.Compare,
        st.tuples(*[st.sampled_from(["==", "!=", "<", "<=", ">", ">="])] * n),
        st.tuples(*[children] * (n + 1))))
    return st.one_of(
        st.builds(ast.Unary, st.sampled_from(["not", "-"]), children),
        st.builds(ast.Binary, st.sampled_from(["<=>", "->", "or", "and", "+", "-", "*", "/"]), children, children),
        compare,
        st.builds(ast.Member, children, children, st.booleans()),
        st.builds(ast.SetLit, small),
        st.builds(ast.SeqLit, small),
        st.builds(ast.TupleLit, st.lists(children, min_size=2, max_size=3).map(tuple)),
        st.builds(ast.Apply, variables, small),
        st.builds(ast.Quant, st.sampled_from(["forall", "exists", "exists_unique"]),
                  st.lists(binding, min_size=1, max_size=2).map(tuple), children),
    )


all_forms: st.SearchStrategy[ast.Expr] = st.recursive(st.one_of(variables, numbers, bools), _extend_exprs,
                                                      max_leaves=12)


def _extend_operators(children: st.SearchStrategy[ast.Expr]) -> st.SearchStrategy[ast.Expr]:
    compare = st.integers(1, 2).flatmap(lambda n: st.builds(
        ast.Compare, st.tuples(*[st.sampled_from(["==", "<", ">="])] * n), st.tuples(*[children] * (n + 1))))
    return st.one_of(
        st.builds(ast.Binary, st.sampled_from(["<=>", "->", "or", "and", "+", "-", "*", "/"]), children, children),
        st.builds(ast.Unary, st.sampled_from(["not", "-"]), children),
        compare,
        st.builds(ast.Member, children, children, st.booleans()),
    )


# Operator trees over a few names: exercises precedence and associativity.
operator_trees: st.SearchStrategy[ast.Expr] = st.recursive(
    st.builds(ast.Var, st.sampled_from(["a", "b", "c"])), _extend_operators, max_leaves=8)
exprs = st.one_of(operator_trees, all_forms)

ros_types = st.one_of(st.from_regex(r"[a-z_]{1,6}(/[A-Z][a-z]{0,5}){1,2}", fullmatch=True), plain_names)
topics = st.builds(ast.Topic, ros_types, plain_names, st.one_of(st.none(), st.builds(ast.Var, primed, prefixes)))
io_vars = st.builds(ast.IOVar, plain_names, types)
clauses = st.builds(ast.Clause, exprs)
decls = st.one_of(st.builds(ast.TypeDecl, plain_names, types),
                  st.builds(ast.ConstDecl, plain_names, exprs, st.one_of(st.none(), types)))
nodes = st.builds(ast.Node, plain_names,
                  st.lists(io_vars, max_size=3).map(tuple), st.lists(io_vars, max_size=3).map(tuple),
                  st.lists(topics, max_size=2).map(tuple), st.lists(clauses, max_size=2).map(tuple),
                  st.lists(clauses, max_size=2).map(tuple))
specs = st.builds(ast.Spec, st.lists(st.builds(ast.Context, st.lists(decls, max_size=3).map(tuple)),
                                     max_size=2).map(tuple),
                  st.lists(nodes, max_size=3).map(tuple))

SETTINGS = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------------------
# RCL printer
# ---------------------------------------------------------------------------

def test_case_study_round_trip() -> None:
    spec = parse_file(CASE_STUDY)
    text = to_rcl(spec)
    again = parse_text(text)
    assert again == spec
    assert to_rcl(again) == text  # printing is a fixed point after one round
    assert parse_text(to_rcl(spec, explicit=True)) == spec


def test_case_study_printed_formulas() -> None:
    spec = parse_file(CASE_STUDY)
    sensor = spec.nodes[3]
    # Parentheses the source wrote around the consequent are not required by
    # precedence; those around the inner implications are.
    assert expr_to_rcl(sensor.guarantees[0].formula) == (
        "forall(i in NATURAL | in.command == inspect(i) -> out.inspected(i) == TRUE"
        " and (0 <= in.r and in.r < 120 -> out.radiationStatus == green)"
        " and (120 <= in.r and in.r < 250 -> out.radiationStatus == orange)"
        " and (250 <= in.r -> out.radiationStatus == red))")
    agent = spec.nodes[2]
    assert expr_to_rcl(agent.guarantees[1].formula, explicit=True) == (
        "forall(x', y' in REAL, i in NATURAL | (in.at(x', y') == TRUE and in.wayP(x', y') == i"
        " and in.inspected(i) == FALSE) -> out.command == inspect(i))")
    assert "context {\n  WayP : REAL x REAL --> NATURAL ;\n" in to_rcl(spec)
    assert "  topics( gazebo_radiation_plugin/Snapshot position matches(out.position) )\n" in to_rcl(spec)


def test_minimal_parentheses_examples() -> None:
    cases = {
        "(a and b) -> c": "a and b -> c",
        "a -> (b -> c)": "a -> b -> c",
        "(a -> b) -> c": "(a -> b) -> c",
        "(a or b) and c": "(a or b) and c",
        "not (a and b)": "not (a and b)",
        "(not a) and b": "not a and b",
        "a - (b - c)": "a - (b - c)",
        "(a - b) - c": "a - b - c",
        "-(a + b) * c": "-(a + b) * c",
        "- (-a)": "- -a",
        "(a < b) == c": "(a < b) == c",
        "a < (b + 1) <= c": "a < b + 1 <= c",
        "(x in S) in T": "(x in S) in T",
        "x in (a or b)": "x in (a or b)",
        "forall(x in (a + b) | (x > 0))": "forall(x in a + b | x > 0)",
        "exists!(x in {1, 2}; f((x, 1)))": "exists_unique(x in {1, 2} | f((x, 1)))",
        "((a <=> b) <=> c)": "a <=> b <=> c",
        "a <=> (b <=> c)": "a <=> (b <=> c)",
    }
    for src, printed in cases.items():
        assert expr_to_rcl(parse_formula(src)) == printed, src


def test_type_printing() -> None:
    R, B = typeexpr.TBase("REAL"), typeexpr.TBase("BOOL")
    assert type_to_rcl(typeexpr.TFunc((R, R), B)) == "REAL x REAL --> BOOL"
    assert type_to_rcl(typeexpr.TFunc((typeexpr.TFunc((R,), R),), typeexpr.TFunc((R,), B))) == "(REAL --> REAL) --> (REAL --> BOOL)"
    assert type_to_rcl(typeexpr.TConstructors((typeexpr.Constructor("move", (R, R)), typeexpr.Constructor("stop", ())))) == (
        "{move(REAL, REAL), stop}")
    assert type_to_rcl(typeexpr.TSeq(typeexpr.TTuple((R, typeexpr.TName("RadStat"))))) == "seq((REAL, RadStat))"
    assert type_to_rcl(typeexpr.TEmpty()) == "{}"


def _paren_pairs(text: str) -> list[tuple[int, int]]:
    pairs, stack = [], []
    for i, ch in enumerate(text):
        if ch == "(":
            stack.append(i)
        elif ch == ")":
            pairs.append((stack.pop(), i))
    return pairs


@SETTINGS
@given(exprs)
def test_expression_round_trip(e: ast.Expr) -> None:
    text = expr_to_rcl(e)
    assert parse_formula(text) == e, text
    assert parse_formula(expr_to_rcl(e, explicit=True)) == e


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(exprs)
def test_no_parenthesis_pair_can_be_dropped(e: ast.Expr) -> None:
    """Minimality: removing any one pair of parentheses from the printed text
    either breaks the syntax or changes the formula."""
    text = expr_to_rcl(e)
    for start, end in _paren_pairs(text):
        shorter = text[:start] + " " + text[start + 1:end] + " " + text[end + 1:]
        try:
            other = parse_formula(shorter)
        except RclError:
            continue
        assert other != e, f"redundant parentheses at {start} in {text!r}"


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(specs)
def test_spec_round_trip(spec: ast.Spec) -> None:
    text = to_rcl(spec)
    assert parse_text(text) == spec, text


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(types)
def test_type_round_trip(t: typeexpr.TypeExpr) -> None:
    spec = parse_text(f"context {{ T : {type_to_rcl(t)} ; }}")
    assert spec.contexts[0].decls[0].type == t


# ---------------------------------------------------------------------------
# LaTeX
# ---------------------------------------------------------------------------

def _agent_block(tex: str) -> str:
    start = tex.index(r"\paragraph{Agent}")
    return tex[start:tex.index(r"\end{tabularx}", start)]


def test_latex_agent_fragments() -> None:
    tex = to_latex(parse_file(CASE_STUDY))
    agent = _agent_block(tex)
    expected = [
        r"inputs & $(\mathit{wayP} : \mathit{WayP}, \mathit{at} : \mathit{AtType}, "
        r"\mathit{radiationStatus} : \mathit{RadStat}, \mathit{inspected} : \mathit{InspectedType})$",
        r"outputs & $(\mathit{command} : \mathit{CommandSet})$",
        r"\texttt{gazebo\_radiation\_plugin/Snapshot}~\texttt{wayPNow} matches: $\mathit{in.wayP}$",
        r"assume & $(\mathit{in.radiationStatus} \in \{\mathit{red}, \mathit{orange}, \mathit{green}\})$",
        r"\forall x', y' \in \mathbb{R}, i \in \mathbb{N} \bullet \mathit{in.at}(x', y') = \mathit{TRUE} \land",
        r"\mathit{in.radiationStatus} \notin \{\mathit{red}, \mathit{orange}\} \Rightarrow \exists x, y \in",
        r"\forall x'', y'' \in \mathbb{R} \bullet \mathit{in.wayP}(x'', y'') \neq i + 1",
        r"\mathit{out.command} = \mathit{inspect}(i))$",
        # a quantifier followed by more text is parenthesised
        r"\lor \lnot (\exists x, y \in \mathbb{R} \bullet \mathit{in.wayP}(x, y) = i + 1) \Rightarrow",
    ]
    for fragment in expected:
        assert fragment in agent, fragment
    assert agent.count("guarantee & $(") == 3
    assert agent.count("assume & $(") == 1


def test_latex_context_and_other_nodes() -> None:
    tex = to_latex(parse_file(CASE_STUDY))
    assert r"$\mathit{WayP}$ & $: \mathbb{R} \times \mathbb{R} \rightarrow \mathbb{N}$" in tex
    assert r"$\mathit{CommandSet}$ & $: \{\mathit{move}(\mathbb{R}, \mathbb{R}), \mathit{inspect}(\mathbb{N})\}$" in tex
    assert r"$\mathit{SensorsType}$ & $: \emptyset$" in tex
    assert r"\exists!\, x, y \in \mathbb{R} \bullet \mathit{out.position}(x, y)" in tex
    assert r"\iff \mathit{out.at}(x, y) = \mathit{TRUE}" in tex
    assert r"(0 \leq \mathit{in.r} \land \mathit{in.r} < 120 \Rightarrow \mathit{out.radiationStatus} = " \
           r"\mathit{green})" in tex
    assert [m.group(1) for m in re.finditer(r"\\paragraph\{(\w+)\}", tex)] == [
        "Context", "Localisation", "Navigation", "Agent", "RadiationSensor"]


def test_latex_document_shape() -> None:
    spec = parse_file(CASE_STUDY)
    tex = to_latex(spec)
    first = tex.splitlines()[0]
    assert first.startswith("% ") and "remote_inspection.rcl:1" in first and "generated by rclverify" in first
    assert tex.count(r"\begin{document}") == 1 and tex.rstrip().endswith(r"\end{document}")
    assert tex.count(r"\begin{tabularx}") == tex.count(r"\end{tabularx}") == 5
    assert to_latex(spec) == tex  # deterministic
    body = to_latex(spec, document=False)
    assert r"\documentclass" not in body and r"\paragraph{Agent}" in body
    # No absolute path of the machine leaks into the artifact.
    absolute = parse_text(CASE_STUDY.read_text(encoding="utf-8"), str(CASE_STUDY))
    assert str(CASE_STUDY.parent) not in to_latex(absolute)
    for line in tex.splitlines():
        if not line.startswith("%"):
            assert line.count("$") % 2 == 0, line
    _assert_balanced(tex)


def test_latex_escapes_and_numbers() -> None:
    assert expr_to_latex(parse_formula("in.max_speed >= 1.5e-3 * my_var'")) == (
        r"\mathit{in.max\_speed} \geq 1.5 \times 10^{-3} \cdot \mathit{my\_var}'")
    assert expr_to_latex(parse_formula("s == {} and q == [1, 2] and (a, b) == t")) == (
        r"s = \emptyset \land q = \langle 1, 2 \rangle \land (a, b) = t")
    assert expr_to_latex(parse_formula("a and b -> c"), explicit=True) == r"(a \land b) \Rightarrow c"
    assert type_to_latex(typeexpr.TSet(typeexpr.TBase("INTEGER"))) == r"\mathcal{P}(\mathbb{Z})"
    spec = parse_text("node my_node { inputs(a_b : REAL) outputs() topics(my_pkg/My_Type f_1 matches(in.a_b)) "
                      "guarantee(TRUE) }")
    tex = to_latex(spec, document=False)
    assert r"\paragraph{my\_node}" in tex
    assert r"\texttt{my\_pkg/My\_Type}~\texttt{f\_1} matches: $\mathit{in.a\_b}$" in tex


def _assert_balanced(tex: str) -> None:
    depth = 0
    for i, ch in enumerate(tex):
        if ch in "{}" and i > 0 and tex[i - 1] == "\\":
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        assert depth >= 0, tex[max(0, i - 40):i + 1]
    assert depth == 0


@SETTINGS
@given(exprs)
def test_latex_of_random_formulas_is_balanced(e: ast.Expr) -> None:
    tex = expr_to_latex(e)
    _assert_balanced(tex)
    assert tex.count("(") == tex.count(")")
    assert "$" not in tex


def test_a_nodes_latex_block_names_its_file_and_the_document_has_one_frame() -> None:
    from rclverify.lang.latex import document_frame, node_latex
    spec = parse_file(CASE_STUDY)
    blocks = [node_latex(n) for n in spec.nodes]
    for n, block in zip(spec.nodes, blocks):
        # an absolute file name is cut to its name: no machine paths in artifacts
        assert block.splitlines()[0] == f"% node {n.name} (remote_inspection.rcl:{n.loc.line})"
        assert r"\documentclass" not in block and "<string>" not in block and "generated by" not in block
    begin, end = document_frame([spec.file])
    assert begin.splitlines()[0] == "% remote_inspection.rcl -- contracts generated by rclverify from RCL; do not edit"
    assert begin.count(r"\documentclass") == begin.count(r"\begin{document}") == 1 and end == "\\end{document}\n"
    _assert_balanced(begin + "".join(blocks) + end)
    # text parsed without a file name names none
    anonymous = parse_text("node n { inputs(a : REAL) outputs() guarantee(TRUE) }")
    tex = to_latex(anonymous)
    assert "<string>" not in tex and tex.startswith("% contracts generated by rclverify")
    assert "% node n (line 1)" in tex and "<string>" not in node_latex(anonymous.nodes[0])
    assert document_frame()[0].startswith("% contracts generated by rclverify")
