"""NoDL v2 documents beside the contracts (docs/nodl.md): read (JSON and YAML, schema, includes), located errors,
contract against document, QoS between documents, parameter constraints; each seeded mismatch with its control,
the unchanged example workspace of tests/data/nodl/ws."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import jsonschema
import pytest

from rclverify.cli.commands import main
from rclverify.lang.errors import RclError
from rclverify.model.nodl.check import check
from rclverify.model.nodl.document import QoS, Resolver, read_document, schema
from rclverify.model.nodl.qos import mismatches
from rclverify.stages.workspace import Workspace

WS = Path(__file__).parent.parent / "data" / "nodl" / "ws"


@pytest.fixture()
def ws(tmp_path: Path) -> Path:
    out = tmp_path / "ws"
    shutil.copytree(WS, out)
    return out


def _findings(ws: Path) -> list:
    return check(Workspace(ws, "contracts/plan.yaml").checked, ws).findings


def _line_of(path: Path, text: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if text in ln)


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


# ---- the control: the example workspace as committed


def test_the_example_documents_are_read_with_their_include_and_match_the_contracts(ws: Path) -> None:
    res = check(Workspace(ws, "contracts/plan.yaml").checked, ws)
    assert res.findings == []
    assert sorted(res.documents) == ["Base", "Dock", "Guard"]
    guard = res.documents["Guard"]
    assert guard.files == ("nodl/Guard.nodl.yaml", "nodl/common/diagnostics.nodl.yaml")
    assert [p.name for p in guard.parameters] == ["diagnostics_period"]  # from the included document
    assert {(e.kind, e.name, e.type) for e in res.documents["Base"].endpoints} == {
        ("subscriptions", "/stop", "std_msgs/msg/Bool"), ("publishers", "/speed", "std_msgs/msg/Float64"),
        ("service_servers", "/estop", "std_srvs/srv/SetBool")}


# ---- reading: located errors, never a traceback


@pytest.mark.parametrize("name,text,where,words", [
    ("Bad.nodl.json", '{\n  "nodl_version": 2,\n  "publishers": [\n    {"name": "/a" "type": 1}\n  ]\n}\n',
     (4, 19), "not JSON: Expecting ',' delimiter"),
    ("Bad.nodl.json", '{"nodl_version": 2,\n "description": "a",\n "description": "b"}\n', (3, 2),
     "duplicate key 'description'"),
    ("Bad.nodl.yaml", "nodl_version: 2\npublishers:\n  - name: /a\n    type: [unclosed\n", (5, 1), "not YAML"),
    ("Bad.nodl.yaml", "nodl_version: 2\npublishers:\n  - name: /a\n    type: std_msgs/msg/Bool\n    qos:\n"
                      "      history: KEEP_LAST\n      depth: 1\n      reliabilty: RELIABLE\n", (8, 7),
     "Additional properties are not allowed ('reliabilty' was unexpected)"),
    ("Bad.nodl.yaml", "nodl_version: 2\nsubscriptions:\n  - name: /a\n    type: std_msgs/msg/Bool\n    qos:\n"
                      "      history: KEEP_LAST\n      depth: 1\n      reliability: SOMETIMES\n", (8, 20),
     "'SOMETIMES' is not one of"),
    ("Bad.nodl.yaml", "nodl_version: 2\npublishers:\n  - name: /a\n    type: std_msgs/msg/Bool\n    qos:\n"
                      "      history: KEEP_LAST\n      reliability: RELIABLE\n", (6, 7), "'depth' is a required property"),
    ("Bad.nodl.yaml", "nodl_version: 3\n", (1, 15), "2 was expected"),
])
def test_a_malformed_document_is_one_located_error(tmp_path: Path, capsys, name: str, text: str,
                                                   where: tuple[int, int], words: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(RclError) as exc:
        read_document(path, name)
    d = next(d for d in exc.value.diagnostics if words in d.message)
    assert (d.loc.file, d.loc.line, d.loc.col) == (name, *where), str(d)
    assert main(["nodl", "validate", str(path)]) == 1  # the command: located lines, exit 1
    err = capsys.readouterr().err
    assert re.search(rf"^{re.escape(str(path))}:{where[0]}:{where[1]}: error: .*{re.escape(words)}", err, re.M)
    assert "Traceback" not in err


def test_the_schema_accepts_what_the_format_allows(tmp_path: Path) -> None:
    """The control of the schema errors above: every list, QoS field, parameter type and validator form."""
    doc = {"nodl_version": 2, "description": "all", "codegen": {"cpp": {"x": 1}},
           "publishers": [{"name": "~/out", "type": "std_msgs/String",
                           "qos": {"history": "KEEP_ALL", "reliability": "BEST_AVAILABLE", "durability": "SYSTEM_DEFAULT",
                                   "deadline_ns": 0, "lifespan_ns": 5, "liveliness": "MANUAL_BY_TOPIC",
                                   "liveliness_lease_duration_ns": 7}}],
           "subscriptions": [{"name": "in", "type": "std_msgs/msg/String",
                              "qos": {"history": "SYSTEM_DEFAULT", "reliability": "SYSTEM_DEFAULT"}}],
           "service_servers": [{"name": "/s", "type": "std_srvs/srv/Trigger",
                                "qos": {"history": "KEEP_LAST", "depth": 1, "reliability": "RELIABLE"}}],
           "service_clients": [{"name": "/c", "type": "std_srvs/Trigger"}],
           "action_servers": [{"name": "a", "type": "example_interfaces/action/Fibonacci"}],
           "action_clients": [{"name": "b", "type": "nav2_msgs/NavigateToPose", "description": "x"}],
           "parameters": {"p": {"type": "double", "default_value": 0.5, "read_only": True, "description": "d",
                                "validation": {"bounds<>": [0, 1], "lt": 2, "gt_eq": [0], "one_of": [[0.5, 1]],
                                               "my_pkg::check": [1, 2]}},
                          "q": {"type": "string_array_fixed_3", "validation": {"not_empty<>": None, "size_lt": [4],
                                                                               "unique": []}},
                          "r": {"type": "byte_array", "default_value": [0, 255]}}}
    jsonschema.Draft202012Validator(schema()).validate(doc)
    path = tmp_path / "All.nodl.json"
    path.write_text(json.dumps(doc, indent=1))
    read = read_document(path)
    assert len(read.endpoints) == 6 and [p.name for p in read.parameters] == ["p", "q", "r"]
    bad = dict(doc, parameters={"r": {"type": "byte_array", "default_value": [256]}})
    assert not jsonschema.Draft202012Validator(schema()).is_valid(bad)


def test_includes_are_followed_and_a_cycle_or_a_repeated_name_is_refused(tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    (tmp_path / "A.nodl.yaml").write_text("nodl_version: 2\ninclude:\n  - ref: local://parts/b.nodl.yaml\n")
    (tmp_path / "parts" / "b.nodl.yaml").write_text(
        "nodl_version: 2\naction_clients:\n  - {name: go, type: pkg/action/Go}\n")
    doc = read_document(tmp_path / "A.nodl.yaml", "A.nodl.yaml", Resolver(display=lambda p: p.name))
    assert [(e.kind, e.name) for e in doc.endpoints] == [("action_clients", "go")]  # the control
    # b includes A: a cycle, located at b's reference
    (tmp_path / "parts" / "b.nodl.yaml").write_text("nodl_version: 2\ninclude:\n  - ref: local://../A.nodl.yaml\n")
    with pytest.raises(RclError) as exc:
        read_document(tmp_path / "A.nodl.yaml", "A.nodl.yaml", Resolver(display=lambda p: p.name))
    d = exc.value.diagnostics[0]
    assert (d.loc.file, d.loc.line, d.loc.col) == ("b.nodl.yaml", 3, 10)
    assert "closes a cycle: A.nodl.yaml -> b.nodl.yaml -> A.nodl.yaml" in d.message
    # a name both documents declare
    (tmp_path / "parts" / "b.nodl.yaml").write_text("nodl_version: 2\naction_clients:\n  - {name: go, type: p/Go}\n")
    (tmp_path / "A.nodl.yaml").write_text("nodl_version: 2\naction_clients:\n  - {name: go, type: p/Go}\n"
                                          "include:\n  - ref: local://parts/b.nodl.yaml\n")
    with pytest.raises(RclError, match=r"action client 'go' is declared twice: first at A.nodl.yaml:3:12"):
        read_document(tmp_path / "A.nodl.yaml", "A.nodl.yaml", Resolver(display=lambda p: p.name))
    # an include nothing resolves
    (tmp_path / "A.nodl.yaml").write_text("nodl_version: 2\ninclude:\n  - ref: local://parts/none.yaml\n"
                                          "  - ref: nodl://pkg/node\n")
    with pytest.raises(RclError, match="no file") as exc:
        read_document(tmp_path / "A.nodl.yaml", "A.nodl.yaml")
    assert exc.value.diagnostics[0].loc.line == 3


def test_a_nodl_reference_resolves_in_the_ament_index(tmp_path: Path) -> None:
    index = tmp_path / "install" / "share" / "ament_index" / "resource_index" / "nodl"
    index.mkdir(parents=True)
    (index / "sensors__imu").write_text("nodl_version: 2\npublishers:\n  - name: imu\n    type: sensor_msgs/Imu\n"
                                        "    qos: {history: KEEP_LAST, depth: 5, reliability: BEST_EFFORT}\n")
    (tmp_path / "N.nodl.yaml").write_text("nodl_version: 2\ninclude:\n  - ref: nodl://sensors/imu\n")
    with pytest.raises(RclError, match="no NoDL resource sensors__imu"):
        read_document(tmp_path / "N.nodl.yaml")
    doc = read_document(tmp_path / "N.nodl.yaml", resolver=Resolver([tmp_path / "install"]))
    assert [(e.name, e.qos.reliability if e.qos else None) for e in doc.endpoints] == [("imu", "BEST_EFFORT")]


# ---- the contract against its document


def test_an_endpoint_the_document_lacks_is_found_at_both_files(ws: Path) -> None:
    doc = ws / "nodl" / "Base.nodl.json"
    data = json.loads(doc.read_text())
    del data["publishers"]
    doc.write_text(json.dumps(data, indent=2))
    f = _findings(ws)
    assert [x.code for x in f] == ["nodl-missing"]
    assert "Base publishes /speed (std_msgs/Float64)" in f[0].message
    rcl = ws / "contracts" / "robot.rcl"
    assert [(loc.file, loc.line) for loc in f[0].locs] == [
        ("contracts/robot.rcl", _line_of(rcl, "std_msgs/Float64 speed")), ("nodl/Base.nodl.json", 1)]


def test_an_endpoint_the_contract_lacks_is_a_warning_at_both_files(ws: Path) -> None:
    _edit(ws / "nodl" / "Dock.nodl.yaml", "action_servers:", "action_clients:\n  - {name: undock, type: p/action/Undock}\n"
                                                             "action_servers:")
    f = _findings(ws)
    assert [(x.code, x.severity) for x in f] == [("nodl-extra", "warning")]
    assert [(loc.file, loc.line) for loc in f[0].locs] == [
        ("nodl/Dock.nodl.yaml", 3), ("contracts/robot.rcl", _line_of(ws / "contracts" / "robot.rcl", "node Dock"))]


def test_a_type_differing_is_found_at_both_files_and_between_the_connected_documents(ws: Path) -> None:
    _edit(ws / "nodl" / "Guard.nodl.yaml", "type: std_msgs/msg/Bool", "type: std_msgs/msg/Empty")
    f = _findings(ws)
    assert sorted(x.code for x in f) == ["nodl-connect-type", "nodl-type"]
    t = next(x for x in f if x.code == "nodl-type")
    line = _line_of(ws / "nodl" / "Guard.nodl.yaml", "std_msgs/msg/Empty")
    assert [(loc.file, loc.line, loc.col) for loc in t.locs] == [
        ("contracts/robot.rcl", _line_of(ws / "contracts" / "robot.rcl", "std_msgs/Bool stop matches(out"), 11),
        ("nodl/Guard.nodl.yaml", line, 11)]
    c = next(x for x in f if x.code == "nodl-connect-type")
    assert {loc.file for loc in c.locs} == {"nodl/Guard.nodl.yaml", "nodl/Base.nodl.json"}


def test_a_direction_differing_names_what_the_document_has(ws: Path) -> None:
    _edit(ws / "nodl" / "Guard.nodl.yaml", "subscriptions:", "publishers_:")
    _edit(ws / "nodl" / "Guard.nodl.yaml", "publishers:", "subscriptions:")
    _edit(ws / "nodl" / "Guard.nodl.yaml", "publishers_:", "publishers:")
    msgs = [x.message for x in _findings(ws) if x.code == "nodl-missing"]
    assert any("publishes /stop" in m and "the document has /stop as a subscription" in m for m in msgs)


# ---- QoS between the documents of connected nodes


@pytest.mark.parametrize("field,old,new,policy", [
    ("reliability", "reliability: RELIABLE\n      durability", "reliability: BEST_EFFORT\n      durability",
     "reliability"),
    ("durability", "durability: TRANSIENT_LOCAL", "durability: VOLATILE", "durability"),
    ("deadline", "deadline_ns: 100000000", "deadline_ns: 300000000", "deadline_ns"),
    ("no deadline", "      deadline_ns: 100000000\n", "", "deadline_ns"),
])
def test_an_incompatible_qos_is_found_at_both_documents(ws: Path, field: str, old: str, new: str, policy: str) -> None:
    guard = ws / "nodl" / "Guard.nodl.yaml"
    _edit(guard, old, new)
    f = _findings(ws)
    assert [x.code for x in f] == ["nodl-qos"], field
    assert f"({policy}: offered" in f[0].message and "the publisher Guard and the subscriber Base never connect" \
        in f[0].message
    assert [loc.file for loc in f[0].locs] == ["nodl/Base.nodl.json", "nodl/Guard.nodl.yaml"]
    key = policy.split("_")[0] + (":" if policy != "deadline_ns" else "_ns:")
    written = key in guard.read_text().split("subscriptions:")[0]
    assert f[0].locs[1].line == _line_of(guard, key if written else "history: KEEP_LAST")
    base = ws / "nodl" / "Base.nodl.json"  # the subscriber: its line of the policy
    assert f[0].locs[0].line == _line_of(base, '"deadline_ns"' if policy == "deadline_ns" else f'"{policy}"')


def test_the_request_offered_rules() -> None:
    q = lambda **kw: QoS(kw.pop("history", "KEEP_LAST"), kw.pop("reliability", "RELIABLE"), **kw)  # noqa: E731
    assert mismatches(q(), q()) == []
    assert [m.policy for m in mismatches(q(reliability="BEST_EFFORT"), q())] == ["reliability"]
    assert mismatches(q(), q(reliability="BEST_EFFORT")) == []  # a reliable writer serves a best-effort reader
    assert mismatches(q(reliability="BEST_EFFORT"), q(reliability="BEST_AVAILABLE")) == []  # it adapts
    assert mismatches(q(reliability="BEST_EFFORT"), q(reliability="SYSTEM_DEFAULT")) != []  # rmw's default: reliable
    assert [m.policy for m in mismatches(q(), q(durability="TRANSIENT_LOCAL"))] == ["durability"]  # left out: volatile
    assert mismatches(q(durability="TRANSIENT_LOCAL"), q()) == []
    assert [m.policy for m in mismatches(q(liveliness="AUTOMATIC"), q(liveliness="MANUAL_BY_TOPIC"))] == ["liveliness"]
    assert mismatches(q(liveliness="MANUAL_BY_TOPIC"), q(liveliness="AUTOMATIC")) == []
    assert [m.policy for m in mismatches(q(liveliness_lease_duration_ns=0), q(liveliness_lease_duration_ns=5))] \
        == ["liveliness_lease_duration_ns"]
    assert mismatches(q(deadline_ns=5), q(deadline_ns=5)) == [] and mismatches(q(deadline_ns=5), q()) == []
    assert mismatches(None, None) == []


def test_a_service_qos_is_judged_both_ways(ws: Path) -> None:
    dock = ws / "nodl" / "Dock.nodl.yaml"
    dock.write_text(dock.read_text() + "service_clients:\n  - name: /estop\n    type: std_srvs/SetBool\n"
                                       "    qos: {history: KEEP_LAST, depth: 1, reliability: BEST_EFFORT}\n")
    f = [x for x in _findings(ws) if x.code == "nodl-qos"]
    assert len(f) == 1 and "service /estop (requests): the client Dock and the server Base" in f[0].message


# ---- parameters and their declared constraints


def test_a_contract_constant_outside_its_parameters_range_is_found_at_both_files(ws: Path) -> None:
    _edit(ws / "nodl" / "Base.nodl.json", '"bounds<>": [0.0, 2.0]', '"bounds<>": [0.0, 1.2]')
    f = _findings(ws)
    assert [x.code for x in f] == ["nodl-parameter"]
    assert "constant MaxSpeed = 1.5 is not within [0.0, 1.2]" in f[0].message
    assert [(loc.file, loc.line) for loc in f[0].locs] == [
        ("contracts/robot.rcl", _line_of(ws / "contracts" / "robot.rcl", "MaxSpeed : REAL")),
        ("nodl/Base.nodl.json", _line_of(ws / "nodl" / "Base.nodl.json", '"MaxSpeed"'))]


def test_a_default_outside_its_declared_range_is_found_in_the_included_document(ws: Path) -> None:
    part = ws / "nodl" / "common" / "diagnostics.nodl.yaml"
    _edit(part, "default_value: 1.0", "default_value: 20.0")
    f = _findings(ws)
    assert [x.code for x in f] == ["nodl-parameter"]
    assert "diagnostics_period's default 20.0 is not within [0.1, 10.0]" in f[0].message
    assert (f[0].locs[0].file, f[0].locs[0].line) == ("nodl/common/diagnostics.nodl.yaml",
                                                      _line_of(part, "default_value"))


# ---- the command


def test_nodl_check_prints_each_finding_at_each_file_and_exits_1(ws: Path, capsys, tmp_path: Path) -> None:
    assert main(["nodl", "check", "-w", str(ws), "--json", str(tmp_path / "f.json")]) == 0  # the control
    assert "3 node document(s) and 0 part(s) read; 0 error(s), 0 warning(s)" in capsys.readouterr().out
    _edit(ws / "nodl" / "Guard.nodl.yaml", "durability: TRANSIENT_LOCAL", "durability: VOLATILE")
    (ws / "nodl" / "Stray.nodl.yaml").write_text("nodl_version: 2\n")
    assert main(["nodl", "check", "-w", str(ws), "--json", str(tmp_path / "f.json")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and "Traceback" not in "".join(err)
    assert err[0].startswith("nodl/Base.nodl.json:") and err[0].endswith("[nodl-qos]")
    assert err[1].startswith("nodl/Guard.nodl.yaml:") and err[2].startswith("nodl/Stray.nodl.yaml:1:1: warning:")
    data = json.loads((tmp_path / "f.json").read_text())
    assert [f["code"] for f in data["findings"]] == ["nodl-qos", "nodl-node"] and data["parts"] == ["nodl/Stray.nodl.yaml"]
    _edit(ws / "nodl" / "Guard.nodl.yaml", "durability: VOLATILE", "durability: TRANSIENT_LOCAL")
    assert main(["nodl", "check", "-w", str(ws)]) == 0  # a warning only
    assert main(["nodl", "check", "-w", str(ws), "--strict"]) == 1


def test_a_parameters_constraints_discharge_the_assumption_on_the_input_it_sets(ws: Path) -> None:
    res = check(Workspace(ws, "contracts/plan.yaml").checked, ws)
    assert [(s.node, s.parameter, s.conjunct, s.status) for s in res.sides] == [
        ("Base", "limit", "0 < in.limit", "proved"), ("Base", "limit", "in.limit <= MaxSpeed", "proved")]
    # seeded: the declaration lets the limit rise above MaxSpeed (1.5), which Base assumes it never does
    _edit(ws / "nodl" / "Base.nodl.json", '"lt_eq<>": [1.2]', '"lt_eq<>": [1.8]')
    res = check(Workspace(ws, "contracts/plan.yaml").checked, ws)
    assert [(s.conjunct, s.status) for s in res.sides] == [("0 < in.limit", "proved"),
                                                          ("in.limit <= MaxSpeed", "refuted")]
    f = res.findings
    assert [x.code for x in f] == ["nodl-parameter-assume"]
    assert "node Base assumes in.limit <= MaxSpeed of input limit, which parameter limit sets" in f[0].message
    m = re.search(r"allow Base\.in\.limit = ([0-9.]+), which breaks it", f[0].message)
    assert m is not None and 1.5 < float(m.group(1)) <= 1.8  # Z3's counterexample: allowed, above MaxSpeed
    assert [(loc.file, loc.line) for loc in f[0].locs] == [
        ("contracts/robot.rcl", _line_of(ws / "contracts" / "robot.rcl", "assume( 0 < in.limit")),
        ("nodl/Base.nodl.json", _line_of(ws / "nodl" / "Base.nodl.json", '"limit"'))]
