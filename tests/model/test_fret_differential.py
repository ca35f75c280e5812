"""rclverify's reading of imported FRET requirements against FRET's own past-time formalisation.

For each (scope, condition, timing) combination the importer translates
(rclverify.model.plan.fret.translate), a requirement written in FRET's
export format carries the ``ptExpanded`` formula FRET gives that
combination (the shapes of FRET v3.1.0's case-study exports, over this
test's variables).  On random finite traces the oracle evaluates that
past-time LTL formula at the trace's last step (FRET's finite-trace
reading: the requirement holds of a trace when the formula holds at its
end), with the small evaluator below.  (The one named difference: FRET's
``eventually`` is false on a trace that ends before its response, rclverify's
``currently_false``, so there the two agree when FRET is true exactly when
rclverify's verdict is ``true``.)  rclverify's side is the statement
the importer produced, parsed and type-checked by rclverify
(``parse_temporal``), its state formulas and the importer's state
variables evaluated by rclverify's evaluator, under the finite-trace
verdicts of docs/requirements.md and the monitor engine (``always``:
false at a step where F is false; the response pattern: false when a
trigger's ``next`` fails; ``eventually[<= N]``: false once step N passed
without F).  The two must agree: FRET true exactly when rclverify's verdict
is not ``false``.  A translation that drops the trigger's edge is the
control: it disagrees with FRET on some trace.
"""
from __future__ import annotations

import math
import random
import re
import zlib
from fractions import Fraction
from typing import Any, Callable

import msgspec
import pytest

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.fret.export import FretExport, FretRequirement, FretSemantics, FretVariable
from rclverify.model.plan.fret.requirements import Options, import_export
from rclverify.model.plan.state import parse_state_formula, state_types
from rclverify.model.plan.temporal import Temporal, parse_temporal, shape
from rclverify.semantics.evaluate import evaluate
from rclverify.lang import ast

CONTRACT = """
node Rover {
  inputs( obstacle : BOOL, asked : REAL, clear : BOOL, manual : BOOL )
  outputs( speed : REAL, braking : BOOL )
  assume( TRUE )
  guarantee( TRUE )
}
"""
VARS = {"obstacle": ("Input", "boolean"), "asked": ("Input", "double"), "clear": ("Input", "boolean"),
        "manual": ("Input", "boolean"), "speed": ("Output", "double"), "braking": ("Output", "boolean")}

