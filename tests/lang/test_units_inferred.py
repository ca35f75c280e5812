"""Units inferred through equations, and a unit mismatch as a problem like any other (issue 48).

* the driver publishes degrees (``out.heading == in.cog``, ``cog : REAL
  [deg]``) where the localiser reads radians: the driver's unit is inferred,
  the mismatch is a located error at the driver's equation, the run goes on
  and writes the report with the other defects, one problem row blames the
  driver and joins the side condition, the missing-unit warning, the
  probable scale mismatch and the live run's assumption violations, and the
  conversion is its first repair, checked by the unit check and Z3;
* linear scaling names the usual conversions (180/pi, 3.6, 0.3048, 1000);
* no false alarm: a factor that is a conversion keeps its literal reading,
  two sources that disagree infer nothing, a conjunct that need not hold is
  no source;
* an oracle: the inferred unit equals a brute-force propagation over random
  small equation systems.
"""
from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, reject, settings
from hypothesis import strategies as st

from rclverify.cli.commands import main
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.lang.unitconv import TARGETS, factor_name
from rclverify.lang.unitinfer import infer_units
from rclverify.lang.units import Unit, factor_text, parse_unit
from rclverify.model.system.model import build, unit_diagnostics

ROBOT = """\
node Gnss {
  inputs( cog : REAL [deg] )
  outputs( heading : REAL )
  assume( 0 <= in.cog and in.cog < 360 )
  guarantee( out.heading == in.cog )
}

node Localiser {
  inputs( heading : REAL [rad] )
  outputs( yaw : REAL [rad] )
  topics( std_msgs/Float64 heading matches(in.heading), std_msgs/Float64 yaw matches(out.yaw) )
  assume( 0 <= in.heading and in.heading <= 6.3 )
  guarantee( out.yaw == in.heading ) triggered by in.heading within 100 ms
}

node Planner {
  inputs( yaw : REAL [rad] )
  outputs( cmd : REAL )
  guarantee( out.cmd >= 1 )
  guarantee( out.cmd <= 0 )
}
"""
PLAN = """\
name: headings
contracts:
  - contracts/robot.rcl
requirements: []
nodes:
  Localiser:
    evidence:
      - backend: monitors
        traces: [runs/live.jsonl]
"""
# the live run: the driver's 90 degrees read as 90 radians, then a heading in range
RUN = [{"topic": "heading", "time": 0.0, "data": 90.0}, {"topic": "yaw", "time": 0.05, "data": 90.0},
       {"topic": "heading", "time": 1.0, "data": 1.5}, {"topic": "yaw", "time": 1.05, "data": 1.5}]


def _checked(src: str, name: str = "robot.rcl") -> Any:
    return check([parse_text(src, name)])


def _inferred(src: str) -> dict[tuple[str, str, str], Any]:
    c = _checked(src)
    return infer_units(c, build(c).links).inferred


# ---------------------------------------------------------------------------
# Inference through equations and linear scaling
# ---------------------------------------------------------------------------

def test_the_unit_is_inferred_through_the_equation_and_the_mismatch_is_located_at_it():
    got = _inferred(ROBOT)
    h = got[("Gnss", "out", "heading")]
    assert (str(h.unit), h.alternative, h.guarantee, h.clause) == ("[deg]", None, 1, "out.heading == in.cog")
    assert (h.loc.line, h.loc.col) == (5, 14)
    diags = unit_diagnostics(_checked(ROBOT))
    errors = [d for d in diags if d.severity == "error"]
    [e] = errors  # one error, at the producer's equation (the consumer's declaration named in it)
    assert str(e).startswith("robot.rcl:5:14: error: unit mismatch on the connection Gnss.out.heading -> "
                             "Localiser.in.heading (via name)")
    assert e.code == "E-unit-scale"
    assert "inferred from guarantee 1 `out.heading == in.cog` (robot.rcl:5:14)" in e.message
    assert "a factor of 180/pi (1 rad = 180/pi deg)" in e.message
    assert "the reader's declaration: robot.rcl:9:11" in e.message
    # the missing unit is still said, at the output's declaration
    assert [(d.code, d.loc.line, d.loc.col) for d in diags if d.severity == "warning"] == [("W-unit-missing", 3, 12)]


