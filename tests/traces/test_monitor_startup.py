"""The ``rclverify monitor`` command's start-up (issue 106; bench/monitor_startup.py measures it).

The message definitions a node's topics name are kept between runs by the
start-up cache and found only under the workspace's ``.msg`` texts (an
edited one is read again); the rosbags version is read without
importlib.metadata and agrees with it; only the command run has its
parser made; and a warm run on a plain log loads none of the libraries
and rclverify parts that only other runs need, while a cold one does
(the control: the probe sees them when they are there).
"""
from __future__ import annotations

import contextlib
import importlib.metadata
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.backends.monitors.summary import distribution_version, tool_versions
from rclverify.cli import commands
from rclverify.core.cache.startup import keeping
from rclverify.traces import bag

SRC = Path(__file__).resolve().parents[2] / "src"

CONTRACT = """node Window {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
"""
#: The deadline monitors: loaded by a run whose contract has a deadline (the control below), by no other.
DEADLINE_PARTS = ("rclverify.backends.monitors.deadlines", "rclverify.backends.monitors.batch_deadlines",
                  "rclverify.backends.monitors.deadline_records", "rclverify.backends.monitors.deadline_text")
#: Loaded by no run on a plain log once the start-up cache is warm: the libraries whose results it keeps
#: (lark, jsonschema, jinja2, Z3, rosbags' type stores), the second solver, and what other commands use.
NOT_ON_A_PLAIN_LOG = ("z3", "cvc5", "lark", "jinja2", "jsonschema", "rosbags.typesys.stores", "networkx", "rich",
                      "hypothesis", "doit", "websockets", "importlib.metadata", "rclverify.tools.lsp",
                      "rclverify.targets.dafny", "rclverify.targets.ajpf", "rclverify.backends.dafny",
                      "rclverify.backends.model_checking",
                      "rclverify.report", "rclverify.calculus", "rclverify.cli.ros", "rclverify.cli.verify",
                      # what a contract with a deadline, a period, a declaration or a link, or a plan with formal
                      # statements, standards, instances or targets loads; the writer of kept files; a close
                      # spelling (difflib) looked for only in an error; importlib.resources (the schema: a miss)
                      *DEADLINE_PARTS, "rclverify.backends.monitors.dds_calls", "rclverify.backends.monitors.bag_calls",
                      "rclverify.backends.monitors.online", "rclverify.model.plan.formal",
                      "rclverify.model.plan.temporal", "rclverify.model.plan.target_text",
                      "rclverify.model.plan.standards.profiles", "rclverify.model.names", "rclverify.records.statistics",
                      "rclverify.core.atomic", "difflib", "importlib.resources",
                      # the YAML files (the plan, the mapping, the backends' declarations) kept parsed by the
                      # start-up cache; rosbags' kinds of the kept message definitions (kept as rclverify's)
                      "yaml", "rosbags.interfaces")


def _cell(root: Path, width: str) -> Path:
    d = root / "msg_defs" / "cells" / "msg"
    d.mkdir(parents=True, exist_ok=True)
    (d / "Cell.msg").write_text(f"std_msgs/Header header\n{width} v\n")
    return root / "msg_defs"


