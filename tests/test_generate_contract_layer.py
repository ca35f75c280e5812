"""The generated Python contract layer (``<node>/contract.py``) against Z3 and against the monitor
engine: on random values (Hypothesis) its verdict is the one Z3 gives clause by clause on the same
values (exact arithmetic; a step the layer accepts only in the node's double arithmetic, as the
monitor does, is false to Z3), and the one the monitor engine gives a question and its answer
(docs/generate.md, "The contract layer")."""
from __future__ import annotations

import importlib.util
from pathlib import Path

from hypothesis import given, settings, strategies as st

from rclverify.cli import main
from rclverify.logic.concrete import check_concrete
from rclverify.pipeline import Workspace
from rclverify.rcl.types import BOOL, EmptyT, FuncT, Scalar

ROOT = Path(__file__).resolve().parents[1]
WAREHOUSE = ROOT / "examples" / "warehouse"
CHECKED = Workspace(WAREHOUSE, "contracts/plan.yaml").checked


def _load(path: Path, name: str):  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _z3_verdict(node_name: str, values: dict) -> tuple[str, int]:
    return _z3_verdict_of(CHECKED, node_name, values)


_REAL = st.one_of(st.integers(-30, 130).map(float), st.floats(-1e4, 1e4, allow_nan=False),
                  st.sampled_from([0.0, 1.5, 2.0, 20.0, 100.0, 1e-9]))


def test_generated_checks_agree_with_z3_on_every_warehouse_node(tmp_path: Path) -> None:
    out = tmp_path / "out"
    seen_all: set[str] = set()
    assert main(["generate", "ros2", "-w", str(WAREHOUSE), "-o", str(out)]) == 0
    for node_name, cn in CHECKED.nodes.items():
        pkg = [p for p in out.iterdir() if (p / p.name / "contract.py").is_file()
               and f"NODE = \"{node_name}\"" in (p / p.name / "contract.py").read_text()]
        assert len(pkg) == 1, node_name
        layer = _load(pkg[0] / pkg[0].name / "contract.py", f"gen_contract_{node_name}")
        io = {f"in.{k}": t for k, t in cn.inputs.items()} | {f"out.{k}": t for k, t in cn.outputs.items()}
        assert all(isinstance(t, Scalar) and t.name in ("REAL", "BOOL") for t in io.values())
        strat = st.fixed_dictionaries({q: (st.booleans() if t == BOOL else _REAL) for q, t in io.items()})
        seen: set[str] = set()

        @settings(max_examples=25, deadline=None, database=None)
        @given(strat)
        def agree(values: dict) -> None:
            got = layer.judge(values)
            want = _z3_verdict(node_name, values)
            if got["semantics"] in ("double", "tolerance"):  # holds only as the node computes: false to Z3
                assert got["verdict"] == "satisfied" and want[0] != "satisfied", (values, want)
                return
            assert (got["verdict"], got["guarantee"]) == want, values
            seen.add(got["verdict"])

        agree()
        assert seen, node_name
        seen_all |= seen
    # the random values reach every verdict the layer can give on these decidable contracts
    assert {"satisfied", "violated", "assumption violated"} <= seen_all, seen_all


def test_generated_checks_agree_with_z3_on_the_case_study_where_both_decide(tmp_path: Path) -> None:
    """The case study's values are finite function tables (the property tests' strategies draw
    them); where the evaluator or Z3 cannot decide a clause the example is not compared."""
    from rclverify.backends.property_tests.strategies import input_space
    checked = Workspace(ROOT, "contracts/plan.yaml").checked
    out = tmp_path / "out"
    assert main(["generate", "ros2", "-w", str(ROOT), "-o", str(out)]) == 0
    compared = 0
    kinds: set[str] = set()
    for node_name, cn in checked.nodes.items():
        pkg = [p for p in out.iterdir() if (p / p.name / "contract.py").is_file()
               and f"NODE = \"{node_name}\"" in (p / p.name / "contract.py").read_text()]
        layer = _load(pkg[0] / pkg[0].name / "contract.py", f"gen_cs_contract_{node_name}")
        space = input_space(cn, {})
        io = {f"in.{k}": t for k, t in cn.inputs.items()} | {f"out.{k}": t for k, t in cn.outputs.items()}
        @st.composite
        def strat(draw, space=space, io=io):  # type: ignore[no-untyped-def]
            space.pools = {}  # one pool of points per example, shared by inputs and outputs
            # an input of the empty type {} has no value (Localisation's sensors; no clause reads it)
            return {q: space.table(draw, t) if isinstance(t, FuncT) else draw(space.value(t))
                    for q, t in io.items() if not isinstance(t, EmptyT)}

        @settings(max_examples=15, deadline=None, database=None)
        @given(strat())
        def agree(values: dict) -> None:
            nonlocal compared
            got = layer.judge(values)
            want = _z3_verdict_of(checked, node_name, values)
            if "inconclusive" in (got["verdict"], want[0]) or got["semantics"] in ("double", "tolerance"):
                return
            assert (got["verdict"], got["guarantee"]) == want, values
            compared += 1
            kinds.add(got["verdict"])

        agree()
    assert compared >= 20
    assert {"satisfied", "violated"} <= kinds, kinds


def _z3_verdict_of(checked, node_name: str, values: dict) -> tuple[str, int]:  # type: ignore[no-untyped-def]
    node = checked.nodes[node_name]
    for c in node.node.assumes:
        ok, _ = check_concrete(c.formula, checked, node, values)
        if ok is not True:
            return ("assumption violated" if ok is False else "inconclusive", 0)
    for k, c in enumerate(node.node.guarantees, 1):
        ok, _ = check_concrete(c.formula, checked, node, values)
        if ok is not True:
            return ("violated" if ok is False else "inconclusive", k)
    return ("satisfied", 0)