def test_check_command_reports_the_inferred_mismatch_once(tmp_path, capsys):
    f = tmp_path / "robot.rcl"
    f.write_text(ROBOT, encoding="utf-8")
    assert main(["check", str(f), "-w", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    lines = [x for x in err.splitlines() if "unit mismatch on the connection Gnss.out.heading" in x]
    assert len(lines) == 1 and lines[0].startswith(f"{f}:5:14: error:")


_SCALE = """
node P {{ inputs( a : REAL [{ua}], b : REAL [{ub}] ) outputs( x : REAL )
  guarantee( out.x == {rhs} ) }}
"""


@pytest.mark.parametrize("ua, ub, rhs, unit, alternative", [
    ("m/s", "m", "3.6 * in.a", "[km/h]", "[m/s]"),                      # km/h from m/s: 3.6
    ("km/h", "m", "in.a / 3.6", "[m/s]", "[km/h]"),
    ("deg", "m", "in.a * 0.017453292519943295", "[rad]", "[deg]"),      # pi/180 as a decimal
    ("rad", "m", "57.29578 * in.a", "[deg]", "[rad]"),                  # 180/pi to 7 digits
    ("m", "m", "1000 * in.a", "[mm]", "[m]"),                           # a power of ten: a prefix
    ("m", "m", "in.a + in.b", "[m]", None),                             # a sum of one unit
    ("m", "s", "in.a / in.b", "[m/s]", None),                           # a quotient
    ("m", "s", "2 * in.a", "[m]", None),                                # a gain: no conversion
    ("deg", "m", "in.a * 1 [rad/deg]", "[rad]", None),                  # a factor written with its unit
])
def test_linear_scaling_names_the_usual_conversions(ua, ub, rhs, unit, alternative):
    x = _inferred(_SCALE.format(ua=ua, ub=ub, rhs=rhs))[("P", "out", "x")]
    assert str(x.unit) == unit
    assert (str(x.alternative) if x.alternative else None) == alternative


def test_the_factors_are_named_as_people_write_them():
    m, mm, ms, kmh = parse_unit("m"), parse_unit("mm"), parse_unit("m/s"), parse_unit("km/h")
    ft = Unit(m.dims, Fraction(3048, 10000), 0, None, "ft")
    assert factor_name(parse_unit("rad"), parse_unit("deg")) == "180/pi"
    assert factor_name(parse_unit("deg"), parse_unit("rad")) == "pi/180"
    assert factor_name(ms, kmh) == "3.6" and factor_name(kmh, ms) == "1/3.6"
    assert factor_name(ft, m) == "0.3048" and factor_name(m, ft) == "1/0.3048"
    assert factor_name(m, mm) == "1000"
    assert "a factor of 3.6 (1 m/s = 3.6 km/h)" == factor_text(ms, kmh)


@pytest.mark.parametrize("src", [
    # two equations that disagree: unsure, nothing inferred
    _SCALE.format(ua="m", ub="mm", rhs="in.a and out.x == in.b"),
    # under an implication: need not hold
    "node P { inputs( a : REAL [m], c : BOOL ) outputs( x : REAL ) guarantee( in.c -> out.x == in.a ) }",
    # a disjunction
    "node P { inputs( a : REAL [m] ) outputs( x : REAL ) guarantee( out.x == in.a or out.x == 0 ) }",
    # a constant says nothing of a unit
    "node P { inputs( a : REAL [m] ) outputs( x : REAL ) guarantee( out.x == 3 ) }",
])
def test_nothing_is_inferred_when_unsure(src):
    assert ("P", "out", "x") not in _inferred(src)


def test_no_false_alarm_on_either_reading_of_a_conversion_factor():
    base = """
node P { inputs( s : REAL [m/s] ) outputs( v : REAL ) guarantee( out.v == 3.6 * in.s ) }
node C { inputs( v : REAL [UNIT] ) outputs( w : REAL ) guarantee( out.w == 0 ) }
"""
    for ok in ("km/h", "m/s"):  # a conversion or a gain: the contract does not say which
        assert not [d for d in unit_diagnostics(_checked(base.replace("UNIT", ok))) if d.severity == "error"]
    [e] = [d for d in unit_diagnostics(_checked(base.replace("UNIT", "mm/s"))) if d.severity == "error"]
    assert "[km/h] (velocity) as its contract says" in e.message and "or [m/s], reading the factor as a gain" in e.message
    # downstream of an ambiguous reading: no error either way
    chain = base.replace("[UNIT]", "").replace("out.w == 0", "out.w == in.v + 1") + \
        "node D { inputs( w : REAL [mm/s] ) outputs( z : REAL ) guarantee( out.z == 0 ) }\n"
    assert not [d for d in unit_diagnostics(_checked(chain)) if d.severity == "error"]


# ---------------------------------------------------------------------------
# The workspace: one problem blaming the driver, the report written, the conversion first
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    ws = tmp_path_factory.mktemp("units") / "headings"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "robot.rcl").write_text(ROBOT, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (ws / "runs").mkdir()
    (ws / "runs" / "live.jsonl").write_text("".join(json.dumps(x) + "\n" for x in RUN), encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0  # the unit mismatch does not stop the run
    return ws, json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


def test_the_report_is_written_with_the_other_defects(verified):
    ws, report = verified
    for ext in ("html", "md", "sarif"):
        assert (ws / "reports" / f"assurance.{ext}").exists()
    ids = {m["id"] for g in report["problems"] for m in g["members"]}
    assert {"Planner.contract-consistent", "Gnss.g1"} <= ids  # the other defects are there too
    [lint] = [x for x in report["lint"] if x["code"] == "E-unit-scale"]
    assert (lint["severity"], lint["location"]) == ("error", "contracts/robot.rcl:5:14")
    from rclverify.report.severity import blocking
    assert any("E-unit-scale" in str(b) for b in blocking(report))  # --strict fails on it
    assert report["meta"]["strict_ok"] is False
    sarif = json.loads((ws / "reports" / "assurance.sarif").read_text(encoding="utf-8"))
    [res] = [r for r in sarif["runs"][0]["results"] if r["ruleId"] == "RCL-LINT-UNIT-SCALE"]
    region = res["locations"][0]["physicalLocation"]["region"]
    assert (region["startLine"], region["startColumn"]) == (5, 14)  # on the producer, not the consumer
    assert res["fixes"] and "Convert in Gnss" in res["fixes"][0]["description"]["text"]


def test_one_problem_blames_the_producer_and_joins_the_evidence(verified):
    _, report = verified
    rows = [g for g in report["problems"] if "Gnss.out.heading.unit" in [m["id"] for m in g["members"]]]
    [row] = rows
    ids = [m["id"] for m in row["members"]]
    assert ids[0] == "Gnss.out.heading.unit"
    for joined in ("Localiser.sc2",                        # the failed side condition
                   "contracts/robot.rcl:5:14",             # the unit error
                   "contracts/robot.rcl:3:12",             # RCL-LINT-UNIT-MISSING on the same variable
                   "Localiser.sc2.scale",                  # the probable scale mismatch (180/pi)
                   "Localiser.g0.monitors.live_jsonl"):    # the live run's assumption violation blamed on Gnss
        assert joined in ids
        assert sum(joined in [m["id"] for m in g["members"]] for g in report["problems"]) == 1
    assert [c["what"] for c in row["culprits"]] == ["guarantee 1 of Gnss"]
    assert row["culprits"][0]["source"] == "contracts/robot.rcl:5:3"
    assert row["sentence"].startswith("Unit mismatch: Gnss publishes Gnss.out.heading in [deg], its unit inferred "
                                      "from guarantee 1 `out.heading == in.cog` (contracts/robot.rcl:5:14), where "
                                      "Localiser reads Localiser.in.heading in [rad]")
    assert "a factor of 180/pi" in row["sentence"]
    assert report["problems"].index(row) == 0  # failed, and first in the report's order


def test_the_conversion_is_the_first_repair_and_z3_checked_it(verified, tmp_path):
    ws, report = verified
    [row] = [g for g in report["problems"] if "Gnss.out.heading.unit" in [m["id"] for m in g["members"]]]
    first = row["repairs"][0]
    assert first["diagnosis"] == "Gnss.out.heading.unit"
    d = next(x for x in report["diagnoses"] if x["id"] == first["diagnosis"])
    rep = d["repairs"][first["index"]]
    assert rep["kind"] == "convert-unit" and rep["checked_by"].startswith("z3 ")
    assert rep["edit"]["deleted"] == "in.cog"
    assert rep["edit"]["inserted"] == "in.cog * 0.017453292519943295 [rad/deg]"
    assert "multiply by pi/180" in rep["summary"]
    assert {"check": "Localiser.sc2", "before": "failed", "after": "discharged"} in rep["cost"]
    assert "Localiser.sc2 follows from the edited contracts" in rep["proves"]
    # applied, the contracts check without a unit error and the side condition is discharged
    src = (ws / "contracts" / "robot.rcl").read_text(encoding="utf-8")
    lines = src.splitlines(keepends=True)
    e = rep["edit"]
    a = sum(len(x) for x in lines[:e["line"] - 1]) + e["col"] - 1
    b = sum(len(x) for x in lines[:e["end_line"] - 1]) + e["end_col"] - 1
    fixed = src[:a] + e["inserted"] + src[b:]
    c = _checked(fixed, "contracts/robot.rcl")
    assert not [x for x in unit_diagnostics(c) if x.severity == "error"]
    assert infer_units(c, build(c).links).inferred[("Gnss", "out", "heading")].unit == parse_unit("rad")
    from rclverify.calculus.compose import compose_node
    assert {sc.id: sc.status for sc in compose_node(c, build(c), "Localiser").side_conditions}["Localiser.sc2"] \
        == "discharged"


def test_a_mismatch_declared_at_both_ends_no_longer_stops_the_run(tmp_path):
    """Before issue 48 the error stopped ``doit verify`` and no report was written."""
    ws = tmp_path / "declared"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "robot.rcl").write_text(
        ROBOT.replace("outputs( heading : REAL )", "outputs( heading : REAL [deg] )"), encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(PLAN.split("nodes:")[0], encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    # recorded once, at the producer's declaration (SARIF and the row on the producer, not the consumer)
    assert [(x["code"], x["location"]) for x in report["lint"]] == [("E-unit-scale", "contracts/robot.rcl:3:12")]
    [row] = [g for g in report["problems"] if "Gnss.out.heading.unit" in [m["id"] for m in g["members"]]]
    assert {"Localiser.sc2", "contracts/robot.rcl:3:12"} <= {m["id"] for m in row["members"]}
    assert [c["what"] for c in row["culprits"]] == ["the contract of Gnss"]
    assert "Planner.contract-consistent" in {m["id"] for g in report["problems"] for m in g["members"]}
    assert main(["verify", "-w", str(ws), "--strict"]) == 1


# ---------------------------------------------------------------------------
# Oracle: the inferred unit equals a brute-force propagation
# ---------------------------------------------------------------------------

_POOL = ["m", "mm", "s", "deg", "rad", "m/s", "km/h"]
_FACTORS = ["2", "3.6", "1000", "0.001", "57.29577951308232", "0.017453292519943295"]


def _mag(u: Unit) -> float:
    return float(u.factor) * math.pi ** u.pi


def _brute_convert(u: Unit, k: Fraction) -> Unit:
    """The reading of ``k`` times a value in ``u``, by search over every target:
    one whose magnitude is ``u``'s over ``k`` (exact first, then within 1e-4), else ``u``."""
    if abs(k) in (0, 1):
        return u
    want = _mag(u) / float(abs(k))
    exact = [t for t in TARGETS if t.dims == u.dims and t.pi == u.pi and t.factor == u.factor / abs(k)]
    near = [t for t in TARGETS if t.dims == u.dims and abs(_mag(t) - want) <= 1e-4 * want]
    return (exact or near or [u])[0]


def _brute(eqs: list[tuple[int, str, Any]], decl: dict[str, Unit], n_out: int) -> dict[int, set]:
    """Every unit derivable for each output by any derivation (outputs read
    only earlier ones: the recursion is over a finite DAG)."""
    memo: dict[int, set] = {}

    def units(v: str) -> set:
        return {decl[v]} if v in decl else derivable(int(v[1:]))

    def derivable(i: int) -> set:
        if i not in memo:
            got: set = set()
            for j, form, args in eqs:
                if j != i:
                    continue
                if form == "copy":
                    got |= units(args)
                elif form == "sum":
                    got |= {a for a in units(args[0]) for b in units(args[1]) if a == b}
                elif form == "prod":
                    got |= {a.times(b) for a in units(args[0]) for b in units(args[1])}
                elif form == "quot":
                    got |= {a.over(b) for a in units(args[0]) for b in units(args[1])}
                elif form == "scale":
                    got |= {_brute_convert(a, Fraction(args[0])) for a in units(args[1])}
            memo[i] = got
        return memo[i]

    return {i: derivable(i) for i in range(n_out)}


@st.composite
def _systems(draw):
    n_in = draw(st.integers(1, 3))
    n_out = draw(st.integers(1, 4))
    decl = {f"a{k}": draw(st.sampled_from(_POOL)) for k in range(n_in)}
    eqs = []
    for i in range(n_out):
        for _ in range(draw(st.integers(0, 2))):  # 0, 1 or 2 sources for each output
            names = [f"a{k}" for k in range(n_in)] + [f"y{j}" for j in range(i)]
            pick = st.sampled_from(names)
            form = draw(st.sampled_from(["copy", "sum", "prod", "quot", "scale"]))
            if form == "copy":
                eqs.append((i, form, draw(pick)))
            elif form == "scale":
                eqs.append((i, form, (draw(st.sampled_from(_FACTORS)), draw(pick))))
            else:
                eqs.append((i, form, (draw(pick), draw(pick))))
    return decl, eqs, n_out


def _term(v: str) -> str:
    return f"in.{v}" if v.startswith("a") else f"out.{v}"


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(_systems())
def test_inference_equals_brute_force_propagation(system):
    decl, eqs, n_out = system
    ops = {"sum": "+", "prod": "*", "quot": "/"}
    clauses = []
    for i, form, args in eqs:
        if form == "copy":
            rhs = _term(args)
        elif form == "scale":
            rhs = f"{args[0]} * {_term(args[1])}"
        else:
            rhs = f"{_term(args[0])} {ops[form]} {_term(args[1])}"
        clauses.append(f"out.y{i} == {rhs}")
    ins = ", ".join(f"{k} : REAL [{u}]" for k, u in decl.items())
    outs = ", ".join(f"y{i} : REAL" for i in range(n_out))
    src = f"node N {{ inputs( {ins} ) outputs( {outs} ) guarantee( {' and '.join(clauses) or 'TRUE'} ) }}"
    try:
        c = check([parse_text(src, "n.rcl")])
    except RclError as exc:  # a sum of two declared units that differ: the checker's error, not inference
        assert all(d.code.startswith("E-unit") for d in exc.diagnostics)
        reject()
    inf = infer_units(c, [])
    want = _brute(eqs, {k: parse_unit(u) for k, u in decl.items()}, n_out)
    for i in range(n_out):
        key = ("N", "out", f"y{i}")
        if len(want[i]) == 1:
            assert key in inf.inferred and inf.inferred[key].unit == next(iter(want[i])), (src, i, want[i])
        else:
            assert key not in inf.inferred, (src, i, want[i], inf.inferred.get(key))
        assert (key in inf.ambiguous) == (len(want[i]) > 1)
