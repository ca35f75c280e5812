"""The ``dafny`` backend: a node's contract as a Dafny method specification,
an implementation that refines it, and Dafny's verdict as evidence.

Paper lines 1667-1762 ("Compositionality enables Interchangeability"): the
Agent node is re-specified and verified in Dafny instead of Gwendolen/AJPF;
any implementation that meets the node's first-order contract may replace
another.  Here the contract side is generated from RCL (:mod:`.stubgen`),
the implementation is the user's ``module <Impl> refines <Node>Contract``,
and Dafny proves the refinement.

Plan entry (``nodes.<Node>.evidence[k]``)::

    - backend: dafny
      implementation: backends/dafny/agent.dfy   # default backends/dafny/<node>.dfy
      executable: false    # true: a compiled `method` instead of a `ghost method`
      time_limit: 60       # seconds per verification condition (Dafny's time limit)
      timeout: 600         # seconds for the whole Dafny process
      dafny: dafny         # command name or path of the Dafny executable
      options: []          # extra Dafny options, verbatim (e.g. ["/arith:2"] for Dafny 2.x/3.x)

Obligation: one per node, the whole method contract (``guarantee`` 0,
instance ``contract``, id ``<Node>.g0.dafny.contract``); its ``data`` lists
the guarantees it covers.  Evidence statuses:

* ``discharged``  Dafny finished with 0 errors, no time-outs, at least one
  verified procedure, and the implementation uses no construct that makes
  Dafny accept an unproved claim;
* ``failed``      a guarantee Dafny could not prove is refuted (:mod:`.refute`:
  Dafny proves every run on the prover's model's inputs breaks it, and Z3
  finds the assumptions satisfiable there); the counterexample is those
  inputs;
* ``inconclusive`` Dafny reported verification errors but no refutation was
  found (each error located, and mapped back to the RCL
  assumption/guarantee when it concerns a ``requires``/``ensures`` of the
  stub; a verification error is no counterexample), a verification
  condition or the process timed out, or the implementation uses
  ``assume``/``{:axiom}``/... (listed);
* ``error``       parse/resolution errors, a crash, an implementation that
  refines nothing or gives the method no body;
* ``pending``     Dafny is not installed, or the implementation file does
  not exist yet (with the exact command to run).
"""
from __future__ import annotations

import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Mapping

import jinja2

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text

from rclverify.lang.errors import RclError
from rclverify.lang.printer import expr_to_rcl
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.dafny import implementation, refute, runner
from rclverify.backends.dafny.stubgen import ClauseRef, Refutation, Stub, build_stub, clause_lines, snake
from rclverify.backends.shapes import DafnyDetails, DafnyError, DafnyPlace, DafnyRefutation, DafnyScan

DEFAULT_TIME_LIMIT_S = 60
DEFAULT_TIMEOUT_S = 600
#: :func:`_judge`'s word for a run whose errors left clauses unproved; :func:`_confirm` turns it into a status
UNPROVED = "unproved"


@lru_cache(maxsize=1)
def _jinja() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.dafny", "templates"),
                              undefined=jinja2.StrictUndefined, keep_trailing_newline=True, autoescape=False)


#: this backend's declaration (its folder's declaration.yaml)
_DECLARED = declared_in(__file__)


