"""The live monitor's side of the DDS bus: readers that follow the
publishers' QoS, and one thread that takes what arrives.

A :class:`Tap` is what the monitor wants to hear: a DDS topic, the struct
of the contract's type, where the contract names it (for warnings).  Its
reader is made when a publisher of the topic is discovered, with the QoS
:func:`~rclverify.ros.live.dds_qos.reader_for` computes from every publisher's
offer (so a best-effort sensor is heard), keeping the last :data:`TAP_DEPTH`
samples, and made again when a publisher appears that the current reader cannot match (counted in
``reader_changes``; messages published while the new reader is being
matched may be missed, which the evidence says).  What cannot be heard is a
located warning, once per publisher and reason, never silence:

* a publisher of another type on the topic (its samples are not the
  contract's type): ``FILE:LINE:COL: warning: /scan: node /lidar publishes
  sensor_msgs::msg::dds_::Imu_, the contract's type is ...; not heard``;
* a publisher of a type with the contract's type name but another layout
  (:mod:`.dds_layout` compares the type objects, or the ROS 2 type
  hashes, never the bare XTypes identifiers): named, with the field that
  differs where its type object says it, never counted as heard, and its
  samples dropped if they reach the reader (Fast DDS's writers are matched
  on the type name: :data:`rclverify.ros.live.dds.COMPATIBILITY`);
* a keyed topic's writer (ROS 2 declares keys in ``.idl`` files only) when the
  contract's type, from a ``.msg``, has none: DDS never matches the two;
* another participant writing a topic only the monitor should write (a
  guarded topic beside the gate, the verdict topic: :meth:`Bus.watch_writers`,
  :mod:`.dds_trust`);
* a publisher whose QoS no one reader matches together with the others
  (exclusive ownership beside shared, partitions): the policy and both
  sides' QoS.

:class:`Bus` runs one thread (``rclverify-dds``): it waits on discovery and
every tap's reader (a Cyclone wait set, which releases the GIL), updates the
taps (discovery at most every ``period_s``, so a busy topic does not make
it read discovery at every sample; after each update it hands
``on_matched`` each tap's matched writers, ``{key: frozenset of writer GUIDs}``,
for the engine's early release), and hands each sample to ``on_sample(tap, raw bytes, sample info,
receipt time)`` (receipt: ``time.time_ns()``, an integer, so a recorded bag
holds the very time the engine used); it never decodes or checks (the
engine thread does, :mod:`.worker`).  With ``linger_s`` (the live run's
lateness bound is set: a message's time is its publisher's source
timestamp, which the wait does not change) the thread, after a round that
took samples, lets the next ones gather in the readers that long before it
waits again, rather than waking for every sample.
"""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field, replace
from typing import Any, Callable

from rclverify.ros.live.dds import take_raw
from rclverify.ros.live.dds_discovery import Discovery
from rclverify.ros.live.dds_qos import QosProfile, from_dds, mismatches, reader_for, to_dds
from rclverify.runtime.dds.layout import OTHER, PENDING, LayoutJudge
from rclverify.runtime.shapes import TapJson

#: Seconds a warning about a publication waits for ros_discovery_info to name its node (a ROS 2 node
#: announces itself after its endpoints are discovered); past it, the participant's id is named.
NAME_GRACE_S = 2.0
#: the history depth of a tap's reader (keep-last; a ROS 2 topic is keyless, one instance, so samples of the
#: topic): at 5000 messages/s over three topics,
#: about 6 s of one topic's messages, should the reading thread be held off the CPU or the interpreter (measured:
#: the default 1000 lost 24 % at 5000 msg/s beside a CPU burner on a loaded machine).  Never keep-all: a monitor
#: that stops reading must not slow a reliable publisher down (rclverify.ros.live.dds_qos)
TAP_DEPTH = 10_000


