"""``rclverify generate ros2``: interfaces parse with rosbags' type system with the mapped field
types, every generated Python file compiles, ``ros scan`` of the generated tree gives back the
contracts' graph exactly, and regeneration keeps logic files (docs/generate.md)."""
from __future__ import annotations

import json
import py_compile
import shutil
from pathlib import Path

import pytest
from rosbags.typesys import get_types_from_msg
from rosbags.interfaces import Nodetype

from rclverify.cli.commands import main
from rclverify.tools.generate.writer import GENERATED, ONCE
from rclverify.app.pipeline import Workspace
from rclverify.ros.extract.treesitter import parser, walk

ROOT = Path(__file__).resolve().parents[2]

ALL_TYPES = """
context {
  Color : {red, green} ;
  Cmd : { go(REAL, NATURAL), turn(INTEGER) } ;
  Tab : NATURAL --> REAL ;
  Pair : (REAL, INTEGER) ;
  Nothing : {} ;
}
node Probe {
  inputs( r : REAL [m], i : INTEGER, n : NATURAL, b : BOOL, s : STRING, c : Color, k : Cmd, f : Tab,
          p : Pair, e : Nothing, q : seq(REAL), z : set(NATURAL), qq : seq(seq(BOOL)) )
  outputs( o : BOOL )
  topics( probe_msgs/All r matches(in.r), probe_msgs/All i matches(in.i), probe_msgs/All n matches(in.n),
          probe_msgs/All b matches(in.b), probe_msgs/All s matches(in.s), probe_msgs/All c matches(in.c),
          probe_msgs/All k matches(in.k), probe_msgs/All f matches(in.f), probe_msgs/All p matches(in.p),
          probe_msgs/All e matches(in.e), probe_msgs/All q matches(in.q), probe_msgs/All z matches(in.z),
          probe_msgs/All qq matches(in.qq), std_msgs/Bool o matches(out.o) )
  assume( TRUE )
  guarantee( out.o == in.b )
}
"""

# field -> the type rosbags reads (BASE name, NAME type, or ('seq', inner))
EXPECTED = {
    "r": "float64", "i": "int64", "n": "uint64", "b": "bool", "s": "string", "c": "uint8",
    "k": "probe_msgs/msg/Cmd", "f": ("seq", "probe_msgs/msg/TabEntry"), "p": "probe_msgs/msg/Pair",
    "e": "std_msgs/msg/Empty", "q": ("seq", "float64"), "z": ("seq", "uint64"),
    "qq": ("seq", "probe_msgs/msg/QqItem"),
}


def _ws(tmp: Path, rcl: str) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "sys.rcl").write_text(rcl)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    return ws


def _simple(t: tuple) -> object:
    kind, arg = t
    if kind == Nodetype.BASE:
        return arg[0]
    if kind == Nodetype.NAME:
        return arg
    assert kind == Nodetype.SEQUENCE
    return ("seq", _simple(arg[0]))


def _parse_all(out: Path) -> dict[str, tuple]:
    """Every interface file parsed with rosbags: full type name -> (constants, fields)."""
    types: dict[str, tuple] = {}
    for f in sorted(out.glob("*/msg/*.msg")) + sorted(out.glob("*/srv/*.srv")) + sorted(out.glob("*/action/*.action")):
        pkg, kind, name = f.parent.parent.name, f.parent.name, f.stem
        parts = f.read_text().split("\n---\n")
        suffixes = {"msg": [""], "srv": ["_Request", "_Response"], "action": ["_Goal", "_Result", "_Feedback"]}[kind]
        assert len(parts) == len(suffixes), f
        for text, suf in zip(parts, suffixes):
            types.update(get_types_from_msg(text, f"{pkg}/{kind}/{name}{suf}"))
    return types