def test_message_definitions_are_kept_and_an_edited_msg_is_read_again(tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    dirs = [_cell(tmp_path, "float32")]
    names = ["cells/msg/Cell", "std_msgs/msg/Float64MultiArray", "no_pkg/msg/Unknown"]
    with keeping(tmp_path / "kept") as kept:
        first = bag.field_definitions(dirs, names)
        assert kept.misses == 1 and kept.hits == 0
        # the named types and every type their fields name, nested or in arrays; an unknown name left out
        assert sorted(first) == ["builtin_interfaces/msg/Time", "cells/msg/Cell", "std_msgs/msg/Float64MultiArray",
                                 "std_msgs/msg/Header", "std_msgs/msg/MultiArrayDimension",
                                 "std_msgs/msg/MultiArrayLayout"]
        assert first == {k: v for k, v in bag.typestore(dirs).fielddefs.items() if k in first}
        with monkeypatch.context() as m:  # a hit: rosbags' store is not made
            m.setattr(bag, "typestore", lambda *a: pytest.fail("the store was made although the result is kept"))
            again = bag.field_definitions(dirs, list(reversed(names)))
            assert again == first
        assert kept.hits == 1
        # kept with rclverify's kinds (rosbags.interfaces not loaded to read them): the same names and values
        kinds = [k for v in again.values() for _, k in v[1]]
        assert {type(k[0]) for k in kinds} == {bag.FieldKind} and {type(k[0]) for v in first.values()
                                                                  for _, k in v[1]} != {bag.FieldKind}
        assert [(k[0].name, int(k[0])) for k in kinds] == [(k[0].name, int(k[0])) for v in first.values()
                                                           for _, k in v[1]]
        _cell(tmp_path, "float64")  # the control: the workspace's definition edited is a miss, read again
        second = bag.field_definitions(dirs, names)
        assert kept.misses == 2
    width = {n: k[1][0] for n, k in second["cells/msg/Cell"][1]}["v"]
    assert width == "float64" and {n: k[1][0] for n, k in first["cells/msg/Cell"][1]}["v"] == "float32"
    # without a kept start-up nothing is kept and the store is asked each time
    calls = []
    real = bag.typestore
    monkeypatch.setattr(bag, "typestore", lambda *a: calls.append(1) or real(*a))
    assert bag.field_definitions(dirs, names) == second and bag.field_definitions(dirs, names) == second
    assert len(calls) == 2


@pytest.mark.parametrize("name", ["rosbags", "msgspec", "numpy", "PyYAML", "z3_solver", "no_such_distribution_x"])
def test_a_distributions_version_is_importlib_metadatas(name: str) -> None:
    try:
        want: str | None = importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        want = None
    assert distribution_version(name) == want
    assert tool_versions() == f"rclverify {__import__('rclverify').__version__}, rosbags {distribution_version('rosbags')}"


def test_only_the_command_run_has_its_parser(monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[str] = []
    adder = commands._adder
    monkeypatch.setattr(commands, "_adder", lambda entry: made.append(entry[1]) or adder(entry))
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        commands.main(["monitor", "--help"])
    assert made == ["add_monitor"] and "--margins" in out.getvalue()
    made.clear()  # the control: the help of the whole command makes every parser
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        commands.main(["--help"])
    assert len(made) == len(commands.COMMANDS + commands.SUBCOMMAND_GROUPS + commands.LAST_COMMANDS)
    # the table names what each function adds: each command's own parser, alone, is the one it names
    for entry in commands.COMMANDS + commands.SUBCOMMAND_GROUPS + commands.LAST_COMMANDS:
        for name in entry[2]:
            assert commands.chosen([name, "--x"]) == name
    assert commands.chosen(["--help"]) is None and commands.chosen(["monitr"]) is None and commands.chosen([]) is None


def _workspace(root: Path) -> Path:
    (root / "contracts").mkdir(parents=True)
    (root / "backends/monitors").mkdir(parents=True)
    (root / "contracts/w.rcl").write_text(CONTRACT)
    (root / "contracts/plan.yaml").write_text("name: w\ncontracts: [contracts/w.rcl]\nnodes:\n  Window:\n"
                                              "    evidence: []\n")
    (root / "backends/monitors/mapping.yaml").write_text(
        "horizon: 0.005\ntopics:\n  limit: {fields: [data]}\n  window: {fields: [data]}\n")
    lines = []
    for i in range(5):
        lines.append(json.dumps({"topic": "limit", "time": i / 100, "data": 1.0}))
        lines.append(json.dumps({"topic": "window", "time": i / 100, "data": [1.5, 2.5, 0.5 if i == 3 else 3.5]}))
    lines.append(json.dumps({"topic": "tick", "time": 1.0}))
    (root / "run.jsonl").write_text("\n".join(lines) + "\n")
    return root


PROBE = ("import json, sys\nfrom rclverify.cli import main\ncode = main(sys.argv[1:])\n"
         "print(json.dumps(sorted(sys.modules)), file=sys.stderr)\nsys.exit(code)\n")


def _loaded(root: Path, cache: Path) -> tuple[int, str, set[str]]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache),
           "PYTHONPATH": os.pathsep.join([str(SRC)] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH")
                                                       else []))}
    p = subprocess.run([sys.executable, "-c", PROBE, "monitor", "--json", "--margins", "-w", str(root),
                        str(root / "run.jsonl")], capture_output=True, text=True, env=env, timeout=300)
    return p.returncode, p.stdout, set(json.loads(p.stderr.strip().splitlines()[-1]))


def _heavy(loaded: set[str]) -> list[str]:
    return [h for h in NOT_ON_A_PLAIN_LOG if any(m == h or m.startswith(h + ".") for m in loaded)]


def test_a_warm_run_on_a_plain_log_loads_no_heavy_part_and_a_cold_one_does(tmp_path: Path,
                                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    root, cache = _workspace(tmp_path / "ws"), tmp_path / "cache"
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache))
    out = io.StringIO()
    with contextlib.redirect_stdout(out):  # the cache warmed in this process (the same sources, the same keys)
        assert commands.main(["monitor", "--json", "--margins", "-w", str(root), str(root / "run.jsonl")]) == 1
    # the backends' declarations are read when their module is imported, which this process did before the
    # command ran: a first command of its own keeps them
    _loaded(root, cache)
    code, printed, loaded = _loaded(root, cache)
    assert code == 1 and json.loads(printed) == json.loads(out.getvalue())  # the window at 0.03 s violated
    assert _heavy(loaded) == []
    assert {"msgspec", "rclverify.backends.monitors.recorded"} <= loaded  # what the run does need
    # the control: a cold start parses the contract (lark), checks the plan (jsonschema), loads rosbags'
    # standard store and parses the YAML files (PyYAML), and the probe sees them
    code, printed_cold, loaded = _loaded(root, tmp_path / "cold")
    assert code == 1 and printed_cold == printed
    assert {"lark", "jsonschema", "rosbags.typesys.stores", "yaml"} <= set(_heavy(loaded))


