"""A cone summary (:mod:`.summary`) made and kept: what it is made from, as
text and numbers (:class:`MadeFrom`), made in a Z3 context of its own
(quantifier elimination, then Z3's proof that the result is implied), and
kept as a file keyed by that text (:func:`use_directory`), which the other
doit worker and later runs read instead of making it again.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence, overload

import z3

from rclverify.core.cache import Blobs, fingerprint
from rclverify.calculus.summary_qe import eliminate, implied

#: A summary whose SMT-LIB text is longer is not kept (the full cone is read instead).
MAX_TEXT = 20_000


@dataclass(frozen=True)
class Summary:
    """What node ``node``'s upstream cone establishes about the values
    read outside it.

    ``formula``  SMT-LIB2 term over ``symbols`` (``((name, sort), ...)``,
                 the encoder's symbol names of the values of ``I(m)``);
    ``used``     ``((label, RCL text, order), ...)``: the cone's premises
                 the summary rests on (``order``: (node index, item index));
    ``script``   the query that showed it implied (unsat); kept in memory
                 (tests), not written."""

    node: str
    formula: str
    symbols: tuple[tuple[str, str], ...]
    used: tuple[tuple[str, str, tuple[int, int]], ...]
    script: str


@dataclass(frozen=True)
class MadeFrom:
    """Everything a summary is made from (:func:`_made`), as text and numbers:
    equal inputs make an equal summary, whichever process makes it."""

    node: str
    index: int
    top: tuple[str, ...]
    decls: str
    premises: tuple[tuple[str, str], ...]
    axioms: tuple[str, ...]
    kept: tuple[tuple[str, str], ...]
    sorts: tuple[tuple[str, str], ...]
    own: tuple[tuple[str, tuple[str, int]], ...]
    producer_keys: tuple[bytes, ...]


#: Summaries kept between the processes of a run and between runs (:func:`use_directory`), keyed by
#: everything :func:`_made` reads (:class:`MadeFrom`: a producer's summary by its own key, which holds
#: its inputs), the rclverify code and Z3's version.  A file holds the node, the formula, the labels
#: of the premises Z3's proof used and the proof's script: a few lines, whatever the cone's size.
_blobs = Blobs(None, "summaries", "json", versions=(f"z3 {z3.get_full_version()}",))


#: Seconds a process waits for the summary another one is making (its two Z3 steps are bounded by
#: :data:`.summary_qe.QE_MS` each), before making it itself.
WAIT_S = 5.0


def use_directory(path: Path | None) -> None:
    """Keep the summaries made in this process under ``path`` (one JSON file
    each, ``<key>.json``) and read those made by another process of the run
    (the other doit worker) or an earlier run from there; ``None``: in
    memory only.  A summary is a function of its inputs' text (it is made
    in a Z3 context of its own, from text alone), so one read equals one
    made again: incremental equals clean.  Raises nothing here."""
    _blobs.directory = path


def kept_summary(made: MadeFrom, key: bytes, memo: Mapping[str, Summary | None]) -> Summary | None:
    """The summary of ``made`` (kept under ``key``): the kept one, else made
    (:func:`_made`) and kept when there is one.  A kept file that does not
    read as one of ``made.node`` is made again and replaced.  ``memo``: the producers'
    summaries, whose premises a proof that used them rests on."""
    text = _blobs.text(key, lambda: _text(_made(made)), wait_s=WAIT_S)
    if text is None:
        return None
    try:
        node, formula, used, script = json.loads(text)
        if node != made.node or not all(isinstance(x, str) for x in (formula, script, *used)):
            raise ValueError(node)
        return _summary(made, formula, used, script, memo)
    except (ValueError, TypeError, KeyError):
        got = _made(made)
        if got is None:
            return None
        _blobs.put(key, _text(got))  # the damaged file replaced, for the processes after this one
        return _summary(made, *got[1:], memo)


@overload
def _text(got: tuple[str, str, list[str], str]) -> str: ...


@overload
def _text(got: None) -> None: ...


def _text(got: tuple[str, str, list[str], str] | None) -> str | None:
    """What a summary's file holds (:func:`_made`'s result as JSON), ``None`` for none."""
    return None if got is None else json.dumps(list(got))


def _made(made: MadeFrom) -> tuple[str, str, list[str], str] | None:
    """Quantifier elimination of the cone's hidden values, then Z3's proof
    that the result is implied by the premises (module docstring), in a Z3
    context of its own: ``(node, formula, labels of the premises the proof
    used, the proof's script)``, or ``None`` when either fails."""
    m, premises, axioms, decls = made.node, made.premises, made.axioms, made.decls
    ctx = z3.Context()  # of its own: the text made depends on nothing this process did before
    try:
        hidden = sorted({n for n, _ in made.sorts} - {n for n, _ in made.kept})
        formula = eliminate(ctx, decls, [b for _, b in premises] + list(axioms), hidden, dict(made.sorts))
        used = (implied(ctx, decls, premises, axioms, formula)
                if formula is not None and len(formula) <= MAX_TEXT else None)
    except z3.Z3Exception:
        used = None
    if used is None or formula is None:
        return None
    script = (f"; rclverify summary of the upstream cone of {m}: its premises entail\n; {formula}\n"
              f"; (summaries of {', '.join(made.top) or 'no producer'}; unsat means implied)\n"
              + decls + "".join(f"; {label}\n(assert {body})\n" for label, body in premises)
              + "".join(f"(assert {a})\n" for a in axioms) + f"(assert (not {formula}))\n(check-sat)\n")
    return m, formula, used, script


def _summary(made: MadeFrom, formula: str, used: Sequence[str], script: str,
             memo: Mapping[str, Summary | None]) -> Summary:
    """The :class:`Summary` of ``made`` whose proof used the premises labelled
    ``used``: a producer's summary stands for the premises its own proof used."""
    own = dict(made.own)
    out: dict[str, tuple[str, str, tuple[int, int]]] = {}
    for label in used:
        if label.endswith(" summary"):
            for u in memo[label[:-len(" summary")]].used:  # type: ignore[union-attr]
                out[u[0]] = u
        else:
            out[label] = (label, own[label][0], (made.index, own[label][1]))
    return Summary(made.node, formula, made.kept, tuple(sorted(out.values(), key=lambda u: u[2])), script)


def summary_key(made: MadeFrom) -> bytes:
    """The key a summary made from ``made`` is kept under."""
    return _blobs.key("summary", fingerprint(dataclasses.astuple(made)))


def forget_texts() -> None:
    """Drop the summary texts held in memory (the files stay)."""
    _blobs.forget()
