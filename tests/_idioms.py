"""Shared by the round-three scan tests (tests/test_ros_scan_idioms3-6.py):
the hand-written corpus case, its expected graph, and a node's edges as
``(role, name, type, file:line)`` rows."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

CORPUS = Path(__file__).parent / "data" / "ros_corpus"
ROLES = ("pub", "sub", "service_servers", "service_clients", "action_servers", "action_clients")


def expected(case: str) -> dict[str, Any]:
    """The hand-written expected graph of corpus case ``case`` (``expected/<case>_sources.json``)."""
    return json.loads((CORPUS / "expected" / f"{case}_sources.json").read_text())


def edges(g: Any, node: str) -> set[tuple[str, str, str | None, str]]:
    """The edges the scan found for ``node``."""
    n = g.nodes[node]
    return {(role, e.topic, e.msg_type, f"{e.src.file}:{e.src.line}") for role in ROLES for e in n.edges_of(role)}


def want(exp: dict[str, Any], node: str) -> set[tuple[str, str, str | None, str]]:
    """The edges ``exp`` (an expected graph) lists for ``node``."""
    spec = exp["nodes"][node]
    return {(role, name, typ, at) for role in ROLES for name, typ, at in spec.get(role, [])}


def graph_fixture(case: str) -> Any:
    """A module-scoped pytest fixture ``graph``: the scan of corpus case ``case``."""
    import pytest

    from rclverify.ros.graph.scan import scan

    @pytest.fixture(scope="module")
    def graph() -> Any:
        return scan([CORPUS / case], [], base=CORPUS, standard=False).graph
    return graph
