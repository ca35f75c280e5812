"""The report's files in two parts, each written by a doit task of its own.

Every file under ``reports/`` is a rendering of one report dict
(:func:`rclverify.report.build.build_report`).  Rendering them one after
the other was the longest serial stretch of a run: on a 1000-node system,
about 9 s after every backend had finished, with the second core idle
(docs/scale.md, "Where the time goes").  The files fall into two parts of about the
same cost, which ``doit -n 2`` renders at once in two processes (each
builds the report dict from the same artifacts; a serial run builds it
once, :func:`rclverify.app.tasks.act_report`):

``html``  ``assurance.html`` (with the Graphviz layouts of the system and
          the argument), ``assurance.json``, the CI formats
          ``assurance.sarif`` and ``assurance.junit.xml``, ``argument.svg``;
``text``  ``assurance.md`` and the argument's ``argument.json``,
          ``argument.gsn.yaml`` and ``argument.dot``.

Each part keeps its rendered pieces in a fragment cache of its own
(:data:`FRAGMENTS`): two processes never write the same file.  The files
are the same whichever way the parts are run.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from rclverify.report.argument.export import FILES as ARGUMENT_FILES
from rclverify.report.argument.export import argument_layout, write_argument
from rclverify.stages.workspace import REPORT_PARTS
from rclverify.report.ci import CI_FILES, write_ci_reports
from rclverify.report.fragments import FragmentCache
from rclverify.report.render import REPORT_FILES, render_files
from rclverify.records.report_record import AssuranceReport
from rclverify.records.report_schema import Report

#: Each part's files under ``reports/`` (``argument.svg`` only when the argument is laid out).
PARTS = REPORT_PARTS

#: Each part's fragment cache, relative to the workspace root.
FRAGMENTS = {part: f"artifacts/cache/report-fragments.{part}.pickle" for part in PARTS}


def write_part(report: Report | AssuranceReport, out_dir: Path, part: str, fragments: FragmentCache | None = None,
               within: Path | None = None) -> list[Path]:
    """Render and write the files of ``part`` (a key of :data:`PARTS`) for
    ``report`` into ``out_dir``; ``fragments`` keeps rendered pieces
    between runs (the caller saves it); ``within`` (the workspace): every
    file must resolve inside it, and none may be a FIFO, device or socket
    (:func:`rclverify.records.published.write_published`).  Returns the paths written: the
    report files, then the CI files, then the argument files.  Raises
    ``KeyError`` for an unknown part and what
    :func:`~rclverify.report.render.render_files`,
    :func:`~rclverify.report.ci.write_ci_reports` and
    :func:`~rclverify.report.argument.export.write_argument` raise.
    """
    names = PARTS[part]
    argument = None
    if "argument.svg" in names:
        # laid out once, in render_files' thread, and written as argument.svg too
        argument = lru_cache(maxsize=None)(argument_layout(report, fragments))
    paths = render_files(report, out_dir, [n for n in REPORT_FILES if n in names], fragments=fragments,
                         argument=argument, within=within)
    if any(n in names for n in CI_FILES):
        paths += write_ci_reports(report, out_dir, fragments, within)
    files = tuple(n for n in ARGUMENT_FILES if n in names)
    if files:
        paths += write_argument(report, out_dir, fragments, files, argument() if argument is not None else None,
                                within)
    return paths
