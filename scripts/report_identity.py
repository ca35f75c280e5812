"""Whether a change to the report's code leaves its five files byte-identical on the bundled examples.

The report's files (``assurance.html``, ``.md``, ``.json``, ``.sarif``,
``.junit.xml``) and the summary ``verify`` prints from (``summary.json``, the
sealed record's content without its seal) are rendered in this process from verified copies of
``examples/warehouse``, ``examples/delivery`` and ``examples/safety_stop``
by the code of the working tree: the report built from the copy's
artifacts (:func:`rclverify.report.build.build_report`) and rendered
without kept pieces.  Each file's sha256 is printed; ``--save`` writes the
digests to a JSON file and ``--compare`` reads such a file and names every
file whose text differs, exiting 1.  The copies are verified once
(``prepare``) and read many times, so that two versions of the report's
code are compared on the same artifacts.

Usage::

    python3 scripts/report_identity.py prepare DIR          # copy and verify the three examples
    python3 scripts/report_identity.py digest DIR --save before.json
    # ... change the report's code ...
    python3 scripts/report_identity.py digest DIR --compare before.json

    # or in one step: the working tree against itself with PATHs as they were at REV
    python3 scripts/report_identity.py against DIR REV PATH...

``against`` takes its baseline from a copy of ``src/`` in which only the
named files are their version at ``REV`` (so that what others changed in
the tree counts on both sides), renders it in a process of its own and
compares the working tree's files with it.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

#: the examples compared
EXAMPLES = ("warehouse", "delivery", "safety_stop")
#: what a run writes in a workspace: left out of a copy
GENERATED = ("artifacts", "reports", ".doit.db", ".doit.sqlite")
#: the report's files, in the order printed
FILES = ("assurance.html", "assurance.md", "assurance.json", "assurance.sarif", "assurance.junit.xml", "summary.json")


def prepare(repo: Path, out: Path) -> int:
    """Copy each example's inputs under ``out`` and verify it (``rclverify verify -w``); returns 0."""
    out.mkdir(parents=True, exist_ok=True)
    for name in EXAMPLES:
        dest = out / name
        if dest.exists():
            shutil.rmtree(dest)
        src = repo / "examples" / name
        shutil.copytree(src, dest, ignore=lambda d, names: {n for n in names if Path(d) == src and n in GENERATED})
        done = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(dest)],
                              capture_output=True, text=True)
        print(f"{name}: verify exited {done.returncode}")
    return 0


def texts(ws_root: Path) -> dict[str, str]:
    """The :data:`FILES` of the verified workspace ``ws_root``, rendered now (no kept pieces)."""
    from rclverify.records.store import dumps
    from rclverify.report.build import build_report
    from rclverify.report.junit import render_junit
    from rclverify.report.render import render_html, render_json, render_markdown
    from rclverify.report.sarif import render_sarif
    from rclverify.report.summary import summary_data
    from rclverify.stages.workspace import Workspace
    report = build_report(Workspace(ws_root))
    return {"assurance.html": render_html(report), "assurance.md": render_markdown(report),
            "assurance.json": render_json(report), "assurance.sarif": render_sarif(report),
            "assurance.junit.xml": render_junit(report), "summary.json": dumps(summary_data(report))}


def digest(out: Path, save: Path | None, compare: Path | None) -> int:
    """Print each example's files' sha256; save or compare them (module docstring). Returns the exit status."""
    now: dict[str, str] = {}
    for name in EXAMPLES:
        for fname, text in texts(out / name).items():
            now[f"{name}/{fname}"] = hashlib.sha256(text.encode("utf-8")).hexdigest()
    for k, v in now.items():
        print(f"{v}  {k}")
    if save is not None:
        save.write_text(json.dumps(now, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    if compare is not None:
        before = json.loads(compare.read_text(encoding="utf-8"))
        differ = sorted(k for k in set(before) | set(now) if before.get(k) != now.get(k))
        print(f"differ: {', '.join(differ)}" if differ else f"byte-identical: all {len(now)} files")
        return 1 if differ else 0
    return 0


def against(repo: Path, out: Path, rev: str, paths: list[str]) -> int:
    """Compare the working tree's files with those rendered by a copy of ``src/`` whose ``paths`` (relative
    to the repository) are their version at ``rev`` (module docstring).  Returns the exit status."""
    with tempfile.TemporaryDirectory(prefix="report-identity-") as tmp:
        base = Path(tmp)
        shutil.copytree(repo / "src", base / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        for rel in paths:
            text = subprocess.run(["git", "show", f"{rev}:{rel}"], cwd=repo, check=True, capture_output=True).stdout
            (base / rel).write_bytes(text)
        saved = base / "before.json"
        env = {**os.environ, "PYTHONPATH": str(base / "src")}
        subprocess.run([sys.executable, __file__, "digest", str(out), "--save", str(saved)], check=True, env=env,
                       stdout=subprocess.DEVNULL)
        return digest(out, None, saved)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("prepare", help="copy and verify the examples under DIR")
    p.add_argument("dir", type=Path)
    d = sub.add_parser("digest", help="the report files' sha256 of the verified copies under DIR")
    d.add_argument("dir", type=Path)
    d.add_argument("--save", type=Path, help="write the digests to this JSON file")
    d.add_argument("--compare", type=Path, help="compare with the digests of this JSON file (exit 1 when any differ)")
    a = sub.add_parser("against", help="compare with the files rendered with PATHs as they were at REV")
    a.add_argument("dir", type=Path)
    a.add_argument("rev")
    a.add_argument("paths", nargs="+", metavar="PATH", help="a file of src/, relative to the repository")
    args = ap.parse_args(argv)
    repo = Path(__file__).resolve().parent.parent
    if args.cmd == "prepare":
        return prepare(repo, args.dir)
    if args.cmd == "against":
        return against(repo, args.dir, args.rev, args.paths)
    return digest(args.dir, args.save, args.compare)


if __name__ == "__main__":
    sys.exit(main())