def test_every_rcl_type_maps_to_the_documented_ros_field(tmp_path: Path) -> None:
    ws = _ws(tmp_path, ALL_TYPES)
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp_path / "out")]) == 0
    types = _parse_all(tmp_path / "out")
    consts, fields = types["probe_msgs/msg/All"]
    got = {n: _simple(t) for n, t in fields}
    assert got == EXPECTED
    assert ("COLOR_RED", "uint8", 0) in consts and ("COLOR_GREEN", "uint8", 1) in consts
    cmd_consts, cmd_fields = types["probe_msgs/msg/Cmd"]
    assert [c[0] for c in cmd_consts] == ["GO", "TURN"]
    assert {n: _simple(t) for n, t in cmd_fields} == {"ctor": "uint8", "go_0": "float64", "go_1": "uint64",
                                                      "turn_0": "int64"}
    assert {n: _simple(t) for n, t in types["probe_msgs/msg/TabEntry"][1]} == {"arg0": "uint64", "value": "float64"}
    assert {n: _simple(t) for n, t in types["probe_msgs/msg/QqItem"][1]} == {"elems": ("seq", "bool")}
    assert "# [m]" in (tmp_path / "out/probe_msgs/msg/All.msg").read_text()
    assert not (tmp_path / "out/std_msgs").exists()  # standard types are used, not generated


def _graph_of_contracts(ws: Path) -> dict[str, set]:
    checked = Workspace(ws, "contracts/plan.yaml").checked
    g: dict[str, set] = {}
    for cn in checked.nodes.values():
        ends = set()
        for t in cn.node.topics:
            if t.match is not None and t.match.prefix in ("in", "out"):
                pkg, name = t.msg_type.split("/")[0], t.msg_type.split("/")[-1]
                ends.add(("subscribes" if t.match.prefix == "in" else "publishes", "/" + t.field, f"{pkg}/msg/{name}"))
        for ln in cn.node.links:
            pkg, name = ln.ros_type.split("/")[0], ln.ros_type.split("/")[-1]
            kind = "srv" if ln.kind == "service" else "action"
            ends.add((f"{ln.kind}_{'servers' if ln.role == 'serves' else 'clients'}", "/" + ln.name,
                      f"{pkg}/{kind}/{name}"))
        g["/" + cn.name] = ends
    return g


def _graph_of_scan(out: Path, tmp: Path) -> dict[str, set]:
    js = tmp / "graph.json"
    assert main(["ros", "scan", str(out), "--json", str(js)]) == 0
    scan = json.loads(js.read_text())
    g: dict[str, set] = {}
    for n in scan["nodes"]:
        ends = set()
        for role in ("publishes", "subscribes", "service_servers", "service_clients", "action_servers",
                     "action_clients"):
            ends |= {(role, e["topic"], e["type"]) for e in n[role]}
        g[n["name"]] = ends
    assert not scan["unresolved"]
    return g


def _chain_system(n: int) -> str:
    """``n`` nodes in a chain over std_msgs topics; node 0 serves a service and an action the last calls."""
    lines = ["context { Mode : {idle, busy} ; }"]
    for k in range(n):
        links = ""
        if k == 0:
            links = ("  services( chain_msgs/Ask ask serves(in.q, out.a) )\n"
                     "  actions( chain_msgs/Go go serves(in.g, out.fb, out.res) )\n")
            io = "inputs( q : BOOL, g : REAL [m] ) outputs( x0 : REAL, a : Mode, fb : REAL, res : BOOL )"
            topics = "topics( std_msgs/Float64 t0 matches(out.x0) )"
        else:
            extra_in = ", a : Mode, fb : REAL, res : BOOL" if k == n - 1 else ""
            extra_out = ", q : BOOL, g : REAL [m]" if k == n - 1 else ""
            if k == n - 1:
                links = ("  services( chain_msgs/Ask ask calls(out.q, in.a) )\n"
                         "  actions( chain_msgs/Go go calls(out.g, in.fb, in.res) )\n")
            io = f"inputs( x{k - 1} : REAL{extra_in} ) outputs( x{k} : REAL{extra_out} )"
            topics = f"topics( std_msgs/Float64 t{k - 1} matches(in.x{k - 1}), std_msgs/Float64 t{k} matches(out.x{k}) )"
        lines.append(f"node N{k} {{\n  {io}\n  {topics}\n{links}  assume( TRUE )\n"
                     f"  guarantee( out.x{k} >= 0 )\n}}")
    return "\n".join(lines)


