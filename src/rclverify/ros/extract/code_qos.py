"""The QoS a publisher or subscription asks for in the code, read where the
code creates it, for ``rclverify ros diff --ros2`` (docs/ros.md, "Expected
against observed").

Only the two policies DDS discovery announces and matching turns on are
read: **reliability** (``reliable``/``best_effort``) and **durability**
(``volatile``/``transient_local``).  History depth is not announced by
discovery (DDS-RTPS 2.5, 9.6.2.2: the publication and subscription data
carry no HISTORY), so it is not read.  What the code does not say literally
is ``None`` (not compared, never guessed).

rclpy (``rclpy/qos.py``): the ``qos_profile`` argument of
``create_publisher(msg_type, topic, qos_profile)`` and
``create_subscription(msg_type, topic, callback, qos_profile)``:

* an integer ``N``: ``QoSProfile(depth=N)``, reliable and volatile;
* ``qos_profile_sensor_data``: best effort, volatile; ``qos_profile_default``,
  ``_services_default``, ``_parameters``, ``_parameter_events``: reliable,
  volatile; ``_action_status_default``, ``_rosout_default``: reliable,
  transient local; ``qos_profile_system_default``: the middleware's (unknown);
* ``QoSProfile(..., reliability=ReliabilityPolicy.X, durability=DurabilityPolicy.Y)``
  (a policy not given: reliable, volatile);
* a variable assigned once in the file to one of those.

rclcpp (``rclcpp/qos.hpp``): the second argument of
``create_publisher<T>(topic, qos)`` and ``create_subscription<T>(topic, qos, cb)``:
an integer (``KeepLast(N)``: reliable, volatile), ``rclcpp::QoS(...)``
(reliable, volatile), ``SensorDataQoS()`` and ``ClockQoS()`` (best effort),
``ServicesQoS()``, ``ParametersQoS()``, ``ParameterEventsQoS()`` (reliable),
``RosoutQoS()`` (reliable, transient local), ``SystemDefaultsQoS()``
(unknown), each changed by chained ``.best_effort()``, ``.reliable()``,
``.transient_local()``, ``.durability_volatile()``; or a variable assigned
once in the file to one of those.
"""
from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

from rclverify.ros.extract.model import Src


@dataclass(frozen=True)
class CodeQos:
    """What the code asks for: ``reliability`` (``reliable``/``best_effort``),
    ``durability`` (``volatile``/``transient_local``), ``None`` where it does not
    say; ``text`` the argument as written."""

    reliability: str | None
    durability: str | None
    text: str

    def describe(self) -> str:
        """``best_effort, volatile`` (the policies known)."""
        return ", ".join(p for p in (self.reliability, self.durability) if p)


#: rclpy's predefined profiles and rclcpp's QoS classes: (reliability, durability)
_PROFILES = {
    "qos_profile_sensor_data": ("best_effort", "volatile"), "qos_profile_default": ("reliable", "volatile"),
    "qos_profile_services_default": ("reliable", "volatile"), "qos_profile_parameters": ("reliable", "volatile"),
    "qos_profile_parameter_events": ("reliable", "volatile"),
    "qos_profile_action_status_default": ("reliable", "transient_local"),
    "qos_profile_rosout_default": ("reliable", "transient_local"), "qos_profile_system_default": (None, None),
    "SensorDataQoS": ("best_effort", "volatile"), "ClockQoS": ("best_effort", "volatile"),
    "ServicesQoS": ("reliable", "volatile"), "ParametersQoS": ("reliable", "volatile"),
    "ParameterEventsQoS": ("reliable", "volatile"), "RosoutQoS": ("reliable", "transient_local"),
    "SystemDefaultsQoS": (None, None), "QoS": ("reliable", "volatile"), "QoSProfile": ("reliable", "volatile"),
}
_POLICY = {"BEST_EFFORT": "best_effort", "RELIABLE": "reliable", "TRANSIENT_LOCAL": "transient_local",
           "VOLATILE": "volatile", "BestEffort": "best_effort", "Reliable": "reliable",
           "TransientLocal": "transient_local", "Volatile": "volatile"}
_CHAIN = {"best_effort": ("reliability", "best_effort"), "reliable": ("reliability", "reliable"),
          "transient_local": ("durability", "transient_local"), "durability_volatile": ("durability", "volatile")}


def read(src: Src, kind: str, base: Path | None = None) -> CodeQos | None:
    """The QoS of the ``kind`` (``pub``/``sub``) endpoint the code creates at
    ``src`` (a path relative to ``base``, default the current directory);
    ``None`` when the file cannot be read or the call is not found there.
    Never raises."""
    path = Path(src.file) if base is None else base / src.file
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    if path.suffix in (".cpp", ".cc", ".cxx", ".hpp", ".h", ".hh"):
        return _cpp(text, src, kind)
    return _py(text, src, kind)


# -- Python ------------------------------------------------------------------------------------

