"""Repairs that respect units and safety (issue 64): a bound written with a
unit (``45 [N]``) is tightened in place first, as a bare one is, in the unit
it is written in; weakening a consumer's assumption that stems from a
requirement is never the first repair."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.diagnosis.units import literal_in, literal_si
from rclverify.lang import ast

# four independent links, one variable each (links join an output to the input of its name)
CELL = """node SupA { inputs( ra : REAL [N] ) outputs( fa : REAL [N] )
  assume( in.ra >= 0 [N] ) guarantee( out.fa >= 0 [N] and out.fa <= 45 [N] ) }
node GripA { inputs( fa : REAL [N] ) outputs( ga : BOOL ) assume( in.fa <= 40 [N] ) guarantee( out.ga == (in.fa > 0 [N]) ) }

node SupC { inputs( rc : REAL [N] ) outputs( fc : REAL [N] )
  assume( in.rc >= 0 ) guarantee( out.fc >= 0 and out.fc <= 45 ) }
node GripC { inputs( fc : REAL [N] ) outputs( gc : BOOL ) assume( in.fc <= 40 [N] ) guarantee( out.gc == (in.fc > 0) ) }

node SupD { inputs( rd : REAL [N] ) outputs( fd : REAL [N] )
  assume( in.rd >= 0 [N] and in.rd <= 45 [N] ) guarantee( out.fd == in.rd ) }
node GripD { inputs( fd : REAL [N] ) outputs( gd : BOOL ) assume( in.fd <= 40 [N] ) guarantee( out.gd == (in.fd > 0 [N]) ) }

node SupE { inputs( re : REAL [N] ) outputs( fe : REAL [N] )
  assume( in.re >= 0 [N] and in.re <= 45 [N] ) guarantee( out.fe == in.re ) }
node GripE { inputs( fe : REAL [N] ) outputs( ge : BOOL ) assume( in.fe <= 40 [N] ) guarantee( out.ge == (in.fe > 0 [N]) ) }
"""
PLAN = """name: cell
contracts: [contracts/cell.rcl]
requirements:
  - id: FORCE-D
    text: The gripper D is never driven above its 40 N rating.
    formal: "GripD.in.fd <= 40 [N]"
    supported_by: [{node: SupD, guarantees: [1]}]
"""


@pytest.fixture(scope="module")
def diagnoses(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = tmp_path_factory.mktemp("repairs") / "cell"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "cell.rcl").write_text(CELL, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) == 0
    report = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    return {d["id"]: d for d in report["diagnoses"]}


def _changed(repair: dict[str, Any]) -> tuple[str, str]:
    lines = repair["diff"].splitlines()
    return ([l[1:].strip() for l in lines if l.startswith("-") and not l.startswith("---")][0],
            [l[1:].strip() for l in lines if l.startswith("+") and not l.startswith("+++")][0])


@pytest.mark.parametrize("sc, old, new", [
    ("GripA.sc1", "out.fa <= 45 [N]", "out.fa <= 40 [N]"),       # the case: the unit kept
    ("GripC.sc1", "out.fc <= 45 )", "out.fc <= 40 )"),            # bare: the variable's declared unit
])
def test_the_safe_tightening_comes_first_whatever_the_units(diagnoses, sc, old, new):
    first = diagnoses[sc]["repairs"][0]
    assert first["kind"] == "strengthen-producer" and "in place" in first["summary"]
    before, after = _changed(first)
    assert old in before and new in after
    assert [r["kind"] for r in diagnoses[sc]["repairs"]][-1] == "weaken-consumer"  # offered, but last


def test_weakening_an_assumption_a_requirement_sets_is_never_first(diagnoses):
    # SupD passes its input on: tightening it leaves inputs in (40, 45] N unanswered, so no safe repair
    d, e = diagnoses["GripD.sc1"], diagnoses["GripE.sc1"]
    assert [r["kind"] for r in e["repairs"]] == ["weaken-consumer"]  # no requirement: the last resort is offered
    assert d["repairs"] == []
    assert any("stems from requirement FORCE-D" in s for s in d["not_offered"])
    assert any("unimplementable" in s for s in d["not_offered"])


def test_bounds_are_read_and_written_in_the_literal_unit():
    n = ast.UnitAnn("N")
    kn = ast.NumLit("0.045", unit=ast.UnitAnn("kN"))
    assert literal_si(kn, {}, n) == literal_si(ast.NumLit("45"), {}, n)
    assert literal_in(literal_si(ast.NumLit("40"), {}, n)[0], kn, n) == "0.04 [kN]"
    assert literal_si(ast.NumLit("40", unit=ast.UnitAnn("m")), {}, n)[1] != literal_si(kn, {}, n)[1]
    assert literal_si(ast.NumLit("20", unit=ast.UnitAnn("degC")), {}, None) is None  # affine: not compared
