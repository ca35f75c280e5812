"""Recall and precision of ``rclverify ros scan`` on published ROS 2 trees held
out from issue 53's development, against call sites counted by hand before
the scan was first run on them (``bench/data/ros_heldout_*.json``).

A ground-truth file names the repository, branch and commit, the directories
scanned (``scan``, relative to the tree's root) and every call site of the
ROS API read by hand (``sites``: ``[file, line, node, role, resolved name,
type, kind]``; role ``pub``/``sub``/``service_servers``/``service_clients``/
``action_servers``/``action_clients``; ``kind`` ``literal`` when the name is
one string literal or named constant reaching the call, ``computed`` when it
is built from literals, ``runtime`` (name null) when only the running
program knows it; ``node`` null when the endpoint's node is not the one the
code names).  No upstream code is kept: the trees are extracted locally
(``git archive COMMIT PATHS | tar -x -C ROOT/NAME`` for the truth file
``ros_heldout_NAME.json``) and given with ``--root ROOT``.

A site is *found* when a graph node with the site's file among its sources
(and, when the site names its node, whose ROS name is that node: the part
before ``@`` of a program kept apart) holds an edge of the site's role,
resolved name and type; *located* when that edge is created at the site's
line.  A site not found is *noted* when the scan gives a located note on its
file within 3 lines of it.  Precision: of the graph's edges created in the
scanned directories, those some site of the same file confirms (role, name,
type).  Printed per tree and in total: all sites, literal/constant sites,
precision, located, not found with/without a note.  Aims (issue 53): recall
>= 0.90 over all sites, >= 0.98 on literals and constants, precision >= 0.98,
every site not found noted.  Figures are printed, not asserted.

Usage::

    PYTHONPATH=src python3 bench/ros_heldout.py --root DIR [--verbose]
    PYTHONPATH=src python3 bench/ros_heldout.py --smoke    # checks the truth files; measures trees found under --root
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
from pathlib import Path

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import SERVICE_ROLES

ROLES = ("pub", "sub") + tuple(SERVICE_ROLES)
KINDS = ("literal", "computed", "runtime")
DATA = Path(__file__).resolve().parent / "data"


def load_truth(path: Path) -> dict:
    """The ground truth at ``path`` (shape in the module docstring), checked:
    raises ``ValueError`` naming the file and row when a row is malformed."""
    truth = json.loads(path.read_text(encoding="utf-8"))
    for key in ("repository", "commit", "scan", "sites"):
        if key not in truth:
            raise ValueError(f"{path.name}: no {key!r}")
    for i, row in enumerate(truth["sites"]):
        if len(row) != 7 or row[3] not in ROLES or row[6] not in KINDS or (row[4] is None) != (row[6] == "runtime"):
            raise ValueError(f"{path.name}: site {i} malformed: {row}")
    return truth


def measure(root: Path, truth: dict, verbose: bool = False) -> dict[str, int]:
    """Counts for one extracted tree ``root`` against ``truth``: ``sites``,
    ``literal`` (sites of kind literal), ``found``, ``found_literal``,
    ``located``, ``edges`` (graph edges of the scanned files), ``right``
    (edges a site confirms), ``missed`` (sites not found), ``noted`` (of
    those, with a located note within 3 lines).  Misses and wrong edges are
    printed with ``verbose``."""
    dirs = [root / d for d in truth["scan"]]
    g = scan(dirs, [], base=root).graph
    prefixes = tuple("" if d in (".", "") else d.rstrip("/") + "/" for d in truth["scan"])
    nodes = [n for n in g.nodes.values() if any(src.startswith(prefixes) for src in n.sources)]
    edges = [(n, role, e) for n in nodes for role in ROLES for e in n.edges_of(role)
             if e.src.file.startswith(prefixes)]

    def hits(site: list) -> list:
        f, _line, node, role, name, typ, _kind = site
        return [e for n, r, e in edges if f in n.sources and (node is None or n.name.split("@")[0] == node)
                and r == role and e.topic == name and e.msg_type == typ]

    c = dict.fromkeys(("sites", "literal", "found", "found_literal", "located", "edges", "right", "missed",
                       "noted"), 0)
    for site in truth["sites"]:
        found = hits(site) if site[4] is not None else []
        c["sites"] += 1
        c["literal"] += site[6] == "literal"
        c["found"] += bool(found)
        c["found_literal"] += bool(found) and site[6] == "literal"
        c["located"] += any(e.src.file == site[0] and e.src.line == site[1] for e in found)
        if not found:
            c["missed"] += 1
            noted = any(nt.src.file == site[0] and site[1] - 3 <= nt.src.line <= site[1] + 3 for nt in g.notes)
            c["noted"] += noted
            if verbose:
                print(f"  missed{'' if noted else ' (no note)'}: {site}")
    for n, r, e in edges:
        ok = any(s[0] == e.src.file and s[3] == r and s[4] == e.topic and s[5] == e.msg_type for s in truth["sites"])
        c["edges"] += 1
        c["right"] += ok
        if verbose and not ok:
            print(f"  wrong edge: {n.name} {r} {e.topic} {e.msg_type} at {e.src.file}:{e.src.line}")
    return c


def _ratio(m: int, e: int) -> str:
    return f"{m}/{e} = {m / e:.3f}" if e else "-"


def report(label: str, c: dict[str, int]) -> str:
    """One line of figures for ``label`` from ``measure``'s counts."""
    return (f"{label:<32} all {_ratio(c['found'], c['sites']):<16} literal {_ratio(c['found_literal'], c['literal']):<16}"
            f" precision {_ratio(c['right'], c['edges']):<16} located {c['located']}/{c['found']}"
            f"  not found {c['missed']}, noted {c['noted']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=Path(os.environ["RCLVERIFY_HELDOUT"]) if os.environ.get(
        "RCLVERIFY_HELDOUT") else None, help="directory holding one extracted tree per truth file (ROOT/NAME)")
    ap.add_argument("--verbose", action="store_true", help="list every site missed and every wrong edge")
    ap.add_argument("--smoke", action="store_true", help="check the truth files; measure only trees present (CI)")
    a = ap.parse_args()
    total: dict[str, int] = {}
    for path in sorted(DATA.glob("ros_heldout_*.json")):
        truth = load_truth(path)
        name = path.stem[len("ros_heldout_"):]
        kinds = {k: sum(s[6] == k for s in truth["sites"]) for k in KINDS}
        print(f"{truth['repository']} @ {truth['commit'][:12]} ({truth.get('branch', '?')}): "
              f"{len(truth['sites'])} sites counted by hand ({', '.join(f'{v} {k}' for k, v in kinds.items())})")
        tree = a.root / name if a.root else None
        if tree is None or not tree.is_dir():
            print(f"  skipped: no extraction of it at {'--root' if a.root is None else tree} "
                  f"(git archive {truth['commit'][:12]} {' '.join(truth['scan'])} | tar -x -C ROOT/{name})")
            continue
        c = measure(tree, truth, a.verbose)
        print("  " + report(name, c))
        for k, v in c.items():
            total[k] = total.get(k, 0) + v
    if total:
        print("  " + report("total", total))


if __name__ == "__main__":
    main()
