"""``generate ros2 --lang cpp``: the ROS-free contract checks compile with g++ (``-Wall -Wextra
-Werror``, syntax only and a real build), and the compiled checks agree with rclverify's own
judgement on random values (Hypothesis) for every node of examples/warehouse and of the case
study (docs/generate.md, "C++ nodes").

The oracle, per clause: the C++ truth is rclverify's double reading
(``floatsem.holds_in("double")``) wherever the clause is translated (bounded quantifiers as
loops, an unbounded one undecided as that reading leaves it), and ``U`` (undecided) where the
header says it is not.  Per step: the C++ verdict is the monitor's judgement (the generated
Python contract layer, ``floatsem.judge``) unless a clause differs for one of the documented
reasons (not translated; true in exact arithmetic only; decided in exact arithmetic only), which
the test names and counts."""
from __future__ import annotations

import dataclasses
import importlib.util
import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import Phase, example, given, settings, strategies as st

from _step_judge import judge as step_judge
from rclverify.cli.commands import main
from rclverify.semantics.floatsem import holds_in
from rclverify.app.pipeline import Workspace
from rclverify.lang.types import BOOL, REAL, DataT, EmptyT, EnumT, FuncT, Scalar
from rclverify.semantics.values import FiniteFunction, Term

ROOT = Path(__file__).resolve().parents[2]
CASES = {"warehouse": ROOT / "examples" / "warehouse", "case_study": ROOT}
CXX = ["g++", "-std=c++17", "-Wall", "-Wextra", "-Werror"]

pytestmark = pytest.mark.skipif(shutil.which("g++") is None, reason="g++ is not installed")


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Both workspaces generated with --lang cpp, every node's driver linked into one binary
    (dispatching on the package name) with every node's logic.cpp; compiled once."""
    tmp = tmp_path_factory.mktemp("cpp")
    pkgs: dict[str, tuple[str, Path]] = {}  # node -> (package, output dir)
    for case, ws in CASES.items():
        out = tmp / case
        assert main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--lang", "cpp"]) == 0
        for h in sorted(out.glob("*/include/*/contract_checks.hpp")):
            node = next(line.split('"')[1] for line in h.read_text().splitlines() if "kNode = " in line)
            pkgs[node] = (h.parent.name, out)
    incs = [f"-I{out / pkg / 'include'}" for pkg, out in pkgs.values()]
    headers = [str(out / pkg / "include" / pkg / "contract_checks.hpp") for pkg, out in pkgs.values()]
    # a check header alone is a translation unit: self-contained, no ROS, no warning (every header
    # comes from one template with the same includes; one is compiled alone, all in the build below)
    subprocess.run(CXX + ["-fsyntax-only", "-x", "c++", headers[0]], check=True, capture_output=True, text=True)
    main_cpp = tmp / "drivers.cpp"  # one translation unit: every driver, every logic.cpp, a dispatch
    main_cpp.write_text("".join(f'#include "{pkg}/contract_driver.hpp"\n' for pkg, _ in pkgs.values())
                        + "".join(f'#include "{out / pkg / "src" / "logic.cpp"}"\n' for pkg, out in pkgs.values())
                        + "#include <iostream>\n#include <string>\nint main(int argc, char ** argv)\n{\n"
                        + "  const std::string n = argc > 1 ? argv[1] : \"\";\n"
                        + "".join(f'  if (n == "{pkg}") {{ return {pkg}::drive(std::cin, std::cout); }}\n'
                                  for pkg, _ in pkgs.values())
                        + "  return 2;\n}\n")
    exe = tmp / "drivers"
    subprocess.run(CXX + ["-O1", *incs, str(main_cpp), "-o", str(exe)], check=True, capture_output=True, text=True)
    return {"pkgs": pkgs, "exe": exe}


