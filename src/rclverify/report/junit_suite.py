"""The end of every ``<testsuite>`` the JUnit report holds (report/junit.py
and the suites of deadlines, near misses and NoDL findings): its counts as
attributes and its time (JUnit XML's ``tests``, ``failures``, ``errors``,
``skipped`` and ``time``)."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Callable


def closed(suite: ET.Element, counts: dict[str, int]) -> tuple[ET.Element, dict[str, int], float]:
    """``suite`` with ``counts`` (``tests``, ``failures``, ``errors``,
    ``skipped``) set as its attributes and a time of 0 s (a suite of
    findings took none of its own); returns ``(suite, counts, 0.0)``, the
    shape :func:`rclverify.report.junit.junit_tree` sums."""
    for k, v in counts.items():
        suite.set(k, str(v))
    suite.set("time", "0.000")
    return suite, counts, 0.0


class FindingSuite:
    """An open ``<testsuite name=NAME>`` of findings and its counts: :meth:`add` records one
    ``<testcase>`` through report/junit.py's ``outcome`` (``kind`` its classname's word) and counts
    it; :meth:`closed` ends it as :func:`closed` does."""

    def __init__(self, name: str, outcome: Callable[..., str], kind: str) -> None:
        self.suite = ET.Element("testsuite", {"name": name})
        self.counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
        self._outcome, self._kind = outcome, kind

    def add(self, case: ET.Element, status: str, summary: str, detail: str) -> None:
        self.counts["tests"] += 1
        bumped = self._outcome(case, status, summary, detail, self._kind)
        if bumped:
            self.counts[bumped] += 1

    def closed(self) -> tuple[ET.Element, dict[str, int], float]:
        return closed(self.suite, self.counts)


__all__ = ["FindingSuite", "closed"]