def _verdict_end(node: str) -> tuple[str, str, str]:
    """A generated node's own verdict publisher: ``~/contract_verdict``, never the monitor's topic."""
    return ("publishes", f"{node}/contract_verdict", "std_msgs/msg/String")  # node: /Name


@pytest.mark.parametrize("lang", ["python", "cpp"])
@pytest.mark.parametrize("case", ["case_study", "warehouse", "chain30", "hostile"])
def test_ros_scan_of_the_generated_tree_is_the_contracts_graph(tmp_path: Path, case: str, lang: str) -> None:
    if case == "hostile":  # keyword and primed names (test_generate_names.py): the same graph, by its RCL names
        from test_generate_names import HOSTILE
        ws = _ws(tmp_path, HOSTILE)
    elif case == "case_study":
        ws = ROOT
    elif case == "warehouse":
        ws = ROOT / "examples" / "warehouse"
    else:
        ws = _ws(tmp_path, _chain_system(30))
    out = tmp_path / "out"
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--system", "sys", "--lang", lang]) == 0
    want = _graph_of_contracts(ws)
    # the contracts' graph, and each node's verdict publisher (its contract layer's violations)
    assert _graph_of_scan(out, tmp_path) == {n: ends | {_verdict_end(n)} for n, ends in want.items()}
    if case == "chain30":
        assert len(want) == 30
    if case == "warehouse":  # units and the assumption's bounds as comments, from every user of the field
        nav = (out / "warehouse_msgs/action/Navigate.action").read_text()
        assert "float64 goal_x  # [m]; RCL REAL; Planner assumes 0 <= goal_x <= 100\n" in nav
    _parse_all(out)  # every interface file parses
    pys = sorted(out.rglob("*.py"))
    if lang == "python":
        assert len(pys) == 6 * len(want) + 1  # per node: __init__, node, contract, contract_eval, logic, setup; launch
    else:
        assert len(pys) == 1  # the launch file
        cpps = sorted(out.rglob("*.cpp")) + sorted(out.rglob("*.hpp"))
        assert len(cpps) == 6 * len(want)  # node, logic .cpp/.hpp, checks, driver .hpp/.cpp
        for p in cpps:  # tree-sitter-cpp reads every C++ file without an error node
            tree = parser("cpp").parse(p.read_bytes())
            bad = [n for n in walk(tree.root_node) if n.type == "ERROR" or n.is_missing]
            assert not bad, (p, bad[0].start_point)
            first = p.read_text().splitlines()[0]
            assert first in (f"// {GENERATED}", f"// {ONCE}"), p
    for p in pys:
        py_compile.compile(str(p), cfile=str(tmp_path / "c.pyc"), doraise=True)
        first = p.read_text().splitlines()[0]
        assert first in (f"# {GENERATED}", f"# {ONCE}"), p


def test_regeneration_keeps_logic_and_names_the_logic_files_to_read(tmp_path: Path, capsys) -> None:
    ws = _ws(tmp_path, _chain_system(3))
    out = tmp_path / "out"
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out)]) == 0
    logic = out / "n1/n1/logic.py"
    logic.write_text(logic.read_text() + "\n# hand-written\n")
    capsys.readouterr()
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out)]) == 0
    msg = capsys.readouterr().out
    assert "0 generated file(s) written" in msg and "warning" not in msg
    # the interface of N2 changes (new topic); N1's does not
    rcl = (ws / "contracts/sys.rcl").read_text().replace(
        "std_msgs/Float64 t2 matches(out.x2)", "std_msgs/Float64 t2b matches(out.x2)")
    (ws / "contracts/sys.rcl").write_text(rcl)
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out)]) == 0
    msg = capsys.readouterr().out
    assert "n2/n2/logic.py: warning" in msg and "n1/n1/logic.py" not in msg
    assert logic.read_text().endswith("# hand-written\n")
    assert "'t2b'" in (out / "n2/n2/node.py").read_text()