@pytest.fixture(scope="module")
def py_trees(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Both workspaces generated with --lang python (the contract layers), once."""
    tmp = tmp_path_factory.mktemp("py")
    for case, ws in CASES.items():
        assert main(["generate", "ros2", "-w", str(ws), "-o", str(tmp / case)]) == 0
    return {case: tmp / case for case in CASES}


def _load(path: Path, name: str):  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _text(q: str, v: object, t: object) -> str:
    if isinstance(v, bool):
        return f"{q}={int(v)}"
    if isinstance(t, Scalar) and t.name == "REAL":
        return f"{q}={float(v)!r}"
    if isinstance(v, FiniteFunction):  # the driver's table text: rows `args->result`, the default `*->result`
        rows = "".join(",".join(map(_atom, k)) + "->" + _atom(r) + ";" for k, r in v.table.items())
        return f"{q}={rows}*->{_atom(v.default)}"
    if isinstance(v, Term):
        return f"{q}={v.name}" + (f"({','.join(map(_atom, v.args))})" if v.args else "")
    return f"{q}={v}"


def _atom(v: object) -> str:
    return str(int(v)) if isinstance(v, bool) else repr(v) if isinstance(v, float) else str(v)


def _held(t: object) -> bool:
    """A value the header holds and the driver reads (scalars, enumerations, tables, terms)."""
    return isinstance(t, (EnumT, FuncT, DataT)) or (isinstance(t, Scalar) and t.name != "STRING")


_REAL = st.one_of(st.integers(-30, 130).map(float), st.floats(-1e4, 1e4, allow_nan=False),
                  st.sampled_from([0.0, 0.5, 1.5, 2.0, 20.0, 30.0, 100.0, 120.0, 250.0, 0.1, 1e-9]))


def _run(exe: Path, pkg: str, steps: list[str]) -> list[tuple[str, int, str]]:
    res = subprocess.run([str(exe), pkg], input="".join(s + "\n" for s in steps), capture_output=True, text=True,
                         check=True)
    rows = [line.split("|") for line in res.stdout.splitlines()]
    return [(v, int(g), t) for v, g, t in rows]


@pytest.mark.parametrize("case", sorted(CASES))
def test_compiled_checks_agree_with_rclverify(built: dict, py_trees: dict, case: str) -> None:
    from rclverify.backends.property_tests.strategies import input_space
    ws = CASES[case]
    checked = Workspace(ws, "contracts/plan.yaml").checked
    stats = {"steps": 0, "agree": 0, "untranslated": 0, "exact_only": 0, "exact_decides": 0, "differ": 0,
             "verdicts": set()}
    for node_name, cn in checked.nodes.items():
        pkg, out = built["pkgs"][node_name]
        header = (out / pkg / "include" / pkg / "contract_checks.hpp").read_text()
        clauses = list(cn.node.assumes) + list(cn.node.guarantees)
        names = [f"assumption_{k}" for k in range(1, len(cn.node.assumes) + 1)] + \
                [f"guarantee_{k}" for k in range(1, len(cn.node.guarantees) + 1)]
        untranslated = [f"inline Truth {n}(" in header and
                        "// not translated" in header.split(f"inline Truth {n}(")[1].split("\n}\n")[0]
                        for n in names]
        io = {f"in.{k}": t for k, t in cn.inputs.items()} | {f"out.{k}": t for k, t in cn.outputs.items()}
        space = input_space(cn, {})

        @st.composite
        def values(draw, io=io, space=space):  # type: ignore[no-untyped-def]
            space.pools = {}
            out = {}
            for q, t in io.items():
                if isinstance(t, EmptyT):
                    continue
                if t == BOOL:
                    out[q] = draw(st.booleans())
                elif isinstance(t, Scalar) and t.name == "REAL":
                    out[q] = draw(_REAL)
                elif isinstance(t, FuncT):
                    out[q] = space.table(draw, t)
                else:
                    out[q] = draw(space.value(t))
            return out

        size = 30 if case == "warehouse" else 8

        @settings(max_examples=3, deadline=None, database=None)
        @given(st.lists(values(), min_size=size, max_size=size))
        def agree(batch: list) -> None:
            steps = [" ".join(_text(q, v, io[q]) for q, v in vals.items() if _held(io[q])) for vals in batch]
            for vals, (verdict, g, truths) in zip(batch, _run(built["exe"], pkg, steps)):
                stats["steps"] += 1
                differs = False
                for k, (clause, u) in enumerate(zip(clauses, untranslated)):
                    if u:
                        assert truths[k] == "U", (node_name, names[k], vals)
                        differs = True
                        continue
                    want = holds_in("double", clause.formula, checked, cn, vals)
                    assert truths[k] == {True: "T", False: "F", None: "U"}[want], (node_name, names[k], vals)
                    exact = holds_in("exact", clause.formula, checked, cn, vals) if want is not True else True
                    if want is not True and exact is True:
                        stats["exact_only"] += 1
                        differs = True
                    elif want is None and exact is False:  # a quantifier only exact arithmetic decides
                        stats["exact_decides"] += 1
                        differs = True
                assert (verdict, g) == _aggregate(truths, len(cn.node.assumes)), (node_name, vals)
                monitor = step_judge(checked, cn, vals)  # rclverify's verdict
                if not differs or monitor["verdict"] == "assumption violated" == verdict:
                    assert (verdict, g) == (monitor["verdict"], monitor["guarantee"]), (node_name, vals)
                    stats["agree"] += 1
                    stats["verdicts"].add(verdict)
                else:
                    stats["untranslated"] += any(untranslated)
                    stats["differ"] += 1

        agree()
    if case == "warehouse":  # every clause translated; the random values reach every verdict
        assert stats["untranslated"] == 0 and stats["agree"] >= 150, stats
        assert {"satisfied", "violated", "assumption violated"} <= stats["verdicts"], stats
    else:  # the guarantees quantify over REAL and NATURAL without literal bounds, over function
        # tables and constructor terms: decided at candidate points in the double reading and in C++,
        # every step the monitor's verdict
        assert stats["untranslated"] == stats["differ"] == stats["exact_decides"] == 0, stats
        assert stats["agree"] == stats["steps"] == 96, stats
        assert {"satisfied", "violated"} <= stats["verdicts"], stats


def _entry(draw, space, t: FuncT) -> FiniteFunction:  # type: ignore[no-untyped-def]
    """A table with at least one entry (a true one for a BOOL result): a run carries a table as one
    message per entry (per true point on a `replace` topic), and an output with no message gets no
    verdict from the engine."""
    f = space.table(draw, t)
    if t.result == BOOL and True not in f.table.values():  # a `replace` topic carries the true points only
        return FiniteFunction(dict(f.table) | {draw(space.small_points(t.args)): True}, f.default, len(t.args))
    if f.table:
        return f
    return FiniteFunction({draw(space.small_points(t.args)): draw(space.value(t.result, small=True))}, f.default,
                          len(t.args))


def _aggregate(truths: str, n_assumes: int) -> tuple[str, int]:
    """The verdict the monitor engine's rule gives these clause truths (docs/generate.md)."""
    for t in truths[:n_assumes]:
        if t != "T":
            return ("assumption violated" if t == "F" else "inconclusive", 0)
    gs = truths[n_assumes:]
    if "F" in gs:
        return ("violated", gs.index("F") + 1)
    if "U" in gs:
        return ("inconclusive", gs.index("U") + 1)
    return ("satisfied", 0)


def test_the_driver_reads_as_the_node_computes(built: dict) -> None:
    """The LidarDriver's check on values written by hand: the SDK's 1000 * range holds in double
    arithmetic (1000 * 0.1 is 100.0 as the node computes; as exact rationals the double nearest 0.1
    times 1000 is not 100), a wrong output is violated, a range below 0 breaks the assumption."""
    pkg, _ = built["pkgs"]["LidarDriver"]
    got = _run(built["exe"], pkg, ["in.range=0.1 out.obstacle=100.0", "in.range=2 out.obstacle=2",
                                   "in.range=-1 out.obstacle=-1000"])
    assert got == [("satisfied", 0, "TT"), ("violated", 1, "TF"), ("assumption violated", 0, "FT")]


def test_a_declared_tolerance_is_the_headers_second_reading(tmp_path: Path) -> None:
    """The plan's monitors entry declares a tolerance: numbers within it are equal to the checks,
    as to the monitor (docs/monitors.md, "Numbers on the wire")."""
    ws = tmp_path / "ws"
    shutil.copytree(ROOT / "examples" / "contracts_first" / "contracts", ws / "contracts")
    plan = (ws / "contracts" / "plan.yaml").read_text()
    (ws / "contracts" / "plan.yaml").write_text(plan.replace(
        "mapping: gen/rclverify_mapping.yaml", "mapping: m.yaml\n        tolerance: {abs: 1.0e-9}"))
    (ws / "m.yaml").write_text("topics: {}\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen"), "--lang", "cpp"]) == 0
    inc = ws / "gen" / "temp_sensor" / "include"
    assert "kTolerance{1e-09, 0.0, 0}" in (inc / "temp_sensor" / "contract_checks.hpp").read_text()
    src = tmp_path / "d.cpp"
    src.write_text('#include "temp_sensor/contract_driver.hpp"\n#include <iostream>\n'
                   "int main() { return temp_sensor::drive(std::cin, std::cout); }\n")
    subprocess.run(CXX + [f"-I{inc}", str(src), "-o", str(tmp_path / "d")], check=True, capture_output=True)
    got = _run(tmp_path / "d", "", ["in.kelvin=300 out.celsius=26.850000000001", "in.kelvin=300 out.celsius=26.86"])
    assert got == [("satisfied", 0, "TT"), ("violated", 1, "TF")]