#: (reqid, scope, condition, timing, pre_condition, post_condition, extra semantics, FRET's ptExpanded)
CASES: list[tuple[str, str, str, str, str | None, str, dict[str, Any], str]] = [
    ("ALWAYS", "null", "null", "always", None, "(speed <= 2.0)", {}, "(H (speed <= 2.0))"),
    ("NEVER", "null", "null", "never", None, "(speed <= 2.0)", {}, "(H (! (speed <= 2.0)))"),
    ("IMMEDIATELY", "null", "null", "immediately", None, "(braking | speed = 0.0)", {},
     "(H ((Z FALSE) -> (braking | (speed = 0.0))))"),
    ("WITHIN", "null", "null", "within", None, "(speed <= asked)", {"duration": 3},
     "(H ((H (! (speed <= asked))) -> (O[0,2] (Z FALSE))))"),
    ("FOR", "null", "null", "for", None, "(braking)", {"duration": 2}, "(H ((O[0,2] (! (Y TRUE))) -> braking))"),
    ("WHENEVER", "null", "noTrigger", "immediately", "(obstacle)", "(braking)", {}, "(H (obstacle -> braking))"),
    ("WHENEVER-NEXT", "null", "noTrigger", "next", "(obstacle)", "(braking)", {},
     "(H ((Y obstacle) -> (braking | (! (Y TRUE)))))"),
    ("HOLDING-NEXT", "null", "holding", "next", "(obstacle & speed = 0.0)", "(braking)", {},
     "(H ((Y (obstacle & (speed = 0.0))) -> (braking | (Z FALSE))))"),
    ("UPON", "null", "regular", "immediately", "(obstacle)", "(braking)", {},
     "(H ((obstacle & (Z (! obstacle))) -> braking))"),
    ("UPON-NEXT", "null", "regular", "next", "(obstacle)", "(! braking)", {},
     "(H ((Y (obstacle & (Z (! obstacle)))) -> ((! braking) | (Z FALSE))))"),
    ("UPON-ALWAYS", "null", "regular", "always", "(obstacle)", "(braking)", {},
     "(H ((H (! obstacle)) | (braking S (braking & (obstacle & ((Y (! obstacle)) | (! (Y TRUE))))))))"),
    ("UPON-UNTIL", "null", "regular", "until", "(obstacle)", "(braking)", {"stop_condition": "(clear)"},
     "(H ((H (! obstacle)) | (((! clear) S ((! clear) & (obstacle & (Z (! obstacle))))) -> braking)))"),
    ("IN-ALWAYS", "in", "null", "always", None, "(speed <= asked)", {"scope_mode": "manual"},
     "(H (manual -> (speed <= asked)))"),
    ("EVENTUALLY", "null", "null", "eventually", None, "(! braking)", {}, "(O (! braking))"),
    ("IN-NEVER", "in", "null", "never", None, "(speed <= asked)", {"scope_mode": "manual"},
     "(H (manual -> (! (speed <= asked))))"),
    ("IN-IMMEDIATELY", "in", "null", "immediately", None, "(braking)", {"scope_mode": "manual"},
     "(H ((manual & (Z (! manual))) -> braking))"),
    ("PREBOOL", "null", "noTrigger", "immediately", "(! obstacle & preBool ( false , obstacle ))", "(! braking)", {},
     "(H (((! obstacle) & (Y obstacle)) -> (! braking)))"),
    ("PERSISTED", "null", "null", "never", None, "(persisted(2, speed > 1.0))", {},
     "(H (! ((H[0,2] (speed > 1.0)) & (H[0,1] (Y TRUE)))))"),
    ("OCCURRED", "null", "noTrigger", "immediately", "(occurred(2, obstacle))", "(braking)", {},
     "(H (((TRUE S obstacle) & (O[0,2] obstacle)) -> braking))"),
    ("PERSISTED-PRE", "null", "regular", "immediately", "(persisted(1, preBool(false, obstacle)))", "(braking)", {},
     "(H ((((H[0,1] (Y obstacle)) & (H[0,0] (Y TRUE))) & (Z (! ((H[0,1] (Y obstacle)) & (H[0,0] (Y TRUE)))))) "
     "-> braking))"),
    ("FTP-IF-THEN", "null", "null", "always", None, "(if FTP then braking)", {}, "(H ((Z FALSE) -> braking))"),
    # the rest: FRET's templates (fret-electron/app/parser/semantics.json, its ptExpanded) over this test's names
    ("NEXT", "null", "null", "next", None, "(braking)", {}, "(H ((Y (Z FALSE)) -> braking))"),
    ("UNTIL", "null", "null", "until", None, "(braking)", {"stop_condition": "(clear)"},
     "(H ((H (! clear)) -> braking))"),
    ("BEFORE", "null", "null", "before", None, "(braking)", {"stop_condition": "(clear)"},
     "(H (clear -> (Y (O braking))))"),
    ("UPON-NEVER", "null", "regular", "never", "(obstacle)", "(braking)", {},
     "(H ((H (! obstacle)) | (! braking)))"),
    ("HOLDING-ALWAYS", "null", "holding", "always", "(obstacle)", "(braking)", {},
     "(H ((H (! obstacle)) | braking))"),
    ("UPON-WITHIN", "null", "regular", "within", "(obstacle)", "(braking)", {"duration": 2},
     "(H ((O[=2] ((obstacle & (Z (! obstacle))) & (! braking))) -> (O[<2] ((Z FALSE) | braking))))"),
    ("HOLDING-WITHIN", "null", "holding", "within", "(obstacle)", "(braking)", {"duration": 2},
     "(H ((O[=2] (obstacle & (! braking))) -> (O[<2] ((Z FALSE) | braking))))"),
    ("UPON-FOR", "null", "regular", "for", "(obstacle)", "(braking)", {"duration": 2},
     "(H ((O[<=2] (obstacle & (Z (! obstacle)))) -> ((H (! obstacle)) | braking)))"),
    ("HOLDING-FOR", "null", "holding", "for", "(obstacle)", "(braking)", {"duration": 1},
     "(H ((O[<=1] obstacle) -> ((H (! obstacle)) | braking)))"),
    ("UPON-EVENTUALLY", "null", "regular", "eventually", "(obstacle)", "(braking)", {},
     "((H (! obstacle)) | (! ((! braking) S ((! braking) & (obstacle & (Z (! obstacle)))))))"),
    ("HOLDING-EVENTUALLY", "null", "holding", "null", "(obstacle)", "(braking)", {},
     "((H (! obstacle)) | (! ((! braking) S ((! braking) & obstacle))))"),
    ("HOLDING-UNTIL", "null", "holding", "until", "(obstacle)", "(braking)", {"stop_condition": "(clear)"},
     "(H ((H (! obstacle)) | (((! clear) S ((! clear) & obstacle)) -> braking)))"),
    ("NESTED-PRE", "null", "noTrigger", "immediately", "(preBool ( false , speed - preReal ( 0.0 , speed ) <= 1.0 ))",
     "(braking)", {}, "(H ((Y ((speed - preReal(0.0,speed)) <= 1.0)) -> braking))"),
    # FRET's sqrt, sin, cos (RCL's own; the oracle evaluates them with Python's math)
    ("SQRT", "null", "null", "always", None, "(speed <= sqrt(asked))", {}, "(H (speed <= sqrt(asked)))"),
    ("SIN-COS", "null", "noTrigger", "immediately", "(sin(asked) > 0.5)", "(cos(speed) < 0.5 | braking)", {},
     "(H ((sin(asked) > 0.5) -> ((cos(speed) < 0.5) | braking)))"),
    ("UPON-SQRT", "null", "regular", "next", "(sqrt(asked + speed) >= 2.0)", "(! braking)", {},
     "(H ((Y ((sqrt((asked + speed)) >= 2.0) & (Z (! (sqrt((asked + speed)) >= 2.0))))) -> ((! braking) | (Z FALSE))))"),
]