def test_a_contract_error_is_located_and_no_tree_is_written(tmp_path: Path, capsys) -> None:
    ws = _ws(tmp_path, "node A { inputs( x : REAL ) outputs( y : REAL ) topics( ) assume( TRUE ) guarantee( out.z > 0 ) }")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert "contracts/sys.rcl:1:" in err and "error" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_a_hand_written_file_at_a_generated_path_is_never_overwritten(tmp_path: Path, capsys) -> None:
    ws = _ws(tmp_path, _chain_system(2))
    out = tmp_path / "out"
    (out / "n0" / "n0").mkdir(parents=True)
    (out / "n0" / "n0" / "node.py").write_text("# mine\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "n0/n0/node.py: error: exists and is not a generated file" in err and "Traceback" not in err
    assert (out / "n0" / "n0" / "node.py").read_text() == "# mine\n"
    assert not (out / "n1").exists()  # nothing written


def test_one_quantity_in_two_units_in_one_interface_is_a_located_error(tmp_path: Path, capsys) -> None:
    """A service whose request carries metres and whose response millimetres (issue 62): refused at
    the later declaration's unit, naming the other, exit 1, nothing written; the same units on a
    message's two fields, or one dimension in one unit, are fine."""
    ws = _ws(tmp_path, "node Ranger {\n  inputs( target : REAL [m] )\n  outputs( dist : REAL [mm] )\n"
                       "  services( range_msgs/Measure measure serves(in.target, out.dist) )\n"
                       "  assume( TRUE )\n  guarantee( out.dist >= 0 )\n}\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert "contracts/sys.rcl:3:24: error: range_msgs/srv/Measure: field dist would carry Ranger's out.dist " \
           "in [mm], and field target the same quantity in [m] (Ranger's in.target, contracts/sys.rcl:2:25)" in err
    assert "Traceback" not in err and not (tmp_path / "out").exists()
    (ws / "contracts" / "sys.rcl").write_text((ws / "contracts" / "sys.rcl").read_text().replace("[mm]", "[m]"))
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp_path / "out")]) == 0
    srv = (tmp_path / "out" / "range_msgs" / "srv" / "Measure.srv").read_text()
    assert "float64 target  # [m]" in srv and "float64 dist  # [m]" in srv


DIFF_CONTRACT = """\
context {
  Mode : {idle, run, halt} ;
  Limit : REAL = 2.5 ;
  Step : REAL = 0.1 ;
}
node Mixer {
  inputs( a : REAL, b : REAL, k : INTEGER, m : Mode, f : BOOL )
  outputs( s : REAL, q : REAL, ok : BOOL, n : NATURAL, mo : Mode )
  topics( std_msgs/Float64 a matches(in.a), std_msgs/Float64 b matches(in.b), std_msgs/Int64 k matches(in.k),
          std_msgs/Float64 s matches(out.s), std_msgs/Float64 q matches(out.q), std_msgs/Bool ok matches(out.ok) )
  assume( -100 <= in.a and in.a <= 100 and in.m in {idle, run} )
  guarantee( out.s == in.a + in.b * Step )
  guarantee( out.q == in.a / in.b or in.b == 0 )
  guarantee( out.ok <=> (in.f or in.a < Limit) )
  guarantee( forall(i in INTEGER | 0 <= i and i <= 3 -> out.n + i >= in.k - 10) )
  guarantee( exists(x in Mode | x == out.mo) and exists_unique(t in BOOL | t == in.f) )
  guarantee( forall(v in {1, 2, 3} | out.s * v != 7.3 or out.ok) )
  guarantee( in.k < 0 -> 0.1 + 0.2 == 0.3 )
  guarantee( in.b * Step == 0.3 -> out.ok )
  guarantee( out.q <= 20 or out.q >= 21 or in.f )
}
"""