class _Config:
    """The validated plan entry (see the module docstring)."""

    def __init__(self, target: NodeTarget) -> None:
        cfg: Mapping[str, Any] = target.config
        where = f"nodes.{target.node.name}.evidence[{target.index}]"

        def bad(key: str, what: str) -> RclError:
            return target.config_error(f"{where}.{key} must be {what}, found {cfg.get(key)!r}", key,
                                       code="E-plan-dafny")

        impl = cfg.get("implementation", f"backends/dafny/{snake(target.node.name)}.dfy")
        if not isinstance(impl, str) or not impl.endswith(".dfy"):
            raise bad("implementation", "a workspace-relative path of a .dfy file")
        self.implementation = impl.replace("\\", "/")
        executable = cfg.get("executable", False)
        if not isinstance(executable, bool):
            raise bad("executable", "true or false")
        self.ghost = not executable
        self.time_limit = cfg.get("time_limit", DEFAULT_TIME_LIMIT_S)
        if isinstance(self.time_limit, bool) or not isinstance(self.time_limit, int) or self.time_limit <= 0:
            raise bad("time_limit", "a positive whole number of seconds")
        self.timeout = cfg.get("timeout", DEFAULT_TIMEOUT_S)
        if isinstance(self.timeout, bool) or not isinstance(self.timeout, (int, float)) or self.timeout <= 0:
            raise bad("timeout", "a positive number of seconds")
        self.dafny = cfg.get("dafny", "dafny")
        if not isinstance(self.dafny, str) or not self.dafny:
            raise bad("dafny", "a command name or path")
        options = cfg.get("options", [])
        if not isinstance(options, list) or not all(isinstance(o, str) and o[:1] in "/-" and o for o in options):
            raise bad("options", "a list of Dafny command-line options (each starting with '/' or '-')")
        self.options: tuple[str, ...] = tuple(options)


class DafnyBackend:
    """Backend ``dafny`` (kind ``proof``); see the module docstring."""

    name = _DECLARED.name
    kind = _DECLARED.evidence_kind

    # -- export -------------------------------------------------------------------------
    def stub_path(self, target: NodeTarget) -> Path:
        """``artifacts/dafny/<Node>/<node>_contract.dfy`` (absolute)."""
        return target.artifacts / f"{snake(target.node.name)}_contract.dfy"

    def render(self, target: NodeTarget) -> tuple[Stub, Path]:
        """Build the node's stub and write it (atomically, only when changed).

        Returns the stub and its absolute path.  Raises
        :class:`~rclverify.model.plan.errors.PlanError` for a bad plan entry or a
        contract Dafny cannot express (located at the RCL construct).
        """
        from rclverify.backends.property_tests.at_width import carried_in  # deferred: start-up (hypothesis)
        cfg = _Config(target)
        path = self.stub_path(target)
        rel = target.rel(path) if path.is_absolute() else path.as_posix()
        n = target.node.node
        stub = build_stub(
            target.checked.env, target.node, ghost=cfg.ghost,
            header=f"Dafny contract of node {n.name} from {n.loc.file}:{n.loc.line} -- generated by rclverify",
            commands=runner.user_commands([rel, cfg.implementation], cfg.time_limit, cfg.options),
            implementation=cfg.implementation, widths=carried_in(target.root, target.node, target.mapping)[0])
        atomic_write_text(path, stub.text)
        return stub, path

    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render the stub and return the node's single obligation.

        Raises :class:`~rclverify.model.plan.errors.PlanError` (see :meth:`render`).
        """
        cfg = _Config(target)
        stub, path = self.render(target)
        n = target.node.node
        assume = " and ".join(f"({expr_to_rcl(c.formula)})" for c in n.assumes) or "TRUE"
        guarantee = " and ".join(f"({expr_to_rcl(c.formula)})" for c in n.guarantees)
        statement = (f"{cfg.implementation} refines {stub.module}: for all inputs, "
                     f"{assume} -> {guarantee}")
        inputs = tuple(dict.fromkeys([cfg.implementation, *target.contract_files, target.plan_file]))
        return [Obligation(
            id=make_obligation_id(n.name, 0, self.name, "contract"), node=n.name, guarantee=0,
            backend=self.name, kind=self.kind, statement=statement,
            source=SourceRef(n.loc.file, n.loc.line, n.loc.col), instance="contract",
            artifact=target.rel(path), inputs=inputs,
            data={
                "module": stub.module, "method": stub.method, "ghost": stub.ghost,
                "implementation": cfg.implementation, "signature": stub.signature(),
                "guarantees": list(range(1, len(n.guarantees) + 1)),
                "clauses": [{"label": c.label, "kind": c.kind, "source": str(c.source), "rcl": c.rcl}
                            for c in stub.clauses],
                "time_limit_s": cfg.time_limit,
            },
        )]

    # -- run -----------------------------------------------------------------------------
    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Verify the implementation against the stub with Dafny; never raises
        for a user-caused problem (see the module docstring for statuses)."""
        clock = Stopwatch()

        def ev(status: str, explanation: str, version: str = "", **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="dafny", tool_version=version, clock=clock,
                                 explanation=explanation, **kw)

        try:
            cfg = _Config(target)
            stub, stub_abs = self.render(target)
        except RclError as exc:
            return ev("error", f"the Dafny stub could not be generated: {exc}")
        stub_rel = target.rel(stub_abs)
        files = [stub_rel, cfg.implementation]
        command = runner.user_command(files, cfg.time_limit, cfg.options)
        impl_path = target.root / cfg.implementation
        if not impl_path.is_file():
            return ev("pending", f"implementation {cfg.implementation} does not exist yet: write a module that "
                                 f"refines {stub.module} (see {stub_rel}), then run: {command}",
                      artifacts=(stub_rel,), details={"command": command})
        exe = runner.find_dafny(cfg.dafny)
        if exe is None:
            return ev("pending", f"dafny not installed (no {cfg.dafny!r} on PATH); run: {command}",
                      "not installed", artifacts=(stub_rel,), details={"command": command})
        tool = runner.detect(exe)
        if tool is None:
            return ev("error", f"{cfg.dafny} does not run or does not report a Dafny version", "unknown",
                      artifacts=(stub_rel,), details={"command": command})
        try:
            text = impl_path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            return ev("error", f"cannot read {cfg.implementation}: {exc}", tool.version)
        scan = implementation.scan_implementation(text, stub.module, stub.method)
        scan_details: DafnyScan = {"refining_modules": [{"module": m, "line": ln} for m, ln in scan.refining],
                                    "unsound_constructs": [{"line": ln, "construct": c} for ln, c in scan.unsound]}
        if not scan.refining:
            return ev("error", f"{cfg.implementation}:1:1: no module refines {stub.module}; write "
                               f"`module {stub.method}Impl refines {stub.module} {{ ... }}`", tool.version,
                      artifacts=(stub_rel,), details=scan_details)
        if scan.body_line is None:
            where = f"{cfg.implementation}:{scan.method_line or scan.refining[0][1]}:1"
            return ev("error", f"{where}: module {scan.refining[0][0]} gives no body for method {stub.method}, "
                               "so Dafny would verify nothing", tool.version, artifacts=(stub_rel,),
                      details=scan_details)
        return _verified(obligation, target, ev, cfg, stub, stub_rel, files, tool, scan, scan_details)

