"""FRET requirements over Internal variables defined in Lustre, against FRET's formalisation.

FRET's formalisation (``ptExpanded``) reads an Internal variable as an
atom whose value at each step is its Lustre definition's
(rclverify.model.plan.fret.lustre: ``->``, ``pre``, ``if then else``, a
variable reading its own ``pre``, a table of constants).  The oracle here
computes each variable's stream from its Lustre meaning written out by hand
(``a -> b``: a at the first step, b after; ``pre e``: e at the step before),
adds it to the trace and evaluates FRET's formula at the trace's end
(test_fret_differential's evaluator).  rclverify's side is the imported
statement and state variables, parsed, type-checked and run by rclverify's
evaluator.  The two must agree on every random trace (FRET true exactly
when rclverify's verdict is not false), and each case meets traces of both
verdicts.  The control: the latch's first value misread (0.0 -> instead of
asked ->) disagrees with the oracle on some trace.
"""
from __future__ import annotations

import random
import zlib
from fractions import Fraction
from typing import Any, Callable

import msgspec
import pytest

from rclverify.lang import ast
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.fret.export import FretExport, FretRequirement, FretSemantics, FretVariable
from rclverify.model.plan.fret.requirements import Options, import_export
from rclverify.model.plan.state import parse_state_formula, state_types
from rclverify.model.plan.temporal import Temporal, parse_temporal
from rclverify.semantics.evaluate import evaluate
from test_fret_differential import _pt, _pt_parse, _rcl_agrees

CONTRACT = """
node Rover {
  inputs( obstacle : BOOL, asked : REAL, manual : BOOL )
  outputs( speed : REAL, braking : BOOL )
  assume( TRUE )
  guarantee( TRUE )
}
"""
PORTS = {"obstacle": ("Input", "boolean"), "asked": ("Input", "double"), "manual": ("Input", "boolean"),
         "speed": ("Output", "double"), "braking": ("Output", "boolean")}
Stream = Callable[[list[dict[str, Any]], int], Any]


def _held(tr: list[dict[str, Any]], i: int) -> Any:
    if i == 0:
        return tr[0]["asked"]
    return tr[i]["asked"] if tr[i]["manual"] and not tr[i - 1]["manual"] else _held(tr, i - 1)


def _sticky(tr: list[dict[str, Any]], i: int) -> bool:
    return i > 0 and (_sticky(tr, i - 1) or tr[i]["obstacle"])


_TABLE = [Fraction(1), Fraction(2), Fraction(1, 2), Fraction(3)]
#: Internal variables: (name, dataType, Lustre definition, its stream written out by hand).
INTERNAL: list[tuple[str, str, str, Stream]] = [
    ("last", "double", "0.0 -> pre speed", lambda tr, i: Fraction(0) if i == 0 else tr[i - 1]["speed"]),
    ("held", "double", "asked -> if (manual and not pre manual) then asked else pre held", _held),
    ("sgn", "double", "if (speed >= 2.0) then 1.0 else (- 1.0)",
     lambda tr, i: Fraction(1) if tr[i]["speed"] >= 2 else Fraction(-1)),
    ("accel", "double", "0.0 -> (speed - pre speed) * 2.0",
     lambda tr, i: Fraction(0) if i == 0 else (tr[i]["speed"] - tr[i - 1]["speed"]) * 2),
    ("tbl", "double", "1.0 -> pre( 2.0 -> pre( 0.5 -> pre( 3.0 )))", lambda tr, i: _TABLE[min(i, 3)]),
    ("dtbl", "double", "0.0 -> (tbl - pre tbl)", lambda tr, i: Fraction(0) if i == 0 else _TABLE[min(i, 3)] -
     _TABLE[min(i - 1, 3)]),
    ("rose", "boolean", "false -> (obstacle and not pre obstacle)",
     lambda tr, i: i > 0 and tr[i]["obstacle"] and not tr[i - 1]["obstacle"]),
    ("sticky", "boolean", "false -> (pre sticky or obstacle)", _sticky),
]
#: (reqid, scope, condition, timing, pre_condition, post_condition, extra semantics, FRET's ptExpanded)
CASES: list[tuple[str, str, str, str, str | None, str, dict[str, Any], str]] = [
    ("L-ARROW-PRE", "null", "null", "always", None, "(last <= speed)", {}, "(H (last <= speed))"),
    ("L-LATCH", "null", "noTrigger", "immediately", "(braking)", "(held = asked)", {}, "(H (braking -> (held = asked)))"),
    ("L-IF", "null", "null", "always", None, "(speed * sgn <= 2.0)", {}, "(H ((speed * sgn) <= 2.0))"),
    ("L-DIFF", "null", "null", "always", None, "(accel <= 2.0)", {}, "(H (accel <= 2.0))"),
    ("L-TABLE", "null", "null", "always", None, "(speed <= tbl)", {}, "(H (speed <= tbl))"),
    ("L-TABLE-FOR", "null", "null", "for", None, "(speed <= tbl)", {"duration": 2},
     "(H ((O[0,2] (! (Y TRUE))) -> (speed <= tbl)))"),
    ("L-PRE-TABLE", "null", "null", "always", None, "(speed + dtbl <= 3.0)", {}, "(H ((speed + dtbl) <= 3.0))"),
    ("L-BOOL", "null", "regular", "immediately", "(rose)", "(braking)", {}, "(H ((rose & (Z (! rose))) -> braking))"),
    ("L-SELF-BOOL", "null", "noTrigger", "next", "(sticky)", "(braking)", {},
     "(H ((Y sticky) -> (braking | (! (Y TRUE)))))"),
    ("L-PRE-INIT", "null", "noTrigger", "immediately", "(preReal(speed, speed) < speed)", "(braking)", {},
     "(H ((preReal(speed,speed) < speed) -> braking))"),
    ("L-IN-MODE", "in", "null", "always", None, "(speed <= held)", {"scope_mode": "manual"},
     "(H (manual -> (speed <= held)))"),
    ("F-MAX-MIN", "null", "null", "always", None, "(maxReal(speed, asked) - minReal(speed, last) <= 2.0)", {},
     "(H ((maxReal(speed,asked) - minReal(speed,last)) <= 2.0))"),
]