def _diff_values(cn):  # type: ignore[no-untyped-def]
    """Values of node ``cn``'s inputs and outputs by their types, any subset of them (missing ones too)."""
    from hypothesis import strategies as st

    from rclverify.lang.types import EnumT, Scalar
    real = st.sampled_from([0.0, 0.1, 0.2, 0.3, 1.5, 2.5, 3, 7.3, -3.0, 19.999999999999996, 20.000000000000004,
                          1e-9, 100.0]) | \
        st.floats(-150, 150, allow_nan=False) | st.integers(-5, 5)
    kinds = {"REAL": real, "INTEGER": st.integers(-20, 20), "NATURAL": st.integers(0, 30), "BOOL": st.booleans()}
    io = {}
    for side, table in (("in", cn.inputs), ("out", cn.outputs)):
        for name, t in table.items():
            if isinstance(t, Scalar) and t.name in kinds:
                io[f"{side}.{name}"] = kinds[t.name]
            elif isinstance(t, EnumT):
                io[f"{side}.{name}"] = st.sampled_from(list(t.values))
    return st.fixed_dictionaries({}, optional=io)


@pytest.mark.parametrize("tolerance", [None, {"abs": 1e-9, "ulps": 4}])
def test_the_carried_judgement_is_rclverifys(tmp_path: Path, tolerance: dict | None) -> None:
    """Differential: the generated package's own judgement (contract_eval.py, no rclverify) gives,
    clause by clause, the truth and the deciding arithmetic rclverify's monitor judgement
    (``logic/floatsem.judge``) gives on the same values: exact, double and tolerance readings,
    enumerations, constants, literal sets, quantifiers over bounded integers, an enumeration, BOOL
    and a literal set, division by zero, missing values; and on every warehouse and
    contracts-first node."""
    import importlib.util

    from hypothesis import given, settings

    from rclverify.semantics.floatsem import judge as floatjudge, parse_tolerance
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.widths import at_carried_widths, carried_widths
    ws = _ws(tmp_path, DIFF_CONTRACT)
    if tolerance:
        (ws / "contracts" / "plan.yaml").write_text(
            "contracts: [contracts/sys.rcl]\nnodes:\n  Mixer:\n    evidence:\n      - backend: monitors\n"
            f"        tolerance: {{abs: {tolerance['abs']}, ulps: {tolerance['ulps']}}}\n")
    cases = [(ws, "Mixer")] + [(ROOT / "examples" / w, n) for w, ns in
                               (("warehouse", ("Base", "BatteryMonitor", "Controller", "LidarDriver", "Localiser",
                                               "MissionManager", "Planner")),
                                ("contracts_first", ("TempSensor", "HeaterControl"))) for n in ns]
    trees: dict[Path, Path] = {}
    decided: dict[str, int] = {}
    readings: set[tuple[bool | None, str]] = set()
    for w, node in cases:
        if w not in trees:
            trees[w] = tmp_path / f"out{len(trees)}"
            assert main(["generate", "ros2", "-w", str(w), "-o", str(trees[w])]) == 0
        from rclverify.targets.typemap import snake
        path = trees[w] / snake(node) / snake(node) / "contract.py"
        spec = importlib.util.spec_from_file_location(f"diff_{node}_{bool(tolerance)}", path)
        assert spec is not None and spec.loader is not None
        layer = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(layer)
        checked = Workspace(w, "contracts/plan.yaml").checked
        # the contract as rclverify's monitor reads it: each comparison at its fields' widths
        cn = at_carried_widths(checked.nodes[node], carried_widths(checked.nodes[node], {}, []),
                               checked.env.constants)
        tol = parse_tolerance(tolerance) if w == ws else None
        mine_tol = layer._TOL
        assert (mine_tol is None) == (tol is None)
        clauses = list(zip(list(cn.node.assumes) + list(cn.node.guarantees),
                           layer.CARRIED["assumes"] + layer.CARRIED["guarantees"]))

        @settings(max_examples=120 if node == "Mixer" else 15, deadline=None, database=None, derandomize=True)
        @given(_diff_values(cn))
        def agree(values: dict) -> None:
            compare(values)

        def compare(values: dict, node: str = node, clauses: list = clauses, cn=cn,  # type: ignore[no-untyped-def]
                    checked=checked, tol=tol, layer=layer, mine_tol=mine_tol) -> None:
            for c, carried in clauses:
                want = floatjudge(c.formula, checked, cn, values, tol)
                truth, sem, reason = layer.ev.judge(carried, values, mine_tol)
                if truth is None and want.truth is not None:
                    assert "not judged by the carried" in reason or "rclverify also asks Z3" in reason, \
                        (node, c.formula, values, want, reason)
                    continue
                assert (truth, sem) == (want.truth, want.semantics), (node, values, want, reason)
                if truth is None and want.reason.startswith("no value for"):  # the value a reading waits for
                    assert reason == want.reason, (want.reason, reason)
                elif truth is None:
                    assert not reason.startswith("no value for"), (want.reason, reason)
                decided[node] = decided.get(node, 0) + (truth is not None)
                if node == "Mixer":
                    readings.add((truth, sem))

        agree()
        if node == "Mixer":  # the readings random values meet rarely: double only, within the tolerance only
            for values in ({"in.b": 3, "out.ok": False}, {"in.b": 3.0, "out.ok": True},
                           {"out.q": 20.000000000000004, "in.f": False}, {"out.s": 0.1, "in.a": 0, "in.b": 1},
                           {"out.s": 0.30000000000000004, "in.a": 0.1, "in.b": 2.0}):
                compare(values)
    assert decided.get("Mixer", 0) >= 200 and all(decided.get(n, 0) > 0 for _, n in cases), decided
    want = {(True, "exact"), (True, "double"), (False, "exact"), (False, "exact, double"), (None, "")}
    if tolerance:  # (every clause the double reading can change, the tolerance can too, here)
        want = (want - {(False, "exact, double")}) | {(True, "tolerance"), (False, "exact, double, tolerance")}
    assert want <= readings, readings


