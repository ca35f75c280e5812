"""Requirements imported from a FRET export (docs/requirements.md, "Requirements from FRET").

The exports are written here in FRET's format (``requirements`` with
``reqid``, ``fulltext``, ``semantics``; ``variables`` with ``idType`` and
``dataType``).  What is checked: each requirement becomes a plan
requirement keyed by its reqid, with the state declarations its statement
reads, type-checked with the contracts; what cannot be translated is kept
informal with its reason and fix; a malformed export is a located error;
a re-import reports added, changed and removed requirements, writes
nothing when nothing changed, and keeps the plan's own requirements.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import _run
from rclverify.cli.fret import cmd_import_fret
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.fret.export import read_export
from rclverify.model.plan.fret.requirements import Options, import_export
from rclverify.model.plan.load import all_requirements, load_plan
from rclverify.stages.workspace import Workspace
from rclverify.tools.fret.importer import import_fret, render

CONTRACT = """node Rover {
  inputs( obstacle : BOOL, asked : REAL )
  outputs( speed : REAL, braking : BOOL )
  assume( 0 <= in.asked and in.asked <= 2 )
  guarantee( out.braking <=> in.obstacle )
  guarantee( (in.obstacle -> out.speed == 0) and (not in.obstacle -> out.speed == in.asked) )
  progress( within 0 steps )
}
"""
PLAN = """name: fret test
contracts:
  - contracts/rover.rcl
requirements:
  - id: CAP
    text: The rover never goes faster than 2 m/s.
    formal: "Rover.out.speed <= 2"
fret:
  components: {rover: Rover}
