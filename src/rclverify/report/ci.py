"""Write the report's CI formats: ``assurance.sarif`` and ``assurance.junit.xml``.

Written with the HTML report (:mod:`rclverify.report.parts`, part ``html``)
by ``rclverify report`` and the doit ``report:html`` task.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.records.published import write_published
from rclverify.report.fragments import FragmentCache
from rclverify.report.junit import render_junit
from rclverify.report.sarif import render_sarif
from rclverify.records.report_record import AssuranceReport
from rclverify.records.report_schema import Report

#: File names written under ``reports/``, in the order :func:`write_ci_reports` returns them.
CI_FILES: tuple[str, ...] = ("assurance.sarif", "assurance.junit.xml")


def write_ci_reports(report: Report | AssuranceReport, out_dir: Path, fragments: FragmentCache | None = None,
                     within: Path | None = None) -> list[Path]:
    """Render ``report`` (what ``build_report`` returns, or its JSON object) as SARIF 2.1.0 and JUnit
    XML and write both to ``out_dir``; ``fragments`` keeps the JUnit text of
    each node between runs (:func:`rclverify.report.junit.render_junit`).

    Both texts are rendered before anything is written, so an error leaves the
    previous files untouched; each write is atomic (and skipped when the text
    is unchanged; ``within``, the workspace, bounds where they may lead:
    :func:`rclverify.records.published.write_published`).  Returns the two
    paths (see :data:`CI_FILES`).  Raises ``KeyError`` for a malformed
    report and ``OSError`` when ``out_dir`` cannot be written
    (:class:`~rclverify.core.within.Refused` for a special file or a link
    out of ``within`` at a file's place).
    """
    texts = dict(zip(CI_FILES, (render_sarif(report), render_junit(report, fragments))))
    paths = []
    for name, text in texts.items():
        path = Path(out_dir) / name
        write_published(path, text, within)
        paths.append(path)
    return paths