def _export(cases: list[Any]) -> FretExport:
    reqs = []
    for k, (rid, scope, cond, timing, pre, post, extra, pt) in enumerate(cases):
        sem: dict[str, Any] = {"scope": {"type": scope}, "condition": cond, "timing": timing,
                               "response": "satisfaction", "component_name": "rover", "post_condition": post,
                               "ptExpanded": pt, **extra}
        if pre is not None:
            sem.update(pre_condition=pre, regular_condition=pre)
        reqs.append(FretRequirement(rid, rid, "rover", msgspec.convert(sem, FretSemantics), ast.Loc("x.json", k + 1, 1),
                                    "", {}))
    variables = {("rover", n): FretVariable("rover", n, i, d, "") for n, (i, d) in VARS.items()}
    return FretExport("x.json", tuple(reqs), variables)


# ---- the oracle: FRET's past-time LTL over a finite trace, at its last step ----

_TOK = re.compile(r"\s*([OH]\[(?:\d+,\d+|<=\d+|<\d+|=\d+)\]|<->|->|<=|>=|\d+\.\d+|\d+|[A-Za-z_][A-Za-z0-9_]*|[()!&|=<>+\-*/,])")
_BIN = [("<->",), ("->",), ("|",), ("&",), ("S",), ("=", "<", "<=", ">", ">="), ("+", "-"), ("*", "/")]


