"""A requirement's status: its Z3 verdict rolled up with the evidence it rests on.

=================================  ==========================  ==================================
verdict (``check``)                what the proof rests on      status shown (``verdict`` / ``status``)
=================================  ==========================  ==================================
``proved``, premises consistent    every used guarantee         ``met`` / ``discharged``
                                   discharged, and the side
                                   conditions of its node
``proved``, premises consistent    some evidence not            ``proved, evidence outstanding`` /
                                   discharged, or a declared    the worst of that evidence
                                   progress or initial value    (a declaration no run or test
                                   whose evidence is not        judged: ``pending``)
                                   discharged (temporal)
``proved``, premises inconsistent  (anything)                   ``proved from an inconsistency`` /
                                                                ``failed``
``proved``, premise never holds    (anything)                   ``proved vacuously`` / ``failed``
``proved``, no run exercises it    (temporal: a value it reads  ``proved vacuously`` / ``failed``
                                   is never published, or its
                                   premise holds on no run)
``proved``, consistency undecided  (anything)                   ``inconclusive`` / ``inconclusive``
``proved``, vacuity undecided      (anything)                   ``inconclusive`` / ``inconclusive``
                                   (Z3 could not say whether
                                   the premise can ever hold)
``refuted``                                                     ``refuted`` / ``failed``
``refuted`` by a run that stops    (temporal: a deadlock)       ``refuted`` / ``failed``
``refuted`` by a lasso in which a  (temporal: the missing       ``refuted`` / ``failed``
node never answers                 progress is named)
``inconclusive``                                                ``inconclusive`` / ``inconclusive``
``informal`` (no formal statement) (nothing: traced only)        ``informal`` / ``pending``
``stale`` (made from other inputs)  (not shown)                  ``stale`` / ``stale``
``error`` (record altered)          (not shown)                  ``error`` / ``error``
=================================  ==========================  ==================================

A declaration the proof uses (``progress``, ``initially``, a period in
steps) is evidenced like a guarantee: the ``monitors`` backend
judges it on every recorded run of its node and the ``property_tests``
backend on the node's implementation, each record carrying a row per
declaration (``details.declarations``, backends/monitors/declarations.py);
:func:`declaration_statuses` rolls them up.

Only ``met`` has the status ``discharged`` (the green tick of every report
format).  An informal requirement is ``pending`` whatever its traced
guarantees' evidence says (the note names their worst status, the
traceability table shows each): nothing decided it, so it is neither
verified nor refuted, and its goal in the assurance argument is undeveloped
(GSN: pending), the same status.
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

import msgspec

from rclverify.records.records import worst
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.statuses import REQUIREMENT_VERDICTS
from rclverify.calculus.shapes import DeclarationEvidence

MET = "met"
OUTSTANDING = "proved, evidence outstanding"
INCONSISTENT = "proved from an inconsistency"
VACUOUS = "proved vacuously"
#: Every verdict a requirement row may carry: the vocabulary's set (records/statuses.py).
VERDICTS = REQUIREMENT_VERDICTS


#: a declaration's status given the premise kind (``"progress"``, ``"initial value"``) and index, with words
DeclStatus = Callable[[str, str, int], tuple[str, str]]
#: how bad a declaration's verdict on one record is (a record judges it, whatever the other records say)
_DECL_RANK = ("failed", "error", "stale", "discharged", "inconclusive", "pending")


def _combined(ss: Sequence[str]) -> str:
    """One declaration's status over its records' statuses (:func:`declaration_statuses`)."""
    return min(ss, key=lambda s: _DECL_RANK.index(s) if s in _DECL_RANK else 0)


def _counted(per: Mapping[str, Sequence[str]], labels: Sequence[str]) -> str:
    seen: dict[str, int] = {}
    for label in labels:
        for x in per.get(label, ()):
            seen[x] = seen.get(x, 0) + 1
    runs = sum(seen.values())
    return ", ".join(f"{n} {x}" for x, n in sorted(seen.items())) + f" of {runs} record{'s' if runs != 1 else ''}"


def declaration_statuses(records: Mapping[str, Sequence[tuple[str, Sequence[Mapping[str, Any]]]]],
                         checked: Any = None) -> DeclStatus:
    """The status of a node's declarations from its evidence records.

    ``records[node]`` lists ``(record status, rows)``: each evidence record
    of the node with its ``details.declarations`` rows (``{"declaration",
    "premise", "index", "status", ...}``).  Returns ``d(node, premise kind,
    index) -> (status, words)``.  Per declaration, over the records: a
    record that is ``stale`` or ``error`` gives its rows that status; then
    any ``failed`` row fails it, else ``error``, ``stale``; else one
    ``discharged`` row discharges it (a run that did not exercise a
    declaration, ``pending`` or ``inconclusive``, showed nothing against it;
    a run that did, showed it held); else ``inconclusive``, else
    ``pending``.  With the checked system (``checked``), what follows from
    other declarations rests on them (calculus/requirements/declared_proof.py): the
    premise ``progress`` on the declarations of the least step bound (the
    best of them; a failed declaration of the node fails it), an
    ``initially`` on the other ``initially`` clauses Z3 shows entail it;
    without it, ``progress`` is the worst of its declarations.  No row at
    all: ``("pending", "declared, not verified")``."""
    from rclverify.calculus.requirements.declared_proof import initial_support, node_of, progress_labels  # deferred: start-up (loads lark, z3 and more only when called)

    def status(node: str, kind: str, index: int) -> tuple[str, str]:
        per: dict[str, list[str]] = {}
        for rec_status, rows in records.get(node, ()):
            for r in rows:
                if r.get("premise") == kind:
                    s = rec_status if rec_status in ("stale", "error") else str(r.get("status", "pending"))
                    per.setdefault(str(r.get("declaration")), []).append(s)
        cn = node_of(checked, node)
        if kind == "initial value":
            return _initial(per, index, cn)
        if not per:
            return "pending", "declared, not verified"
        each = {label: _combined(ss) for label, ss in per.items()}
        least = [label for label in (progress_labels(cn) if cn is not None else []) if label in each]
        if "failed" in each.values() or not least:
            st = worst(list(each.values()))
            return st, f"declaration, {st}: {_counted(per, list(per))}"
        st = min((each[label] for label in least), key=_DECL_RANK.index)
        rest = [label for label in each if label not in least]
        return st, (f"declaration, {st}: {_counted(per, least)}"
                    + (f"; {', '.join(rest)} follow{'s' if len(rest) == 1 else ''} from {', '.join(least)}"
                       if rest else ""))

    def _initial(per: Mapping[str, Sequence[str]], index: int, cn: Any) -> tuple[str, str]:
        label = f"initially {index}"
        own = _combined(per[label]) if label in per else None
        if own in ("failed", "error", "stale", "discharged"):
            return str(own), f"declaration, {own}: {_counted(per, [label])}"
        support = initial_support(checked, cn, index) if cn is not None else None
        if support is not None:
            rest = [_combined(per[f"initially {j}"]) if f"initially {j}" in per else "pending" for j in support]
            st = worst(rest, empty="discharged")
            if st == "discharged":
                return st, ("follows from " + ", ".join(f"initially {j}" for j in support) + " (Z3)" if support
                            else "holds of every value of its outputs' types (Z3)")
        if own is None:
            return "pending", "declared, not verified"
        return own, f"declaration, {own}: {_counted(per, [label])}"
    return status


class _Stuck(msgspec.Struct, frozen=True):
    """A producer that keeps a lasso stuck (:class:`rclverify.calculus.shapes.StuckProducer`)."""

    node: str
    output: str = ""
    value: str = ""
    consumer: str = ""


class _Gap(msgspec.Struct, frozen=True):
    """A node whose progress declaration a lasso shows missing (:class:`rclverify.calculus.shapes.MissingProgress`)."""

    node: str


class _Temporal(msgspec.Struct, frozen=True):
    """What the roll-up reads of a temporal check's record (``temporal``, calculus/shapes.py
    ``TemporalVerdictJson`` with its ``Gaps``): the method (``deadlock`` among its parts for a run that
    stops), the bound (steps) and what a lasso shows missing."""

    method: str | None = None
    bound: int | None = None
    missing_progress: list[_Gap] = []
    missing_initially: list[_Stuck] = []


def _premise_statuses(record: RequirementCheckRow, g_status: Callable[[str, int], str], sc_status: Mapping[str, str],
                      d_status: DeclStatus | None) -> dict[str, str]:
    """The evidence status of each premise the proof used, by its words in the note."""
    statuses: dict[str, str] = {}
    for p in record.used:
        node = p.node or ""
        if p.kind == "guarantee":
            statuses[p.label] = g_status(node, p.index)
            statuses[f"side conditions of {node}"] = sc_status.get(node, "discharged")
        elif p.kind in ("progress", "initial value"):  # declared of the implementation: its own evidence
            st, words = d_status(node, p.kind, p.index) if d_status is not None else (
                "pending", "declared, not verified")
            statuses[f"{p.label} ({words})"] = st
    return statuses


def declaration_evidence(record: Mapping[str, Any] | None, d_status: DeclStatus | None) -> list[DeclarationEvidence]:
    """The declarations a requirement's proof used, each with its evidence:
    ``[{"label", "node", "kind", "index", "text", "source", "status",
    "words"}]`` (``d_status`` as for :func:`roll_up`; ``[]`` without a
    record).  The report carries them in the requirement's ``check`` and
    the argument makes a goal of each (report/argument/build.py).  Raises
    :class:`msgspec.ValidationError` for a record of another shape."""
    out: list[DeclarationEvidence] = []
    for p in RequirementCheckRow.of(record or {}).used:
        if p.kind in ("progress", "initial value"):
            node = p.node or ""
            st, words = d_status(node, p.kind, p.index) if d_status is not None else (
                "pending", "declared, not verified")
            out.append({"label": p.label, "node": node, "kind": p.kind, "index": p.index,
                        "text": f"initially( {p.text} )" if p.kind == "initial value" else p.text,
                        "source": p.source, "status": st, "words": words})
    return out


def _vacuous_note(record: RequirementCheckRow) -> str:
    """The note of a requirement proved vacuously: its premise and the premises that exclude it (a state
    requirement, :mod:`.check`), or the reason no run exercises a temporal proof (:mod:`.exercised`)."""
    if record.vacuity_reason:
        return f"proved only because it never applies: {record.vacuity_reason}"
    core = ", ".join(p.label for p in record.vacuity_core)
    why = f"together with the premises of its cone ({core})" if core else "(it contradicts itself)"
    return f"the requirement's premise can never hold {why}: it is proved only because it never applies"


def _temporal_refutation(t: _Temporal) -> str | None:
    """The note of a temporal requirement refuted by a run that stops (a deadlock) or by a lasso that never
    reaches it (a node that never answers in its loop, or producers that never give a value); ``None``
    for another refutation."""
    if "deadlock" in str(t.method).split(" + "):
        return (f"a run of the system stops at step {t.bound}: no next state satisfies the "
                "premises of its cone (a deadlock), and the runs of the system must not stop")
    gaps = t.missing_progress
    if gaps:
        return (f"a run that never reaches it, because {gaps[0].node} never answers in its loop "
                f"although its assumption holds there: no progress declared on "
                + ", ".join(g.node for g in gaps)
                + " excludes it (declare progress( eventually ) or progress( within K steps ) "
                  "on a node that does answer)")
    stuck = t.missing_initially
    if stuck:
        names = ", ".join(dict.fromkeys(r.node for r in stuck))
        first = stuck[0]
        why = (f"{first.consumer} never has a value: {first.node} never publishes {first.node}.{first.output}"
               if first.value.startswith("none") else
               f"{first.consumer} keeps the value {first.node}.{first.output} had before the run")
        return (f"a run that never reaches it, in which no node waiting on {names} ever has a "
                f"question it owes an answer: {why}, and no initial value is declared "
                f"(declare initially( ... ) on {names})")
    return None


def _or(value: str | None, default: str) -> str:
    """``value``, or ``default`` when the record does not have it."""
    return default if value is None else value


def roll_up(record: Mapping[str, Any] | None, g_status: Callable[[str, int], str], sc_status: Mapping[str, str],
            traced_status: str, d_status: DeclStatus | None = None) -> tuple[str, str, str]:
    """``(verdict, status, note)`` of one requirement.

    ``record`` is the requirement's check record (:func:`.check.check_requirement`;
    ``None`` when not checked yet), read decoded
    (:class:`~rclverify.records.requirement_check.RequirementCheckRow`, its temporal part
    :class:`_Temporal`), ``g_status(node, k)`` a guarantee's
    evidence status, ``sc_status[node]`` the worst of a node's side
    conditions, ``traced_status`` the worst status of the traced guarantees
    (the roll-up of an informal requirement), ``d_status`` the status of a
    declaration (:func:`declaration_statuses`; ``None``: none verified).
    Raises :class:`msgspec.ValidationError` for a record of another shape.
    """
    if record is None:
        return "inconclusive", "pending", "not checked yet: run `rclverify requirements` or `doit verify`"
    c = RequirementCheckRow.of(record)
    v = c.verdict
    if v == "error":  # the seal does not hold (requirements/stage.read_records): what it claims is not shown
        return "error", "error", f"error: {_or(c.reason, 'record altered outside rclverify')}; run `doit verify`"
    if v == "stale":
        return "stale", "stale", (f"STALE: {_or(c.reason, 'made from other inputs')} than the current one "
                                  f"(recorded verdict {c.recorded_verdict}); run `doit verify`")
    if v == "informal":
        return "informal", "pending", (f"no formal statement: traced only, never shown as met (its traced guarantees: "
                                       f"{traced_status})")
    bad = [t for t in c.traces if t.status == "failed"]
    if bad:  # a recorded run refutes it: never met, whatever Z3 says (backends/monitors/temporal_evidence.py)
        w = bad[0].verdict
        return "refuted", "failed", (f"the recorded run {bad[0].trace} refutes it: {w.reason if w else ''} "
                                     f"(Z3: {v})")
    lasso = _temporal_refutation(msgspec.convert(c.temporal or {}, _Temporal)) if v == "refuted" else None
    if lasso is not None:
        return "refuted", "failed", lasso
    if v == "refuted":
        who = ", ".join(p.label for p in c.failed_to_prevent) or "no guarantee of the cone"
        return "refuted", "failed", f"Z3 found a counterexample that every premise allows; it is not prevented by: {who}"
    if v != "proved" and c.recorded_verdict == "proved" and c.solvers is not None:
        return "inconclusive", "inconclusive", (f"Z3 proved it, but the second solver does not confirm it "
                                                f"({c.solvers.why}): not proved (docs/second-solver.md)")
    if v != "proved" and c.temporal:  # the detail says what was tried and the next step
        return "inconclusive", "inconclusive", f"not proved: {_or(c.reason, 'undecided')}"
    if v != "proved":
        return "inconclusive", "inconclusive", f"Z3 could not decide it ({_or(c.reason, 'unknown')}); not proved"
    if c.consistency == "inconsistent":
        core = ", ".join(p.label for p in c.inconsistent_core)
        return INCONSISTENT, "failed", (f"the premises the proof used contradict each other ({core}): the "
                                        "requirement follows vacuously, not because the system meets it")
    if c.vacuity == "vacuous":
        return VACUOUS, "failed", _vacuous_note(c)
    statuses = _premise_statuses(c, g_status, sc_status, d_status)
    ev = worst(list(statuses.values()), empty="discharged")
    if c.consistency != "consistent":  # the worst of that and the evidence, as the argument has it
        return "inconclusive", worst(["inconclusive", ev]), (
            "proved, but it is not decided whether the premises it used are consistent "
            f"({_or(c.consistency_reason, 'unknown')})")
    if c.vacuity not in (None, "non-vacuous"):  # undecided: never met (it may hold only vacuously)
        return "inconclusive", worst(["inconclusive", ev]), (
            "proved, but it is not decided whether the requirement's premise can ever hold together with the "
            "premises of its cone: it may be proved only because it never applies (vacuity undecided"
            + (f": {c.vacuity_reason})" if c.vacuity_reason else ")"))
    if ev == "discharged":
        return MET, "discharged", "proved from the used premises, and all the evidence they rest on is discharged"
    open_ = ", ".join(f"{k} ({s})" for k, s in statuses.items() if s != "discharged")
    return OUTSTANDING, ev, f"proved, but the evidence it rests on is not all discharged: {open_}"