def _verified(obligation: Obligation, target: NodeTarget, ev: Callable[..., Evidence], cfg: _Config, stub: Stub,
              stub_rel: str, files: list[str], tool: runner.DafnyTool, scan: implementation.ImplementationScan,
              scan_details: DafnyScan) -> Evidence:
    """Run Dafny on ``files`` (the stub and the implementation), write its
    log, and judge what it said: a guarantee left unproved is confirmed
    ``failed`` only by a refutation (:func:`_confirm`), else
    ``inconclusive``; ``ev`` makes the evidence (module docstring)."""
    argv = runner.verify_argv(tool, files, cfg.time_limit, error_limit=len(stub.clauses) + 10,
                              options=cfg.options)
    shown = " ".join([Path(argv[0]).name, *argv[1:]])
    with tempfile.TemporaryDirectory(prefix="rclverify-dafny-") as tmp:
        model = Path(tmp) / "model.bvd" if runner.takes_model_file(tool) else None
        try:
            res = runner.run(runner.verify_argv(tool, files, cfg.time_limit, error_limit=len(stub.clauses) + 10,
                                                options=cfg.options, model_file=str(model) if model else None),
                             target.root, float(cfg.timeout))
        except OSError as exc:
            return ev("error", f"could not start {tool.exe}: {exc}", tool.version, details={"command": shown})
        models = refute.read_models(model.read_text(encoding="utf-8", errors="replace")) \
            if model is not None and model.is_file() else []
    log_path = target.artifacts / f"{snake(target.node.name)}_dafny.log"
    shown_log, log_notes = runner.filter_log(res.output)
    atomic_write_text(log_path, _jinja().get_template("log.txt.j2").render(
        node=target.node.name, obligation=obligation.id, command=shown,
        exit_code="killed at the process timeout" if res.timed_out else res.returncode,
        output=shown_log.rstrip("\n"), notes=log_notes))
    artifacts: tuple[str, ...] = (stub_rel, target.rel(log_path))
    out = runner.parse_output(res.output)
    clauses = clause_lines(stub.text)
    status, explanation, details = _judge(res, out, clauses, stub_rel, cfg, scan, tool,
                                          len(target.node.node.guarantees), target)
    cex: dict[str, object] | None = None
    if status == UNPROVED:
        status, explanation, cex, tried = _confirm(target, cfg, tool, stub, scan, out, clauses, stub_rel, models,
                                                   explanation, details)
        artifacts += tuple(t["artifact"] for t in tried if t["artifact"])
    details["refining_modules"] = scan_details["refining_modules"]
    details["unsound_constructs"] = scan_details["unsound_constructs"]
    details["command"] = shown
    if log_notes:
        details["log_filtered"] = log_notes
    return ev(status, explanation, tool.version, log=shown_log, artifacts=artifacts, details=details,
              counterexample=cex)


