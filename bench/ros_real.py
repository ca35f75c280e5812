"""How much of published ROS packages ``rclverify ros scan`` reads: recall
and precision of call sites, nodes, topics, services and actions against a
hand-counted ground truth (issue 32).

The checkouts are not part of the project: give their directories on the
command line, each followed by ``--truth`` and its ground-truth JSON
(``bench/data/ros_real_*.json``: facts about the published package, no
code).  A ground-truth file lists the directories scanned (``scan``,
relative to the checkout), entry launch files (``launch``), extra node names
(``nodes``) and every call site of the ROS API read by hand
(``sites``: ``[file, line, node, role, resolved name, type]``; role is
``pub``/``sub``/``service_servers``/``service_clients``/``action_servers``/
``action_clients``; ``name`` is null when the code computes it at run time,
``node`` null when the node's name is computed at run time).

A site with a name is *found* when a graph node that has the site's file
among its sources (and, when the site names its node, has that name) holds an
edge of the site's role with the site's resolved name and type; it is
*located* when such an edge is created at the site's file and line
(``sites_located``: expected = found sites, matched = located ones).  A site
whose name is computed at run time cannot be in the graph; it is *reported*
when the scan gives a located note on its file within 3 lines of it.
Precision: a graph edge coming from a scanned file is right when some site of
that file has its role, name and type.  Nodes, topics (pub/sub names),
services and actions are compared as sets of names (``found`` restricted to
graph nodes with a source in the scanned directories).

Usage::

    PYTHONPATH=src python3 bench/ros_real.py CHECKOUT --truth bench/data/ros_real_X.json [CHECKOUT --truth ...]
    PYTHONPATH=src python3 bench/ros_real.py --smoke    # a two-node package written here, its truth known

``--smoke`` needs no checkout: it writes a catkin package of two rospy
nodes (a publisher with a name computed at run time, a service server and
a subscriber) and measures it against the call sites it was written with.

Figures are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import tempfile
from pathlib import Path

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import SERVICE_ROLES

ROLES = ("pub", "sub") + tuple(SERVICE_ROLES)
GROUP = {"pub": "topics", "sub": "topics", "service_servers": "services", "service_clients": "services",
         "action_servers": "actions", "action_clients": "actions"}


def measure(root: Path, truth: dict) -> dict[str, tuple[int, ...]]:
    """``{what: (expected, found, matched[, right])}`` for one checkout ``root`` against
    ``truth`` (the ground-truth JSON, shape in the module docstring); ``what``
    is ``sites`` (found = graph edges, matched = sites found, right = graph
    edges some site confirms), ``sites_located`` (expected = sites found,
    matched = those whose edge is at the site's line), ``sites_runtime`` (expected = run-time names,
    matched = reported), ``nodes``, ``topics``, ``services``, ``actions``."""
    dirs = [root / d for d in truth["scan"]]
    res = scan(dirs, [root / lf for lf in truth.get("launch", [])], base=root)
    g = res.graph
    prefixes = tuple("" if d in (".", "") else d.rstrip("/") + "/" for d in truth["scan"])
    sites = [tuple(s) for s in truth["sites"]]
    static = [s for s in sites if s[4] is not None]
    runtime = [s for s in sites if s[4] is None]
    nodes = [n for n in g.nodes.values() if any(src.startswith(prefixes) for src in n.sources)]
    edges = [(n, role, e) for n in nodes for role in ROLES for e in n.edges_of(role)]

    def holds(site: tuple) -> bool:
        f, _line, node, role, name, typ = site
        return any(f in n.sources and (node is None or n.name == node) and r == role
                   and e.topic == name and e.msg_type == typ for n, r, e in edges)

    found_sites = sum(holds(s) for s in static)

    def at_line(site: tuple) -> bool:
        f, line, node, role, name, typ = site
        return any(f in n.sources and (node is None or n.name == node) and r == role and e.topic == name
                   and e.msg_type == typ and e.src.file == f and e.src.line == line for n, r, e in edges)

    located = sum(at_line(s) for s in static if holds(s))
    reported = sum(any(nt.src.file == s[0] and s[1] <= nt.src.line <= s[1] + 3 for nt in g.notes)
                   for s in runtime)
    right = sum(any(s[0] == e.src.file and s[2] in (None, n.name) and s[3] == r and s[4] == e.topic and s[5] == e.msg_type for s in static)
                for n, r, e in edges)
    out = {"sites": (len(static), len(edges), found_sites, right), "sites_located": (found_sites, 0, located),
           "sites_runtime": (len(runtime), 0, reported)}
    want_nodes = {s[2] for s in sites if s[2]} | set(truth.get("nodes", []))
    got_nodes = {n.name for n in nodes}
    out["nodes"] = (len(want_nodes), len(got_nodes), len(want_nodes & got_nodes))
    for group in ("topics", "services", "actions"):
        want = {s[4] for s in static if GROUP[s[3]] == group}
        got = {e.topic for _n, r, e in edges if GROUP[r] == group}
        out[group] = (len(want), len(got), len(want & got))
    return out


def _row(label: str, what: str, e: int, f: int, m: int, right: int | None = None) -> str:
    rec = f"{m / e:.3f}" if e else "-"
    prec = f"{(m if right is None else right) / f:.3f}" if f else "-"
    return f"{label:<40} {what:<14} {e:>8} {f:>6} {m:>7} {rec:>7} {prec:>9}"


SMOKE_FILES = {
    "package.xml": '<?xml version="1.0"?>\n<package format="2"><name>smoke_pkg</name><version>0.1.0</version>'
                   '<description>bench smoke</description><maintainer email="dev@example.org">dev</maintainer>'
                   '<license>MIT</license><buildtool_depend>catkin</buildtool_depend><depend>rospy</depend>'
                   '<depend>std_msgs</depend><depend>std_srvs</depend></package>\n',
    "CMakeLists.txt": "cmake_minimum_required(VERSION 3.0.2)\nproject(smoke_pkg)\nfind_package(catkin REQUIRED)\n"
                      "catkin_package()\ncatkin_install_python(PROGRAMS scripts/talker.py scripts/listener.py\n"
                      "  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})\n",
    "scripts/talker.py": "#!/usr/bin/env python3\nimport sys\nimport rospy\nfrom std_msgs.msg import String\n"
                         "from std_srvs.srv import Trigger\n\n"
                         "if __name__ == '__main__':\n"
                         "    rospy.init_node('talker')\n"
                         "    pub = rospy.Publisher('chatter', String, queue_size=1)\n"
                         "    extra = rospy.Publisher(sys.argv[1], String, queue_size=1)\n"
                         "    srv = rospy.Service('reset', Trigger, lambda req: None)\n"
                         "    rospy.spin()\n",
    "scripts/listener.py": "#!/usr/bin/env python3\nimport rospy\nfrom std_msgs.msg import String\n\n"
                           "if __name__ == '__main__':\n"
                           "    rospy.init_node('listener')\n"
                           "    rospy.Subscriber('chatter', String, lambda m: None)\n"
                           "    rospy.spin()\n",
}
#: The call sites the smoke package was written with (the module docstring's shape).
SMOKE_TRUTH = {"repository": "smoke_pkg (written by --smoke)", "scan": ["."], "launch": [], "nodes": [],
               "sites": [["scripts/talker.py", 9, "/talker", "pub", "/chatter", "std_msgs/msg/String"],
                         ["scripts/talker.py", 10, "/talker", "pub", None, "std_msgs/msg/String"],
                         ["scripts/talker.py", 11, "/talker", "service_servers", "/reset", "std_srvs/srv/Trigger"],
                         ["scripts/listener.py", 7, "/listener", "sub", "/chatter", "std_msgs/msg/String"]]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("items", nargs="*", help="CHECKOUT --truth FILE pairs")
    ap.add_argument("--truth", action="append", type=Path, default=[], help="ground-truth JSON (one per checkout)")
    ap.add_argument("--smoke", action="store_true", help="a package written here against its known call sites (CI)")
    a = ap.parse_intermixed_args()
    if not a.smoke and (not a.items or len(a.items) != len(a.truth)):
        ap.error("give one --truth per checkout")
    print(f"{'repository':<40} {'what':<14} {'expected':>8} {'found':>6} {'matched':>7} {'recall':>7} {'precision':>9}")
    if a.smoke:
        with tempfile.TemporaryDirectory(prefix="rclverify-rosreal-") as d:
            root = Path(d) / "smoke_pkg"
            for rel, text in SMOKE_FILES.items():
                (root / rel).parent.mkdir(parents=True, exist_ok=True)
                (root / rel).write_text(text, encoding="utf-8")
            for what, figures in measure(root, SMOKE_TRUTH).items():
                print(_row(str(SMOKE_TRUTH["repository"]), what, *figures))
        return
    for root, tpath in zip(a.items, a.truth):
        truth = json.loads(tpath.read_text())
        for what, figures in measure(Path(root), truth).items():
            print(_row(truth.get("repository", root), what, *figures))


if __name__ == "__main__":
    main()
