"""Recall, precision and the accounting of programs of ``rclverify ros scan`` on
issue 87's held-out trees (*heldout-d*): four published ROS 2 repositories
counted by hand before their first scan (``bench/data/ros_heldout5_*.json``),
none named before in docs/ or bench/.

A truth file is ``ros_heldout4.py``'s (repository, branch, commit, ``scan``,
``split``, ``own``, ``library``, ``sites``) plus ``programs``: each program the
packages declare (an executable, a component class, an entry point) and the
node names it is, counted by hand.  Sites are judged by ``ros_heldout4.measure``
(found, noted within 3 lines, precision); a program is *accounted for* when the
scan's ``programs`` list makes it those nodes, *said* when it is listed as
unaccounted with its located ``ROS-PROGRAM`` note, and *silent* otherwise.
Aims (issue 87): recall >= 0.85, static sites 1.00, precision >= 0.98, no
silent miss (every missed site noted, every program a node or said).  Figures
are printed, not asserted.

Usage::

    PYTHONPATH=src python3 bench/ros_heldout5.py --root DIR|--smoke [--verbose]

where ``DIR/NAME`` holds ``git archive COMMIT SCAN... | tar -x`` of the truth
file ``ros_heldout5_NAME.json`` (no upstream code is kept here).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ros_heldout4 import DATA, load_truth, measure, report  # noqa: E402

from rclverify.ros.graph.scan import scan  # noqa: E402


def programs(root: Path, truth: dict[str, Any], verbose: bool = False) -> dict[str, int]:
    """``{declared, accounted, said, silent}`` for the programs ``truth`` counts:
    accounted when the scan's programs list gives the program the counted nodes."""
    g = scan([root / d for d in truth["scan"]], [], base=root).graph
    c = dict.fromkeys(("declared", "accounted", "said", "silent", "listed"), 0)
    c["listed"] = len(g.unaccounted())
    for name, want in truth.get("programs", {}).items():
        c["declared"] += 1
        got = [p for p in g.programs if p["name"] == name]
        nodes = {n.split("@")[0] for p in got for n in p["nodes"]}
        if got and set(want) <= nodes:
            c["accounted"] += 1
        elif any(p["unaccounted"] for p in got):
            c["said"] += 1
            if verbose:
                print(f"    program said unaccounted: {name}: {[p['unaccounted'] for p in got]}")
        else:
            c["silent"] += 1
            if verbose:
                print(f"    program silent: {name} (scan: {got})")
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
    for path in sorted(DATA.glob("ros_heldout5_*.json")):
        truth = load_truth(path)
        name = path.stem[len("ros_heldout5_"):]
        print(f"[{truth['split']}] {truth['repository']} @ {truth['commit'][:12]}: {len(truth['sites'])} sites, "
              f"{len(truth.get('programs', {}))} programs")
        tree = a.root / name if a.root else None
        if tree is None or not tree.is_dir():
            print(f"  skipped: no extraction of it at {tree or '--root'} (git archive {truth['commit'][:12]} "
                  f"{' '.join(truth['scan'])} | tar -x)")
            continue
        c = measure(tree, truth, a.verbose)
        p = programs(tree, truth, a.verbose)
        print("  " + report(name, c))
        print(f"  programs: {p['accounted']}/{p['declared']} accounted, {p['said']} said unaccounted, "
              f"{p['silent']} silent; {p['listed']} listed unaccounted by the scan")
        for k, v in list(c.items()) + list(p.items()):
            total[k] = total.get(k, 0) + v
    if total:
        print(report("total heldout-d", total))
        print(f"programs: {int(total['accounted'])}/{int(total['declared'])} accounted, {int(total['said'])} said, "
              f"{int(total['silent'])} silent")


if __name__ == "__main__":
    main()