"""


def _req(rid: str, text: str, timing: str, post: str, cond: str = "null", pre: str | None = None,
         **extra: Any) -> dict[str, Any]:
    sem: dict[str, Any] = {"type": "nasa", "scope": {"type": "null"}, "condition": cond, "timing": timing,
                           "response": "satisfaction", "component_name": "rover", "post_condition": post, **extra}
    if pre is not None:
        sem.update(pre_condition=pre, regular_condition=pre)
    return {"reqid": rid, "parent_reqid": "", "project": "Rover", "fulltext": text, "semantics": sem, "_id": rid}


def _var(name: str, id_type: str, data_type: str, assignment: str = "") -> dict[str, Any]:
    return {"project": "Rover", "component_name": "rover", "variable_name": name, "idType": id_type,
            "dataType": data_type, "assignment": assignment, "modeRequirement": "", "_id": name}


VARIABLES = [_var("obstacle", "Input", "boolean"), _var("asked", "Input", "double"),
             _var("speed", "Output", "double"), _var("braking", "Output", "boolean"),
             _var("limit", "Internal", "double", "2.0"), _var("filtered", "Internal", "double", "0.0 -> pre speed"),
             _var("unguarded", "Internal", "double", "pre speed"),
             _var("sampled", "Internal", "double", "speed when braking")]
#: FRET's ptExpanded of R-4 (null scope, upon, after 2 ticks; FRET v3.1.0's formalisation of that combination).
AFTER_PT = ("((H ((O[<=2] (obstacle & (Z (! obstacle)))) -> ((H (! obstacle)) | (! (speed = 0.0))))) & (H ((O[=3] "
            "((obstacle & (Z (! obstacle))) & (! (speed = 0.0)))) -> (O[<3] ((Z FALSE) | (speed = 0.0))))))")
#: FRET's ptExpanded of "in manual mode upon obstacle the rover shall immediately satisfy braking".
MODE_TRIGGER_PT = (
    "((H (((! manual) & (Y manual)) -> (Y (((obstacle & ((Y (! obstacle)) | (manual & (Z (! manual))))) -> braking) S "
    "(((obstacle & ((Y (! obstacle)) | (manual & (Z (! manual))))) -> braking) & (manual & (Z (! manual)))))))) & "
    "(((! ((! manual) & (Y manual))) S ((! ((! manual) & (Y manual))) & (manual & (Z (! manual))))) -> (((obstacle & "
    "((Y (! obstacle)) | (manual & (Z (! manual))))) -> braking) S (((obstacle & ((Y (! obstacle)) | (manual & (Z (! "
    "manual))))) -> braking) & (manual & (Z (! manual)))))))")
REQS = [
    _req("R-1", "the rover shall always satisfy speed <= limit", "always", "(speed <= limit)"),
    _req("R-2", "upon obstacle the rover shall immediately satisfy braking", "immediately", "(braking)",
         "regular", "(obstacle)"),
    _req("R-3", "the rover shall within 3 ticks satisfy speed <= asked", "within", "(speed <= asked)", duration=3),
    _req("R-4", "upon obstacle the rover shall after 2 ticks satisfy speed = 0.0", "after", "(speed = 0.0)",
         "regular", "(obstacle)", duration=2, ptExpanded=AFTER_PT),
    _req("R-6", "upon obstacle the rover shall finally satisfy braking", "finally", "(braking)", "regular",
         "(obstacle)", ptExpanded="((H (! obstacle)) | braking)"),
]


def _write(path: Path, reqs: list[dict[str, Any]], variables: list[dict[str, Any]] = VARIABLES) -> Path:
    path.write_text(json.dumps({"requirements": reqs, "variables": variables}, indent=2), encoding="utf-8")
    return path


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "rover.rcl").write_text(CONTRACT, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    return tmp_path


def test_each_requirement_becomes_a_plan_requirement_by_reqid(ws: Path, tmp_path: Path) -> None:
    res = import_fret(ws, "contracts/plan.yaml", _write(tmp_path / "export.json", REQS), "export.json")
    assert res.added == ["R-1", "R-2", "R-3", "R-4", "R-6"] and res.written and res.plan_edited
    plan = load_plan(ws)
    reqs = {r.id: r for r in all_requirements(plan)}
    assert list(reqs) == ["CAP", "R-1", "R-2", "R-3", "R-4", "R-6"]  # the plan's own first, then the export's
    assert reqs["R-1"].text == "the rover shall always satisfy speed <= limit"
    assert reqs["R-1"].origin == "fret/export.json" and reqs["R-1"].loc.file == "fret/export.json"
    assert reqs["R-1"].formal is not None and reqs["R-1"].formal.text == "always (Rover.out.speed <= (2.0))"
    assert reqs["R-2"].formal is not None and "Rover.state.fret_R_2_prev" in reqs["R-2"].formal.text
    assert [s.name for s in plan.states][0] == "fret_R_2_prev"
    assert reqs["R-3"].formal is not None and reqs["R-3"].formal.text.startswith("eventually[<= 3] ")
    assert reqs["R-4"].formal is not None and reqs["R-4"].formal.text.startswith("always (")  # FRET's ptExpanded
    assert {s.name for s in plan.states if s.name.startswith("fret_R_4_pt")}
    assert reqs["R-6"].formal is None  # not translated: informal, never dropped
    Workspace(ws, "contracts/plan.yaml").checked  # every imported statement type-checks with the contract
    out = render(res)
    assert "export.json:R-6: the timing finally asks the response at the last step of the scope's interval" in out
    assert "4 translated to a decided temporal statement, 1 kept as informal" in out


def test_reimport_reports_added_changed_removed_and_keeps_the_plans_own(ws: Path, tmp_path: Path) -> None:
    first = _write(tmp_path / "export.json", REQS)
    import_fret(ws, "contracts/plan.yaml", first, "export.json")
    plan_text = (ws / "contracts" / "plan.yaml").read_text(encoding="utf-8")
    copy = (ws / "fret" / "export.json").read_bytes()
    again = import_fret(ws, "contracts/plan.yaml", first, "export.json")
    assert (again.added, again.changed, again.removed) == ([], [], [])
    assert again.unchanged == ["R-1", "R-2", "R-3", "R-4", "R-6"] and not again.written and not again.plan_edited
    assert (ws / "fret" / "export.json").read_bytes() == copy
    edited = [dict(r) for r in REQS if r["reqid"] != "R-3"]
    edited[0] = _req("R-1", "the rover shall always satisfy speed <= 1.5", "always", "(speed <= 1.5)")
    edited.append(_req("R-5", "whenever obstacle the rover shall immediately satisfy speed = 0.0", "immediately",
                       "(speed = 0.0)", "noTrigger", "(obstacle)"))
    res = import_fret(ws, "contracts/plan.yaml", _write(tmp_path / "export.json", edited), "export.json")
    assert (res.added, res.changed, res.removed) == (["R-5"], ["R-1"], ["R-3"])
    assert (ws / "contracts" / "plan.yaml").read_text(encoding="utf-8") == plan_text  # the plan is not touched
    ids = [r.id for r in all_requirements(load_plan(ws))]
    assert ids == ["CAP", "R-1", "R-2", "R-4", "R-5", "R-6"]
    assert "  changed: R-1" in render(res) and "  removed: R-3" in render(res)


def test_refusals_name_the_reason_and_the_fix(tmp_path: Path) -> None:
    reqs = [
        _req("LUSTRE", "the rover shall always satisfy unguarded <= 2.0", "always", "(unguarded <= 2.0)"),
        _req("LUSTRE-WHEN", "the rover shall always satisfy sampled <= 2.0", "always", "(sampled <= 2.0)"),
        _req("LUSTRE-OK", "the rover shall always satisfy filtered <= 2.0", "always", "(filtered <= 2.0)"),
        _req("UNDECLARED", "the rover shall always satisfy ghost", "always", "(ghost)"),
        _req("FUNCTION", "the rover shall always satisfy cbrt(speed) < 2.0", "always", "(cbrt(speed) < 2.0)"),
        _req("MODE-TRIGGER", "in manual mode upon obstacle the rover shall immediately satisfy braking", "immediately",
             "(braking)", "regular", "(obstacle)", scope_mode="manual"),
        {"reqid": "NOSEM", "fulltext": "not parsed by FRET"},
        _req("PRE-INIT", "whenever preBool(false, speed - preReal(speed, speed) <= 1.0) the rover shall immediately "
                         "satisfy braking", "immediately", "(braking)", "noTrigger",
             "(preBool ( false , speed - preReal ( speed , speed ) <= 1.0 ))"),
        _req("OK", "the rover shall never satisfy speed > 2.0", "never", "(speed > 2.0)"),
        _req("MODE-TRIGGER-PT", "in manual mode upon obstacle the rover shall immediately satisfy braking",
             "immediately", "(braking)", "regular", "(obstacle)", scope_mode="manual", ptExpanded=MODE_TRIGGER_PT),
    ]
    reqs[5]["semantics"]["scope"] = {"type": "in"}
    reqs[-1]["semantics"]["scope"] = {"type": "in"}
    variables = VARIABLES + [_var("manual", "Input", "boolean")]
    got = {i.fret.reqid: i for i in import_export(read_export(_write(tmp_path / "e.json", reqs, variables), "e.json"),
                                                   Options())}
    why = {k: (i.refusal.reason, i.refusal.fix) if i.refusal else None for k, i in got.items()}
    assert why["LUSTRE"] == ("unguarded's definition reads pre at the first step, where Lustre leaves it undefined",
                             "give the pre an initial value in FRET (i -> pre e)")
    assert why["LUSTRE-WHEN"] == ("sampled is defined with Lustre's when, which rclverify does not read",
                                  "define sampled with ->, pre and if-then-else")
    assert why["LUSTRE-OK"] is None and got["LUSTRE-OK"].requirement.formal is not None  # Lustre's 0.0 -> pre speed
    assert got["LUSTRE-OK"].requirement.formal.text == (
        "always ((rover.state.fret_LUSTRE_OK_ftp -> ((0.0) <= 2.0)) and ((not rover.state.fret_LUSTRE_OK_ftp) -> "
        "((rover.state.fret_LUSTRE_OK_pre2) <= 2.0)))")
    assert why["UNDECLARED"] is not None and why["UNDECLARED"][0] == "ghost is not declared in the export"
    assert why["FUNCTION"] is not None and "FRET function cbrt(_)" in why["FUNCTION"][0]
    assert why["MODE-TRIGGER"] == ("its export has no past-time formalisation (semantics.ptExpanded), which rclverify "
                                   "states for the scope in with the timing immediately",
                                   "export the requirement again from FRET")
    assert why["MODE-TRIGGER-PT"] is None  # the same with FRET's formalisation: stated from it
    assert why["NOSEM"] is not None and "FRET has not formalised it" in why["NOSEM"][0]
    assert why["PRE-INIT"] is None  # preReal(speed, speed): Lustre's speed -> pre speed, FRET's first time point
    assert why["OK"] is None and got["OK"].requirement.formal is not None  # the control
    assert got["OK"].requirement.formal.text == "always (not (rover.out.speed > 2.0))"


def test_names_and_types_are_checked_against_the_contracts(ws: Path, tmp_path: Path) -> None:
    wrong = [_var("obstacle", "Input", "double"), _var("speed", "Input", "double"), _var("braking", "Output", "boolean")]
    reqs = [_req("TYPE", "whenever obstacle > 0.0 the rover shall immediately satisfy braking", "immediately",
                 "(braking)", "noTrigger", "(obstacle > 0.0)"),
            _req("SIDE", "the rover shall always satisfy speed <= 2.0", "always", "(speed <= 2.0)"),
            _req("GOOD", "the rover shall always satisfy braking | ! braking", "always", "(braking | ! braking)")]
    res = import_fret(ws, "contracts/plan.yaml", _write(tmp_path / "e.json", reqs, wrong), "e.json")
    why = {i.fret.reqid: i.refusal.reason if i.refusal else None for i in res.imported}
    assert why["TYPE"] == "obstacle is a FRET double but Rover.in.obstacle is a BOOL"
    assert why["SIDE"] == "Rover has no input named speed (its inputs: asked, obstacle)"
    assert why["GOOD"] is None
    (ws / "contracts" / "plan.yaml").write_text(PLAN.replace("{rover: Rover}", "{rover: Robot}"), encoding="utf-8")
    unmapped = import_fret(ws, "contracts/plan.yaml", tmp_path / "e.json", "e.json")
    assert {i.refusal.reason for i in unmapped.imported if i.refusal} == {"no node named Robot in the contracts "
                                                                         "(nodes: Rover)"}


@pytest.mark.parametrize("text, where, message", [
    ('{"requirements": [\n  {"reqid": "A", }\n]}', (2, 18), "the FRET export is not JSON"),
    ('{"requirements": [{"fulltext": "no id"}]}', (1, 1), "requirement 1 of the FRET export has no 'reqid' string"),
    ('[\n {"reqid": "A"},\n {"reqid": "A"}\n]', (3, 12), "reqid 'A' is used twice in the FRET export (first at 2:12)"),
    ('{"reqs": []}', (1, 1), "a FRET export is a list of requirements or an object with a 'requirements' list"),
    ('[\n {"reqid": "A", "semantics": {"timing": 3}}\n]', (2, 12),
     "requirement A of the FRET export: Expected `str | null`, got `int` - at `$.semantics.timing`"),
    ('{"requirements": [],\n "variables": [{"variable_name": "v", "idType": "Input", "dataType": 1}]}', (2, 34),
     "variable \"v\" of the FRET export: Expected `str | array | null`, got `int` - at `$.dataType`"),
])
def test_a_malformed_export_is_a_located_error(tmp_path: Path, text: str, where: tuple[int, int], message: str) -> None:
    p = tmp_path / "bad.json"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(PlanError) as e:
        read_export(p, "bad.json")
    d = e.value.diagnostics[0]
    assert (d.loc.file, d.loc.line, d.loc.col) == ("bad.json", *where) and d.message.startswith(message)


def test_the_command_exits_1_only_on_a_malformed_export(ws: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    good = _write(tmp_path / "export.json", REQS)
    args = argparse.Namespace(fn=cmd_import_fret, command="import", export=str(good), workspace=str(ws),
                              plan="contracts/plan.yaml")
    assert _run(args) == 0  # one requirement not imported is no error
    assert "export.json:R-6: " in capsys.readouterr().out
    bad = tmp_path / "bad.json"
    bad.write_text("{", encoding="utf-8")
    args.export = str(bad)
    assert _run(args) == 1
    err = capsys.readouterr().err
    assert f"{bad}:1:2: error: the FRET export is not JSON" in err and "Traceback" not in err
    assert not (ws / "fret" / "bad.json").exists()  # nothing is written for a malformed export


def test_durations_in_ticks_and_secs_and_modes(tmp_path: Path) -> None:
    from fractions import Fraction
    reqs = [_req("TICKS", "the rover shall within 4 ticks satisfy braking", "within", "(braking)", duration=4),
            _req("SECS", "the rover shall within 2 secs satisfy braking", "within", "(braking)", duration=2),
            _req("MSECS", "the rover shall for 300 msecs satisfy braking", "for", "(braking)", duration=300),
            _req("PART", "the rover shall within 150 msecs satisfy braking", "within", "(braking)", duration=150),
            _req("MODE", "in manual mode the rover shall always satisfy braking", "always", "(braking)",
                 scope_mode="manual")]
    reqs[4]["semantics"]["scope"] = {"type": "in"}
    defined = dict(_var("fast", "Mode", "boolean"), modeRequirement="speed > 1.0")
    reqs.append(_req("DEFINED-MODE", "in fast mode the rover shall always satisfy braking", "always", "(braking)",
                     scope_mode="fast"))
    reqs[5]["semantics"]["scope"] = {"type": "in"}
    variables = VARIABLES + [_var("manual", "Mode", "boolean"), defined]
    exp = read_export(_write(tmp_path / "e.json", reqs, variables), "e.json")

    def read(step: Fraction | None) -> dict[str, Any]:
        return {i.fret.reqid: i.requirement.formal.text if i.requirement.formal else i.refusal
                for i in import_export(exp, Options(step=step))}
    tenth = read(Fraction(1, 10))
    assert tenth["TICKS"] == "eventually[<= 4] rover.out.braking"
    assert tenth["SECS"] == "eventually[<= 20] rover.out.braking"
    assert tenth["MSECS"] == "always (rover.state.fret_MSECS_t <= 3 -> rover.out.braking)"
    assert tenth["PART"].reason == "its duration is not a whole number of steps (3/2)"
    assert tenth["MODE"].reason == "manual is a FRET Mode variable without a mode requirement"
    assert tenth["DEFINED-MODE"] == "always (((rover.out.speed > 1.0)) -> rover.out.braking)"  # the control
    bare = read(None)
    assert bare["TICKS"] == "eventually[<= 4] rover.out.braking"  # ticks need no step period
    assert bare["SECS"].reason == "its duration is 2 secs, and the plan declares no step period"
    assert bare["SECS"].fix.startswith("declare the step period in the plan (fret: {step: 100 ms})")
    from rclverify.model.plan.fret.requirements import options_of
    assert options_of({"fret": {"step": "100 ms", "components": {"rover": "Rover"}}}) == \
        Options({"rover": "Rover"}, Fraction(1, 10))  # the plan's fret: section


def test_a_statement_that_does_not_type_check_is_an_error_at_the_export(ws: Path, tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """Its names are the contract's, but ``braking = 1.0`` compares a BOOL with a number: the plan no longer
    checks, the checker's message is at the requirement in the export, and the command exits 1."""
    reqs = [_req("BAD-TYPE", "the rover shall always satisfy braking = 1.0", "always", "(braking = 1.0)")]
    args = argparse.Namespace(fn=cmd_import_fret, command="import", export=str(_write(tmp_path / "t.json", reqs)),
                              workspace=str(ws), plan="contracts/plan.yaml")
    assert _run(args) == 1
    err = capsys.readouterr().err
    assert "fret/t.json:4:13: error: BAD-TYPE: cannot compare BOOL with REAL using '==' (column 30 of its " \
           "translation: always (Rover.out.braking == 1.0))" in err  # at the reqid in the workspace's copy
    assert "the plan does not check with the imported requirements" in err
    reqs[0] = _req("BAD-TYPE", "the rover shall always satisfy braking", "always", "(braking)")  # the control
    _write(tmp_path / "t.json", reqs)
    assert _run(args) == 0


