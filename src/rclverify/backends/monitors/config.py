"""The monitors plan entry and the workspace's mapping file.

Plan entry (``nodes.<Node>.evidence[k]``)::

    - backend: monitors
      mapping: backends/monitors/mapping.yaml   # topic rules, .msg dirs
      horizon: 2.0                              # seconds (default 5.0)
      tolerance: {abs: 1.0e-6}                  # optional, overrides the mapping's
      traces: [backends/monitors/traces/nominal.jsonl, ...]

Mapping file: ``msg_dirs`` (directories holding ``<pkg>/msg/<Type>.msg``),
``topics`` (:func:`rclverify.traces.mapping.load_rules`), optional
``ros_version`` (``ros1``/``ros2``, default ``ros2``), ``horizon``,
``tolerance`` (``{abs, rel, ulps}``: recorded numbers this close are equal
to the comparisons, :class:`rclverify.semantics.floatsem.Tolerance`), ``skew``
(seconds, default 0.02: how far apart two messages on different topics may be
stamped in the other order than they were published, :mod:`.skew`),
``use_sim_time`` (``true``: every node keeps its time from ``/clock``; a list
of contract node names: those nodes do, the others the wall clock; ``false``:
none does; absent: not said, docs/semantics.md "Deadlines in simulated time") and
``ros_nodes`` (contract node -> ``{name, package, path}`` of the ROS node
to instrument, as ROSMonitoring's configuration lists it)::

    ros_nodes:
      RadiationSensor: {name: radiation_sensor, package: rover, path: launch/rover.launch}
"""
from __future__ import annotations

import math
import posixpath
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from rclverify.semantics.floatsem import Tolerance, ToleranceError, parse_tolerance
from rclverify.traces.mapping import RuleError, TopicRule, load_rules
from rclverify.model.plan.yamlguard import read_yaml_text, safe_load_guarded, yaml_error
from rclverify.backends.monitors.skew import DEFAULT_SKEW_S, parse_skew
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import load_located
from rclverify.model.plan.mapping_file import DEFAULT_MAPPING as DEFAULT_MAPPING  # the one default path, re-exported
from rclverify.model.plan.paths import escape_reason
from rclverify.lang.errors import Diagnostic

DEFAULT_HORIZON = 5.0


class ConfigError(Exception):
    """A bad mapping file or plan entry: ``(message, path)`` where ``path`` is
    the plan key at fault (``()`` for the mapping file itself)."""

    def __init__(self, message: str, *path: Any) -> None:
        super().__init__(message)
        self.path = path

    @property
    def located(self) -> tuple[str, int, int, str] | None:
        """``(file, line, col, message)`` when the error is located in the
        mapping file itself (its text starts ``file:line:col: error: ``),
        else ``None`` (locate it at the plan key :attr:`path`)."""
        m = re.match(r"^(.+?):(\d+):(\d+): error: (.*)$", str(self), re.S)
        return (m[1], int(m[2]), int(m[3]), m[4]) if m else None


@dataclass(frozen=True)
class MonitorConfig:
    """Resolved options: workspace-relative ``mapping`` file, ``rules`` per topic,
    ``msg_dirs`` (relative), ``horizon`` in seconds, ``ros_version``, ``traces``,
    ``tolerance`` of recorded numbers (the plan entry's, else the mapping
    file's; ``None``: none; ``rules.tolerance`` holds it too, so a monitor
    given the rules applies it)."""

    mapping: str
    rules: Mapping[str, TopicRule]
    msg_dirs: tuple[str, ...]
    horizon: float
    ros_version: str
    traces: tuple[str, ...] = ()
    ros_nodes: Mapping[str, Mapping[str, str]] = field(default_factory=dict)
    tolerance: Tolerance | None = None

    def msg_files(self, root: Path) -> list[str]:
        """Workspace-relative ``.msg`` files under the message directories, sorted
        (regular files only: hashing a FIFO would block)."""
        return sorted(p.relative_to(root).as_posix() for d in self.msg_dirs for p in (root / d).rglob("*.msg")
                      if p.is_file())


def is_seconds(value: Any) -> bool:
    """``value`` is a duration in seconds: a finite number >= 0 (not a
    boolean, not NaN, not an infinity: a NaN horizon would leave every
    response obligation open, docs/monitors.md)."""
    return (not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
            and value >= 0)


