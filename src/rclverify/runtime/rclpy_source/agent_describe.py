"""Type descriptions served by the rclpy agent (:mod:`agent`, module
docstring's "Type descriptions"): the definition a publisher declares, for
a publisher whose type hash is not the monitor's.  First rosidl's own
description of the type in this Python (:func:`installed_description`),
when its hash is the one asked; else the publisher's node's type
description service (REP-2011, from Iron on), waited for at most
:data:`DESCRIBE_TIMEOUT_S` (:class:`Describing`, mixed into the agent).
Each request is answered by one ``description`` frame (:mod:`wire`).

Imported by the agent as a top-level module (its folder is the script's):
the standard library only, and :mod:`wire` and :mod:`agent_frames` beside
it (type_description_interfaces and ament_index_python where present).
"""
from __future__ import annotations

import json
import os
import sys
import time
from typing import TYPE_CHECKING, Any

import wire  # type: ignore[import-not-found]  # beside this script (agent.py's docstring)

if TYPE_CHECKING:  # mypy reads the siblings as the package's modules
    from rclverify.runtime.rclpy_source.agent_frames import emit
else:  # run beside the agent script: its folder is on sys.path (agent.py's docstring)
    from agent_frames import emit

#: seconds a publisher's node has to answer a type description request (its service found, then the answer)
DESCRIBE_TIMEOUT_S = 5.0


class Describing:
    """The agent's requests of type descriptions (module docstring)."""

    node: Any  # the agent's rclpy node
    #: type description requests waiting for a node's answer: (type, hash) -> their state (:meth:`describe`)
    asked: dict[tuple[str, str], dict[str, Any]]

    def describe(self, type_name: str, type_hash: str, node: str, ns: str) -> None:
        """Find the description of ``type_name`` whose hash is ``type_hash`` (module docstring): this
        Python's own when its hash is that one (said at once), else ask ``node``'s service (said by
        :meth:`describing` when it answers or :data:`DESCRIBE_TIMEOUT_S` passed)."""
        failures: list[str] = []
        own = installed_description(type_name)
        if own is not None and own[0] == type_hash:
            emit(_description_frame(type_name, type_hash, [{"from": own[2], "description": own[1]}], []))
            return
        if own is not None:
            failures.append(f"{own[2]} has the type hash {own[0]}")
        else:
            failures.append(f"this ROS 2 Python has no rosidl description of {type_name}")
        if not node:
            emit(_description_frame(type_name, type_hash, [], failures + ["the publisher's node is not known"]))
            return
        try:
            self.asked[(type_name, type_hash)] = self.ask_service(type_name, type_hash, node, ns)
        except Exception as exc:  # noqa: BLE001 - a ROS 2 without type_description_interfaces: said
            emit(_description_frame(type_name, type_hash, [], failures + [
                f"the type description service cannot be called ({type(exc).__name__}: {exc})"]))
            return
        self.asked[(type_name, type_hash)]["failures"] = failures

    def ask_service(self, type_name: str, type_hash: str, node: str, ns: str) -> dict[str, Any]:
        """A request of ``type_name``'s description (hash ``type_hash``) to the type description
        service of node ``ns``/``node``: its state, which :meth:`step_request` moves on.  Raises
        ``ImportError`` where this ROS 2 has no ``type_description_interfaces`` (before Iron)."""
        from type_description_interfaces.srv import GetTypeDescription  # type: ignore[import-not-found]  # deferred: Iron and later only
        service = ns.rstrip("/") + "/" + node + "/get_type_description"
        client = self.node.create_client(GetTypeDescription, service)
        request = GetTypeDescription.Request(type_name=type_name, type_hash=type_hash, include_type_sources=False)
        return {"client": client, "request": request, "future": None, "service": service, "failures": [],
                "deadline": time.monotonic() + DESCRIBE_TIMEOUT_S}

    def step_request(self, state: dict[str, Any]) -> dict[str, Any] | None:
        """Move one service request on: send it once the service is found; ``None`` while it
        waits, else ``{"candidates": [...], "failures": [...]}`` (the client then destroyed)."""
        fut = state["future"]
        done: dict[str, Any] | None = None
        origin = f"the type description service {state['service']}"
        if fut is None and state["client"].service_is_ready():
            state["future"] = fut = state["client"].call_async(state["request"])
        if fut is not None and fut.done():
            exc = fut.exception()
            answer = None if exc is not None else fut.result()
            if answer is not None and answer.successful:
                done = {"candidates": [{"from": origin, "description": _description_dict(answer.type_description)}],
                        "failures": []}
            else:
                why = answer.failure_reason if answer is not None else f"{type(exc).__name__}: {exc}"
                done = {"candidates": [], "failures": [f"{origin} answered: {why}"]}
        elif time.monotonic() >= state["deadline"]:
            done = {"candidates": [], "failures": [f"{origin} did not answer within {DESCRIBE_TIMEOUT_S:g} s" + (
                "" if fut is not None else " (not found: a node from before Iron, or one started with "
                "start_type_description_service false)")]}
        if done is not None:
            self.node.destroy_client(state["client"])
        return done

    def describing(self) -> None:
        """Say each service request that is answered or out of time (:meth:`step_request`)."""
        for key, state in list(self.asked.items()):
            done = self.step_request(state)
            if done is not None:
                del self.asked[key]
                emit(_description_frame(key[0], key[1], done["candidates"], state["failures"] + done["failures"]))