def test_every_import_of_a_node_package_is_declared_and_none_is_rclverify(tmp_path: Path) -> None:
    """A node package runs in a ROS 2 Python without rclverify (issue 62): each module its files
    import is the standard library's, the package's own, or a package its package.xml names
    (``exec_depend``); rclverify is never one."""
    import ast as pyast
    import re
    import sys
    for ws in (ROOT / "examples" / "warehouse", _ws(tmp_path, _chain_system(3))):
        out = tmp_path / f"out_{ws.name}"
        assert main(["generate", "ros2", "-w", str(ws), "-o", str(out)]) == 0
        for xml in out.glob("*/package.xml"):
            pkg = xml.parent
            if not (pkg / "setup.py").is_file():
                continue
            declared = set(re.findall(r"<exec_depend>([\w]+)</exec_depend>", xml.read_text()))
            used: set[str] = set()
            for py in (pkg / pkg.name).glob("*.py"):
                for n in pyast.walk(pyast.parse(py.read_text())):
                    if isinstance(n, pyast.Import):
                        used |= {a.name.split(".")[0] for a in n.names}
                    elif isinstance(n, pyast.ImportFrom) and n.level == 0 and n.module:
                        used.add(n.module.split(".")[0])
            foreign = used - set(sys.stdlib_module_names) - {pkg.name}
            assert "rclverify" not in used, pkg
            assert foreign <= declared, (pkg.name, foreign - declared)
            assert "std_msgs" in declared  # the verdict publisher's String
