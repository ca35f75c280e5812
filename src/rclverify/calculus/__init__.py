"""calculus (its place among the layers: docs/architecture.md): the contracts composed (rules R1-R4, paper section 4)
and judged.

The composition and refinement checks with Z3 (``compose``, ``refinement``,
``context``, ``quotient``, ``deadlines``), contract health (``health/``:
vacuity, realizability, over a bounded output sequence or by a witness,
shape) and formal requirements decided from the
composed contracts (``requirements/``).  Imports ``ros`` and below.
"""