def _pt_parse(text: str) -> Any:
    toks = _TOK.findall(text)
    pos = [0]

    def peek() -> str | None:
        return toks[pos[0]] if pos[0] < len(toks) else None

    def take() -> str:
        pos[0] += 1
        return toks[pos[0] - 1]

    def level(k: int) -> Any:
        if k == len(_BIN):
            return unary()
        left = level(k + 1)
        while peek() in _BIN[k]:
            op = take()
            left = (op, left, level(k if op == "->" else k + 1))
        return left

    def unary() -> Any:
        t = peek()
        if t in ("H", "O", "Y", "Z", "!") or (t or "")[:2] in ("O[", "H["):
            take()
            return (t, unary())
        return atom()

    def atom() -> Any:
        t = take()
        if t == "(":
            e = level(0)
            assert take() == ")"
            return e
        if t in ("TRUE", "FALSE"):
            return ("const", t == "TRUE")
        if t[0].isdigit():
            return ("const", Fraction(t))
        if peek() == "(" and t in ("sqrt", "sin", "cos"):  # FRET's math functions: Python's math in the oracle
            take()
            arg = level(0)
            assert take() == ")"
            return ("math", t, arg)
        if peek() == "(":  # preReal(init, e): FRET's pt keeps Lustre's "init -> pre e" as a call; maxReal(a, b)
            take()
            init = level(0)
            assert take() == ","
            e = level(0)
            assert take() == ")"
            return (t[:3] if t[:3] in ("max", "min") else "pre", init, e)
        return ("var", t)
    e = level(0)
    assert peek() is None, text
    return e


def _pt(e: Any, tr: list[dict[str, Any]], i: int) -> Any:
    op = e[0]
    if op == "const":
        return e[1]
    if op == "var":
        return tr[i][e[1]]
    if op == "!":
        return not _pt(e[1], tr, i)
    if op == "pre":
        return _pt(e[1], tr, i) if i == 0 else _pt(e[2], tr, i - 1)
    if op == "math":
        return getattr(math, e[1])(float(_pt(e[2], tr, i)))
    if op in ("max", "min"):  # FRET's maxReal/minReal (its field guide, "builtin functions")
        return (max if op == "max" else min)(_pt(e[1], tr, i), _pt(e[2], tr, i))
    if op == "+" or op == "-" or op == "*" or op == "/":
        a, b = _pt(e[1], tr, i), _pt(e[2], tr, i)
        return {"+": a + b, "-": a - b, "*": a * b, "/": a / b if b else None}[op]
    if op == "Y":
        return i > 0 and _pt(e[1], tr, i - 1)
    if op == "Z":
        return i == 0 or _pt(e[1], tr, i - 1)
    if op in ("H", "O"):
        vals = (_pt(e[1], tr, j) for j in range(i + 1))
        return all(vals) if op == "H" else any(vals)
    if op[:2] in ("O[", "H["):
        w = op[2:-1]  # [a,b]: a..b steps ago; [=n]: n ago; [<n]: 0..n-1 ago; [<=n]: 0..n ago
        lo, hi = (map(int, w.split(",")) if "," in w else (int(w[1:]), int(w[1:])) if w[0] == "=" else
                  (0, int(w[2:])) if w[:2] == "<=" else (0, int(w[1:]) - 1))
        vals = (_pt(e[1], tr, j) for j in range(max(0, i - hi), i - lo + 1))
        return all(vals) if op[0] == "H" else any(vals)
    a = _pt(e[1], tr, i)
    if op == "S":  # a S b: b held at some j <= i and a at every step after j
        return any(_pt(e[2], tr, j) and all(_pt(e[1], tr, k) for k in range(j + 1, i + 1)) for j in range(i + 1))
    b = _pt(e[2], tr, i)
    return {"&": lambda: a and b, "|": lambda: a or b, "->": lambda: (not a) or b, "<->": lambda: a == b,
            "=": lambda: a == b, "<": lambda: a < b, "<=": lambda: a <= b, ">": lambda: a > b,
            ">=": lambda: a >= b}[op]()


# ---- rclverify's reading of the imported statement on the same trace ----

def _values(step: dict[str, Any], states: dict[str, Any]) -> dict[str, object]:
    out: dict[str, object] = {}
    for n, v in step.items():
        p = "in" if VARS[n][0] == "Input" else "out"
        out[f"{p}.Rover.{p}.{n}"] = v
    out.update({f"in.Rover.state.{k}": v for k, v in states.items()})
    return out


def _local(step: dict[str, Any], states: dict[str, Any], nxt: dict[str, Any] | None = None) -> dict[str, object]:
    out: dict[str, object] = {f"{'in' if VARS[n][0] == 'Input' else 'out'}.{n}": v for n, v in step.items()}
    out.update({f"in.state.{k}": v for k, v in states.items()})
    out.update({f"in.next.{k}": v for k, v in (nxt or {}).items()})
    return out