def load_mapping(root: Path, rel: str | None, horizon: Any = None, traces: Any = (),
                 tolerance: Any = None) -> MonitorConfig:
    """Read the mapping file (``rel`` or the default; absent default -> no rules).
    ``horizon`` and ``tolerance`` (the plan entry's, raw) override the file's.

    Raises :class:`ConfigError` for an unreadable file or malformed options.
    """
    path = root / (rel or DEFAULT_MAPPING)
    raw: Any = {}
    if path.is_file():
        name = rel or DEFAULT_MAPPING
        from rclverify.core.cache.startup import read_kept  # deferred: start-up (loads rclverify.core.cache.store only when called)
        try:  # kept by the command's start-up cache (core/cache/startup.py): a warm start does not parse it
            raw = read_kept(f"mapping {name}", read_yaml_text(path, name), lambda t: safe_load_guarded(t, name)) or {}
        except yaml_error() as exc:
            mark = getattr(exc, "problem_mark", None)
            line = f"{mark.line + 1}:{mark.column + 1}" if mark is not None else "1:1"
            raise ConfigError(f"{rel or DEFAULT_MAPPING}:{line}: error: not valid YAML: {exc}") from None
    elif rel:
        raise ConfigError(f"no such mapping file: {rel}", "mapping")
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:1:1: error: expected a mapping")
    try:
        rules = load_rules(raw.get("topics"))
    except RuleError as exc:
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, exc.path)}: error: {exc}") from None
    h = horizon if horizon is not None else raw.get("horizon", DEFAULT_HORIZON)
    if not is_seconds(h):
        msg = f"horizon must be a finite number of seconds >= 0, not {h!r}"
        if horizon is not None:  # the plan entry's (or --horizon): located by the caller
            raise ConfigError(msg, "horizon")
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, ('horizon',))}: error: {msg}")
    if isinstance(traces, str) or not isinstance(traces, (list, tuple)):
        raise ConfigError("traces must be a list of files", "traces")
    seen: dict[str, int] = {}
    for k, t in enumerate(traces):
        if not (root / str(t)).exists():
            raise ConfigError(f"no such trace: {t}", "traces", k)
        norm = posixpath.normpath(str(t))
        if norm in seen:  # one run, two obligations of one id: refused where it is written
            raise ConfigError(f"trace {t} is listed twice (also as traces[{seen[norm]}])", "traces", k)
        seen[norm] = k
    try:
        tol = parse_tolerance(tolerance)
    except ToleranceError as exc:  # the plan entry's: located by the caller
        raise ConfigError(str(exc), "tolerance", *exc.key) from None
    if tolerance is None:
        try:
            tol = parse_tolerance(raw.get("tolerance"))
        except ToleranceError as exc:
            raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, ('tolerance', *exc.key))}: "
                              f"error: {exc}") from None
    rules.tolerance = tol
    sk = parse_skew(raw.get("skew", DEFAULT_SKEW_S))
    if sk is None:
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, ('skew',))}: error: skew must "
                          f"be a finite number of seconds >= 0, not {raw.get('skew')!r}")
    rules.skew = sk
    sim = raw.get("use_sim_time")
    if not (sim is None or isinstance(sim, bool) or (isinstance(sim, list) and all(isinstance(n, str) for n in sim))):
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, ('use_sim_time',))}: error: "
                          f"use_sim_time must be true, false or a list of contract node names, not {sim!r}")
    rules.sim_time = frozenset(sim) if isinstance(sim, list) else sim
    ros = str(raw.get("ros_version", "ros2"))
    msg_dirs = raw.get("msg_dirs", ()) or ()
    if not isinstance(msg_dirs, (list, tuple)):
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:{_at(path, rel or DEFAULT_MAPPING, ('msg_dirs',))}: error: msg_dirs must be a list of "
                          f"directories, not {msg_dirs!r}")
    if msg_dirs:
        _check_msg_dirs(root, rel or DEFAULT_MAPPING, path, [str(d) for d in msg_dirs])
    ros_nodes = raw.get("ros_nodes") or {}
    if not isinstance(ros_nodes, Mapping) or not all(
            isinstance(v, Mapping) and isinstance(v.get("name"), str) and set(v) <= {"name", "package", "path"}
            for v in ros_nodes.values()):
        raise ConfigError(f"{rel or DEFAULT_MAPPING}:1:1: error: ros_nodes must map each contract node to "
                          "{name, package, path} (name required)")
    return MonitorConfig(rel or DEFAULT_MAPPING if path.is_file() else "", rules,
                         tuple(str(d) for d in raw.get("msg_dirs", ()) or ()), float(h), ros,
                         tuple(str(t) for t in traces),
                         {str(k): {f: str(x) for f, x in v.items()} for k, v in ros_nodes.items()}, tol)


def _at(path: Path, rel: str, keys: tuple[Any, ...]) -> str:
    """``line:col`` of the value at ``keys`` in the mapping file (``1:1``
    when it cannot be found)."""
    try:
        _, locs = load_located(read_yaml_text(path, rel), rel)
    except (PlanError, yaml_error()):
        return "1:1"
    while keys and keys not in locs:
        keys = keys[:-1]
    at = locs.get(keys)
    return f"{at.line}:{at.col}" if at is not None else "1:1"


def _check_msg_dirs(root: Path, rel: str, path: Path, dirs: list[str]) -> None:
    """Refuse message directories outside the workspace (the rules of
    :mod:`rclverify.model.plan.paths`): the ``.msg`` files are inputs of the
    evidence and belong in the assessor's bundle.  Raises ``PlanError``
    located at the directory in the mapping file."""
    bad = [(i, d, why) for i, d in enumerate(dirs) for why in [escape_reason(root, d)] if why is not None]
    if not bad:
        return
    _, locs = load_located(read_yaml_text(path, rel), rel)
    diags: list[Diagnostic] = []
    for i, d, why in bad:
        at = locs.get(("msg_dirs", i))
        line, col = (at.line, at.col) if at is not None else (1, 1)
        diags.extend(plan_error(rel, line, col, f"message directory {d!r} {why}; the mapping may name only "
                                "directories inside the workspace", "E-path").diagnostics)
    raise PlanError(diags)