def test_a_distributions_folder_is_found_by_its_normalised_name_on_the_first_path_entry(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A wheel's lower-case ``pyyaml-6.0.4.dist-info`` is ``PyYAML``'s, and the first ``sys.path`` entry
    holding one decides, as importlib.metadata decides (an older ``PyYAML-6.0.dist-info`` on a later
    entry, a system's, is not read); the control: the two entries the other way round."""
    new, old = tmp_path / "venv", tmp_path / "system"
    (new / "pyyaml-6.0.4.dist-info").mkdir(parents=True)
    (old / "PyYAML-6.0.dist-info").mkdir(parents=True)
    monkeypatch.setattr(sys, "path", [str(new), str(old)])
    assert distribution_version("PyYAML") == "6.0.4"
    monkeypatch.setattr(sys, "path", [str(old), str(new)])
    assert distribution_version("PyYAML") == "6.0"


DEADLINE = """node Window {
  inputs( a : REAL )
  outputs( b : REAL )
  topics( std_msgs/Float64 trig matches(in.a), std_msgs/Float64 ans matches(out.b) )
  guarantee( out.b > in.a ) triggered by in.a within 30 ms
}
"""


def test_the_deadline_monitors_are_loaded_by_a_run_with_a_deadline_only(tmp_path: Path) -> None:
    """A warm run on a plain log loads none of :data:`DEADLINE_PARTS`; the control: the same workspace
    with a deadline in its contract loads them all, and judges its triggers (one met, one missed)."""
    plain, timed, cache = _workspace(tmp_path / "plain"), _workspace(tmp_path / "timed"), tmp_path / "cache"
    (timed / "contracts/w.rcl").write_text(DEADLINE)
    (timed / "backends/monitors/mapping.yaml").write_text(
        "horizon: 0.005\ntopics:\n  trig: {fields: [data]}\n  ans: {fields: [data]}\n")
    (timed / "run.jsonl").write_text("".join(json.dumps(line) + "\n" for line in [
        {"topic": "trig", "time": 0.0, "data": 0.0}, {"topic": "ans", "time": 0.01, "data": 1.0},
        {"topic": "trig", "time": 0.1, "data": 0.0}, {"topic": "ans", "time": 0.2, "data": 1.0},
        {"topic": "tick", "time": 1.0}]))
    for root in (plain, timed):
        _loaded(root, cache)  # the start-up cache warmed
    code, printed, loaded = _loaded(plain, cache)
    assert code == 1 and "deadlines" not in printed
    assert [m for m in DEADLINE_PARTS if m in loaded] == []
    code, printed, loaded = _loaded(timed, cache)
    deadlines = next(r["deadlines"] for r in json.loads(printed) if "deadlines" in r)
    assert code == 1 and deadlines["counts"]["true"] == 1 and deadlines["counts"]["false"] == 1
    assert set(DEADLINE_PARTS) <= loaded


@pytest.mark.parametrize(("report", "laid_out"), [
    ([], True), ([{}], True),
    ([{"node": "W", "counts": {"violated": 2, "satisfied": 0}, "margins": [], "not_judged": [],
       "values": {"out.x": [1e-05, 2.5, -0.0, 1e300, 5e-324], "in.r": 10 ** 30}, "why": "a\tb\n\"c\" \\ /"}], True),
    ([{"é": "ü\u2028\x00", "nested": [[], {}, [1, [2, {"z": None, "a": True}]]]}], True),
    # text msgspec does not read: written by the indenting encoder
    ([{"margin": float("inf"), "low": float("-inf")}], False), ([{"x": float("nan")}], False),
    ([{"k": "\ud800"}], False),
])
def test_the_json_report_is_the_indenting_encoders_text(report: list[dict[str, object]], laid_out: bool) -> None:
    """``monitor --json`` lays out the one-line JSON with msgspec's ``format``: byte for byte what
    ``json.dumps(indent=2, sort_keys=True)`` writes (escapes, floats, empty lists and mappings, key order);
    the control: the reports msgspec refuses to read are the indenting encoder's own text."""
    import msgspec
    from rclverify.cli.monitor import _indented
    assert _indented(report) == json.dumps(report, indent=2, sort_keys=True)
    try:
        msgspec.json.format(json.dumps(report, sort_keys=True).encode(), indent=2)
        read = True
    except msgspec.DecodeError:
        read = False
    assert read == laid_out