# -- against the monitor engine itself ------------------------------------------------------------
# The nodes whose every input and output is one topic (the engine's question is the one input
# message, its answer the one output message); their outputs drawn at random or computed in
# doubles as the node would (1000.0 * range), which only the monitor's double reading accepts.
_ENGINE_NODES = {"LidarDriver": lambda v: {"out.obstacle": 1000.0 * v["in.range"]},
                 "Localiser": lambda v: {"out.pose_x": v["in.marker_x"]},
                 "BatteryMonitor": lambda v: {"out.battery_low": v["in.charge"] < 20}}


def _engine_verdict(cn, rules, values: dict) -> tuple[str, int]:  # type: ignore[no-untyped-def]
    from rclverify.backends.monitors.check import check_trace
    from rclverify.traces.events import Event
    events = []
    for t in cn.node.topics:
        key = f"{t.match.prefix}.{t.match.name}"
        path = (rules[t.field].fields or ("data",))[0]
        fields = {path: values[key]}
        events.append((0 if t.match.prefix == "in" else 1, t.field, fields))
    evs = [Event(k, 0.01 * when, topic, fields, f"step:{k}") for k, (when, topic, fields) in enumerate(sorted(
        events, key=lambda e: e[0]))]
    got: list = []
    check_trace(CHECKED, [cn], evs, rules, 1.0, on_verdict=got.append)
    final = [v for v in got if v.verdict in ("satisfied", "violated", "assumption violated", "inconclusive")]
    assert len(final) == 1, [v.to_json() for v in got]
    return final[0].verdict, final[0].guarantee


def test_generated_checks_agree_with_the_monitor_engine(tmp_path: Path) -> None:
    from rclverify.backends.monitors.config import load_mapping
    rules = load_mapping(WAREHOUSE, None).rules
    out = tmp_path / "out"
    assert main(["generate", "ros2", "-w", str(WAREHOUSE), "-o", str(out)]) == 0
    seen: set[tuple[str, str]] = set()
    for node_name, computed in _ENGINE_NODES.items():
        cn = CHECKED.nodes[node_name]
        pkg = out / _snake(node_name) / _snake(node_name)
        layer = _load(pkg / "contract.py", f"engine_contract_{node_name}")
        (inp,), (outp,) = cn.inputs.items(), cn.outputs.items()
        real_in = st.sampled_from([0.1, 0.7, 1.1, 2.3, 12.3, 29.9, 19.999999999999996]) | _REAL
        strat = st.builds(lambda x, r, own: {f"in.{inp[0]}": x, **(computed({f"in.{inp[0]}": x}) if own else
                                                                     {f"out.{outp[0]}": r})},
                          real_in, st.booleans() if outp[1] == BOOL else _REAL, st.booleans())

        @settings(max_examples=25, deadline=None, database=None)
        @given(strat)
        def agree(values: dict) -> None:
            got = layer.judge(values)
            assert (got["verdict"], got["guarantee"]) == _engine_verdict(cn, rules, values), values
            seen.add((got["verdict"], got["semantics"]))

        agree()
    verdicts = {v for v, _ in seen}
    assert {"satisfied", "violated", "assumption violated"} <= verdicts, seen
    assert ("satisfied", "double") in seen, seen  # the node's double arithmetic, as the monitor reads it


def _snake(name: str) -> str:
    from rclverify.generate.typemap import snake
    return snake(name)


def test_the_verdict_message_is_the_monitors(tmp_path: Path) -> None:
    """The generated layer's message for rclverify/verdict has the monitor's fields (Verdict.to_json)
    and JSON form (live.dumps); node.py publishes it for a violation only."""
    import json
    from rclverify.backends.monitors.live import dumps
    from rclverify.backends.monitors.verdicts import Verdict
    out = tmp_path / "out"
    assert main(["generate", "ros2", "-w", str(WAREHOUSE), "-o", str(out)]) == 0
    layer = _load(out / "lidar_driver/lidar_driver/contract.py", "msg_contract_lidar")
    msg = layer.verdict_message({"in.range": 2.0, "out.obstacle": 3.0}, 7, 1.5, "/obstacle")
    ref = Verdict("LidarDriver", "violated", 7, 1.5, "node LidarDriver", "/obstacle", 1.5, 1,
                  {"in.range": "2.0", "out.obstacle": "3.0"}, msg["reason"], "exact, double").to_json()
    assert msg == ref
    assert layer.dumps(msg) == dumps(ref) and json.loads(layer.verdict_json(
        {"in.range": 2.0, "out.obstacle": 3.0}, 7, 1.5, "/obstacle")) == ref
    assert msg["verdict"] in layer.VIOLATIONS
    ok = layer.verdict_message({"in.range": 0.1, "out.obstacle": 100.0})
    assert (ok["verdict"], ok["semantics"]) == ("satisfied", "double") and ok["verdict"] not in layer.VIOLATIONS
    node_py = (out / "lidar_driver/lidar_driver/node.py").read_text()
    assert "self.create_publisher(String, contract.VERDICT_TOPIC, QOS_DEPTH)" in node_py
    assert "if message['verdict'] in contract.VIOLATIONS:" in node_py
    assert layer.FIELDS == {"in.range": ("sub_scan", "range"), "out.obstacle": ("pub_obstacle", "data")}
