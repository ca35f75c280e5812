"""GSN elements, the goal structure, and status propagation.

Element types and identifier prefixes are those of the GSN Community
Standard (as gsn2x reads them): goal ``G``, strategy ``S``, solution ``Sn``,
context ``C``, assumption ``A``, justification ``J``.  ``supported_by`` links
a goal or strategy to goals, strategies and solutions; ``in_context_of``
links a goal or strategy to contexts, assumptions and justifications.

Statuses are the evidence statuses (:data:`rclverify.records.records.SEVERITY`).
A solution carries the status of the evidence it stands for; an undeveloped
goal (no evidence at all) counts as ``pending``; every other goal and every
strategy takes the worst status of what supports it
(:func:`rclverify.records.records.worst`, shared design "Evidence": roll-up
takes the worst child).  Contexts, assumptions and justifications have no
status (``None``): they are what the argument rests on, not what it shows.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import msgspec

from rclverify.report.shapes import ArgumentJson, ElementJson

from rclverify.records.records import SEVERITY, worst

#: Element type -> GSN identifier prefix (gsn2x derives the type from it).
PREFIX: Mapping[str, str] = {
    "goal": "G", "strategy": "S", "solution": "Sn", "context": "C", "assumption": "A", "justification": "J",
    # the GSN Community Standard v3's dialectic extension: counter-evidence that challenges a claim
    "counter_solution": "CSn",
}
#: Types that may appear in ``supported_by`` / ``in_context_of``.
SUPPORT_TYPES = ("goal", "strategy", "solution")
CONTEXT_TYPES = ("context", "assumption", "justification")
#: Status of an undeveloped goal (missing evidence counts as pending).
UNDEVELOPED_STATUS = "pending"


class ArgumentError(ValueError):
    """A malformed goal structure: an unknown link target, a link of the
    wrong type, a cycle, or a status that is not an evidence status."""


class ElementRecord(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A GSN element as ``reports/argument.json`` holds it (:meth:`Element.to_json` writes it):
    ``challenges`` and ``defeated`` written only for counter-evidence, ``acp`` (claim point name ->
    references) only with claim points; what a reader decodes it with (:meth:`Element.from_json`)."""

    id: str
    type: str
    text: str
    status: str | None = None
    supported_by: list[str] = []
    in_context_of: list[str] = []
    undeveloped: bool = False
    ref: str = ""
    url: str = ""
    challenges: list[str] = []
    defeated: bool = False
    acp: dict[str, list[str]] = {}