@dataclass
class Tap:
    """One DDS topic the monitor reads (module docstring).  ``key`` is what
    samples are handed on as; ``where`` locates the contract's mention."""

    key: str
    dds_topic: str
    struct: type
    where: str
    reader: Any = None
    condition: Any = None
    qos: QosProfile | None = None
    reader_changes: int = 0
    samples: int = 0
    heard: set[bytes] = field(default_factory=set)  # writer GUIDs the current reader matches
    warned: set[tuple[bytes, str]] = field(default_factory=set)
    #: per publication handle (sample info): whether its samples are the contract's layout
    admitted: dict[int, bool] = field(default_factory=dict)
    dropped: int = 0  # samples of a publisher of another layout, not handed on

    def to_json(self) -> TapJson:
        return {"topic": self.dds_topic, "samples": self.samples, "reader_changes": self.reader_changes,
                "qos": self.qos.to_json() if self.qos is not None else None, "publishers_heard": len(self.heard),
                "other_layout_samples": self.dropped}


class Bus:
    """Discovery, taps and the thread that reads them (module docstring).
    ``warn(text)`` receives each warning line; ``period_s`` bounds a wait;
    ``on_reader(tap, publishers)`` is told each time a tap's reader is made
    (in the bus thread), with the publishers it was made for; ``type_hash(struct)``
    the ROS 2 type hash of a contract struct (:meth:`.dds_types.TypeBook.type_hash`); ``linger_s`` (s, 0:
    none) how long samples gather after a round that took some (module docstring)."""

    def __init__(self, dp: Any, on_sample: Callable[[Tap, bytes, Any, int], None],
                 warn: Callable[[str], None], period_s: float = 0.05,
                 on_reader: Callable[[Tap, list[Any]], None] | None = None,
                 type_hash: Callable[[type], str | None] | None = None, linger_s: float = 0.0) -> None:
        from cyclonedds.core import WaitSet  # deferred: start-up (loads cyclonedds and more only when called)
        self.dp, self.on_sample, self.warn, self.period_s = dp, on_sample, warn, period_s
        self.linger_s = linger_s
        self.on_reader = on_reader
        self.layouts = LayoutJudge(dp, type_hash or (lambda struct: None))
        self._pending = False  # a publisher's type object not yet resolved: update again next period
        self._final = False  # stopping: no warning waits any more
        self.discovery = Discovery(dp)
        self.taps: list[Tap] = []
        self.waitset = WaitSet(dp)
        self._conds = self.discovery.conditions()  # kept alive with the wait set
        for c in self._conds:
            self.waitset.attach(c)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rclverify-dds", daemon=True)
        self.error: BaseException | None = None
        self._lock = threading.Lock()
        #: first sight (monotonic s) of each publication not yet named by ros_discovery_info: its warning
        #: waits up to NAME_GRACE_S for the node's announcement, which may come after the endpoint's
        self._unnamed: dict[bytes, float] = {}
        #: topics only the monitor should write (dds_topic -> key, where, role) and the others found writing them
        self.watched: dict[str, tuple[str, str, str]] = {}
        self.bypass: dict[str, set[str]] = {}
        #: told, in the bus thread after each update, every tap's matched writers (tap key -> the
        #: 16-byte GUIDs its reader hears), taps without a reader left out (set before :meth:`start`)
        self.on_matched: Callable[[dict[str, frozenset[bytes]]], None] | None = None

    def tap(self, key: str, dds_topic: str, struct: type, where: str) -> Tap:
        """Ask to hear ``dds_topic`` (call before :meth:`start`)."""
        t = Tap(key, dds_topic, struct, where)
        self.taps.append(t)
        return t

    def watch_writers(self, dds_topic: str, key: str, where: str, role: str) -> None:
        """Warn about every other participant's writer on ``dds_topic`` (a topic
        only the monitor should write: a guarded topic, the verdict topic) and
        record it in :attr:`bypass` under ``key`` (:mod:`.dds_trust`)."""
        self.watched[dds_topic] = (key, where, role)
        self.bypass.setdefault(key, set())

    def writer(self, dds_topic: str, struct: type, qos: QosProfile, user_data: bytes = b"") -> Any:
        """A writer of the monitor on ``dds_topic``."""
        from cyclonedds.pub import DataWriter  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.topic import Topic  # deferred: start-up (loads cyclonedds and more only when called)
        return DataWriter(self.dp, Topic(self.dp, dds_topic, struct), qos=to_dds(qos, user_data))

    def start(self) -> Bus:
        self._thread.start()
        return self

    def stop(self, timeout: float = 10.0) -> None:
        """End the thread (after it took what had arrived); re-raise what it died of."""
        self._stop.set()
        self._thread.join(timeout)
        if self.error is not None:
            raise self.error

    # -- the thread --------------------------------------------------------------------------------
    def _run(self) -> None:
        try:
            self._update()
            next_poll = 0.0
            while not self._stop.is_set():
                self.waitset.wait(int(self.period_s * 1e9))
                now = time.monotonic()
                if now >= next_poll:  # discovery at most every period, not at every sample
                    next_poll = now + self.period_s
                    if self.discovery.poll() or self._pending \
                            or any(now - t0 >= NAME_GRACE_S for t0 in self._unnamed.values()):
                        self._update()
                if self._drain() and self.linger_s > 0:
                    time.sleep(self.linger_s)  # let the next samples gather (module docstring)
            self._final = True  # a warning still waiting for its node's name is said now, with the participant's
            self._update()
            self._drain(every=True)
        except BaseException as exc:  # noqa: BLE001 - kept for stop(): a dead reader thread must be said
            self.error = exc

    def _drain(self, every: bool = False) -> int:
        """Take what waits in each triggered tap's reader (each when ``every``) and hand it on; how many."""
        taken = 0
        for t in self.taps:
            if t.reader is None or not (every or t.condition.triggered):
                continue
            while True:
                got = take_raw(t.reader, 256)
                if not got:
                    break
                self._hand_on(t, got)
                taken += len(got)
                if len(got) < 256:
                    break
        return taken

    def _update(self) -> None:
        """Make or remake each tap's reader for the publishers discovered now; warn."""
        from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.sub import DataReader  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.topic import Topic  # deferred: start-up (loads cyclonedds and more only when called)
        disc = self.discovery
        self._pending = False
        for t in self.taps:
            pubs = disc.publishers(t.dds_topic)
            same = self._heard_publishers(t, pubs)
            if not same:
                continue
            req, left = reader_for([p.qos for p in same])
            req = replace(req, depth=max(req.depth or 0, TAP_DEPTH))
            for k in left:
                p = same[k]
                if (p.guid, "qos") in t.warned or not self._named(p.guid):
                    continue
                self._warn_once(t, p.guid, "qos", f"{t.where}: warning: {t.key}: {disc.who(p)} offers "
                                f"{p.qos.describe()}; the monitor's reader ({req.describe()}) cannot match it "
                                f"together with the other publishers: {'; '.join(mismatches(p.qos, req))}; its "
                                f"messages are not heard")
            if t.reader is not None and t.qos is not None and not any(mismatches(p.qos, t.qos) for p in same):
                t.heard = {p.guid for p in same}
                continue  # the reader in place hears every publisher: keep it (no gap)
            if t.reader is not None:
                self._drain_one(t)
                self.waitset.detach(t.condition)
                t.reader.__del__()
                t.reader_changes += 1
            t.reader = DataReader(self.dp, Topic(self.dp, t.dds_topic, t.struct), qos=to_dds(req))
            t.condition = ReadCondition(t.reader, SampleState.Any | ViewState.Any | InstanceState.Any)
            self.waitset.attach(t.condition)
            t.qos = req
            t.heard = {p.guid for k, p in enumerate(same) if k not in left}
            if self.on_reader is not None:
                self.on_reader(t, same)
        if self.on_matched is not None:
            self.on_matched({t.key: frozenset(t.heard) for t in self.taps if t.reader is not None})
        if self.watched:
            self._foreign()

    def _heard_publishers(self, t: Tap, pubs: list[Any]) -> list[Any]:
        """The publishers of ``pubs`` whose samples are the contract's type (name, key, layout); a located
        warning, once, for each of the others."""
        disc = self.discovery
        want = t.struct.__idl_typename__  # type: ignore[attr-defined]
        same = []
        for p in pubs:
            if p.type_name != want:
                if (p.guid, "type") not in t.warned and self._named(p.guid):
                    self._warn_once(t, p.guid, "type", f"{t.where}: warning: {t.key}: {disc.who(p)} publishes "
                                    f"{p.type_name}, the contract's type is {want}; its messages are not heard")
                continue
            if _keyed(p.guid) and _keyless(t.struct):
                if (p.guid, "key") not in t.warned and self._named(p.guid):
                    self._warn_once(t, p.guid, "key", f"{t.where}: warning: {t.key}: {disc.who(p)} publishes "
                                    f"{p.type_name} as a keyed topic (its writer's entity kind), the contract's "
                                    "type has no key (a .msg cannot declare one; ROS 2 declares keys only in "
                                    ".idl files, which the monitor does not read); its messages are not heard")
                continue
            verdict, why = self.layouts.judge(t.struct, p.type_id, p.qos.user_data)
            self._pending = self._pending or verdict == PENDING
            if verdict == OTHER and (p.guid, "layout") not in t.warned and self._named(p.guid):
                self._warn_once(t, p.guid, "layout", f"{t.where}: warning: {t.key}: {disc.who(p)} publishes "
                                f"{p.type_name} with another layout than the contract's type: {why}; its "
                                "messages are not heard")
            if verdict != OTHER:
                same.append(p)
        return same

    def _foreign(self) -> None:
        """The writers discovery reports on the watched topics (never the monitor's own)."""
        for dds_topic, (key, where, role) in self.watched.items():
            for p in self.discovery.publishers(dds_topic):
                who = self.discovery.who(p)
                if who in self.bypass[key] or not self._named(p.guid):
                    continue
                self.bypass[key].add(who)
                self.warn(f"{where}: warning: /{key}: {who} writes on the {role} beside the monitor; what it "
                          "writes is not checked, and the evidence is not discharged while it does")

    def _drain_one(self, t: Tap) -> None:
        self._hand_on(t, take_raw(t.reader, 100000))

    def _hand_on(self, t: Tap, got: list[tuple[bytes, Any]]) -> None:
        """Hand each sample on, but those of a publisher of another layout (counted in ``dropped``)."""
        now = time.time_ns()
        for raw, info in got:
            ok = t.admitted.get(info.publication_handle)
            if ok is None:
                ok = t.admitted[info.publication_handle] = self._admit(t, info.publication_handle)
            if ok:
                t.samples += 1
                self.on_sample(t, raw, info, now)
            else:
                t.dropped += 1

    def _admit(self, t: Tap, handle: int) -> bool:
        """Whether the writer of publication ``handle`` (matched by the tap's reader) has the contract's
        layout; a writer discovery cannot describe any more is taken at its type name."""
        try:
            ep = t.reader.get_matched_publication_data(handle)
        except Exception:  # noqa: BLE001 - gone already: nothing to compare
            ep = None
        if ep is None:
            return True
        verdict, _why = self.layouts.judge(t.struct, getattr(ep, "type_id", None),
                                           from_dds(getattr(ep, "qos", None)).user_data)
        return verdict != OTHER

    def _named(self, guid: bytes) -> bool:
        """May a warning about publication ``guid`` be said now: its node is known, or the grace for
        ros_discovery_info to name it has passed (then it is said with the participant's id)."""
        if self.discovery.node_of(guid) or self._final:
            self._unnamed.pop(guid, None)
            return True
        first = self._unnamed.setdefault(guid, time.monotonic())
        if time.monotonic() - first >= NAME_GRACE_S:
            self._unnamed.pop(guid, None)
            return True
        return False

    def _warn_once(self, t: Tap, guid: bytes, why: str, text: str) -> None:
        if (guid, why) not in t.warned:
            t.warned.add((guid, why))
            self.warn(text)

    def close(self) -> None:
        """Delete the readers and discovery (the participant stays)."""
        for t in self.taps:
            if t.reader is not None:
                t.reader.__del__()
        self.discovery.close()


def _keyless(struct: type) -> bool:
    """Whether a cyclonedds struct has no key member (the binding knows it once the type is populated)."""
    idl = struct.__idl__  # type: ignore[attr-defined]
    idl.populate()
    return bool(idl.keyless)


def _keyed(guid: bytes) -> bool:
    """Whether a writer's GUID names a keyed topic's writer: entity kind 0x02 (user-defined writer with key;
    0x03 is one without, DDS-RTPS 2.5, 9.3.1.2).  A keyless reader never matches it."""
    return len(guid) == 16 and guid[15] == 0x02


__all__ = ["Bus", "Tap"]
