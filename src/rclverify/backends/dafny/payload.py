"""The Dafny backend's evidence payload, defined once: :class:`DafnyPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The Dafny backend (:mod:`.backend`,
judged by :mod:`.verdict`) writes, for a run, Dafny's counts (verified,
errors, time-outs, other outcomes, parse and resolution errors), each error
with the RCL clause its stub line holds, the warnings, the exit code, the
prover's first messages, the command-line flavour, a verdict per guarantee,
the refutations sought (:mod:`.refute`), the implementation's refining
modules and unsound constructs, the command run and the log lines filtered
out; a record of a run that did not happen holds the command to run, or the
scan of the implementation only.  Each producer checks its JSON object
through the Struct (:meth:`~rclverify.backends.payload_base.EvidencePayload.checked`)
and writes it unchanged.  A reader decodes the record's ``details`` once, by
its ``backend`` (``backends/payloads.py``
:func:`~rclverify.backends.payloads.payload_of`), and reads attributes mypy
checks.  A key no field declares is refused.
"""
from __future__ import annotations

from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.shapes import DafnyError, DafnyPlace, DafnyRefutation, RefiningModule, UnsoundConstruct
from rclverify.backends.timing_scope import TimingNote


class DafnyPayload(EvidencePayload, frozen=True, tag="dafny"):
    """A Dafny run's evidence payload (module docstring)."""

    verified: int = 0  #: verification conditions Dafny proved
    errors: list[DafnyError] = []  #: each error or time-out, with its RCL clause
    error_count: int = 0
    timeouts: int = 0
    other_outcomes: int = 0
    warnings: list[DafnyPlace] = []
    exit_code: int | None = None  #: ``None``: killed at the process timeout
    parse_errors: int = 0
    resolution_errors: int = 0
    prover_messages: list[str] = []  #: the prover's first five messages
    cli: str = ""  #: ``verify`` or ``legacy``, the command line Dafny was run with
    guarantees: dict[str, str] = {}  #: guarantee number -> its verdict
    refining_modules: list[RefiningModule] = []
    unsound_constructs: list[UnsoundConstruct] = []
    command: str = ""  #: the command run, or to run
    log_filtered: list[str] = []  #: what the log shown leaves out
    refutations: list[DafnyRefutation] = []  #: the refutations sought of unproved guarantee clauses
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["DafnyPayload"]