_QUANTIFIED = """context { Mode : {idle, heat, cool} ; }
node Quantified {
  inputs( n : INTEGER, mode : Mode, x : REAL, flag : BOOL )
  outputs( y : REAL, k : NATURAL, m : Mode )
  topics( std_msgs/Int64 n matches(in.n), std_msgs/Float64 x matches(in.x), std_msgs/Bool flag matches(in.flag),
          std_msgs/Float64 y matches(out.y), std_msgs/UInt64 k matches(out.k) )
  assume( forall(i in NATURAL | i <= 3 -> i * in.x <= 1000) )
  guarantee( exists(i in INTEGER | -3 <= i and i <= 3 and out.k == i * i) )
  guarantee( forall(v in Mode | v == out.m -> (v == heat -> out.y >= in.x)) )
  guarantee( exists_unique(b in BOOL | b == in.flag) and exists(c in {idle, cool} | c == in.mode or in.n < 5) )
  guarantee( forall(i in {3, 1, 2, 1} | out.y / (in.n - i) <= 100 or in.flag) )
  guarantee( forall(i in NATURAL | i <= 4 -> exists(j in NATURAL | j <= 4 and i + j == in.n) or in.n > 8 or in.n < 0) )
  guarantee( forall(r in REAL | out.y >= 0.1 * 3 or not in.flag) )
  guarantee( in.n < 20 or forall(r in REAL | r * out.y == out.y) )
}
"""


