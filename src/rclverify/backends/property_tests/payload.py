"""The property-tests backend's evidence payload, defined once: :class:`PropertyTestsPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The property-tests backend
(:mod:`.backend`) builds a :class:`PropertyTestsPayload` and writes
:meth:`PropertyTestsPayload.details`: the examples counted by outcome, the
seed, the configuration, the command that replays the test, the
environment facts used and not used, the valid examples' coverage, and the
node's declarations judged on the implementation; a run cut short holds
what cut it (``timeout_s``, ``seeding``).  A reader decodes the record's
``details`` once, by its ``backend`` (``backends/payloads.py``
:func:`~rclverify.backends.payloads.payload_of`), and reads attributes mypy
checks.  A field at its default is left out of the JSON (``omit_defaults``);
a key no field declares is refused.
"""
from __future__ import annotations

from rclverify.backends.shapes import DeclarationRow, InputCoverage
from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.timing_scope import TimingNote


class PropertyTestsPayload(EvidencePayload, frozen=True, tag="property_tests"):
    """A property test's evidence payload (module docstring)."""

    examples: dict[str, int] = {}  #: examples by outcome: run, valid, rejected, failures, inconclusive
    seed: int | None = None  #: the seed the examples were drawn with
    max_examples: int | None = None  #: the plan entry's ``max_examples``
    implementation: str = ""  #: the implementation under test, ``file.py:function``
    deadline_ms: int | None = None  #: the plan entry's per-example deadline, milliseconds
    replay: str = ""  #: the command that runs the test again
    facts: list[str] = []  #: the environment facts the examples were drawn under, each with its source
    facts_not_used: list[str] = []  #: the facts left out (they name an output), each with why
    coverage: dict[str, InputCoverage] = {}  #: input -> how much of its range the valid examples covered
    unknown_reasons: list[str] = []  #: why examples were inconclusive
    health_check: str = ""  #: what Hypothesis's health check said
    imports_not_hashed: list[str] = []  #: files the implementation imports that the evidence does not hash
    #: the node's progress and initial values judged on the run (``[]``: it declares some, none judged here)
    declarations: list[DeclarationRow] | None = None
    timeout_s: float | None = None  #: the run's time limit, seconds, when it was cut by it
    seeding: str = ""  #: why Z3's search for the first example under the facts was cut
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["PropertyTestsPayload"]
