"""rclverify's name resolution (model/names.py) held against rcl itself, through rclpy in ROS 2's
Python: the validators (``validate_topic_name``, ``validate_full_topic_name``, ``validate_namespace``,
``validate_node_name``), ``expand_topic_name`` and a node's ``resolve_topic_name`` under remap rules,
over the cases of ROS 2's design article "Topic and Service Names" and names drawn at random.
All cases go to one subprocess; skipped without ROS 2's Python (tests/_ros2.py)."""
from __future__ import annotations

import json
import random
import subprocess
from typing import Any, Callable

import pytest

from rclverify.model import names

from _ros2 import ros2_python

PROBE = """
import json, sys
import rclpy
from rclpy.expand_topic_name import expand_topic_name
from rclpy.validate_topic_name import validate_topic_name
from rclpy.validate_full_topic_name import validate_full_topic_name
from rclpy.validate_namespace import validate_namespace
from rclpy.validate_node_name import validate_node_name
from rclpy.node import Node
cases = json.loads(sys.stdin.read())
def ok(f, *a):
    try:
        f(*a)
        return True
    except Exception:
        return False
def value(f, *a):
    try:
        return f(*a)
    except Exception:
        return None
out = {"topic": [ok(validate_topic_name, n) for n in cases["topic"]],
       "full": [ok(validate_full_topic_name, n) for n in cases["full"]],
       "namespace": [ok(validate_namespace, n) for n in cases["namespace"]],
       "node": [ok(validate_node_name, n) for n in cases["node"]],
       "expand": [value(expand_topic_name, *c) for c in cases["expand"]]}
rclpy.init()
res = []
for name, node, ns, rules in cases["resolve"]:
    args = ["--ros-args"] + [x for r in rules for x in ("-r", r)]
    try:
        n = Node(node, namespace=ns, cli_args=args, start_parameter_services=False, enable_rosout=False)
    except Exception:
        res.append("refused")
        continue
    res.append([n.get_fully_qualified_name(), value(n.resolve_topic_name, name)])
    n.destroy_node()
rclpy.shutdown()
out["resolve"] = res
print(json.dumps(out))
"""

#: The design article's names (valid and invalid, "Topic and Service Names"), and edges of the rules.
ARTICLE = ["foo", "abc123", "_foo", "Foo", "BAR", "~", "foo/bar", "~/foo", "{foo}_bar", "foo/{ping}/bar",
           "foo/_bar", "foo_/bar", "foo_", "/foo", "/bar/baz", "123abc", "123", " ", "foo bar", "foo//bar", "/~",
           "~foo", "foo~", "foo~/bar", "foo/~bar", "foo/~/bar", "foo/", "/", "", "{}", "{1a}", "{a{b}}", "a}",
           "{a", "foo/1bar", "{node}", "{ns}", "{namespace}", "~/{node}/x", "{ns}/x", "a-b", "a.b", "ä",
           "/" + "t" * 246, "/" + "t" * 247, "/a/" + "b" * 244]
#: The design article's table: each input under node ``my_node`` in the root namespace and in ``/my_ns``.
TABLE = [("ping", "/ping", "/my_ns/ping"), ("/ping", "/ping", "/ping"), ("~", "/my_node", "/my_ns/my_node"),
         ("~/ping", "/my_node/ping", "/my_ns/my_node/ping")]
NODES = ["my_node", "a", "_a", "a__b_", "1a", "a-b", "", "n" * 255, "n" * 256, "Relay2"]
NAMESPACES = ["/", "/my_ns", "/a/b", "/a/", "a", "/1a", "//a", "/" + "s" * 244, "/" + "s" * 245, "/r1", "/r2"]


def _random_names(rng: random.Random, count: int) -> list[str]:
    alphabet = "ab_1/~{}" + "Z-"
    out = []
    for _ in range(count):
        n = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 9)))
        if rng.random() < 0.2:
            n = rng.choice(["{node}", "{ns}", "{namespace}", "~/"]) + n
        out.append(n)
    return out