def test_the_plan_gains_only_its_requirements_from_line(ws: Path, tmp_path: Path) -> None:
    """A plan that reads a Doorstop tree gets the fret line under its requirements_from: (block style); one
    written in flow style is left alone, with a located error naming the line to add."""
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(PLAN + "requirements_from:\n    doorstop: reqs\n", encoding="utf-8")
    import_fret(ws, "contracts/plan.yaml", _write(tmp_path / "e.json", REQS), "e.json")
    assert plan.read_text(encoding="utf-8") == PLAN + "requirements_from:\n    fret: fret/e.json\n    doorstop: reqs\n"
    plan.write_text(PLAN + "requirements_from: {doorstop: reqs}\n", encoding="utf-8")
    with pytest.raises(PlanError) as e:
        import_fret(ws, "contracts/plan.yaml", _write(tmp_path / "f.json", REQS), "f.json")
    assert not (ws / "fret" / "f.json").exists()  # nothing written
    assert "add 'fret: fret/f.json' to it" in e.value.diagnostics[0].message
    assert plan.read_text(encoding="utf-8") == PLAN + "requirements_from: {doorstop: reqs}\n"


UNIT_CONTRACT = """node Rover {
  inputs( obstacle : BOOL, asked : REAL [m/s], gap : REAL )
  outputs( speed : REAL [m/s], braking : BOOL )
  assume( TRUE )
  guarantee( TRUE )
}
"""


