"""Fuzz test: the checker never raises anything but its own located errors.

Hypothesis mutates the repository's RCL contracts and its plan, and
generates RCL formulas and YAML from token vocabularies.  Every case runs the
front end as ``rclverify check`` does (parse, type-check, file warnings,
lint) plus the printers; the only exception allowed is
:class:`~rclverify.lang.errors.RclError` (which :class:`PlanError` extends),
and every diagnostic it carries must be located (line >= 1).  A case that
parses must also round-trip through ``fmt``.

Runs are derandomized (a fixed seed derived from the test) so CI sees the
same 2,400 cases every time; together they take a few seconds.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.semantics.encode import Encoder, EncodingError
from rclverify.model.plan.load import read_plan_data
from rclverify.lang.errors import RclError
from rclverify.lang.filewarn import file_warnings
from rclverify.lang.latex import to_latex
from rclverify.lang.lint import lint
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.typecheck import check

ROOT = Path(__file__).resolve().parents[2]
SEEDS = [p.read_text(encoding="utf-8") for p in sorted(ROOT.rglob("*.rcl")) if ".git" not in p.parts]
PLAN = (ROOT / "contracts" / "plan.yaml").read_text(encoding="utf-8")

VOCAB = ["(", ")", "{", "}", "<", ">", "<>", ",", ";", ":", "|", "=", "==", "!=", "<=", ">=", "+", "-", "*", "/",
         "and", "or", "not", "->", "<=>", "in", "!in", "upto", "x", "-->", "forall(", "exists(", "exists_unique(",
         "exists!(", "A(", "G(", "assume(", "guarantee(", "node", "context", "inputs(", "outputs(", "topics(",
         "matches", "set(", "seq(", "REAL", "INTEGER", "NATURAL", "BOOL", "STRING", "TRUE", "FALSE", "0", "1",
         "2.5", "1e400", '"s"', '"', "'", "in.a", "out.o", "a", "o", "u", "v", "(u, v)", "[", "]", "/*", "*/",
         "//", "\n", "\t", "é", "\x00", "pkg/Msg", ".", "REAL.REAL", "NATURAL.INTEGER", "(1, 2)", "(in.a, 1)",
         # units of measure (docs/rcl-language.md): well-formed, unknown, malformed, affine
         "[m]", "[mm/m]", "[s^-2]", "[degC]", "[furlong]", "[m/]", "[(m]", "in.b", "[]",
         # progress, initial values and periodic outputs (docs/rcl-language.md)
         "initially(", "progress(", "eventually", "within", "steps", "periodic(", "progress( within 2 steps )",
         "initially( out.o == 0 )", "periodic( out.o, 100 ms )"]

FUZZ = settings(derandomize=True, deadline=None, database=None, max_examples=500,
                suppress_health_check=list(HealthCheck))


def run_front_end(text: str) -> None:
    """What ``rclverify check`` and ``fmt``/``latex`` do with one file's text;
    fails the test on any exception other than a located RclError."""
    try:
        spec = parse_text(text, "fuzz.rcl")
    except RclError as e:
        assert e.diagnostics and all(d.loc.line >= 1 for d in e.diagnostics), e
        return
    assert parse_text(to_rcl(spec), "fuzz.rcl") == spec, to_rcl(spec)
    file_warnings(spec)
    lint(spec)
    try:
        checked = check([spec])
    except RclError as e:
        assert e.diagnostics and all(d.loc.line >= 1 for d in e.diagnostics), e
        return
    to_latex(spec)
    # The Z3 encoding the calculus and health checks use: a located
    # EncodingError for what it does not support, never anything else.
    enc = Encoder(checked.env)
    for n in spec.nodes:
        for clause in n.assumes + n.guarantees + n.initially:
            try:
                enc.formula(clause.formula, checked.nodes[n.name])
            except EncodingError as e:
                assert ":" in str(e), e


mutation = st.tuples(st.sampled_from(["insert", "delete", "replace", "duplicate"]),
                     st.floats(0, 1), st.integers(1, 40), st.sampled_from(VOCAB))


def mutate(text: str, ops: list[tuple[str, float, int, str]]) -> str:
    for op, where, length, token in ops:
        i = int(where * len(text))
        if op == "insert":
            text = text[:i] + token + text[i:]
        elif op == "delete":
            text = text[:i] + text[i + length:]
        elif op == "replace":
            text = text[:i] + token + text[i + length:]
        else:
            text = text[:i] + text[i:i + length] + text[i:]
    return text


@FUZZ
@given(st.sampled_from(SEEDS), st.lists(mutation, min_size=1, max_size=6))
def test_mutated_contracts(seed: str, ops: list[tuple[str, float, int, str]]) -> None:
    run_front_end(mutate(seed, ops))


@FUZZ
@given(st.lists(st.sampled_from(VOCAB), max_size=30))
def test_generated_formulas(tokens: list[str]) -> None:
    body = " ".join(tokens)
    run_front_end("context { K = 3 ; E : {e1, e2} ; }\n"
                  "node n { inputs(a : REAL, b : REAL [mm], s : set((E, E))) outputs(o : BOOL)\n guarantee(" + body
                  + ") }\n")


YAML_VOCAB = ["&a ", "*a", "&b ", "*b", "[", "]", "{", "}", ": ", "- ", "\n", "  ", "contracts", "x", "'", '"',
              "!!python/object:os.system", "!!binary", "? ", "|", ">", "#", ",", "%YAML 1.1\n", "---\n", "...\n"]


@settings(derandomize=True, deadline=None, database=None, max_examples=500, suppress_health_check=list(HealthCheck))
@given(st.one_of(st.lists(mutation.map(lambda m: (m[0], m[1], m[2], YAML_VOCAB[hash(m[3]) % len(YAML_VOCAB)])),
                          min_size=1, max_size=6).map(lambda ops: mutate(PLAN, ops)),
                 st.lists(st.sampled_from(YAML_VOCAB), max_size=40).map("".join)))
def test_plan_yaml(tmp_path_factory: pytest.TempPathFactory, text: str) -> None:
    d = tmp_path_factory.getbasetemp() / "fuzz-ws"
    (d / "contracts").mkdir(parents=True, exist_ok=True)
    (d / "contracts" / "plan.yaml").write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        read_plan_data(d, "contracts/plan.yaml")
    except RclError as e:
        assert e.diagnostics and all(d.loc.line >= 1 for d in e.diagnostics), e
