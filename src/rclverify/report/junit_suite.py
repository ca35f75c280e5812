"""The end of every ``<testsuite>`` the JUnit report holds (report/junit.py
and the suites of deadlines, near misses and NoDL findings): its counts as
attributes and its time (JUnit XML's ``tests``, ``failures``, ``errors``,
``skipped`` and ``time``)."""
from __future__ import annotations

import xml.etree.ElementTree as ET


def closed(suite: ET.Element, counts: dict[str, int]) -> tuple[ET.Element, dict[str, int], float]:
    """``suite`` with ``counts`` (``tests``, ``failures``, ``errors``,
    ``skipped``) set as its attributes and a time of 0 s (a suite of
    findings took none of its own); returns ``(suite, counts, 0.0)``, the
    shape :func:`rclverify.report.junit.junit_tree` sums."""
    for k, v in counts.items():
        suite.set(k, str(v))
    suite.set("time", "0.000")
    return suite, counts, 0.0


__all__ = ["closed"]