def test_a_fret_unit_that_differs_from_the_ports_is_refused(tmp_path: Path) -> None:
    """A FRET variable's unit (its ``unit`` field, or ``[unit]`` ending its description) is the port's
    unit or the requirement is refused at its reqid with the reason; none said in FRET is not checked."""
    from rclverify.lang.parser import parse_text
    from rclverify.model.plan.fret.requirements import ports_of
    ports = ports_of([parse_text(UNIT_CONTRACT, "rover.rcl")])

    def imported(speed: dict[str, Any], gap: dict[str, Any] | None = None) -> Any:
        variables = [_var("obstacle", "Input", "boolean"), {**_var("speed", "Output", "double"), **speed},
                     {**_var("gap", "Input", "double"), **(gap or {})}, _var("asked", "Input", "double")]
        reqs = [_req("U", "the rover shall always satisfy speed <= 2.0 & gap >= 0.0", "always",
                     "(speed <= 2.0 & gap >= 0.0)")]
        exp = read_export(_write(tmp_path / "u.json", reqs, variables), "u.json")
        (got,) = import_export(exp, Options({"rover": "Rover"}), ports)
        return got
    km_h = imported({"unit": "km/h"})
    assert km_h.refusal is not None and km_h.requirement.formal is None
    assert (km_h.refusal.reason, km_h.refusal.fix) == (
        "speed is in [km/h] in FRET but Rover.out.speed is in [m/s]",
        "make the units agree: write [m/s] in FRET, or declare [km/h] on the port")
    described = imported({"description": "commanded speed [mm/s]"})
    assert described.refusal is not None and "[mm/s] in FRET" in described.refusal.reason
    no_unit = imported({}, {"unit": "m"})
    assert no_unit.refusal is not None and no_unit.refusal.reason == \
        "gap is in [m] in FRET but Rover.in.gap declares no unit"
    unknown = imported({"unit": "furlong"})
    assert unknown.refusal is not None and "is not a unit rclverify reads" in unknown.refusal.reason
    # the controls: the same unit however written, and no unit said in FRET
    assert imported({"unit": "m / s"}).refusal is None
    assert imported({"description": "commanded speed [m*s^-1]"}).refusal is None
    assert imported({}).refusal is None
