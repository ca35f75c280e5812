"""Bounded calls to a ROS 1 master and to a service's TCPROS port.

A master is an external peer: it may never answer, answer slowly, or answer
with anything.  Every call here has a time limit (seconds) that covers the
whole exchange, not only each read, and every answer is checked against the
shape the ROS Master API gives it (wiki.ros.org/ROS/Master_API: each call
returns ``[code, statusMessage, value]``, ``code`` 1 on success) before
anything reads it.  A call that fails, times out or returns a malformed
answer raises :class:`MasterError`, whose text names the call and what
was wrong, and says the limit when it was hit (the caller names the master).

:func:`probe_service_type` reads a service's type with the TCPROS probe
(a connection header with ``probe=1``; ROS wiki "ROS/TCPROS": each header
field is a 4-byte little-endian length then ``key=value``, the header
itself prefixed by its 4-byte length), under one time limit for connect,
write and read together.

:class:`TimeoutTransport` is the ``xmlrpc.client`` transport with a
socket timeout, for clients (rospy's master proxy) that make the calls
themselves.
"""
from __future__ import annotations

import http.client
import socket
import struct
import threading
import time
import xmlrpc.client
from typing import Any, Callable
from urllib.parse import urlsplit
from xml.parsers.expat import ExpatError

#: Seconds one call to the master may take, answer read (``ros diff``, ``ros scan --master``, the live monitor).
MASTER_TIMEOUT_S = 10.0
#: Seconds one TCPROS probe of a service may take (connect, write, read).
PROBE_TIMEOUT_S = 5.0
#: Largest probe answer read (bytes); a service header is a few hundred.
PROBE_MAX_BYTES = 65536


class MasterError(Exception):
    """The master cannot be reached, did not answer in time or answered
    something malformed (reason in ``str``)."""


#: Largest XML-RPC answer read from a master (bytes): a graph of thousands of topics is a few MiB.
MAX_ANSWER_BYTES = 64 * 1024 * 1024


class TimeoutTransport(xmlrpc.client.Transport):
    """An ``xmlrpc.client`` transport whose connections time out after
    ``timeout`` seconds of silence (each connect and read) and that reads
    at most :data:`MAX_ANSWER_BYTES` of an answer."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self.timeout = timeout

    def make_connection(self, host: Any) -> http.client.HTTPConnection:
        conn = super().make_connection(host)
        conn.timeout = self.timeout
        return conn

    def parse_response(self, response: Any) -> Any:
        stream = response
        if response.getheader("Content-Encoding", "") == "gzip":  # the answer as xmlrpc.client reads it
            stream = xmlrpc.client.GzipDecodedResponse(response)
        p, u = self.getparser()
        read = 0
        while True:
            data = stream.read(65536)
            if not data:
                break
            read += len(data)
            if read > MAX_ANSWER_BYTES:
                raise ValueError(f"an answer longer than {MAX_ANSWER_BYTES} bytes")
            p.feed(data)
        if stream is not response:
            stream.close()
        p.close()
        return u.close()


def check_uri(uri: str) -> None:
    """Raise :class:`MasterError` unless ``uri`` is an ``http://host:port`` URI."""
    try:
        parts = urlsplit(uri)
        ok = parts.scheme == "http" and bool(parts.hostname) and parts.port is not None
    except ValueError:
        ok = False
    if not ok:
        raise MasterError(f"{uri!r} is not a master URI (http://HOST:PORT)")


def in_thread(fn: Callable[[], Any], seconds: float, name: str,
              stop: threading.Event | None = None) -> tuple[str, Any]:
    """``fn()`` run in a daemon thread named ``name``, waited for at most
    ``seconds`` (in steps of 50 ms when a ``stop`` event may end the wait
    early): ``("value", v)``, ``("error", exc)``, ``("timeout", None)`` or
    ``("stopped", None)``.  A thread still running is left to end on its own
    (a daemon: it never keeps the process alive).  The one way every call
    to a ROS 1 master is bounded (``within``, the live monitor's
    registration and shutdown)."""
    box: dict[str, object] = {}

    def run() -> None:
        try:
            box["value"] = fn()
        except BaseException as exc:  # noqa: BLE001 - handed to the caller
            box["error"] = exc

    t = threading.Thread(target=run, name=name, daemon=True)
    t.start()
    if stop is None:
        t.join(seconds)
    else:
        deadline = time.monotonic() + seconds
        while t.is_alive() and not stop.is_set() and time.monotonic() <= deadline:
            t.join(0.05)
    if t.is_alive():
        return ("stopped", None) if stop is not None and stop.is_set() else ("timeout", None)
    return ("error", box["error"]) if "error" in box else ("value", box.get("value"))