def _py(text: str, src: Src, kind: str) -> CodeQos | None:
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError, RecursionError):
        return None
    call = next((c for c in ast.walk(tree) if isinstance(c, ast.Call) and c.lineno == src.line
                 and c.col_offset + 1 == src.col), None)
    if call is None:
        return None
    arg = next((k.value for k in call.keywords if k.arg == "qos_profile"), None)
    pos = 2 if kind == "pub" else 3
    if arg is None and len(call.args) > pos:
        arg = call.args[pos]
    if arg is None:
        return None
    assigned: dict[str, list[ast.expr]] = {}
    for st in ast.walk(tree):
        if isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name):
            assigned.setdefault(st.targets[0].id, []).append(st.value)
    rel, dur = _py_value(arg, assigned, 0)
    return CodeQos(rel, dur, ast.unparse(arg))


def _last(e: ast.expr) -> str:
    return e.attr if isinstance(e, ast.Attribute) else e.id if isinstance(e, ast.Name) else ""


def _py_value(e: ast.expr, assigned: dict[str, list[ast.expr]], depth: int) -> tuple[str | None, str | None]:
    if isinstance(e, ast.Constant) and isinstance(e.value, int) and not isinstance(e.value, bool):
        return "reliable", "volatile"
    if isinstance(e, ast.Name) and len(assigned.get(e.id, [])) == 1 and depth < 4:
        return _py_value(assigned[e.id][0], assigned, depth + 1)
    if isinstance(e, (ast.Name, ast.Attribute)):
        return _PROFILES.get(_last(e), (None, None))
    if isinstance(e, ast.Call) and _last(e.func) == "QoSProfile":
        out = {"reliability": "reliable", "durability": "volatile"}
        for k in e.keywords:
            if k.arg in out:
                v = _POLICY.get(_last(k.value).replace("RMW_QOS_POLICY_RELIABILITY_", "")
                                .replace("RMW_QOS_POLICY_DURABILITY_", ""))
                out[k.arg] = v  # type: ignore[assignment]  # None: not said literally
        return out["reliability"], out["durability"]
    return None, None


# -- C++ ---------------------------------------------------------------------------------------

def _args(text: str, start: int) -> list[str] | None:
    """The top-level arguments of the call whose ``(`` is at ``start``."""
    out, depth, cur, i = [], 0, [], start
    while i < len(text):
        ch = text[i]
        if ch in "\"'":  # a literal: copied whole
            j = i + 1
            while j < len(text) and text[j] != ch:
                j += 2 if text[j] == "\\" else 1
            cur.append(text[i:j + 1])
            i = j + 1
            continue
        if ch in "([{":
            depth += 1
            if depth == 1:
                i += 1
                continue
        elif ch in ")]}":
            depth -= 1
            if depth == 0:
                out.append("".join(cur).strip())
                return out
        elif ch == "," and depth == 1:
            out.append("".join(cur).strip())
            cur = []
            i += 1
            continue
        cur.append(ch)
        i += 1
    return None


def _cpp(text: str, src: Src, kind: str) -> CodeQos | None:
    lines = text.splitlines(keepends=True)
    if src.line > len(lines):
        return None
    at = sum(len(x) for x in lines[: src.line - 1]) + src.col - 1
    name = "create_publisher" if kind == "pub" else "create_subscription"
    m = re.compile(rf"\b{name}\b\s*(<[^;()]*>)?\s*\(").search(text, at)
    if m is None or text.count("\n", at, m.start()) > 2:
        return None
    args = _args(text, m.end() - 1)
    if not args or len(args) < 2:
        return None
    rel, dur = _cpp_value(args[1], text, 0)
    return CodeQos(rel, dur, " ".join(args[1].split()))


def _cpp_value(arg: str, text: str, depth: int) -> tuple[str | None, str | None]:
    a = "".join(arg.split())
    if re.fullmatch(r"\d+u?", a):
        return "reliable", "volatile"
    if re.fullmatch(r"[A-Za-z_]\w*", a) and depth < 4:  # a variable: its one assignment in the file
        found = re.findall(rf"\b{a}\s*(?:=\s*([^;]+);|([({{][^;]*);)", text)
        if len(found) == 1:
            init = found[0][0] or ("rclcpp::QoS" + found[0][1])
            return _cpp_value(init, text, depth + 1)
        return None, None
    m = re.match(r"(?:[\w:]*::)?(\w+)\s*[({]", a)
    if m is None or m.group(1) not in _PROFILES:
        return None, None
    out = dict(zip(("reliability", "durability"), _PROFILES[m.group(1)]))
    for call in re.findall(r"\.(\w+)\(", a[m.end():]):
        if call in _CHAIN:
            k, v = _CHAIN[call]
            out[k] = v
    for pol in re.findall(r"(?:ReliabilityPolicy|DurabilityPolicy)::(\w+)", a):
        if pol in _POLICY:
            out["reliability" if _POLICY[pol] in ("reliable", "best_effort") else "durability"] = _POLICY[pol]
    return out["reliability"], out["durability"]


__all__ = ["CodeQos", "read"]