def test_bounded_quantifiers_are_loops_with_the_double_readings_verdict(tmp_path: Path) -> None:
    """Quantifiers over BOOL, an enumeration, a literal set (with repeats), guarded integer ranges
    (nested), an unused REAL variable, and one over REAL the double reading cannot enumerate: each
    compiled clause's truth on random values is rclverify's double reading (``U`` where it is
    undecided, division by zero included), and the step's verdict is the monitor's (the Python
    layer's) where exact and double agree (docs/generate.md, "C++ nodes")."""
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "q.rcl").write_text(_QUANTIFIED)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/q.rcl]\n")
    out = ws / "gen"
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--lang", "cpp"]) == 0
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "py")]) == 0
    header = (out / "quantified" / "include" / "quantified" / "contract_checks.hpp").read_text()
    assert "// not translated" not in header and header.count("for (") >= 7, header
    assert "// undecided where reached (as rclverify's double reading): r ranges over REAL" in header
    src = tmp_path / "q.cpp"
    src.write_text('#include "quantified/contract_driver.hpp"\n#include <iostream>\n'
                   "int main() { return quantified::drive(std::cin, std::cout); }\n")
    subprocess.run(CXX + [f"-I{out / 'quantified' / 'include'}", str(src), "-o", str(tmp_path / "q")],
                   check=True, capture_output=True, text=True)
    checked = Workspace(ws, "contracts/plan.yaml").checked
    cn = checked.nodes["Quantified"]
    clauses = list(cn.node.assumes) + list(cn.node.guarantees)
    modes = ["idle", "heat", "cool"]
    step = st.fixed_dictionaries({
        "in.n": st.integers(-3, 25), "in.mode": st.sampled_from(modes), "in.x": _REAL, "in.flag": st.booleans(),
        "out.y": _REAL | st.sampled_from([0.3, 0.30000000000000004, 150.0]), "out.k": st.sampled_from([0, 1, 4, 9, 2, 5]),
        "out.m": st.sampled_from(modes)})
    seen: set[str] = set()

    @settings(max_examples=2, deadline=None, database=None, derandomize=True,
              phases=[Phase.explicit, Phase.generate])  # a failure is reported as drawn (no slow shrinking)
    @given(st.lists(step, min_size=50, max_size=50))
    # guarantee 4 false for sure (150 / (4 - 3) > 100, flag false), whatever the draws give
    @example([{"in.n": 4, "in.mode": "idle", "in.x": 1.0, "in.flag": False, "out.y": 150.0, "out.k": 4,
               "out.m": "idle"}])
    def agree(batch: list) -> None:
        lines = [" ".join(_text(q, v, REAL if isinstance(v, float) else None) for q, v in vals.items())
                 for vals in batch]
        for vals, (verdict, g, truths) in zip(batch, _run(tmp_path / "q", "", lines)):
            differs = False
            for k, clause in enumerate(clauses):
                want = holds_in("double", clause.formula, checked, cn, vals)
                assert truths[k] == {True: "T", False: "F", None: "U"}[want], (k, vals, truths)
                differs |= want is not True and holds_in("exact", clause.formula, checked, cn, vals) is True
                seen.add(f"{k}{truths[k]}")
            assert (verdict, g) == _aggregate(truths, len(cn.node.assumes)), vals
            if not differs:
                monitor = step_judge(checked, cn, vals)  # rclverify's verdict
                assert (verdict, g) == (monitor["verdict"], monitor["guarantee"]), (vals, truths, monitor)
                seen.add(verdict)

    agree()
    # every guarantee reaches true and false on these values, the division by zero and the REAL quantifier U
    assert {f"{k}{t}" for k in range(1, 6) for t in "TF"} <= seen, sorted(seen)
    assert {"4U", "7U"} <= seen and {"satisfied", "violated"} <= seen, sorted(seen)