class ArgumentRecord(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """``reports/argument.json``: the top goal's id and every element in order (:meth:`Argument.to_json`)."""

    top: str
    elements: list[ElementRecord]


@dataclass(frozen=True)
class Element:
    """One GSN element.

    ``id`` starts with the prefix of ``type`` (:data:`PREFIX`); ``text`` is
    the claim, strategy, context or evidence description; ``status`` is an
    evidence status for solutions (given) and goals/strategies (computed by
    :func:`propagate`), ``None`` otherwise; ``ref`` is what the element
    stands for in the report (a requirement id, ``Node.g<k>``, an obligation
    id ...); ``url`` a workspace-relative path to the record behind it ('' if
    none).
    """

    id: str
    type: str
    text: str
    status: str | None = None
    supported_by: tuple[str, ...] = ()
    in_context_of: tuple[str, ...] = ()
    undeveloped: bool = False
    ref: str = ""
    url: str = ""
    #: a counter solution's targets (the dialectic extension's ``challenges``)
    challenges: tuple[str, ...] = ()
    #: the claim is defeated by counter-evidence (the dialectic extension's ``defeated``)
    defeated: bool = False
    #: assurance claim points (the confidence extension's ``acp``): ``(name, references)`` each, a
    #: reference being the element itself or one of its ``supported_by`` / ``in_context_of`` targets
    acp: tuple[tuple[str, tuple[str, ...]], ...] = ()

    def to_json(self) -> ElementJson:
        out: ElementJson = {"id": self.id, "type": self.type, "text": self.text, "status": self.status,
                               "supported_by": list(self.supported_by), "in_context_of": list(self.in_context_of),
                               "undeveloped": self.undeveloped, "ref": self.ref, "url": self.url}
        if self.challenges or self.defeated:
            out["challenges"], out["defeated"] = list(self.challenges), self.defeated
        if self.acp:
            out["acp"] = {name: list(refs) for name, refs in self.acp}
        return out

    @staticmethod
    def from_json(d: ElementJson | ElementRecord) -> "Element":
        """The element of its JSON object (decoded as an :class:`ElementRecord`; raises
        :class:`msgspec.ValidationError` for one of another shape)."""
        r = d if isinstance(d, ElementRecord) else msgspec.convert(d, ElementRecord)
        return Element(id=r.id, type=r.type, text=r.text, status=r.status, supported_by=tuple(r.supported_by),
                       in_context_of=tuple(r.in_context_of), undeveloped=r.undeveloped, ref=r.ref, url=r.url,
                       challenges=tuple(r.challenges), defeated=r.defeated,
                       acp=tuple((n, tuple(refs)) for n, refs in r.acp.items()))


@dataclass(frozen=True)
class Argument:
    """A goal structure: ``top`` is the id of the top goal, ``elements`` maps
    ids to elements in a deterministic order (the order they were added)."""

    top: str
    elements: Mapping[str, Element] = field(default_factory=dict)

    def to_json(self) -> ArgumentJson:
        """``{"top": id, "elements": [element JSON, ...]}`` in element order."""
        return {"top": self.top, "elements": [e.to_json() for e in self.elements.values()]}

    @staticmethod
    def from_json(d: ArgumentJson) -> "Argument":
        """The argument of ``reports/argument.json``'s object (decoded as an :class:`ArgumentRecord`;
        raises :class:`msgspec.ValidationError` for one of another shape)."""
        r = msgspec.convert(d, ArgumentRecord)
        return Argument(r.top, {e.id: Element.from_json(e) for e in r.elements})

    def status(self, element_id: str) -> str | None:
        """The status of one element (``KeyError`` for an unknown id)."""
        return self.elements[element_id].status


def validate(arg: Argument) -> None:
    """Check ids, prefixes, link targets and types, and that ``supported_by``
    is acyclic.  Raises :class:`ArgumentError` naming the first problem."""
    els = arg.elements
    if arg.top not in els or els[arg.top].type != "goal":
        raise ArgumentError(f"top goal {arg.top!r} is not a goal of the structure")
    for e in els.values():
        if e.type not in PREFIX:
            raise ArgumentError(f"{e.id}: unknown element type {e.type!r}")
        if not e.id.startswith(PREFIX[e.type]) or (e.type == "strategy" and e.id.startswith("Sn")):
            raise ArgumentError(f"{e.id}: a {e.type} id must start with {PREFIX[e.type]!r}")
        if e.status is not None and e.status not in SEVERITY:
            raise ArgumentError(f"{e.id}: {e.status!r} is not an evidence status")
        if e.type in ("solution", "counter_solution") and e.status is None:
            raise ArgumentError(f"{e.id}: a solution needs the status of its evidence")
        if e.challenges and e.type != "counter_solution":
            raise ArgumentError(f"{e.id}: only a counter solution challenges other elements")
        for x in e.challenges:
            if x not in els or els[x].type not in ("goal", "solution"):
                raise ArgumentError(f"{e.id}: challenges {x!r}, which is not a goal or solution of the structure")
        for name, refs in e.acp:  # gsn2x V09: the element itself or an element directly related to it
            for x in refs:
                if x != e.id and x not in e.supported_by and x not in e.in_context_of:
                    raise ArgumentError(f"{e.id}: assurance claim point {name} references {x!r}, which is neither "
                                        "the element nor one of its supportedBy / inContextOf targets")
        if e.supported_by and e.type not in ("goal", "strategy"):
            raise ArgumentError(f"{e.id}: only goals and strategies are supported by other elements")
        if e.undeveloped and e.supported_by:
            raise ArgumentError(f"{e.id}: an undeveloped goal has no support")
        for t, allowed in ((e.supported_by, SUPPORT_TYPES), (e.in_context_of, CONTEXT_TYPES)):
            for x in t:
                if x not in els:
                    raise ArgumentError(f"{e.id}: links to unknown element {x!r}")
                if els[x].type not in allowed:
                    raise ArgumentError(f"{e.id}: cannot link to {els[x].type} {x}")
    state: dict[str, int] = {}

    def visit(i: str) -> None:
        state[i] = 1
        for x in els[i].supported_by:
            if state.get(x) == 1:
                raise ArgumentError(f"{x}: supports itself (cycle through {i})")
            if x not in state:
                visit(x)
        state[i] = 2
    for i in els:
        if i not in state:
            visit(i)


def propagate(arg: Argument) -> Argument:
    """The same structure with every goal's and strategy's status computed
    bottom-up: undeveloped -> ``pending`` (``unverified`` when the goal is
    marked so: the evidence of a guarantee no obligation covers); otherwise the worst status of its
    ``supported_by`` children (a goal with no children and not marked
    undeveloped is also ``pending``: nothing shows it).  Solutions keep
    their status; contexts and assumptions get ``None``.  A goal marked
    ``defeated`` is never better than the counter solutions that challenge
    it (a culprit guarantee whose own evidence holds reads its problem's
    status).  Raises
    :class:`ArgumentError` via :func:`validate`.
    """
    validate(arg)
    els = arg.elements
    memo: dict[str, str | None] = {}
    defeaters: dict[str, list[str]] = {}
    for e in els.values():
        for t in e.challenges:
            defeaters.setdefault(t, []).append(e.id)

    def status(i: str) -> str | None:
        if i in memo:
            return memo[i]
        e = els[i]
        s: str | None
        if e.type in ("solution", "counter_solution"):
            s = e.status
        elif e.type in CONTEXT_TYPES:
            s = None
        elif e.undeveloped:
            # an undeveloped goal may say why it is worse than pending (a guarantee no obligation covers)
            s = e.status if e.status == "unverified" else UNDEVELOPED_STATUS
        else:
            kids = [status(x) for x in e.supported_by]
            s = worst([k for k in kids if k is not None], empty=UNDEVELOPED_STATUS)
        if e.defeated and s is not None:  # never better than what defeats it (a problem's culprit)
            s = worst([s, *(str(els[c].status) for c in defeaters.get(i, ()) if els[c].status is not None)])
        memo[i] = s
        return s
    out = {}
    for i, e in els.items():
        s = status(i)
        # most elements keep theirs (solutions); the constructor, not dataclasses.replace (4x slower)
        out[i] = e if s == e.status else Element(
            id=e.id, type=e.type, text=e.text, status=s, supported_by=e.supported_by, in_context_of=e.in_context_of,
            undeveloped=e.undeveloped, ref=e.ref, url=e.url, challenges=e.challenges, defeated=e.defeated,
            acp=e.acp)
    return Argument(arg.top, out)