def _candidates(type_name: str) -> list[object]:
    return [False, True] if type_name == "BOOL" else list(range(0, 5))  # the counters of CASES stay below 5


def _state_run(svs: Any, parsed: Any, checked: Any, tr: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The importer's state variables ``svs`` (``parsed`` their init and next) along the trace, each the one
    value its init/next defines."""
    now: dict[str, Any] = {}
    for sv in svs:
        init = parsed[sv.name][0]
        ok = [c for c in _candidates(sv.type_name) if evaluate(init.expr, checked, init.scope, {f"in.state.{sv.name}": c})]
        assert len(ok) == 1, (sv.name, ok)
        now[sv.name] = ok[0]
    run = [dict(now)]
    for step in tr[:-1]:
        nxt: dict[str, Any] = {}
        for sv in svs:
            f = parsed[sv.name][1]
            ok = [c for c in _candidates(sv.type_name)
                  if evaluate(f.expr, checked, f.scope, _local(step, now, {**nxt, sv.name: c}))]
            assert len(ok) == 1, (sv.name, ok)
            nxt[sv.name] = ok[0]
        now = nxt
        run.append(dict(now))
    return run


def _holds(f: Formal, checked: Any, step: dict[str, Any], states: dict[str, Any]) -> bool:
    got = evaluate(f.expr, checked, f.scope, _values(step, states))
    assert got is not None
    return got


def _rcl_agrees(t: Temporal, checked: Any, tr: list[dict[str, Any]], run: list[dict[str, Any]],
                fret_holds: bool) -> bool:
    """Whether rclverify's finite-trace verdict on ``tr`` agrees with FRET's: FRET true exactly when the
    verdict is not ``false``; for an unbounded ``eventually`` (alone or as a response), the named
    difference, exactly when it is ``true`` (a trace that ends before the response is FRET's false,
    rclverify's ``currently_false``)."""
    verdict = _rcl_verdict(t, checked, tr, run)
    inner = t.args[0].args[1] if shape(t, None) == "response" else t  # type: ignore[union-attr]
    if isinstance(inner, Temporal) and inner.op == "eventually" and inner.bound is None:
        return fret_holds == (verdict == "true")
    return fret_holds == (verdict != "false")


def _rcl_verdict(t: Temporal, checked: Any, tr: list[dict[str, Any]], run: list[dict[str, Any]]) -> str:
    """rclverify's finite-trace verdict on ``tr`` (docs/requirements.md, "On recorded runs"): ``true``,
    ``false`` or ``open`` (``currently_false`` or ``inconclusive``: not decided by this trace)."""
    kind = shape(t, None)
    n = len(tr)
    at = (lambda f, i: _holds(f, checked, tr[i], run[i]))  # noqa: E731
    if kind == "always":
        f = t.args[0]
        assert isinstance(f, Formal)
        return "true" if all(at(f, i) for i in range(n)) else "false"
    if kind == "next":
        f = t.args[0]
        assert isinstance(f, Formal)
        return "open" if n < 2 else "true" if at(f, 1) else "false"
    if kind == "response":
        imp = t.args[0]
        assert isinstance(imp, Temporal)
        trig, resp = imp.args
        assert isinstance(trig, Formal) and isinstance(resp, Temporal)
        q = resp.args[0]
        assert isinstance(q, Formal)
        if resp.op == "next":
            return "false" if any(at(trig, i) and not at(q, i + 1) for i in range(n - 1)) else "true"
        bound = n if resp.bound is None else resp.bound  # a trigger at i needs q at one of i..i+bound
        verdict = "true"
        for i in range(n):
            if at(trig, i) and not any(at(q, j) for j in range(i, min(i + bound, n - 1) + 1)):
                if i + bound <= n - 1:
                    return "false"
                verdict = "open"
        return verdict
    assert kind == "eventually"
    f = t.args[0]
    assert isinstance(f, Formal)
    if any(at(f, i) for i in range(n if t.bound is None else min(n, t.bound + 1))):
        return "true"
    return "false" if t.bound is not None and n > t.bound else "open"


def _trace(rng: random.Random) -> list[dict[str, Any]]:
    return [{n: (rng.random() < 0.5) if d == "boolean" else Fraction(rng.choice([0, 1, 2, 3]))
             for n, (_, d) in VARS.items()} for _ in range(rng.randint(1, 7))]


@pytest.fixture(scope="module")
def checked() -> Any:
    return check([parse_text(CONTRACT, "rover.rcl")])


def _disagreements(imp: Any, checked: Any, pt_text: str, traces: int, seed: int,
                   make: Callable[[random.Random], list[dict[str, Any]]] = _trace) -> list[Any]:
    rng = random.Random(seed)
    return _disagree_on(imp, checked, pt_text, [make(rng) for _ in range(traces)])


def _disagree_on(imp: Any, checked: Any, pt_text: str, traces: list[list[dict[str, Any]]]) -> list[Any]:
    """The traces of ``traces`` on which rclverify's verdict on ``imp``'s statement and FRET's ``pt_text`` at
    the trace's end disagree."""
    stypes = state_types(imp.states, checked)
    assert imp.requirement.formal is not None, imp.refusal
    t = parse_temporal(imp.requirement.formal, checked, imp.fret.reqid, stypes)
    assert isinstance(t, Temporal)
    pt = _pt_parse(pt_text)
    svs = imp.states
    parsed = {sv.name: (parse_state_formula(sv, "init", checked, svs), parse_state_formula(sv, "next", checked, svs))
              for sv in svs}
    out = []
    for tr in traces:
        fret_holds = bool(_pt(pt, tr, len(tr) - 1))
        if not _rcl_agrees(t, checked, tr, _state_run(svs, parsed, checked, tr), fret_holds):
            out.append(tr)
    return out


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_reading_equals_fret_past_time_formalisation(case: Any, checked: Any) -> None:
    (imp,) = import_export(_export([case]), Options(components={"rover": "Rover"}))
    assert imp.refusal is None
    assert _disagreements(imp, checked, case[-1], 150, zlib.crc32(case[0].encode())) == []


def test_a_trigger_read_without_its_edge_disagrees_with_fret(checked: Any) -> None:
    """The control: "upon" read as "whenever" (the trigger's edge dropped) differs from FRET's
    formalisation on some trace, so the comparison above can fail."""
    upon = next(c for c in CASES if c[0] == "UPON")
    whenever = ("UPON",) + upon[1:2] + ("noTrigger",) + upon[3:]
    (imp,) = import_export(_export([whenever]), Options(components={"rover": "Rover"}))
    assert _disagreements(imp, checked, upon[-1], 100, 7) != []


def test_the_oracle_reads_fret_operators() -> None:
    """The oracle's own operators on hand-made traces (Y false, Z true at the first step; S; O[a,b])."""
    tr = [{"a": True, "b": False}, {"a": False, "b": True}, {"a": False, "b": False}]
    at: Callable[[str, int], Any] = lambda f, i: _pt(_pt_parse(f), tr, i)
    assert at("(Y TRUE)", 0) is False and at("(Z FALSE)", 0) is True
    assert at("(a S b)", 1) is True and at("(a S b)", 2) is False
    assert at("(O[0,1] a)", 1) is True and at("(O[0,1] a)", 2) is False
    assert at("(H[0,1] (! a))", 2) is True and at("(H (! a))", 2) is False


def test_a_function_read_as_another_disagrees_with_fret(checked: Any) -> None:
    """The control of the math cases: ``sin`` imported as ``cos`` differs from FRET's formalisation (Python's
    math in the oracle) on some trace, so the agreement of SIN-COS above is not vacuous."""
    case = next(c for c in CASES if c[0] == "SIN-COS")
    swapped = case[:4] + (str(case[4]).replace("sin", "cos"),) + case[5:]
    (imp,) = import_export(_export([swapped]), Options(components={"rover": "Rover"}))
    assert _disagreements(imp, checked, case[-1], 100, 11) != []
