"""One contract-health finding: the record both health modules produce.

:mod:`.checks` (consistency and vacuity) and :mod:`.shape` (what a guarantee
constrains) both make :class:`Finding` records; the name lives here, below
both, so neither imports the other's module to get it (docs/decisions.md,
"Layers").  :class:`Finding` is
:class:`rclverify.records.findings.HealthFinding`, the one definition of a
finding's fields: the health stage seals it and the report decodes it
(records/findings.py).  A check returns the text of the query it decided in
``smt2`` (and ``witness_smt2``); the stage keeps each text as a file and
records its path.
"""
from __future__ import annotations

from rclverify.records.findings import HealthFinding as Finding

__all__ = ["Finding"]
