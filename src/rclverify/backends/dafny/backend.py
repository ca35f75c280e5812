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

The plan entry is checked by :mod:`.config`, Dafny's output judged by
:mod:`.verdict`.
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
from rclverify.backends.dafny.stubgen import Stub, build_stub, clause_lines, snake
from rclverify.backends.shapes import DafnyScan
from rclverify.backends.dafny.config import DafnyConfig
from rclverify.backends.dafny.payload import DafnyPayload
from rclverify.backends.dafny.verdict import UNPROVED, confirm_unproved, judge_run


@lru_cache(maxsize=1)
def _jinja() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.dafny", "templates"),
                              undefined=jinja2.StrictUndefined, keep_trailing_newline=True, autoescape=False)


#: this backend's declaration (its folder's declaration.yaml)
_DECLARED = declared_in(__file__)


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
        cfg = DafnyConfig(target)
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
        cfg = DafnyConfig(target)
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

        def ev(status: str, explanation: str, version: str = "", *, details: Mapping[str, object] | None = None,
               **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="dafny", tool_version=version, clock=clock,
                                 explanation=explanation, details=DafnyPayload.checked(details or {}), **kw)

        try:
            cfg = DafnyConfig(target)
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

def _verified(obligation: Obligation, target: NodeTarget, ev: Callable[..., Evidence], cfg: DafnyConfig, stub: Stub,
              stub_rel: str, files: list[str], tool: runner.DafnyTool, scan: implementation.ImplementationScan,
              scan_details: DafnyScan) -> Evidence:
    """Run Dafny on ``files`` (the stub and the implementation), write its
    log, and judge what it said: a guarantee left unproved is confirmed
    ``failed`` only by a refutation (:func:`confirm_unproved`), else
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
    status, explanation, details = judge_run(res, out, clauses, stub_rel, cfg, scan, tool,
                                          len(target.node.node.guarantees), target)
    cex: dict[str, object] | None = None
    if status == UNPROVED:
        status, explanation, cex, tried = confirm_unproved(target, cfg, tool, stub, scan, out, clauses, stub_rel, models,
                                                   explanation, details)
        artifacts += tuple(t["artifact"] for t in tried if t["artifact"])
    details["refining_modules"] = scan_details["refining_modules"]
    details["unsound_constructs"] = scan_details["unsound_constructs"]
    details["command"] = shown
    if log_notes:
        details["log_filtered"] = log_notes
    return ev(status, explanation, tool.version, log=shown_log, artifacts=artifacts, details=details,
              counterexample=cex)

