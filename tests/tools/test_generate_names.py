"""``generate ros2`` and hostile RCL names (issue 63 row 10; docs/generate.md, "Names").

An RCL identifier may end in primes (``x'``) and may be a Python or C++ keyword (``class``,
``delete``, ``lambda``, ``None``, ``namespace``, ``int``).  Before targets/names.py the tree
of such a contract did not compile (``def step(x', class)``, ``double delete{};``) and the
command said 0.  Here:

* a hand-written hostile contract, generated for Python and for C++: every Python file compiles
  and ``logic.py``'s property-test entry takes the RCL names; the C++ checks, drivers, logic and
  nodes compile with g++ in one translation unit (rclcpp and the message headers stubbed from
  the generated interface files: _rclcpp_stub.py); every interface file parses with rosidl's own
  parser (rosidl_adapter to IDL, rosidl_parser), from ROS 2's wheels; the mapping still maps
  each topic's field to its RCL variable;
* names a tree cannot carry are refused, located at the contract's name, exit 1, nothing written;
* 30 seeded random contracts whose names are drawn from RCL's identifier grammar and from lists
  of Python and C++ keywords and builtins: each one generates a tree that compiles (Python,
  C++ in one g++ call, rosidl in one parser process) or is refused by a located name error.
"""
from __future__ import annotations

import importlib.util
import keyword
import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

from _ros2 import ros2_python
from rclverify.cli.commands import main
from rclverify.targets.names import constant_name, field_name, msg_name, package_name, py_name
from rclverify.ros.extract.treesitter import parser, walk
from _rclcpp_stub import write_stubs

CXX = ["g++", "-std=c++17", "-Wall", "-Wextra", "-Werror", "-fsyntax-only"]

HOSTILE = """
context {
  Mode : {on, off'};
  Cmd : {go(REAL), delete(NATURAL)};
}
node class {
  inputs( x' : REAL, delete : INTEGER, lambda : BOOL, None : Mode, namespace : Cmd )
  outputs( int : REAL, auto : BOOL )
  topics( hostile_msgs/Reading reading matches(in.x'), hostile_msgs/Reading reading2 matches(in.delete),
          hostile_msgs/Reading reading3 matches(in.lambda), hostile_msgs/Reading reading4 matches(in.None),
          hostile_msgs/Reading reading5 matches(in.namespace),
          hostile_msgs/Out new matches(out.int), std_msgs/Bool flag matches(out.auto) )
  assume( in.x' >= 0 and in.delete < 5 )
  guarantee( out.int == in.x' + 1 and (out.auto <=> in.lambda) and forall(x' in BOOL | x' or not x')
             and in.None == on )
}
node lambda {
  inputs( int : REAL, import : REAL, await'' : BOOL, try : INTEGER )
  outputs( self : REAL, yield : BOOL, virtual : NATURAL )
  topics( hostile_msgs/Out new matches(in.int), std_msgs/Float64 template matches(out.self) )
  services( hostile_msgs/Ask delete serves(in.import, out.yield) )
  actions( hostile_msgs/Go operator calls(out.virtual, in.await'', in.try) )
  guarantee( out.self == in.int )
}
"""