def _export(cases: list[Any], internal: list[tuple[str, str, str, Stream]] = INTERNAL) -> FretExport:
    reqs = []
    for k, (rid, scope, cond, timing, pre, post, extra, pt) in enumerate(cases):
        sem: dict[str, Any] = {"scope": {"type": scope}, "condition": cond, "timing": timing,
                               "response": "satisfaction", "component_name": "rover", "post_condition": post,
                               "ptExpanded": pt, **extra}
        if pre is not None:
            sem.update(pre_condition=pre, regular_condition=pre)
        reqs.append(FretRequirement(rid, rid, "rover", msgspec.convert(sem, FretSemantics), ast.Loc("x.json", k + 1, 1),
                                    "", {}))
    variables = {("rover", n): FretVariable("rover", n, i, d, "") for n, (i, d) in PORTS.items()}
    variables.update({("rover", n): FretVariable("rover", n, "Internal", d, a) for n, d, a, _ in internal})
    return FretExport("x.json", tuple(reqs), variables)


def _trace(rng: random.Random) -> list[dict[str, Any]]:
    return [{n: (rng.random() < 0.5) if d == "boolean" else Fraction(rng.choice([0, 1, 2, 3]))
             for n, (_, d) in PORTS.items()} for _ in range(rng.randint(1, 7))]


def _with_internal(tr: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The trace with each Internal variable's value by its Lustre meaning (the oracle's side)."""
    return [{**step, **{n: f(tr, i) for n, _, _, f in INTERNAL}} for i, step in enumerate(tr)]


#: The values a state variable may take on these traces: the ports' (0..3), the definitions' constants,
#: differences doubled, step counters.
_VALUES: list[object] = sorted({Fraction(k, 2) for k in range(-16, 25)})


def _state_run(svs: Any, parsed: Any, checked: Any, tr: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """rclverify's state variables along ``tr``, each the one value its init/next formula admits."""
    def one(sv: Any, f: Any, env: Callable[[object], dict[str, object]]) -> object:
        ok = [c for c in ([False, True] if sv.type_name == "BOOL" else _VALUES) if evaluate(f.expr, checked, f.scope, env(c))]
        assert len(ok) == 1, (sv.name, ok)
        return ok[0]
    now = {sv.name: one(sv, parsed[sv.name][0], lambda c, sv=sv: {f"in.state.{sv.name}": c}) for sv in svs}
    run = [dict(now)]
    for step in tr[:-1]:
        nxt: dict[str, object] = {}
        base: dict[str, object] = {f"{'in' if PORTS[n][0] == 'Input' else 'out'}.{n}": v for n, v in step.items()}
        base.update({f"in.state.{k}": v for k, v in now.items()})
        for sv in svs:
            nxt[sv.name] = one(sv, parsed[sv.name][1], lambda c, sv=sv: {**base, **{f"in.next.{k}": v for k, v in
                                                                                       {**nxt, sv.name: c}.items()}})
        now = nxt
        run.append(dict(now))
    return run


