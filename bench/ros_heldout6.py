"""Recall, precision, programs and launch rows of ``rclverify ros scan`` on
issue 108's held-out trees (*heldout-e*): three published ROS 2 repositories
counted by hand before their first scan (``bench/data/ros_heldout6_*.json``),
scanned with the launch files a user would give.

A truth file is ``ros_heldout5.py``'s (sites judged by
``ros_heldout4.judge``: found, noted within 3 lines, precision; programs
accounted, said or silent, judged on a scan without launch files) plus:

* ``launch``: the entry launch files (paths in the tree), scanned with their
  defaults; the sites' node names are the names these launch files give;
* ``launch_nodes``: ``[file, line, node]`` for each launch action that starts
  a node when ``ros2 launch`` runs the entry files with their defaults
  (``node`` ``None`` when its name is its code's, in a package outside the
  tree): *yielded* when the graph has node ``node`` declared in that file,
  *said* when a note of the scan sits in that file within 3 lines, *silent*
  otherwise;
* ``launch_not_started``: ``[file, line, why]`` for actions ``ros2 launch``
  does not run with those defaults: a graph node declared at that line is
  counted *wrong*.

Aims (issue 108): recall >= 0.85 on rows never seen, precision >= 0.98, no
silent miss (every missed site noted, every program a node or said, every
launch row yielded or said).  Figures are printed, not asserted.

Usage::

    PYTHONPATH=src python3 bench/ros_heldout6.py --root DIR|--smoke [--verbose]

where ``DIR/NAME`` holds ``git archive COMMIT SCAN... | tar -x`` of the truth
file ``ros_heldout6_NAME.json`` (no upstream code is kept here).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ros_heldout4 import DATA, judge, load_truth, report  # noqa: E402
from ros_heldout5 import programs  # noqa: E402

from rclverify.ros.graph.scan import scan  # noqa: E402


def launch_rows(g: Any, truth: dict[str, Any], verbose: bool = False) -> dict[str, int]:
    """``{rows, yielded, l_said, l_silent, wrong}`` for the truth's launch rows in graph ``g``."""
    c = dict.fromkeys(("rows", "yielded", "l_said", "l_silent", "wrong"), 0)

    def near(src: Any, f: str, line: int) -> bool:
        return src is not None and src.file == f and line - 3 <= src.line <= line + 3

    for f, line, node in truth.get("launch_nodes", []):
        c["rows"] += 1
        if node is not None and any(n.name.split("@")[0] == node and n.declared_at is not None
                                    and n.declared_at.file == f for n in g.nodes.values()):
            c["yielded"] += 1
        elif any(near(nt.src, f, line) for nt in g.notes):
            c["l_said"] += 1
            if verbose:
                print(f"    launch row said: {f}:{line} {node}: "
                      f"{next(nt.message for nt in g.notes if near(nt.src, f, line))[:160]}")
        else:
            c["l_silent"] += 1
            if verbose:
                print(f"    launch row silent: {f}:{line} {node}")
    for f, line, why in truth.get("launch_not_started", []):
        bad = [n.name for n in g.nodes.values() if near(n.declared_at, f, line)]
        c["wrong"] += len(bad)
        if verbose and bad:
            print(f"    started, but ros2 launch does not ({why}): {bad}")
    return c


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, help="directory holding one extracted tree per truth file (required "
                                              "unless --smoke)")
    ap.add_argument("--smoke", action="store_true", help="check the truth files; measure only trees present (CI)")
    ap.add_argument("--verbose", action="store_true", help="list every site missed and every wrong edge")
    a = ap.parse_args()
    if a.root is None and not a.smoke:
        ap.error("the following arguments are required: --root")
    total: dict[str, float] = {}
    for path in sorted(DATA.glob("ros_heldout6_*.json")):
        truth = load_truth(path)
        name = path.stem[len("ros_heldout6_"):]
        print(f"[{truth['split']}] {truth['repository']} @ {truth['commit'][:12]}: {len(truth['sites'])} sites, "
              f"{len(truth.get('programs', {}))} programs, {len(truth.get('launch_nodes', []))} launch rows")
        tree = a.root / name if a.root else None
        if tree is None or not tree.is_dir():
            print(f"  skipped: no extraction of it at {tree or '--root'} (git archive {truth['commit'][:12]} "
                  f"{' '.join(truth['scan'])} | tar -x)")
            continue
        t0 = time.perf_counter()
        g = scan([tree / d for d in truth["scan"]], [tree / lf for lf in truth.get("launch", [])],
                 base=tree).graph
        c = judge(g, tree, truth, time.perf_counter() - t0, a.verbose)
        p = programs(tree, truth, a.verbose)
        lr = launch_rows(g, truth, a.verbose)
        print("  " + report(name, c))
        print(f"  programs: {p['accounted']}/{p['declared']} accounted, {p['said']} said unaccounted, "
              f"{p['silent']} silent; launch rows: {lr['yielded']}/{lr['rows']} yielded, {lr['l_said']} said, "
              f"{lr['l_silent']} silent, {lr['wrong']} started that ros2 launch does not start")
        for k, v in list(c.items()) + list(p.items()) + list(lr.items()):
            total[k] = total.get(k, 0) + v
    if total:
        print(report("total heldout-e", total))
        print(f"programs: {int(total['accounted'])}/{int(total['declared'])} accounted, {int(total['said'])} said, "
              f"{int(total['silent'])} silent; launch rows {int(total['yielded'])}/{int(total['rows'])} yielded, "
              f"{int(total['l_said'])} said, {int(total['l_silent'])} silent, {int(total['wrong'])} not started")


if __name__ == "__main__":
    main()
