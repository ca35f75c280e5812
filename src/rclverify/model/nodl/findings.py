"""A finding of a NoDL check: one problem, located in every file it involves.

A finding names each place that must change for it to go (the contract's
entry and the document's, the two documents of a topic's writer and
reader), so it is printed once per place (:meth:`Finding.lines`), each
line naming the others.
"""
from __future__ import annotations

from dataclasses import dataclass

from rclverify.lang import ast

#: The finding codes, each with what it means (docs/nodl.md, "Findings").
CODES = {
    "nodl-missing": "the contract declares an endpoint its node's document lacks",
    "nodl-extra": "the document declares an endpoint its node's contract lacks",
    "nodl-type": "the contract and the document give one endpoint different types",
    "nodl-qos": "a topic's or service's writer offers less than its reader requests (request-offered QoS)",
    "nodl-connect-type": "two documents give one topic, service or action different types",
    "nodl-parameter": "a parameter's default, or the contract constant of its name, breaks its declared constraints",
    "nodl-parameter-assume": "a parameter's declared constraints do not ensure what the contract assumes of the "
                             "input it sets",
    "nodl-node": "a document is named after no node of the contracts",
    "nodl-no-publisher": "a subscription no document of the set publishes, not declared external",
    "nodl-no-server": "a service or action client no document of the set serves, not declared external",
    "nodl-code-undeclared": "the code (or the running node: nodl-live-*) has an endpoint the document lacks",
    "nodl-code-absent": "the document declares an endpoint the code (the running node) lacks",
    "nodl-code-type": "the code (the running node) and the document give an endpoint different types",
    "nodl-code-qos": "the code (the running node) gives a topic another reliability or durability than the document",
    "nodl-code-unmatched": "no node of the code (of the running graph: an error there) is the document's: nothing "
                           "of it was compared",
    # an Autoware System Designer design against the contracts (docs/nodl.md, "Autoware System Designer")
    "design-timeout": "the gaps the contracts let a trigger's input leave are longer than the design's timeout",
    "design-error-rate": "the gaps the contracts let a trigger's input leave are longer than 1/error_rate",
    "design-warn-rate": "the gaps the contracts let a trigger's input leave are longer than 1/warn_rate",
    "design-undecided": "nothing bounds a trigger's gaps (an input from outside, an untimed guarantee, a loop)",
    "design-missing": "the design's node, or the input a trigger names, has no contract",
    "design-unwired": "the design wires an input to nothing and the system model feeds it by an equal name",
}


@dataclass(frozen=True)
class Finding:
    """One problem: ``code`` (:data:`CODES`), ``severity`` (``error`` or ``warning``), the
    ``message`` and the places involved, most important first."""

    code: str
    message: str
    locs: tuple[ast.Loc, ...]
    severity: str = "error"

    def lines(self) -> list[str]:
        """``file:line:col: severity: message [code]`` once per place, each naming the others."""
        out = []
        for i, loc in enumerate(self.locs):
            others = [str(o) for j, o in enumerate(self.locs) if j != i]
            also = f" (also at {', '.join(others)})" if others else ""
            out.append(f"{loc}: {self.severity}: {self.message}{also} [{self.code}]")
        return out

    def to_json(self) -> dict[str, object]:
        """The finding as JSON data: code, severity, message and ``places`` (file, line, col)."""
        return {"code": self.code, "severity": self.severity, "message": self.message,
                "places": [{"file": loc.file, "line": loc.line, "col": loc.col} for loc in self.locs]}


__all__ = ["CODES", "Finding"]