@pytest.fixture(scope="module")
def checked() -> Any:
    return check([parse_text(CONTRACT, "rover.rcl")])


def _verdicts(imp: Any, checked: Any, pt_text: str, traces: list[list[dict[str, Any]]]) -> list[tuple[bool, bool]]:
    """(FRET's verdict, agreement) on each trace."""
    import test_fret_differential as d
    assert imp.refusal is None, imp.refusal
    stypes = state_types(imp.states, checked)
    assert imp.requirement.formal is not None
    t = parse_temporal(imp.requirement.formal, checked, imp.fret.reqid, stypes)
    assert isinstance(t, Temporal)
    pt = _pt_parse(pt_text)
    parsed = {sv.name: (parse_state_formula(sv, "init", checked, imp.states),
                        parse_state_formula(sv, "next", checked, imp.states)) for sv in imp.states}
    out = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(d, "VARS", PORTS)  # the differential test's verdict reads this test's ports
        for tr in traces:
            fret = bool(_pt(pt, _with_internal(tr), len(tr) - 1))
            run = _state_run(imp.states, parsed, checked, tr)
            out.append((fret, _rcl_agrees(t, checked, tr, run, fret)))
    return out


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_lustre_internal_variables_read_as_fret_reads_them(case: Any, checked: Any) -> None:
    (imp,) = import_export(_export([case]), Options(components={"rover": "Rover"}))
    rng = random.Random(zlib.crc32(case[0].encode()))
    got = _verdicts(imp, checked, case[-1], [_trace(rng) for _ in range(40)])
    assert all(agree for _, agree in got)
    assert {fret for fret, _ in got} == {True, False}  # both verdicts met: the comparison can fail


def test_a_misread_first_value_disagrees_with_fret(checked: Any) -> None:
    """The control: the latch's first value read as 0.0 (not asked) differs from the oracle on some trace."""
    wrong = [(n, d, "0.0 -> if (manual and not pre manual) then asked else pre held" if n == "held" else a, f)
             for n, d, a, f in INTERNAL]
    latch = next(c for c in CASES if c[0] == "L-LATCH")
    (imp,) = import_export(_export([latch], wrong), Options(components={"rover": "Rover"}))
    rng = random.Random(3)
    assert not all(agree for _, agree in _verdicts(imp, checked, latch[-1], [_trace(rng) for _ in range(60)]))


def test_a_table_is_one_counter_not_a_chain_of_states() -> None:
    """A 200-step table of constants (FRET's case studies' test vectors) is one step counter, not 200 state
    variables, and reads the constant of each step."""
    chain = "0.0"
    for k in range(199, 0, -1):
        chain = f"{k}.0 -> pre( {chain} )" if k < 199 else f"{k}.0 -> pre( 0.0 )"
    table = [("vec", "double", "0.5 -> pre( " + chain + " )", lambda tr, i: Fraction(0))]
    req = ("L-VEC", "null", "null", "always", None, "(speed <= vec)", {}, "(H (speed <= vec))")
    (imp,) = import_export(_export([req], table), Options(components={"rover": "Rover"}))
    assert imp.refusal is None and [s.name for s in imp.states] == ["fret_L_VEC_step"]
    formal = imp.requirement.formal
    assert formal is not None and "(Rover.state.fret_L_VEC_step == 0) -> (Rover.out.speed <= (0.5))" in formal.text
    assert "(Rover.state.fret_L_VEC_step >= 200) -> (Rover.out.speed <= (0.0))" in formal.text
    assert "state.fret_L_VEC_step < 200" in imp.states[0].next.text


def test_lustre_precedence() -> None:
    """Lustre's, not FRETish's: ``not`` binds tighter than a comparison, ``pre`` tightest, ``->`` loosest."""
    from rclverify.model.plan.fret.lustre import parse_lustre
    assert parse_lustre("v", "not a = b") == ("bin", "=", ("not", ("var", "a")), ("var", "b"))
    assert parse_lustre("v", "0.0 -> x - pre x * 2.0") == (
        "arrow", ("num", "0.0"), ("bin", "-", ("var", "x"), ("bin", "*", ("lpre", ("var", "x")), ("num", "2.0"))))
