"""The JSON records of live monitoring, as TypedDicts.

What the live run writes into its evidence record and log besides the
monitors' own records (those are :mod:`rclverify.backends.monitors.shapes`):
a silence noted (:class:`SilenceNote`), a node's live counts
(:class:`LiveCounts`), the offline checks' part (:class:`LogChecksPart`),
the service proxy's summary (:class:`DeadlineSummary`), a gate's counts and
the verdict that blocks a message (:class:`GateCounts`,
:class:`BlockVerdict`), and the oracle's reply (:class:`OracleReply`).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict

from rclverify.ros.extract.shapes import QosJson
from rclverify.backends.shapes import DeclarationRow
from rclverify.backends.monitors.shapes import DeadlineResultJson, PeriodResultJson, VerdictJson


class SilenceNote(TypedDict):
    """A topic that fell silent: for how long (s) and the monitors' time then (s)."""
    topic: str
    silent: bool
    for_s: float
    time: float


class LiveCounts(TypedDict):
    """What a live run counted of one node (``runtime/live.py`` ``live_counts``); ``seconds`` observed."""
    recorded: str
    sha256: str
    answers: int
    violations: int
    inconclusive: int
    seconds: float


class TopicDeadlinesEntry(TypedDict):
    """One node's topic deadlines as the offline check reports them."""
    node: str
    status: str
    explanation: str
    deadlines: DeadlineResultJson


class PeriodsEntry(TypedDict):
    """One node's periods as the offline check reports them."""
    node: str
    status: str
    explanation: str
    periods: PeriodResultJson


class DeclarationsEntry(TypedDict):
    """One node's declarations as the offline check reports them."""
    node: str
    status: str
    explanation: str
    declarations: list[DeclarationRow]


class LogChecksPart(TypedDict):
    """The live record's part the log's deadline, period and declaration checks add (``logchecks.py``)."""
    topic_deadlines: list[TopicDeadlinesEntry]
    periods: list[PeriodsEntry]
    declarations: list[DeclarationsEntry]


class DeadlineSummary(TypedDict):
    """The service proxy's last log line: each call deadline's result and the false verdicts counted."""
    kind: str
    results: list[DeadlineResultJson]
    false: int


class GateCounts(TypedDict):
    """A guarded topic's gate: its private topic, messages released and blocked, ``policy``
    ``open`` or ``closed``; ``released_undecided`` only for an open gate."""
    private: str
    released: int
    blocked: int
    policy: str
    released_undecided: NotRequired[int]


class BlockVerdict(TypedDict, total=False):
    """The guarantee that blocks a message (``enforce.judge``); empty when it is released.
    ``values`` the values read, in RCL syntax."""
    node: str
    verdict: str
    guarantee: int
    formula: str
    values: dict[str, str]
    reason: str


class OracleReply(TypedDict):
    """The oracle's reply to one event: ``verdict`` (``currently_true``, ``currently_false``,
    ``false``, ``unknown``), the verdicts decided (``rclverify``) or ``error``."""
    verdict: str
    error: NotRequired[str]
    rclverify: NotRequired[list[VerdictJson]]


class TapJson(TypedDict):
    """One tap of the DDS bus (``dds/bus.py`` ``Tap.to_json``): samples taken, readers remade,
    the reader's QoS, publishers heard and samples of another layout."""
    topic: str
    samples: int
    reader_changes: int
    qos: QosJson | None
    publishers_heard: int
    other_layout_samples: int
    published_before_heard: NotRequired[int]


class BagSummary(TypedDict):
    """What the evidence says of the bag a live run recorded (``dds/bag.py`` ``BagRecorder.close``)."""
    path: str
    messages: int
    topics: list[str]
    call_messages: NotRequired[int]
    call_topics: NotRequired[list[str]]
    failed: NotRequired[int]
    error: NotRequired[str]
    calls_failed: NotRequired[int]


class IdlTypedef(TypedDict):
    """An array typedef of an IDL definition (``dds/bag_types.py``): element type, name, length."""
    elem: str
    name: str
    n: int


class IdlMember(TypedDict):
    """A member of an IDL struct: its IDL type and name."""
    type: str
    name: str


class IdlStruct(TypedDict):
    """One struct of a bag connection's ``ros2idl`` definition, as its template reads it."""
    full: str
    pkg: str
    ns: str
    name: str
    typedefs: list[IdlTypedef]
    members: list[IdlMember]