# rosidl_adapter's .msg -> .idl and rosidl_parser on the result, in ROS 2's own Python; prints one
# line per interface file that fails, and per field name a Python keyword (rosidl_generator_py
# cannot write it)
ROSIDL_CHECK = r"""
import contextlib, io, keyword, sys, tempfile
from pathlib import Path
from rosidl_adapter.msg import convert_msg_to_idl
from rosidl_adapter.srv import convert_srv_to_idl
from rosidl_adapter.action import convert_action_to_idl
from rosidl_parser.parser import parse_idl_file
from rosidl_parser.definition import Action, IdlLocator, Message, Service
conv = {'msg': convert_msg_to_idl, 'srv': convert_srv_to_idl, 'action': convert_action_to_idl}
n = 0
for f in map(Path, sys.argv[1:]):
    pkg_dir = f.parent.parent
    with tempfile.TemporaryDirectory() as tmp:
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                idl = conv[f.parent.name](pkg_dir, pkg_dir.name, f.relative_to(pkg_dir), Path(tmp))
            content = parse_idl_file(IdlLocator(Path(tmp), idl.relative_to(tmp)))
        except BaseException as exc:
            print(f'{f}: {type(exc).__name__}: {exc}')
            continue
        structs = [m.structure for m in content.content.get_elements_of_type(Message)]
        structs += [p.structure for s in content.content.get_elements_of_type(Service)
                    for p in (s.request_message, s.response_message)]
        structs += [p.structure for a in content.content.get_elements_of_type(Action)
                    for p in (a.goal, a.result, a.feedback)]
        for st in structs:
            for member in st.members:
                if keyword.iskeyword(member.name):
                    print(f'{f}: field {member.name} is a Python keyword')
        n += 1
print(f'parsed {n}')
"""


def _ws(tmp: Path, rcl: str) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "sys.rcl").write_text(rcl)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    return ws


def _generate(ws: Path, out: Path, lang: str) -> int:
    return main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--lang", lang, "--system", "hostile"])