def within(seconds: float, what: str, fn: Callable[[], Any]) -> Any:
    """``fn()`` run in a daemon thread, waited for at most ``seconds``
    (:func:`in_thread`): its value, or its exception re-raised;
    :class:`MasterError` naming ``what`` and the limit when it has not
    finished in time."""
    state, got = in_thread(fn, seconds, f"rclverify-{what[:40]}")
    if state == "timeout":
        raise MasterError(f"{what}: no answer within the time limit of {seconds:g} s")
    if state == "error":
        raise got
    return got


def call(uri: str, method: str, *args: Any, timeout: float = MASTER_TIMEOUT_S) -> Any:
    """``method(*args)`` on the master at ``uri``; the ``value`` of its
    ``[code, statusMessage, value]`` answer.  Raises :class:`MasterError`
    when the master cannot be reached, takes longer than ``timeout``
    seconds, answers with a fault, a code other than 1, or an answer of
    another shape."""
    check_uri(uri)
    proxy = xmlrpc.client.ServerProxy(uri, transport=TimeoutTransport(timeout), allow_none=False)
    what = method

    def run() -> Any:
        try:
            return getattr(proxy, method)(*args)
        except (socket.timeout, TimeoutError):
            raise MasterError(f"{what}: no answer within the time limit of {timeout:g} s") from None
        except xmlrpc.client.Fault as exc:
            raise MasterError(f"{what}: fault {exc.faultCode}: {' '.join(str(exc.faultString).split())[:200]}") from None
        except (xmlrpc.client.ProtocolError, http.client.HTTPException, ExpatError, xmlrpc.client.ResponseError,
                ValueError, TypeError, OverflowError) as exc:
            raise MasterError(f"{what}: not an XML-RPC answer: {' '.join(str(exc).split())[:200]}") from None
        except OSError as exc:
            raise MasterError(f"{what}: cannot reach it: {exc.strerror or exc}") from None
        finally:
            proxy("close")()

    answer = within(timeout + 1.0, what, run)
    if not (isinstance(answer, (list, tuple)) and len(answer) == 3 and isinstance(answer[0], int)
            and not isinstance(answer[0], bool)):
        raise MasterError(f"{what}: malformed answer {_short(answer)} (expected [code, statusMessage, value])")
    code, message, value = answer
    if code != 1:
        raise MasterError(f"{what}: the master refused (code {code}): {_short(message)}")
    return value


def _short(x: Any) -> str:
    text = repr(x)
    return text if len(text) <= 120 else text[:117] + "..."


def system_state(uri: str, timeout: float = MASTER_TIMEOUT_S) -> tuple[list[tuple[str, list[str]]], ...]:
    """``getSystemState``: ``(publishers, subscribers, services)``, each a
    list of ``(name, [node, ...])``.  Raises :class:`MasterError` (above),
    naming the entry at fault in a malformed answer."""
    value = call(uri, "getSystemState", "/rclverify", timeout=timeout)
    what = "getSystemState"
    if not (isinstance(value, (list, tuple)) and len(value) == 3):
        raise MasterError(f"{what}: malformed answer {_short(value)} (expected [publishers, subscribers, services])")
    out = []
    for label, table in zip(("publishers", "subscribers", "services"), value):
        if not isinstance(table, (list, tuple)):
            raise MasterError(f"{what}: {label} is {_short(table)}, not a list")
        rows = []
        for k, row in enumerate(table):
            if not (isinstance(row, (list, tuple)) and len(row) == 2 and isinstance(row[0], str)
                    and isinstance(row[1], (list, tuple)) and all(isinstance(n, str) for n in row[1])):
                raise MasterError(f"{what}: {label} entry {k} is {_short(row)}, not [name, [node, ...]]")
            rows.append((row[0], list(row[1])))
        out.append(rows)
    return tuple(out)