def _confirm(target: NodeTarget, cfg: _Config, tool: runner.DafnyTool, stub: Stub,
             scan: implementation.ImplementationScan, out: runner.Output, clauses: Mapping[int, ClauseRef],
             stub_rel: str, models: list[dict[str, str]], unproved: str,
             details: DafnyDetails) -> tuple[str, str, dict[str, object] | None, list[DafnyRefutation]]:
    """Status, explanation, counterexample and refutation attempts of a run
    whose errors left guarantees unproved (:mod:`.refute`): ``failed`` when
    one guarantee clause is refuted, else ``inconclusive`` with each reason.
    Sets ``details["guarantees"]`` of a refuted guarantee to ``failed`` and
    ``details["refutations"]``."""
    failing: list[tuple[int, int, int]] = []  # (guarantee, conjunct, index of its model)
    k = -1
    for m in out.messages:
        if m.severity != "error":
            continue
        k += 1
        c = _clause_of(m, clauses, stub_rel, target.root)
        if c is not None and c.role == "guarantee" and all((g, j) != (c.index, c.conjunct) for g, j, _ in failing):
            failing.append((c.index, c.conjunct, k))
    tried: list[DafnyRefutation] = []
    free = 0  # refutations sought with every input free: one per run (each is rarely true, and costs a run)
    for g, j, k in failing[:refute.MAX_REFUTATIONS]:
        if scan.unsound:
            break  # a refutation proved with `assume` in the code proves nothing either
        pinned = refute.pins(models[k] if k < len(models) else {}, stub)
        if not pinned and free:
            continue
        free += not pinned
        tried.append(_refute_one(target, cfg, tool, g, j, pinned))
    details["refutations"] = tried
    done = [t for t in tried if t["status"] == "refuted"]
    for t in done:
        details.setdefault("guarantees", {})[str(t["guarantee"])] = "failed"
    if done:
        t = done[0]
        on = (", ".join(f"{n} = {v}" for n, v in t["inputs"].items()) if t["inputs"]
              else "every input that meets the assumptions")
        return "failed", (f"Dafny refutes guarantee {t['clause']} ({t['rcl']}) of {cfg.implementation}: on {on}, "
                          f"Dafny proves that every run of the implementation breaks it ({t['artifact']}), and Z3 "
                          f"finds the assumptions satisfiable there. {unproved}"), dict(t["inputs"]), tried
    if scan.unsound:
        why = "the implementation relies on constructs Dafny does not prove, so no refutation was sought"
    elif not failing:
        why = "no guarantee clause was among them (an assertion, a loop invariant or a call's precondition was)"
    else:
        why = "; ".join(f"guarantee {t['clause']}: {t['reason']}" for t in tried)
        if len(failing) > len(tried):
            why += (f"; {len(failing) - len(tried)} more guarantee clause(s) not tried (at most "
                    f"{refute.MAX_REFUTATIONS} per run, one of them with no input fixed by the prover's model)")
    return "inconclusive", (f"{unproved}. A verification error is no counterexample (the verifier may lack a loop "
                            f"invariant, a lemma or nonlinear arithmetic), and none was shown: {why}"), None, tried


