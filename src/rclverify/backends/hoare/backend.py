"""The ``hoare`` backend: a node's guarantee as Hoare triples over a program, checked by Z3.

The paper verifies the Radiation Sensor node by modelling it as a small
imperative program and proving Hoare triples that correspond to its guarantee
by hand (shared/reference, lines 1477-1541, appendix B from line 1984).  This
backend mechanises that step:

* ``export`` reads the plan entry ``{backend: hoare, program: <.imp>,
  binding: {in.x: <expr>, out.y: <var>}, timeout_ms: <ms>}``, splits the
  node's guarantees into triples (:mod:`.obligations`), computes each one's
  weakest-precondition proof outline (:mod:`.wp`) and renders it to
  ``artifacts/hoare/<Node>/g<guarantee>.<program>.c<k>.txt``;
* every triple has definedness VCs as well (:mod:`.defined`): each
  division in the program, the precondition and the postcondition must not
  divide by zero where it is evaluated (docs/semantics.md, "Definedness");
* ``run`` checks every verification condition with Z3 (:mod:`.solve`):
  all valid -> ``discharged``; one refuted with a run of the program that
  breaks the triple -> ``failed`` with that counterexample (initial values,
  extern applications, final values); refuted only in a state no run need
  reach (a loop invariant too weak), unknown or timeout -> ``inconclusive``
  with the reason; a conjunct the program does not model
  -> ``pending`` with the reason (never discharged).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Mapping

import jinja2
import z3

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.records.ties import tie_query
from rclverify.semantics.encode import EncodingError, Encoder
from rclverify.lang.errors import RclError, error
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.hoare.defined import definedness_vcs
from rclverify.backends.hoare.config import HoareConfig, load_program
from rclverify.backends.hoare.obligations import Conjunct, EncodedTriple, conjuncts, encode_triple, statement
from rclverify.backends.hoare.outline import OutlineLine, outline_text, render_outline, term_printer
from rclverify.backends.hoare.solve import TripleResult, check_all
from rclverify.backends.hoare.program_model import ProgramModel
from rclverify.backends.hoare.wp import VC, WP, main_vc, wp
from rclverify.backends.hoare.payload import HoarePayload
from rclverify.backends.shapes import HoareData

#: this backend's name and evidence kind, as its declaration.yaml states them
_DECLARED = declared_in(__file__)
NAME, KIND = _DECLARED.name, _DECLARED.evidence_kind


@lru_cache(maxsize=1)  # one environment per process: jinja2 then compiles each template once
def _templates() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.hoare", "templates"),
                              undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True,
                              trim_blocks=False, lstrip_blocks=False)


@dataclass(frozen=True)
class Prepared:
    """One exported triple with everything needed to render and check it.

    ``triple``/``result``/``vcs`` are ``None``/empty for a pending conjunct.
    """

    id: str
    instance: str
    conjunct: Conjunct
    statement: str
    artifact: Path
    smt2: Path
    source: SourceRef
    config: HoareConfig
    model: ProgramModel
    triple: EncodedTriple | None
    result: WP | None
    vcs: tuple[VC, ...]
    identified: tuple[str, ...]

    @property
    def pending(self) -> str:
        return self.conjunct.pending_reason


def _source(target: NodeTarget, loc: Any) -> SourceRef:
    file = str(loc.file)
    p = Path(file)
    if p.is_absolute():
        try:
            file = p.resolve().relative_to(target.root.resolve()).as_posix()
        except ValueError:
            pass
    return SourceRef(file, loc.line, loc.col)


def prepare(target: NodeTarget, only: str | None = None) -> list[Prepared]:
    """Derive every triple of ``target``'s node for its plan entry (only the
    one with obligation id ``only`` when given: a run checks one triple and
    need not encode the others).

    Raises :class:`~rclverify.model.plan.errors.PlanError` (bad entry) or
    :class:`~rclverify.lang.errors.RclError` (bad program, or a guarantee the
    Z3 encoding cannot express, located in the RCL file).
    """
    cfg, program, types = load_program(target)
    m = ProgramModel(program, types, Encoder(target.checked.env))  # uses the encoder's sorts only
    node = target.node
    covered = set(cfg.inputs) | set(cfg.outputs)
    out: list[Prepared] = []
    for c in conjuncts(node, covered):
        instance = f"{cfg.stem}.c{c.index}"
        oid = make_obligation_id(node.name, c.guarantee, NAME, instance)
        if only is not None and oid != only:
            continue
        identified = tuple(nm for b in c.bindings for nm in b.names if nm in types.vars)
        triple: EncodedTriple | None = None
        result: WP | None = None
        vcs: tuple[VC, ...] = ()
        if not c.uncovered:
            # A fresh encoder per triple: a triple's background (the typing axioms
            # of the symbols encoded so far) is then the same whether one triple
            # (a run) or all of them (an export) are prepared.
            enc = Encoder(target.checked.env)
            try:
                triple = encode_triple(c, cfg, m, enc, node, program)
            except EncodingError as exc:
                raise RclError([error(exc.loc, str(exc).split(": error: ", 1)[-1], "E-encode")]) from None
            result = wp(program.body, triple.post, m)
            vcs = (main_vc(triple.pre, result, m, c.loc), *result.vcs, *definedness_vcs(program, m, triple, c.loc))
        src = _source(target, c.clause.loc)
        text = statement(c, cfg, node, frozenset(types.vars))
        stem = f"g{c.guarantee}.{instance}"
        out.append(Prepared(oid, instance, c, text, target.artifacts / f"{stem}.txt",
                            target.artifacts / f"{stem}.smt2", src, cfg, m, triple, result, vcs, identified))
    return out


def _header(target: NodeTarget, p: Prepared) -> str:
    return (f"{p.id}: from {p.source} ({target.node.name}, guarantee {p.conjunct.guarantee}) and "
            f"{p.config.program}; generated by rclverify")


@dataclass(frozen=True)
class Rendered:
    """The texts of one prepared triple: ``text`` the obligation artifact,
    ``lines`` the proof outline, ``pre``/``post`` the triple's pre- and
    postcondition (``lines`` ``None`` and ``pre``/``post`` empty when pending)."""

    text: str
    lines: list[OutlineLine] | None
    pre: str = ""
    post: str = ""


def render(target: NodeTarget, p: Prepared) -> Rendered:
    """Render the obligation artifact of ``p`` (the triple, binding, VCs and proof outline)."""
    ctx: dict[str, Any] = dict(
        header=_header(target, p), id=p.id, node=target.node.name, guarantee=p.conjunct.guarantee,
        conjunct=p.conjunct.index, source=str(p.source), conjunct_text=p.conjunct.conjunct_text,
        statement=p.statement, program=p.config.program, program_name=p.config.stem,
        binding=sorted(p.config.binding_text.items()), identified=p.identified, pending=p.pending,
        pre="", post="", vcs=[], outline=[])
    lines: list[OutlineLine] | None = None
    if p.triple is not None and p.result is not None:
        show = term_printer(p.triple.names)  # one printer: the outline repeats pre and post
        lines = render_outline(p.result.outline, p.triple.names, p.triple.pre,
                               "precondition of the triple; implies the next assertion (main)", show)
        ctx.update(pre=show(p.triple.pre), post=show(p.triple.post), vcs=p.vcs,
                   outline=[dict(pad=" " * ln.indent, text=ln.text, note=ln.note) for ln in lines])
    text = _templates().get_template("obligation.txt.j2").render(**ctx)
    return Rendered(text, lines, ctx["pre"], ctx["post"])


def render_queries(target: NodeTarget, p: Prepared, res: TripleResult) -> str:
    """SMT-LIB2 text of every VC query of a checked triple."""
    queries = [dict(id=r.vc.id, status=r.status, text=r.smt2 if r.smt2.endswith("\n") else r.smt2 + "\n")
               for r in res.results]
    return _templates().get_template("query.smt2.j2").render(header=_header(target, p), id=p.id, queries=queries)


class HoareBackend:
    """Hoare triples over an imperative model of the node, discharged by Z3.

    ``name`` ``"hoare"``, ``kind`` ``"proof"``.  Paper: lines 1477-1541 and
    appendix B (1984-).
    """

    name = NAME
    kind = KIND
    #: The export asks no solver: the obligation records (ids, statements, the VC
    #: ids, which follow the program's loops) and the artifact's text (the triple
    #: and its proof outline, printed by walking the terms, :mod:`.outline`) follow
    #: from the structure of the terms alone, which Z3 shares by structure
    #: (hash-consing) whatever else its context holds; so the export needs no
    #: fresh Z3 context of its own (app/pipeline.py, ``stage_export``).  Each
    #: run still rebuilds its triple in a fresh one: its answers are the solver's.
    export_reads_z3_state = False

    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render one artifact per triple under ``target.artifacts``; return the obligations.

        Raises :class:`PlanError`/:class:`RclError` for user mistakes (located).
        """
        obligations = []
        for p in prepare(target):
            r = render(target, p)
            atomic_write_text(p.artifact, r.text)
            inputs = tuple(sorted({p.config.program, *target.contract_files, target.plan_file}))
            data: HoareData = {
                "program": p.config.program, "guarantee": p.conjunct.guarantee, "conjunct": p.conjunct.index,
                "conjunct_rcl": p.conjunct.conjunct_text, "binding": dict(sorted(p.config.binding_text.items())),
                "conjunct_source": str(p.conjunct.loc), "timeout_ms": p.config.timeout_ms,
            }
            if p.pending:
                data["pending"] = p.pending
            else:
                data["vcs"] = [vc.id for vc in p.vcs]
            obligations.append(Obligation(
                id=p.id, node=target.node.name, guarantee=p.conjunct.guarantee, backend=NAME, kind=KIND,
                statement=p.statement, source=p.source, instance=p.instance, artifact=target.rel(p.artifact),
                inputs=inputs, data=data))
        return obligations

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Check one exported triple with Z3 and return its evidence record (never raises
        for a user-caused problem)."""
        clock = Stopwatch()
        version = z3.get_version_string()

        def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="z3", tool_version=version, clock=clock,
                                 explanation=explanation, **kw)

        # Rebuilt here, in the run's own fresh Z3 context (semantics/world.py): a triple kept from the
        # export would carry the Z3 state of another unit of work, and its counterexample could differ
        # between an incremental and a clean run.
        try:
            prepared = {p.id: p for p in prepare(target, only=obligation.id)}
        except RclError as exc:
            return evidence("error", f"the obligation could not be rebuilt: {exc}", log=str(exc))
        found = prepared.get(obligation.id)
        if found is None:
            return evidence("error", "the plan entry, program or contract no longer yields this obligation; "
                            "export again")
        p, rendered = found, render(target, found)
        atomic_write_text(p.artifact, rendered.text)  # not rewritten when the export wrote the same text
        artifacts = [target.rel(p.artifact)]
        if p.pending or p.triple is None:
            return evidence("pending", p.pending, artifacts=tuple(artifacts),
                            details=HoarePayload(reason=p.pending, uncovered=list(p.conjunct.uncovered)).details())
        try:
            res = check_all(p.vcs, p.triple.background, p.model, p.config.timeout_ms, p.triple.observe,
                            p.triple.observe_final, p.triple.names, triple=(p.triple.pre, p.triple.post))
        except z3.Z3Exception as exc:
            return evidence("error", f"Z3 failed: {exc}", log=str(exc), artifacts=tuple(artifacts))
        # it ends naming the obligation it decides (records/ties.py), read back by `bundle --verify`
        atomic_write_text(p.smt2, tie_query(render_queries(target, p, res), "hoare", obligation.id,
                                            {"id": obligation.id, "statement": obligation.statement}))
        artifacts.append(target.rel(p.smt2))
        assert rendered.lines is not None
        outline = outline_text(rendered.lines)
        failed = res.failed if res.status == "failed" else None
        details = HoarePayload(
            outline=outline if len(outline) <= 8000 else outline[:8000] + "...\n",
            vcs={r.vc.id: r.status for r in res.results}, program=p.config.program,
            triple={"pre": rendered.pre, "post": rendered.post}, failed_vc=failed.vc.id if failed else "",
            notes=list(res.notes) if res.status != "discharged" else []).details()
        log = "\n".join(f"{r.vc.id}: {r.status}" + (f" ({r.reason})" if r.reason else "") for r in res.results)
        if res.status == "discharged":
            return evidence("discharged", f"Z3 proved all {len(res.results)} verification condition(s) of the "
                            f"triple over {p.config.program}", log=log, artifacts=tuple(artifacts), details=details)
        if res.status == "failed":
            assert res.failed is not None
            if res.failed.vc.id.startswith("defined"):
                return evidence("failed", f"{p.config.program} does not meet the triple: a division by zero on this "
                                f"run ({res.failed.vc.label}; verification condition {res.failed.vc.id}): "
                                f"{_cex_text(res.counterexample or {})}", log=log,
                                artifacts=tuple(artifacts), counterexample=res.counterexample, details=details)
            return evidence("failed", f"{p.config.program} does not meet the triple: the postcondition "
                            f"{rendered.post} fails on this run (verification condition "
                            f"{res.failed.vc.id}: {res.failed.vc.label}): {_cex_text(res.counterexample or {})}", log=log,
                            artifacts=tuple(artifacts), counterexample=res.counterexample, details=details)
        if res.notes:  # refuted verification conditions, but no run of the program that breaks the triple
            return evidence("inconclusive", f"{p.config.program} is not proved to meet the triple, and no "
                            f"counterexample was shown: {'; '.join(res.notes)}", log=log,
                            artifacts=tuple(artifacts), details=details)
        reasons = sorted({r.reason for r in res.results if r.status == "unknown"})
        return evidence("inconclusive", f"Z3 answered unknown ({', '.join(reasons) or 'no reason given'}) "
                        f"within {p.config.timeout_ms} ms", log=log, artifacts=tuple(artifacts), details=details)


def _cex_text(cex: Mapping[str, object]) -> str:
    return ", ".join(f"{k} = {v}" for k, v in cex.items())