def topic_types(uri: str, timeout: float = MASTER_TIMEOUT_S) -> dict[str, str]:
    """``getTopicTypes``: topic -> type.  Raises :class:`MasterError`."""
    value = call(uri, "getTopicTypes", "/rclverify", timeout=timeout)
    what = "getTopicTypes"
    if not isinstance(value, (list, tuple)):
        raise MasterError(f"{what}: malformed answer {_short(value)} (expected [[topic, type], ...])")
    out: dict[str, str] = {}
    for k, row in enumerate(value):
        if not (isinstance(row, (list, tuple)) and len(row) == 2 and all(isinstance(x, str) for x in row)):
            raise MasterError(f"{what}: entry {k} is {_short(row)}, not [topic, type]")
        out[row[0]] = row[1]
    return out


def lookup_service(uri: str, service: str, timeout: float = MASTER_TIMEOUT_S) -> str:
    """``lookupService``: the service's ``rosrpc://host:port`` URI.  Raises :class:`MasterError`."""
    value = call(uri, "lookupService", "/rclverify", service, timeout=timeout)
    if not isinstance(value, str):
        raise MasterError(f"lookupService {service}: malformed answer {_short(value)}")
    return value


def probe_service_type(service: str, service_uri: str, timeout: float = PROBE_TIMEOUT_S) -> str:
    """The type (``pkg/Type``) a service declares in its TCPROS header,
    asked with a probe; the whole exchange within ``timeout`` seconds.
    Raises :class:`MasterError` (not answered, refused, malformed)."""
    parts = urlsplit(service_uri)
    if parts.scheme != "rosrpc" or not parts.hostname or parts.port is None:
        raise MasterError(f"service {service}: {service_uri!r} is not a rosrpc://HOST:PORT URI")
    fields = {"probe": "1", "md5sum": "*", "callerid": "/rclverify", "service": service}
    body = b"".join(struct.pack("<I", len(b)) + b for b in (f"{k}={v}".encode() for k, v in fields.items()))
    deadline = time.monotonic() + timeout

    def left() -> float:
        rest = deadline - time.monotonic()
        if rest <= 0:
            raise MasterError(f"service {service}: no probe answer within the time limit of {timeout:g} s")
        return rest

    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=left()) as s:
            s.settimeout(left())
            s.sendall(struct.pack("<I", len(body)) + body)

            def read(n: int) -> bytes:
                buf = b""
                while len(buf) < n:
                    s.settimeout(left())
                    chunk = s.recv(n - len(buf))
                    if not chunk:
                        raise MasterError(f"service {service}: the connection closed before the header was read")
                    buf += chunk
                return buf

            (size,) = struct.unpack("<I", read(4))
            if size > PROBE_MAX_BYTES:
                raise MasterError(f"service {service}: a probe header of {size} bytes (limit {PROBE_MAX_BYTES})")
            raw = read(size)
    except (socket.timeout, TimeoutError):
        raise MasterError(f"service {service}: no probe answer within the time limit of {timeout:g} s") from None
    except OSError as exc:
        raise MasterError(f"service {service}: the probe failed: {exc.strerror or exc}") from None
    header: dict[str, str] = {}
    pos = 0
    while pos + 4 <= len(raw):
        (n,) = struct.unpack("<I", raw[pos:pos + 4])
        field = raw[pos + 4:pos + 4 + n].decode("utf-8", "replace")
        pos += 4 + n
        key, eq, val = field.partition("=")
        if eq:
            header[key] = val
    if header.get("error"):
        raise MasterError(f"service {service}: the probe was refused: {_short(header['error'])}")
    if not header.get("type"):
        raise MasterError(f"service {service}: the probe's header has no type")
    return header["type"]


__all__ = ["MASTER_TIMEOUT_S", "PROBE_TIMEOUT_S", "MasterError", "TimeoutTransport", "call", "check_uri",
           "lookup_service", "probe_service_type", "system_state", "topic_types", "within"]
