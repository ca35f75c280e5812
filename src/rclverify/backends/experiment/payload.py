"""The experiment backend's evidence payload, defined once: :class:`ExperimentPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  The experiment backend (:mod:`.backend`)
writes, for a criterion over an experiment's figures, the criterion, the
data file, the figures and constants as written, whether the criterion
holds, the consistency flags, the failing trials, the rows the report shows
(``figures_table``) and the plot's artifact; for a plan entry's target over
the trials (:mod:`.target`) it writes the trials' counts and the decision
(``statistics``, :class:`ExperimentStatistics`; docs/statistics.md).  Each
producer checks its JSON object through the Struct
(:meth:`~rclverify.backends.payload_base.EvidencePayload.checked`) and
writes it unchanged.  A reader decodes the record's ``details`` once, by
its ``backend`` (``backends/payloads.py``
:func:`~rclverify.backends.payloads.payload_of`), and reads attributes mypy
checks.  A key no field declares is refused.
"""
from __future__ import annotations

import msgspec
from msgspec import UNSET, UnsetType

from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.shapes import FigureJson
from rclverify.backends.timing_scope import TimingNote


class ExperimentStatistics(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A target's trials (``details["statistics"]``, :func:`.target.run_target`): the environment, the
    origin (``operation``), the target, the counts (without the digests), the data file's sha256, the
    decision against the target and the first 20 failing trials; a key a record lacks is ``UNSET``
    (left out of the JSON again), the fields in the order the backend writes them."""

    environment: str | UnsetType = UNSET
    origin: str | UnsetType = UNSET
    target: dict[str, object] | UnsetType = UNSET
    counts: dict[str, object] | UnsetType = UNSET
    file_sha256: str | UnsetType = UNSET
    decision: dict[str, object] | UnsetType = UNSET
    failing_trials: list[int] | UnsetType = UNSET


class ExperimentPayload(EvidencePayload, frozen=True, tag="experiment"):
    """An experiment's evidence payload (module docstring)."""

    criterion: str = ""  #: the criterion as written
    file: str = ""  #: the data file, relative to the workspace
    figures: dict[str, FigureJson] = {}  #: statistic name -> as written and in base units
    constants: dict[str, str] = {}  #: constant name -> its quantity as shown
    criterion_holds: bool | None = None  #: ``None``: Z3 could not decide
    flags: list[dict[str, str]] = []  #: the summary statistics' consistency flags (.consistency)
    per_trial: bool = False  #: whether the criterion was judged trial by trial
    failing_trials: list[int] = []  #: the trials (1-based) that miss the criterion
    figures_table: list[list[str]] = []  #: the rows the report shows
    plot: str | None = None  #: the plot's SVG artifact, relative to the workspace
    statistics: ExperimentStatistics | None = None  #: a target over the trials (.target)
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["ExperimentPayload", "ExperimentStatistics"]