def installed_description(type_name: str) -> tuple[str, dict[str, Any], str] | None:
    """``(type hash, type description, where)`` of ``type_name`` (``pkg/msg/T``) as rosidl wrote it
    for this Python (``share/<pkg>/msg/<T>.json``: ``type_description_msg`` and ``type_hashes``), from
    the package's share directory in the ament index, else under ``AMENT_PREFIX_PATH`` and this
    Python's prefix; ``None`` where there is none (or it does not describe ``type_name``)."""
    parts = type_name.strip("/").split("/")
    if len(parts) != 3:
        return None
    pkg, kind, name = parts
    shares = []
    try:
        from ament_index_python.packages import get_package_share_directory  # type: ignore[import-not-found]  # deferred: not in every ROS 2 Python
        shares.append(get_package_share_directory(pkg))
    except Exception:  # noqa: BLE001 - not indexed: the prefixes below
        pass
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p] + [sys.prefix]
    shares += [os.path.join(p, "share", pkg) for p in prefixes]
    for share in shares:
        path = os.path.join(share, kind, name + ".json")
        try:
            with open(path, encoding="utf-8") as fh:
                doc = json.load(fh)
            desc = doc["type_description_msg"]
            if desc["type_description"]["type_name"] != type_name:
                continue
            found = next(h["hash_string"] for h in doc["type_hashes"] if h["type_name"] == type_name)
        except (OSError, ValueError, KeyError, TypeError, StopIteration):
            continue
        return str(found), desc, f"this ROS 2 Python's {pkg} ({path})"
    return None


def _description_dict(td: Any) -> dict[str, Any]:
    """A ``type_description_interfaces/msg/TypeDescription`` as the dict the monitor reads (rosidl's
    ``.json`` form)."""
    def one(d: Any) -> dict[str, Any]:
        return {"type_name": d.type_name, "fields": [
            {"name": f.name, "type": {"type_id": f.type.type_id, "capacity": f.type.capacity,
                                      "string_capacity": f.type.string_capacity,
                                      "nested_type_name": f.type.nested_type_name},
             "default_value": f.default_value} for f in d.fields]}
    return {"type_description": one(td.type_description),
            "referenced_type_descriptions": [one(r) for r in td.referenced_type_descriptions]}


def _description_frame(type_name: str, type_hash: str, candidates: list[dict[str, Any]],
                       failures: list[str]) -> bytes:
    frame: bytes = wire.json_frame({"what": "description", "type": type_name, "hash": type_hash,
                                    "candidates": candidates, "failures": failures})
    return frame