def _refute_one(target: NodeTarget, cfg: _Config, tool: runner.DafnyTool, g: int, j: int,
                pinned: list[refute.Pin]) -> DafnyRefutation:
    """Seek the refutation of guarantee ``g``'s conjunct ``j`` on the ``pinned`` inputs (:mod:`.refute`):
    writes the refutation stub under the node's artifacts and runs Dafny on it and the implementation."""
    from rclverify.backends.property_tests.at_width import carried_in  # deferred: start-up (hypothesis)
    label = f"{g}.{j}" if j else str(g)
    # the guarantee negated as the contract stub states it: each comparison at its fields' widths
    stub = build_stub(target.checked.env, target.node, ghost=cfg.ghost,
                      header=f"Dafny refutation of guarantee {label} of node {target.node.name} -- generated by "
                             "rclverify", widths=carried_in(target.root, target.node, target.mapping)[0],
                      refute=Refutation(g, j, tuple((p.param, p.literal, f"{p.name} == {p.shown}") for p in pinned)))
    [clause] = [c for c in stub.clauses if c.kind == "ensures"]
    path = target.artifacts / f"{snake(target.node.name)}_refute_g{label.replace('.', '_')}.dfy"
    atomic_write_text(path, stub.text)
    rel = target.rel(path)
    record: DafnyRefutation = {"guarantee": g, "conjunct": j, "clause": label, "rcl": str(clause.source),
                               "inputs": {p.name: p.shown for p in pinned}, "status": "not refuted", "reason": "",
                               "artifact": rel}
    try:
        res = runner.run(runner.verify_argv(tool, [rel, cfg.implementation], cfg.time_limit, options=cfg.options),
                         target.root, float(cfg.timeout))
    except OSError as exc:
        record["reason"] = f"Dafny could not be started for the refutation: {exc}"
        return record
    out = runner.parse_output(res.output)
    if res.timed_out or not out.summary or out.errors or out.timeouts or out.other or not out.verified:
        shown = ", ".join(f"{n} = {v}" for n, v in record["inputs"].items()) or "the inputs left free"
        record["reason"] = (f"Dafny did not prove that every run on {shown} breaks it ({out.errors} error(s), "
                            f"{out.timeouts} time-out(s){', killed at the process timeout' if res.timed_out else ''}"
                            f"; {rel})")
        return record
    answer, why = refute.assumptions_satisfiable(target.checked, target.node, pinned)
    if answer != "sat":
        record["reason"] = ("Z3 finds no inputs that meet the assumptions there, so the refutation is vacuous"
                            if answer == "unsat" else f"whether inputs meet the assumptions there is not known: {why}")
        return record
    record["status"] = "refuted"
    return record


def _same_file(printed: str, rel: str, root: Path) -> bool:
    p = Path(printed)
    if not p.is_absolute():
        p = root / p
    try:
        return p.resolve() == (root / rel).resolve()
    except OSError:  # pragma: no cover
        return False


def _clause_of(msg: runner.Message, clauses: Mapping[int, ClauseRef], stub_rel: str, root: Path) -> ClauseRef | None:
    for pos in [msg.at] + [p for p, _ in msg.related]:
        if _same_file(pos.file, stub_rel, root) and pos.line in clauses:
            return clauses[pos.line]
    return None


