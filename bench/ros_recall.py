"""How much of real ROS code ``rclverify ros scan`` reads: recall and precision
against hand-written ground truth.

The corpus (``tests/data/ros_corpus``) is the project's own small ROS 1
(catkin) and ROS 2 (ament) packages, each written to reproduce one idiom of
published code (a Python 2 rospy script, a C++ class node with private
handles and parameters, rclcpp components with an export macro registered
through a CMake wrapper function and started as launch composable nodes,
rclpy with parameters, every service and action API, ROS 2 pluginlib plugins
whose endpoints are the node whose parameter file loads them: ``idioms8``).  ``expected/*.json``
holds, per entry launch file, the graph written by hand from reading the
code: each node with its publishers, subscribers, service servers/clients and
action servers/clients, resolved names and types, and (``[name, type,
"file:line"]``) the call site that creates each.

Each case is scanned (launch file given, default arguments) and compared:
an item is a node name, or ``(node, role, resolved name, type)``; a found item
matches only when name and type both agree.  Printed per package and in
total, for nodes, topics (pub/sub), services and actions: expected, found,
matched, recall (matched / expected), precision (matched / found), and
*located*: of the expected edges written with their call site, how many the
graph's node holds at that file and line (each call site is one edge).
Aims (issue 42): recall >= 0.98, precision 1.0, every edge located.  A case's
``unresolved`` list (issue 53) names the call sites whose name cannot be read
statically (``"file:line"``: argv, argparse, topics found at run time); the
bench counts how many carry a located note of the scan.  Figures are printed,
not asserted.

Usage::

    PYTHONPATH=src python3 bench/ros_recall.py [--corpus tests/data/ros_corpus] [--verbose]
    PYTHONPATH=src python3 bench/ros_recall.py --smoke      # two cases of the corpus: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
from collections import defaultdict
from pathlib import Path

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import SERVICE_ROLES

GROUPS = {"pub": "topics", "sub": "topics", "service_servers": "services", "service_clients": "services",
          "action_servers": "actions", "action_clients": "actions"}


def items_expected(exp: dict) -> dict[str, set[tuple]]:
    """``{group: {item}}`` of an expected graph (``group``: nodes/topics/services/actions)."""
    out: dict[str, set[tuple]] = defaultdict(set)
    for node, spec in exp["nodes"].items():
        out["nodes"].add((node,))
        for role, group in GROUPS.items():
            for name, typ, *_at in spec.get(role, []):
                out[group].add((node, role, name, typ))
    return out


def sites_expected(exp: dict) -> list[tuple]:
    """``[(node, role, name, type, "file:line")]``: the expected edges written with a call site."""
    return [(node, role, name, typ, at[0]) for node, spec in exp["nodes"].items() for role in GROUPS
            for name, typ, *at in spec.get(role, []) if at]


def located(site: tuple, graph) -> bool:  # type: ignore[no-untyped-def]
    """Whether the graph's node holds the site's edge created at the site's file and line."""
    node, role, name, typ, at = site
    n = graph.nodes.get(node)
    return n is not None and any(e.topic == name and e.msg_type == typ and f"{e.src.file}:{e.src.line}" == at
                                 for e in n.edges_of(role))


def items_found(graph) -> dict[str, set[tuple]]:  # type: ignore[no-untyped-def]
    out: dict[str, set[tuple]] = defaultdict(set)
    for node in graph.nodes.values():
        out["nodes"].add((node.name,))
        for role in ("pub", "sub") + SERVICE_ROLES:
            for e in node.edges_of(role):
                out[GROUPS[role]].add((node.name, role, e.topic, e.msg_type))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, default=Path(__file__).parents[1] / "tests" / "data" / "ros_corpus")
    ap.add_argument("--verbose", action="store_true", help="list every missed and every extra item")
    ap.add_argument("--smoke", action="store_true", help="the first two cases of the corpus only (CI)")
    a = ap.parse_args()
    # per package: group -> [expected, found, matched]
    table: dict[str, dict[str, list[int]]] = defaultdict(lambda: defaultdict(lambda: [0, 0, 0]))
    where = [0, 0]  # expected call sites, located
    noted = [0, 0, 0]  # expected unresolvable call sites, with a located note there, saying the name's origin
    for case in sorted((a.corpus / "expected").glob("*.json"))[:2 if a.smoke else None]:
        exp = json.loads(case.read_text())
        ws = a.corpus / exp["workspace"]
        g = scan([ws], [ws / lf for lf in exp["launch"]], base=a.corpus, standard=False).graph
        want, got = items_expected(exp), items_found(g)
        for site in sites_expected(exp):
            ok = located(site, g)
            where[0] += 1
            where[1] += ok
            if a.verbose and not ok:
                print(f"  {case.stem}: not located {site}")
        at_notes = {f"{n.src.file}:{n.src.line}" for n in g.notes}
        said = {f"{n.src.file}:{n.src.line}" for n in g.notes if "not a string literal" not in n.message}
        for site in exp.get("unresolved", []):
            noted[0] += 1
            noted[1] += site in at_notes
            noted[2] += site in said
            if a.verbose and site not in at_notes:
                print(f"  {case.stem}: no located note at {site}")
        pkg_of = {n: s.get("package", "?") for n, s in exp["nodes"].items()}
        pkg_of.update({n.name: n.package or "?" for n in g.nodes.values() if n.name not in pkg_of})
        for group in ("nodes", "topics", "services", "actions"):
            for item in want[group] | got[group]:
                row = table[pkg_of.get(item[0], "?")][group]
                row[0] += item in want[group]
                row[1] += item in got[group]
                row[2] += item in want[group] and item in got[group]
            if a.verbose:
                for item in sorted(want[group] - got[group], key=str):
                    print(f"  {case.stem}: missed {item}")
                for item in sorted(got[group] - want[group], key=str):
                    print(f"  {case.stem}: extra  {item}")
    total: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0])
    print(f"{'package':<12} {'what':<9} {'expected':>8} {'found':>6} {'matched':>7} {'recall':>7} {'precision':>9}")
    for pkg in sorted(table):
        for group, (e, f, m) in sorted(table[pkg].items()):
            t = total[group]
            t[0], t[1], t[2] = t[0] + e, t[1] + f, t[2] + m
            print(_row(pkg, group, e, f, m))
    for group, (e, f, m) in sorted(total.items()):
        print(_row("TOTAL", group, e, f, m))
    e, f, m = (sum(t[k] for t in total.values()) for k in range(3))
    print(_row("TOTAL", "all", e, f, m))
    print(f"edges located at their call site: {where[1]} of {where[0]}")
    print(f"unresolvable call sites with a located note: {noted[1]} of {noted[0]} "
          f"({noted[2]} saying where the name comes from)")


def _row(pkg: str, group: str, e: int, f: int, m: int) -> str:
    rec = f"{m / e:.3f}" if e else "-"
    prec = f"{m / f:.3f}" if f else "-"
    return f"{pkg:<12} {group:<9} {e:>8} {f:>6} {m:>7} {rec:>7} {prec:>9}"


if __name__ == "__main__":
    main()