def _cases() -> dict[str, list[Any]]:
    rng = random.Random(110)
    drawn = _random_names(rng, 600)
    topics = ARTICLE + drawn
    expand = [[n, node, ns] for n in ARTICLE for node, ns in (("my_node", "/"), ("my_node", "/my_ns"))]
    expand += [[n, rng.choice(NODES[:5] + ["r"]), rng.choice(NAMESPACES[:3] + ["/r1"])] for n in drawn]
    expand += [["x", node, ns] for node in NODES for ns in NAMESPACES]
    expand += [[n, "my_node", ns] for n, _, _ in TABLE for ns in ("/", "/my_ns")]
    valid = [n for n in drawn if names.name_problem(n) is None]
    rules = ["odom:=/r1/odom", "relay:odom:=other", "other_node:odom:=nope", "~/x:=y", "/abs:=~/y",
             "rostopic://q:=/p", "odom:=a", "odom:=b", "rosservice://odom:=s", "relay:__node:=relay2",
             "__ns:=/r3", "relay2:odom:=two", "/abs:={node}/y", "a__b:=c", "1a:=b", "a:=~", "*:=b"]
    resolve = [[n, "relay", "/r2", []] for n in ("odom", "/odom", "~/x", "/abs", "q", "{node}")]
    resolve += [[n, "relay", ns, rs] for ns in ("/", "/r2") for n in ("odom", "/odom", "~/x", "/abs", "q")
                for rs in (rules[:1], rules[1:3], rules[3:6], rules[6:9], rules[8:12], rules[2:12], rules[9:11] + rules[:1],
                           rules[12:13], rules[13:14], rules[14:15], rules[15:16], rules[16:])]
    resolve += [[rng.choice(valid), "relay", rng.choice(["/", "/r1"]), [f"{rng.choice(valid)}:={rng.choice(valid)}"]]
                for _ in range(30)]
    return {"topic": topics, "full": topics + [n for n in ARTICLE if n.startswith("/")],
            "namespace": NAMESPACES + topics, "node": NODES + topics, "expand": expand, "resolve": resolve}


@pytest.fixture(scope="module")
def rcl() -> tuple[dict[str, list[Any]], dict[str, list[Any]]]:
    """The cases and rcl's answers, from one run of ROS 2's Python."""
    py = ros2_python()
    cases = _cases()
    got = subprocess.run([str(py), "-c", PROBE], input=json.dumps(cases), capture_output=True, text=True,
                         timeout=120)
    assert got.returncode == 0, got.stderr[-2000:]
    return cases, json.loads(got.stdout.strip().splitlines()[-1])


def _ours(f: Callable[..., Any], *a: Any) -> Any:
    try:
        return f(*a)
    except names.BadName:
        return None


def _resolved(name: str, node: str, ns: str, rules: list[str]) -> str | list[str | None]:
    """Ours as the probe answers: ``refused`` for a rule rcl's argument parser refuses."""
    try:
        remaps = [names.Remap.parse(r) for r in rules]
    except names.BadName:
        return "refused"
    node, ns = names.node_identity(node, ns, remaps)
    return [names.node_fqn(ns, node), _ours(names.resolve, name, node, ns, remaps)]


def test_validators_agree_with_rcl(rcl: tuple[dict[str, list[Any]], dict[str, list[Any]]]) -> None:
    cases, theirs = rcl
    for key, problem in (("topic", names.name_problem), ("full", names.full_name_problem),
                         ("namespace", names.namespace_problem), ("node", names.node_name_problem)):
        wrong = [(n, theirs[key][i]) for i, n in enumerate(cases[key]) if (problem(n) is None) != theirs[key][i]]
        assert not wrong, f"{key}: ours differs from rcl on (name, rcl's valid): {wrong[:10]}"
        # control: both verdicts occur in every family, so agreement is not agreement on one side
        assert set(theirs[key]) == {True, False}


def test_expansion_agrees_with_rcl(rcl: tuple[dict[str, list[Any]], dict[str, list[Any]]]) -> None:
    cases, theirs = rcl
    wrong = [(c, theirs["expand"][i], _ours(names.expand, *c)) for i, c in enumerate(cases["expand"])
             if _ours(names.expand, *c) != theirs["expand"][i]]
    assert not wrong, f"(case, rcl, ours): {wrong[:10]}"
    table = {(n, ns): want for n, root, in_ns in TABLE for ns, want in (("/", root), ("/my_ns", in_ns))}
    assert {(c[0], c[2]): theirs["expand"][i] for i, c in enumerate(cases["expand"]) if c[1] == "my_node"
            and (c[0], c[2]) in table} == table, "rcl answers the design article's table"
    assert sum(x is None for x in theirs["expand"]) > 20 and sum(x is not None for x in theirs["expand"]) > 100


def test_remapped_resolution_agrees_with_rcl(rcl: tuple[dict[str, list[Any]], dict[str, list[Any]]]) -> None:
    cases, theirs = rcl
    ours = [_resolved(*c) for c in cases["resolve"]]
    wrong = [(c, t, o) for c, t, o in zip(cases["resolve"], theirs["resolve"], ours) if t != o]
    assert not wrong, f"(case, rcl, ours): {wrong[:10]}"
    # control: the rules change names (an unremapped resolution would differ), and a node-scoped rule for another node does not
    assert names.resolve("odom", "relay", "/r2", [names.Remap.parse("odom:=/r1/odom")]) == "/r1/odom"
    assert names.resolve("odom", "relay", "/r2", [names.Remap.parse("other:odom:=/r1/odom")]) == "/r2/odom"