def _judge(res: runner.RunOutput, out: runner.Output, clauses: Mapping[int, ClauseRef], stub_rel: str,
           cfg: _Config, scan: implementation.ImplementationScan, tool: runner.DafnyTool, n_guarantees: int,
           target: NodeTarget) -> tuple[str, str, DafnyDetails]:
    """Status, explanation and details of one Dafny run."""
    errors: list[DafnyError] = []
    per: dict[str, list[str]] = {}
    for m in out.messages:
        if m.severity == "warning":
            continue
        c = _clause_of(m, clauses, stub_rel, target.root)
        e: DafnyError = {"severity": m.severity, "file": m.at.file, "line": m.at.line, "col": m.at.col,
                             "message": m.message, "code": m.code,
                             "related": [{"file": p.file, "line": p.line, "col": p.col, "message": t}
                                         for p, t in m.related]}
        if c is not None:
            e["clause"], e["role"], e["index"], e["rcl"] = c.label, c.role, c.index, c.source
            if c.role == "guarantee":
                e["guarantee"] = c.index
                per.setdefault(str(c.index), []).append(m.severity)
        errors.append(e)
    warnings: list[DafnyPlace] = [{"file": m.at.file, "line": m.at.line, "col": m.at.col, "message": m.message}
                for m in out.messages if m.severity == "warning"]
    details: DafnyDetails = {
        "verified": out.verified, "errors": errors, "error_count": out.errors, "timeouts": out.timeouts,
        "other_outcomes": out.other, "warnings": warnings, "exit_code": res.returncode,
        "parse_errors": out.parse_errors, "resolution_errors": out.resolution_errors,
        "prover_messages": out.prover_messages[:5], "cli": "legacy" if tool.legacy else "verify",
    }

    def located(e: DafnyError) -> str:
        where = f"{e['file']}({e['line']},{e['col']})"
        rcl = f" [{e['clause']} at {e['rcl']}]" if "clause" in e else ""
        return f"{where}: {e['message']}{rcl}"

    if res.timed_out:
        status, expl = "inconclusive", f"Dafny did not finish within the process timeout of {cfg.timeout} s"
    elif not out.summary:
        tail = res.output.strip().splitlines()
        first = "; ".join(located(e) for e in errors[:3]) or (tail[-1] if tail else "no output")
        kind = ("parse errors" if out.parse_errors else "resolution/type errors" if out.resolution_errors
                else "no verification summary (Dafny crashed or was misconfigured)")
        status, expl = "error", f"Dafny stopped with {kind}: {first}"
    elif out.errors:  # unproved: failed or inconclusive once a refutation was sought (:func:`_confirm`)
        failed = sorted({(e["index"], e["rcl"]) for e in errors if e.get("role") == "guarantee"
                         and e["severity"] == "error"})
        which = ", ".join(f"guarantee {k} ({src})" for k, src in failed) or "the contract"
        status = UNPROVED
        expl = (f"Dafny could not prove that {cfg.implementation} meets {which}: {out.errors} error(s): "
                + "; ".join(located(e) for e in errors if e["severity"] == "error")[:1500])
    elif out.timeouts or out.other:
        status = "inconclusive"
        expl = (f"Dafny timed out (time limit {cfg.time_limit} s per verification condition) or ran out of "
                f"resources: {out.timeouts} time out(s), {out.other} other; nothing was refuted")
    elif out.verified == 0:
        status, expl = "error", "Dafny verified nothing (0 verified, 0 errors): the implementation was not checked"
    elif scan.unsound:
        status = "inconclusive"
        expl = ("Dafny verified the implementation, but it relies on constructs Dafny does not prove: "
                + ", ".join(f"{c} at {cfg.implementation}:{ln}" for ln, c in scan.unsound))
    else:
        status = "discharged"
        expl = (f"Dafny {tool.version} proved that {cfg.implementation} (module {scan.refining[0][0]}) meets "
                f"every requires/ensures of the contract ({out.verified} verified, 0 errors)")
    guarantees: dict[str, str] = {}
    for k in range(1, n_guarantees + 1):
        sev = per.get(str(k), [])
        if "error" in sev:
            guarantees[str(k)] = "unproved"  # "failed" once refuted (:func:`_confirm`)
        elif "timeout" in sev:
            guarantees[str(k)] = "inconclusive"
        elif status == "discharged":
            guarantees[str(k)] = "verified"
        elif out.summary:
            guarantees[str(k)] = "no error reported"
        else:
            guarantees[str(k)] = "not checked"
    details["guarantees"] = guarantees
    return status, expl, details