@pytest.mark.parametrize("node_name", ["Controller", "Planner"])
def test_triggered_guarantees_are_owed_as_the_python_stream_owes_them(built: dict, py_trees: dict,
                                                                      node_name: str) -> None:
    """A step of the C++ node answers the input message that made it (``Owed``: a guarantee
    ``triggered by in.x`` is judged only when that message is on in.x): on random runs (each step
    one input message, then every output) its verdict is the one the generated Python layer's
    Stream, which reads messages as the monitor engine does (test_generate_contract_layer.py),
    gives the step's output messages (violated, inconclusive, satisfied or assumption violated);
    every guarantee the Stream finds violated is false in C++, whose verdict names the first."""
    ws = CASES["warehouse"]
    checked = Workspace(ws, "contracts/plan.yaml").checked
    cn = checked.nodes[node_name]
    pkg, _ = built["pkgs"][node_name]
    out = py_trees["warehouse"]
    layer = _load(out / pkg / pkg / "contract.py", f"owed_{pkg}")
    ins, outs = [f"in.{k}" for k in cn.inputs], [f"out.{k}" for k in cn.outputs]
    real = st.sampled_from([0.0, 0.3, 1.0, 1.5, 2.0, 5.0, 40.0, 100.0]) | _REAL
    within = st.sampled_from([0.2, 0.5, 1.0, 1.5])  # inputs the assumptions accept, mostly
    step = st.tuples(st.sampled_from(ins), within | within | real, st.fixed_dictionaries(
        {q: st.booleans() if cn.outputs[q[4:]] == BOOL else real for q in outs}))
    seen: set[str] = set()

    @settings(max_examples=4, deadline=None, database=None, derandomize=True, phases=[Phase.explicit, Phase.generate])
    @given(st.dictionaries(st.sampled_from(ins), within, min_size=len(ins), max_size=len(ins)),
           st.lists(step, min_size=16, max_size=16))
    def agree(first: dict, steps: list) -> None:
        stream = layer.Stream()
        for q, v in first.items():  # every input once: the question raised by the last message
            primed = stream.on_input({q: v})
        steps = [(list(first)[-1], first[list(first)[-1]], {q: 0.0 if cn.outputs[q[4:]] != BOOL else False
                                                            for q in outs})] + steps
        lines, want = [], []
        values = dict(first)
        for var, v, o in steps:
            values[var] = v
            refused = stream.on_input({var: v}) if len(want) else primed
            got = [stream.on_output({q: x}) for q, x in o.items()]
            kinds = [g for g in got if g["verdict"] == "violated"] or [g for g in got if g["verdict"] == "inconclusive"]
            if refused is not None:
                want.append((refused["verdict"], set()))
            elif kinds:  # each message's own (the engine's combination), all of one kind
                want.append((kinds[0]["verdict"], {g["guarantee"] for g in kinds}))
            else:
                want.append(("satisfied", set()))
            lines.append(" ".join([f"heard={var}"] + [_text(q, x, REAL if isinstance(x, float) else None)
                                                      for q, x in {**values, **o}.items()]))
        rows = _run(built["exe"], pkg, lines)
        n = len(cn.node.assumes)
        for line, (v, g, truths), (wv, wg) in zip(lines, rows, want):
            # the same verdict; a violated step's guarantee the first false one, the Stream's among the false
            assert v == wv and all(truths[n + k - 1] == "F" for k in wg), (line, v, g, truths, wv, wg)
            assert v != "inconclusive" or g in wg, (line, v, g, wv, wg)
        got = [(v, g) for v, g, _ in rows]
        seen.update(v for v, _ in got)
        every = [(v, g) for v, g, _ in _run(built["exe"], pkg, [ln.split(" ", 1)[1] for ln in lines])]
        seen.update("not owed" for a, b in zip(got, every) if a != b)  # a triggered guarantee not owed

    agree()
    assert {"violated", "satisfied", "not owed"} <= seen, seen