@pytest.fixture(scope="module")
def hostile(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """HOSTILE generated for both languages, once."""
    tmp = tmp_path_factory.mktemp("hostile")
    ws = _ws(tmp, HOSTILE)
    trees = {lang: ws / lang for lang in ("python", "cpp")}
    for lang, out in trees.items():
        assert _generate(ws, out, lang) == 0
    return trees


def _py_compile_all(out: Path) -> int:
    files = sorted(out.rglob("*.py"))
    for f in files:
        compile(f.read_text(encoding="utf-8"), str(f), "exec")  # raises SyntaxError
    return len(files)


def _load(path: Path):
    spec = importlib.util.spec_from_file_location(f"gen_{abs(hash(str(path)))}", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _plan_steps(out: Path) -> dict[str, str]:
    """node -> the plan fragment's property-test implementation (``pkg/pkg/logic.py:step``)."""
    plan = yaml.safe_load((out / "rclverify_plan.yaml").read_text())
    return {n: e["implementation"] for n, v in plan["nodes"].items() for e in v["evidence"]
            if e["backend"] == "property_tests"}


def _cpp_unit(trees: list[Path], unit: Path) -> list[str]:
    """One translation unit with every package's driver, logic.cpp and node (its ``main`` renamed;
    rclcpp and the message headers stubbed: tests/_rclcpp_stub.py); the g++ command for it."""
    pkgs = [h.parent for t in trees for h in sorted(t.glob("*/include/*/contract_driver.hpp"))]
    stubs = write_stubs(trees, unit.parent / "stubs")
    unit.write_text("".join(f'#include "{p.name}/contract_driver.hpp"\n' for p in pkgs)
                    + "".join(f'#include "{p.parent.parent / "src" / "logic.cpp"}"\n' for p in pkgs)
                    + "".join(f'#define main main_{p.name}\n#include "{p.parent.parent / "src" / (p.name + "_node.cpp")}"\n'
                              f"#undef main\n" for p in pkgs))
    return CXX + [f"-I{stubs}"] + [f"-I{p.parent}" for p in pkgs] + [str(unit)]


def _node_cpp_parses(tree: Path) -> None:
    for p in sorted(tree.glob("*/src/*_node.cpp")):
        bad = [n for n in walk(parser("cpp").parse(p.read_bytes()).root_node) if n.type == "ERROR" or n.is_missing]
        assert not bad, f"{p}: {bad[:3]}"


def _rosidl(trees: list[Path]) -> list[str]:
    files = [str(f) for t in trees for k in ("msg", "srv", "action") for f in sorted(t.glob(f"*/{k}/*.{k}"))]
    res = subprocess.run([str(ros2_python()), "-c", ROSIDL_CHECK, *files], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[-1] == f"parsed {len(files)}", "\n".join(lines)
    return files


def test_hostile_python_compiles_and_its_step_takes_the_rcl_names(hostile: dict[str, Path]) -> None:
    out = hostile["python"]
    assert _py_compile_all(out) >= 10
    logic = (out / "class_node" / "class_node" / "logic.py").read_text()
    assert "def step(x_prime, delete, lambda_, None_, namespace):" in logic
    assert _plan_steps(out) == {"class": "python/class_node/class_node/logic.py:step_rcl",
                                "lambda": "python/lambda_node/lambda_node/logic.py:step_rcl"}
    for node, inputs in (("class", ["x'", "delete", "lambda", "None", "namespace"]),
                         ("lambda", ["int", "import", "await''", "try"])):
        impl = _plan_steps(out)[node]
        file, _, fn = impl.rpartition(":")
        assert getattr(_load(out.parent / file), fn)(**{n: 0 for n in inputs}) == {}


def test_hostile_cpp_compiles(hostile: dict[str, Path], tmp_path: Path) -> None:
    if shutil.which("g++") is None:
        pytest.skip("g++ is not installed")
    out = hostile["cpp"]
    checks = (out / "class_node" / "include" / "class_node" / "contract_checks.hpp").read_text()
    assert "double x_prime{};  // in.x' : REAL" in checks and "std::int64_t delete_field{};" in checks
    res = subprocess.run(_cpp_unit([out], tmp_path / "unit.cpp"), capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr[:3000]
    _node_cpp_parses(out)
    node_cpp = (out / "class_node" / "src" / "class_node_node.cpp").read_text()
    assert "inputs_.delete_field = msg.delete_field;" in node_cpp
    assert '#include "hostile_msgs/msg/reading.hpp"' in node_cpp


def test_hostile_interfaces_parse_with_rosidl_and_map_to_the_rcl_names(hostile: dict[str, Path]) -> None:
    out = hostile["python"]
    assert len(_rosidl([out])) == 5  # Reading, Out, Cmd, Ask.srv, Go.action
    assert (out / "hostile_msgs" / "srv" / "Ask.srv").read_text().split("---")[1].split()[0:2] == ["bool", "yield_field"]
    assert "bool await_prime_prime" in (out / "hostile_msgs" / "action" / "Go.action").read_text()
    reading = (out / "hostile_msgs" / "msg" / "Reading.msg").read_text()
    for line in ("float64 x_prime", "int64 delete_field", "bool lambda_field", "uint8 none",
                 "hostile_msgs/Cmd namespace_field", "uint8 MODE_OFF_PRIME=1"):
        assert line in reading
    assert "uint8 DELETE_VALUE=1" not in reading and "uint64 delete_0" in (out / "hostile_msgs/msg/Cmd.msg").read_text()
    mapping = yaml.safe_load((out / "rclverify_mapping.yaml").read_text())
    fields = {t: r["fields"] for t, r in mapping["topics"].items()}
    assert fields["reading"] == ["x_prime"] and fields["reading2"] == ["delete_field"] and fields["new"] == ["int_field"]
    contract = _load(out / "class_node" / "class_node" / "contract.py")
    assert contract.FIELDS["in.x'"] == ("sub_reading", "x_prime")


REFUSED = [
    ("node a' {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 p matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n",
     "1:1", "node name a' cannot be a ROS 2 node name"),
    ("node a {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 p' matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n",
     "4:11", "topic name p' cannot be a ROS 2 topic name"),
    ("node a {\n  inputs( x' : REAL, x_prime : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 p matches(in.x'), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x' )\n}\n",
     "2:22", "in.x_prime and in.x' (contracts/sys.rcl:2:11) would both be"),
    ("node a {\n  inputs( class : REAL, class_field : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 p matches(in.class), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.class )\n}\n",
     "2:25", "in.class_field and in.class (contracts/sys.rcl:2:11) would both be a's C++ Inputs field class_field"),
    ("node FooBar {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 p matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n"
     "node foo_bar {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( std_msgs/Float64 q matches(in.x), std_msgs/Float64 r matches(out.y) )\n  guarantee( out.y == in.x )\n}\n",
     "7:1", "node foo_bar and node FooBar (contracts/sys.rcl:1:1) would both be the ROS package foo_bar"),
    ("node a {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( class/Reading p matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n",
     "4:11", "interface package class of class/Reading cannot be generated"),
    ("node a {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( my_msgs/reading p matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n",
     "4:11", "interface reading of my_msgs/reading cannot be generated"),
    ("node a {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( my_msgs/R fooBar matches(in.x), my_msgs/R foo_bar matches(in.x), std_msgs/Float64 q matches(out.y) )\n"
     "  guarantee( out.y == in.x )\n}\n",
     "4:43", "foo_bar and fooBar (contracts/sys.rcl:4:11) would both be node a's end sub_foo_bar"),
    ("node a {\n  inputs( x' : REAL )\n  outputs( y : REAL )\n"
     "  topics( my_msgs/R p matches(in.x'), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x' )\n}\n"
     "node b {\n  inputs( z : REAL )\n  outputs( x_prime : REAL )\n"
     "  topics( std_msgs/Float64 q matches(in.z), my_msgs/R p matches(out.x_prime) )\n"
     "  guarantee( out.x_prime == in.z )\n}\n",
     "9:12", "my_msgs/msg/R: b's out.x_prime and a's in.x' (contracts/sys.rcl:2:11) would both be field x_prime"),
    ("node a {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
     "  topics( my_msgs/R p matches(in.x), std_msgs/Float64 q matches(out.y) )\n  guarantee( out.y == in.x )\n}\n"
     "node b {\n  inputs( z : REAL )\n  outputs( x : BOOL )\n"
     "  topics( std_msgs/Float64 q matches(in.z), my_msgs/R p matches(out.x) )\n  guarantee( out.x <=> in.z > 0 )\n}\n",
     "9:12", "my_msgs/msg/R: field x would carry b's out.x of type BOOL and a's in.x (contracts/sys.rcl:2:11) of type REAL"),
    ("context {\n  Mode : {a', a_prime};\n  Cmd : {go(REAL), go_(REAL)};\n}\n"
     "node Foo {\n  inputs( m : Mode, c : Cmd )\n  outputs( y : REAL )\n"
     "  topics( my_msgs/R p matches(in.m), my_msgs/R q matches(in.c), std_msgs/Float64 r matches(out.y) )\n"
     "  guarantee( out.y == 1 )\n}\n",
     "2:3", "Mode's value a_prime and Mode's value a' (contracts/sys.rcl:2:3) would both be the rosidl constant "
            "MODE_A_PRIME"),
    ("node c {\n  inputs( pair : REAL --> REAL )\n  outputs( w : REAL )\n"
     "  topics( my_msgs/S s matches(in.pair), my_msgs/PairEntry t matches(out.w) )\n  guarantee( out.w == 1 )\n}\n",
     "4:41", "my_msgs/msg/PairEntry is declared here and is also the nested message"),
]


@pytest.mark.parametrize("rcl, where, message", REFUSED, ids=[
    "prime-node", "prime-topic", "prime-collision", "keyword-collision", "package-collision", "keyword-package",
    "lowercase-type", "end-collision", "field-collision-across-nodes", "field-of-two-types", "context-constant-collision",
    "nested-message-collision"])
def test_a_name_the_tree_cannot_carry_is_refused_located(tmp_path: Path, capsys, rcl: str, where: str,
                                                          message: str) -> None:
    ws = _ws(tmp_path, rcl)
    out = tmp_path / "out"
    for lang in ("python", "cpp"):
        assert _generate(ws, out, lang) == 1
        err = capsys.readouterr().err
        assert f"contracts/sys.rcl:{where}: error: {message}" in err, err
        assert "Traceback" not in err
        assert not out.exists()  # nothing written


# ---- random names ---------------------------------------------------------------------------

#: RCL's reserved words and the words its parser reads as keywords where a name may stand in
#: the contracts below (docs/rcl-language.md): never drawn
RCL_WORDS = {"and", "or", "not", "in", "forall", "exists", "exists_unique", "TRUE", "FALSE", "REAL", "INTEGER",
             "NATURAL", "BOOL", "STRING", "x", "set", "seq", "context", "node", "inputs", "outputs", "topics",
             "matches", "assume", "guarantee", "A", "G", "services", "actions", "serves", "calls", "triggered",
             "by", "within", "initially", "progress", "periodic", "eventually", "upto", "out"}
HOSTILE_WORDS = sorted(({"class", "def", "lambda", "None", "True", "False", "self", "delete", "new", "namespace",
                         "int", "float", "auto", "template", "operator", "return", "import", "from", "yield",
                         "async", "await", "nonlocal", "global", "pass", "is", "if", "else", "while", "for", "try",
                         "except", "finally", "with", "as", "del", "raise", "assert", "break", "continue",
                         "struct", "union", "enum", "static", "const", "virtual", "this", "typename", "using",
                         "bool", "char", "double", "long", "short", "signed", "unsigned", "void", "volatile",
                         "register", "restrict", "friend", "explicit", "export", "module", "requires", "concept",
                         "__debug__", "errno", "linux", "unix", "NULL", "EOF", "string", "list", "dict", "type",
                         "print", "std", "rclpy", "launch", "msg", "node_", "_", "__", "_x", "x_1", "X1", "a__b",
                         "step", "values", "heard", "inputs_", "Inputs", "kNode", "judge", "q_a", "cand_n"}
                        | set(keyword.kwlist)) - RCL_WORDS)


def _name(rng: random.Random, used: set[str], primes: bool = True) -> str:
    """A fresh RCL identifier: a hostile word or a random one, with 0-2 primes."""
    while True:
        if rng.random() < 0.6:
            base = rng.choice(HOSTILE_WORDS)
        else:
            base = rng.choice("abcXYZ_") + "".join(rng.choice("abcxyzABQ019_") for _ in range(rng.randint(0, 5)))
        n = rng.choice([0, 0, 1, 2]) if primes else 0
        name = base + "'" * n
        if base not in RCL_WORDS and name not in used and re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*'*", name):
            used.add(name)
            return name


def _contract(rng: random.Random, node_name: str, pkg: str) -> tuple[str, list[str]]:
    """A random contract (one node ``node_name``) with hostile names everywhere a name stands;
    returns the text and the node's inputs."""
    used = {node_name}
    enum, e1, e2 = _name(rng, used), _name(rng, used), _name(rng, used)
    data, c1, c2 = _name(rng, used), _name(rng, used), _name(rng, used)
    types = ["REAL", "INTEGER", "NATURAL", "BOOL", enum, data]
    ins = [(_name(rng, used), rng.choice(types)) for _ in range(rng.randint(2, 4))]
    twin = field_name(ins[0][0])  # sometimes an input named as another's generated field: refused
    if rng.random() < 0.2 and twin != ins[0][0] and twin not in used | RCL_WORDS:
        used.add(twin)
        ins.append((twin, ins[0][1]))
    outs = [(_name(rng, used), rng.choice(["REAL", "BOOL", "INTEGER"])) for _ in range(rng.randint(1, 3))]
    q1, q2 = _name(rng, used), _name(rng, used)
    topics = []
    for side, vs, msg in (("in", ins, "Data"), ("out", outs, "Result")):
        for v, _ in vs:
            topics.append(f"{pkg}/{msg} {_name(rng, used, primes=False)} matches({side}.{v})")
    links = []
    if rng.random() < 0.5:  # a service: request and response variables of their own
        req, resp = (_name(rng, used), "REAL"), (_name(rng, used), "BOOL")
        ins.append(req)
        outs.append(resp)
        links.append(f"  services( {pkg}/Ask {_name(rng, used, primes=False)} serves(in.{req[0]}, out.{resp[0]}) )\n")
    if rng.random() < 0.4:  # an action: goal, feedback, result
        goal, fb, res = (_name(rng, used), "REAL"), (_name(rng, used), "REAL"), (_name(rng, used), "BOOL")
        ins.append(goal)
        outs.extend([fb, res])
        links.append(f"  actions( {pkg}/Go {_name(rng, used, primes=False)} "
                     f"serves(in.{goal[0]}, out.{fb[0]}, out.{res[0]}) )\n")
    real_in = next((v for v, t in ins if t == "REAL"), None)
    parts = [f"forall({q1} in BOOL | {q1} or not {q1})", f"exists({q2} in {enum} | {q2} == {e1})"]
    for v, t in outs:
        if t == "BOOL":
            parts.append(f"(out.{v} <=> not not out.{v})")
        elif real_in is not None and t == "REAL":
            parts.append(f"out.{v} >= in.{real_in} - 1")
        else:
            parts.append(f"out.{v} <= 7")
    for v, t in ins:
        if t == enum:
            parts.append(f"(in.{v} == {e2} or in.{v} != {e2})")
        if t == data:
            parts.append(f"(in.{v} == {c2}(3) -> TRUE)")
    assume = f"  assume( in.{real_in} >= 0 )\n" if real_in else ""
    rcl = (f"context {{\n  {enum} : {{{e1}, {e2}}};\n  {data} : {{{c1}(REAL), {c2}(NATURAL)}};\n}}\n"
           f"node {node_name} {{\n  inputs( {', '.join(f'{v} : {t}' for v, t in ins)} )\n"
           f"  outputs( {', '.join(f'{v} : {t}' for v, t in outs)} )\n  topics( {', '.join(topics)} )\n"
           f"{''.join(links)}{assume}  guarantee( {' and '.join(parts)} )\n}}\n")
    return rcl, [v for v, _ in ins]


@pytest.fixture(scope="module")
def random_trees(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """30 seeded random contracts, each generated for Python and for C++ (node packages unique over
    the lot, so that every C++ package goes into one translation unit)."""
    rng = random.Random(63_10)
    tmp = tmp_path_factory.mktemp("random")
    made: dict[str, list] = {"python": [], "cpp": [], "refused": [], "inputs": []}
    packages: set[str] = set()
    for i in range(30):
        node = _name(rng, set(), primes=False)
        while package_name(node) in packages or package_name(node).startswith("gen"):
            node = f"{node}{i}"
        packages.add(package_name(node))
        rcl, ins = _contract(rng, node, f"gen{i}_msgs")  # one interface package per contract: one C++ unit
        ws = _ws(tmp / f"c{i}", rcl)
        results = {}
        for lang in ("python", "cpp"):
            out = ws / lang
            results[lang] = (_generate(ws, out, lang), out)
        codes = {r[0] for r in results.values()}
        assert len(codes) == 1, (rcl, results)
        if codes == {0}:
            made["python"].append(results["python"][1])
            made["cpp"].append(results["cpp"][1])
            made["inputs"].append((results["python"][1], node, ins))
        else:
            made["refused"].append((rcl, results["python"][1], results["cpp"][1]))
    return made


def test_random_hostile_names_generate_trees_that_compile(random_trees: dict, tmp_path: Path, capsys) -> None:
    capsys.readouterr()
    # seed 6310: 28 generated (12 with a service, 11 with an action), 2 refused (two names on one generated name)
    assert len(random_trees["python"]) >= 20, f"only {len(random_trees['python'])} of 30 contracts generated"
    assert len(random_trees["python"]) + len(random_trees["refused"]) == 30
    for rcl, py_out, cpp_out in random_trees["refused"]:  # a refusal is a located name error, nothing written
        assert not py_out.exists() and not cpp_out.exists()
    for out, node, ins in random_trees["inputs"]:
        _py_compile_all(out)
        impl = _plan_steps(out)[node]
        file, _, fn = impl.rpartition(":")
        assert getattr(_load(out.parent / file), fn)(**{n: 0 for n in ins}) == {}
        assert fn == ("step" if all(py_name(n) == n for n in ins) else "step_rcl")
    if shutil.which("g++") is not None:
        res = subprocess.run(_cpp_unit(random_trees["cpp"], tmp_path / "unit.cpp"), capture_output=True, text=True,
                             timeout=120)
        assert res.returncode == 0, res.stderr[:3000]
    for out in random_trees["cpp"]:
        _node_cpp_parses(out)
    _rosidl(random_trees["python"])


def test_a_random_refusal_is_a_located_name_error(random_trees: dict, tmp_path: Path, capsys) -> None:
    assert random_trees["refused"], "the seed draws no colliding names: the refusal path is not exercised"
    for k, (rcl, _, _) in enumerate(random_trees["refused"]):
        capsys.readouterr()
        assert _generate(_ws(tmp_path / f"r{k}", rcl), tmp_path / f"r{k}" / "out", "python") == 1
        err = capsys.readouterr().err
        assert re.search(r"contracts/sys\.rcl:\d+:\d+: error: .*(would both be|cannot be)", err), (rcl, err)


def test_the_name_rules() -> None:
    assert field_name("x'") == "x_prime" and field_name("class") == "class_field" and field_name("wayP") == "way_p"
    assert field_name("None") == "none" and field_name("x''") == "x_prime_prime" and field_name("_") == "f"
    assert py_name("class") == "class_" and py_name("x'") == "x_prime" and py_name("__debug__") == "__debug___"
    assert package_name("class") == "class_node" and package_name("string") == "string_node"
    assert package_name("A") == "a_node" and package_name("RadiationSensor") == "radiation_sensor"
    assert package_name("StdMsgs") == "std_msgs_node" and package_name("rclpy") == "rclpy_node"
    assert msg_name("none") == "NoneMsg" and msg_name("T'") == "TPrime"
    assert constant_name("null") == "NULL_VALUE" and constant_name("RadStat", "red'") == "RAD_STAT_RED_PRIME"
    rosidl = re.compile(r"^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$")
    for w in HOSTILE_WORDS + [w + "'" for w in HOSTILE_WORDS]:
        f = field_name(w)
        assert rosidl.match(f) and not keyword.iskeyword(f), w
        assert py_name(w).isidentifier() and not keyword.iskeyword(py_name(w)), w


PT_CONTRACT = """
node class {
  inputs( x' : REAL, lambda : BOOL )
  outputs( delete : REAL )
  topics( hostile_msgs/Reading reading matches(in.x'), std_msgs/Bool flag matches(in.lambda),
          std_msgs/Float64 result matches(out.delete) )
  assume( 0 <= in.x' and in.x' <= 10 )
  guarantee( out.delete >= in.x' )
}
"""


def test_verify_property_tests_the_renamed_step(tmp_path: Path, capsys) -> None:
    """The plan fragment's entry (``logic.py:step_rcl``) copied into the plan: ``verify`` calls the
    hand-written ``step(x_prime, lambda_)`` through it, finds a seeded bug and discharges the fix."""
    ws = _ws(tmp_path, PT_CONTRACT)
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen")]) == 0
    frag = yaml.safe_load((ws / "gen" / "rclverify_plan.yaml").read_text())
    assert frag["nodes"]["class"]["evidence"][0]["implementation"] == "gen/class_node/class_node/logic.py:step_rcl"
    (ws / "contracts" / "plan.yaml").write_text(yaml.safe_dump(
        {"name": "names", "contracts": ["contracts/sys.rcl"], "connections": [], "environment": {},
         "nodes": {"class": {"evidence": frag["nodes"]["class"]["evidence"][:1]}}}, sort_keys=False))
    logic = ws / "gen" / "class_node" / "class_node" / "logic.py"
    text = logic.read_text()
    stub = "def step(x_prime, lambda_):\n    \"\"\"The outputs for these inputs (RCL values, docs/values.md): " \
           "``{output name: value}``.\"\"\"\n    return {}\n"
    assert stub in text
    for body, want in (("x_prime - (1 if lambda_ else 0)", "failed"), ("x_prime + (1 if lambda_ else 0)", "discharged")):
        logic.write_text(text.replace(stub, stub.replace("return {}", f"return {{'delete': {body}}}")))
        capsys.readouterr()
        main(["verify", "-w", str(ws)])
        out = capsys.readouterr().out
        assert f"overall: {want}" in out, out[-2000:]
        if want == "failed":
            assert "logic.py:step_rcl violates guarantee 1 of class" in out


def test_a_type_named_like_a_name_node_py_uses_is_imported_under_an_alias(tmp_path: Path) -> None:
    """``my_msgs/Node`` would rebind rclpy's Node, ``my_msgs/String`` the verdicts' String,
    ``my_msgs/FooNode`` the node's class, ``my_msgs/Pose`` and ``geometry_msgs/Pose`` each other:
    each is imported as ``pkg_kind_Class``."""
    ws = _ws(tmp_path, "node Foo {\n  inputs( a : REAL, b : REAL, c : REAL )\n  outputs( d : BOOL, e : REAL )\n"
                       "  topics( my_msgs/Node t1 matches(in.a), my_msgs/Pose t2 matches(in.b), "
                       "geometry_msgs/Pose t3 matches(in.c), my_msgs/String t4 matches(out.d), "
                       "my_msgs/FooNode t5 matches(out.e) )\n  guarantee( out.d <=> in.a > 0 )\n}\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen")]) == 0
    node = (ws / "gen" / "foo" / "foo" / "node.py").read_text()
    compile(node, "node.py", "exec")
    assert "from my_msgs.msg import FooNode as my_msgs_msg_FooNode, Node as my_msgs_msg_Node, " \
           "Pose as my_msgs_msg_Pose, String as my_msgs_msg_String\n" in node
    assert "from geometry_msgs.msg import Pose as geometry_msgs_msg_Pose\n" in node
    assert "from rclpy.node import Node\n" in node and "class FooNode(Node):" in node
    assert "self.create_subscription(geometry_msgs_msg_Pose, 't3'" in node
    assert "self.create_publisher(String, contract.VERDICT_TOPIC" in node


def test_names_yaml_would_read_as_booleans_stay_strings(tmp_path: Path) -> None:
    """A node ``True``, topics ``yes``/``off``, fields ``on``/``null``: plain YAML reads them as
    booleans and null; the plan fragment and the mapping quote them, so they read back as names."""
    ws = _ws(tmp_path, "node True {\n  inputs( on : REAL )\n  outputs( null : BOOL )\n"
                       "  topics( my_msgs/R yes matches(in.on), my_msgs/S off matches(out.null) )\n"
                       "  guarantee( out.null <=> in.on > 0 )\n}\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen")]) == 0
    mapping = yaml.safe_load((ws / "gen" / "rclverify_mapping.yaml").read_text())
    assert mapping == {"topics": {"yes": {"fields": ["on"]}, "off": {"fields": ["null"]}}}
    plan = yaml.safe_load((ws / "gen" / "rclverify_plan.yaml").read_text())
    assert list(plan["nodes"]) == ["True"]
    assert plan["nodes"]["True"]["evidence"][0]["implementation"] == "gen/true_node/true_node/logic.py:step"