@pytest.mark.parametrize("case", sorted(CASES))
def test_compiled_checks_agree_with_the_monitor_engine_on_every_node(built: dict, py_trees: dict, case: str) -> None:
    """Every node's compiled checks against the monitor engine itself (``check_trace``): random
    values as the messages of a run (test_generate_contract_layer.py's ``_stream_and_engine``:
    inputs, then every output), the step judged by C++ with ``heard=`` the inputs whose messages
    raised or carried the question: a C++ verdict that decides (not ``inconclusive``) is the kind
    of the engine's verdicts on the run's messages, and every guarantee the engine finds violated
    is false in C++, unless a clause's double and exact readings differ (docs/generate.md)."""
    from test_generate_contract_layer import _stream_and_engine  # the run both are fed

    from rclverify.backends.monitors.check import NodeMonitor
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.traces.mapping import TopicRule, initial_value
    from rclverify.backends.property_tests.strategies import input_space
    ws = CASES[case]
    checked = Workspace(ws, "contracts/plan.yaml").checked
    out = py_trees[case]
    rules = load_mapping(out if case == "warehouse" else ws,
                         "rclverify_mapping.yaml" if case == "warehouse" else "backends/monitors/mapping.yaml").rules
    if case == "case_study":  # the mapping gives wayPNow no default (unknown off its entries), which a C++ table
        # cannot hold: the runs here read it with the default 0 (a mapping's `default: 0`)
        rules = {t: dataclasses.replace(r, default=0) if t == "wayPNow" else r for t, r in rules.items()}
    stats = {"compared": 0, "inconclusive in C++": 0, "readings differ": 0, "an output with no message": 0, "a table with no default": 0}
    kinds: set[str] = set()
    for node_name, cn in checked.nodes.items():
        pkg, _ = built["pkgs"][node_name]
        layer = _load(out / pkg / pkg / "contract.py", f"engine_cpp_{case}_{pkg}")
        io = {f"in.{k}": t for k, t in cn.inputs.items()} | {f"out.{k}": t for k, t in cn.outputs.items()}
        space = input_space(cn, {})
        clauses = list(cn.node.assumes) + list(cn.node.guarantees)
        n = len(cn.node.assumes)
        topic_rule = {key: rules.get(topic, TopicRule()) for topic, vs in NodeMonitor(checked, cn, rules, 100.0).topics.items()
                      for key, _, _ in vs}

        @st.composite
        def values(draw, io=io, space=space):  # type: ignore[no-untyped-def]
            space.pools = {}
            return {q: (draw(st.booleans()) if t == BOOL else draw(_REAL | st.sampled_from([-1.0, -0.5])) if t == REAL else
                        _entry(draw, space, t) if isinstance(t, FuncT) else draw(space.value(t)))
                    for q, t in io.items() if not isinstance(t, EmptyT)}

        @settings(max_examples=9 if case == "warehouse" else 8, deadline=None, database=None, derandomize=True,
                  phases=[Phase.explicit, Phase.generate])
        @given(values())
        def agree(vals: dict) -> None:
            rows = _stream_and_engine(checked, cn, rules, layer, vals, [])
            # a table before its first entry is empty, with the mapping's default (traces/mapping.initial_value)
            final = {q: initial_value(t, topic_rule.get(q, TopicRule())) for q, t in io.items()
                     if isinstance(t, FuncT) and q.startswith("in.")} | {key: v for _, _, _, key, v in rows}
            heard = [key for kind, engine, _, key, _ in rows
                     if kind == "in" and not any(v == "incomplete input" for v, _, _ in engine)]
            last_in = [engine for kind, engine, _, _, _ in rows if kind == "in"][-1:]  # the question the step answers
            asked = [v for engine in last_in for v in engine
                     if v[0] == "assumption violated" or (v[0] == "inconclusive" and v[2].startswith("assumption"))]
            answers = [(v, g) for kind, engine, _, _, _ in rows if kind == "out" for v, g, r in engine
                       if v in ("satisfied", "violated", "inconclusive") and "whatever the value" not in r
                       and "undecided on the outputs published" not in r]
            line = " ".join([f"heard={h}" for h in heard] + [_text(q, v, io[q]) for q, v in final.items()
                                                             if _held(io[q])])
            (verdict, g, truths), = _run(built["exe"], pkg, [line])
            if set(final) != set(vals):  # an output with no message (an empty table): no engine verdict
                stats["an output with no message"] += 1
                return
            if any(isinstance(v, FiniteFunction) and v.default is None for v in final.values()):
                stats["a table with no default"] += 1  # the mapping gives none (unknown): C++ holds no such table
                return
            if verdict == "inconclusive":
                stats["inconclusive in C++"] += 1
                return
            if any(holds_in("double", c.formula, checked, cn, final) != holds_in("exact", c.formula, checked, cn, final)
                   for c in clauses):
                stats["readings differ"] += 1
                return
            if asked and asked[-1][0] == "assumption violated":  # the last question's, the one the step answers
                assert verdict == "assumption violated", (node_name, line, truths, final, asked)
            else:
                violated = {g2 for v, g2 in answers if v == "violated"}
                want = "violated" if violated else "inconclusive" if any(v == "inconclusive" for v, _ in answers) \
                    else "satisfied"
                assert verdict == want, (node_name, line, truths, answers)
                assert all(truths[n + k - 1] == "F" for k in violated), (node_name, line, truths, answers)
            stats["compared"] += 1
            kinds.add(verdict)

        agree()
    if case == "warehouse":
        assert stats["compared"] >= 45 and {"satisfied", "violated", "assumption violated"} <= kinds, (stats, kinds)
    else:  # the quantified guarantees decided at candidate points: C++ decides every run and agrees with
        # the engine
        print(case, stats, sorted(kinds))
        assert stats["inconclusive in C++"] == 0 and stats["compared"] == 32, (stats, kinds)
        assert {"satisfied", "violated", "assumption violated"} <= kinds, (stats, kinds)
