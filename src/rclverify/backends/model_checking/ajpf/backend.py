"""The ``ajpf`` backend: a node's guarantees as AJPF properties of a Gwendolen agent.

Paper lines 1338-1475: the Agent node is a Gwendolen BDI program, and its
RCL guarantees are model checked with AJPF (MCAPL) as LTL properties over the
agent's beliefs and actions, one property per waypoint.  This backend

* translates every guarantee instance with the plan's mapping table
  (:mod:`.mapping`, :mod:`.instantiate`),
* renders ``artifacts/ajpf/<Node>/agent.psl`` (numbered properties, each
  preceded by comments naming the guarantee, its RCL location and the
  instances it checks), ``agent.ail`` (the agent program and its
  verification environment) and one ``agent_<n>.jpf`` per property,
* gives one obligation per guarantee instance,
  ``<Node>.g<k>.ajpf.p<n>_i<value>`` (instances whose formulas coincide share
  the property number ``n``; an instance with unmapped atoms is
  ``<Node>.g<k>.ajpf.unmapped_i<value>`` and has no property), and
* produces evidence: a log placed in ``<results>/<Node>/agent_<n>.log`` is
  imported; otherwise, with MCAPL installed, AJPF is run; otherwise the
  evidence is ``pending`` with the command to run.

Plan entry keys (``nodes.<Node>.evidence[k]``)::

    backend: ajpf
    agent: jackal                       # the Gwendolen agent's :name:
    model: backends/ajpf/jackal.gwen    # the agent program (workspace-relative)
    domains: {i: [0, 12]}               # instantiated variables, inclusive ranges
    mapping: [ {rcl: ..., ajpf: ..., when: ...}, ... ]
    environment_class: <Java class>     # AIL verification environment
                                        # (default ail.mas.DefaultEnvironment)
    mcapl_home: <dir>                   # optional; else MCAPL_HOME / AJPF_HOME
    timeout_s: 600                      # per AJPF run, seconds (with SPIN: per tool
                                        # run and for the exploration, default 300)
    results: backends/ajpf/results      # where imported logs are looked for
    log_info: [ ... ]                   # loggers at info level in the .jpf
    model_checker: spin                 # or ajpf (default: see model_checking.backend)
    environment: {percepts: [...]}      # SPIN: the verification environment
    max_states: 100000                  # SPIN: exploration bounds
    max_depth: 10000
    properties: [file.psl, ...]         # extra properties, one obligation each

With ``model_checker: spin`` the evidence comes from
:mod:`rclverify.backends.model_checking.backend` (SPIN on rclverify's own
exploration of the Gwendolen program) instead of AJPF.  The plan entry is
checked by :mod:`.config`.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Mapping, Sequence

from jinja2 import Environment, PackageLoader, StrictUndefined

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.lang import ast
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.model_checking.payload import AjpfPayload
from rclverify.backends.model_checking.ajpf.config import DEFAULT_TIMEOUT_S, AjpfConfig, fixed_names, io_sides, read_config
from rclverify.backends.model_checking.ajpf.coverage import coverage_notes
from rclverify.backends.model_checking.ajpf import psl, runner
from rclverify.backends.model_checking.ajpf.instantiate import Instance, Translator
from rclverify.backends.model_checking.ajpf.results import AjpfResult, parse_log
from rclverify.backends.shapes import AjpfData

TOOL = "AJPF (MCAPL)"
#: this backend's declaration (its folder's declaration.yaml)
_DECLARED = declared_in(__file__)


@lru_cache(maxsize=1)  # one environment per process: jinja2 then compiles each template once
def _templates() -> Environment:
    return Environment(loader=PackageLoader("rclverify.backends.model_checking.ajpf", "templates"), undefined=StrictUndefined,
                       keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True, autoescape=False)


# ---------------------------------------------------------------------------
# The backend
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Property:
    number: int
    text: str
    comments: list[str] = field(default_factory=list)


class AjpfBackend:
    """Model checking of Gwendolen agents with AJPF (``backend: ajpf``)."""

    name = _DECLARED.name
    kind = _DECLARED.evidence_kind

    def __init__(self) -> None:
        self._runs: dict[tuple[str, str], tuple[runner.RunOutcome, AjpfResult, str]] = {}

    # -- export ------------------------------------------------------------
    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render ``agent.psl``, ``agent.ail`` and ``agent_<n>.jpf`` under
        ``target.artifacts`` and return one obligation per guarantee instance.

        Raises :class:`PlanError` for a bad plan entry (see :func:`read_config`).
        """
        cfg = read_config(target)
        node = target.node
        translator = Translator(cfg.rows, cfg.domains, fixed_names(target), io_sides(target))
        art = target.artifacts
        art.mkdir(parents=True, exist_ok=True)
        psl_rel = target.rel(art / "agent.psl")
        ail_rel = target.rel(art / "agent.ail")
        node_src = self._src(target, node.node.loc)

        numbers: dict[str, int] = {}
        props: list[_Property] = []
        unmapped_lines: list[str] = []
        planned: list[tuple[int, ast.Clause, Instance]] = []
        for g, clause in enumerate(node.node.guarantees, 1):
            for inst in translator.guarantee(clause.formula, g):
                planned.append((g, clause, inst))
                where = f"{node.name} guarantee {g} ({self._src(target, clause.loc, col=True)})"
                what = f"instance {inst.label}" if inst.label else "the guarantee"
                if inst.formula is None:
                    unmapped_lines.append(f"{where}, {what}: {'; '.join(inst.unmapped)}")
                    continue
                text = psl.to_text(inst.formula)
                if text not in numbers:
                    numbers[text] = len(numbers) + 1
                    props.append(_Property(numbers[text], text))
                props[numbers[text] - 1].comments.append(f"{where}, {what}")

        env = _templates()
        atomic_write_text(art / "agent.psl", env.get_template("agent.psl.j2").render(
            source=node_src, node=node.name, agent=cfg.agent, plan=target.plan_file,
            properties=props, unmapped=unmapped_lines))
        atomic_write_text(art / "agent.ail", env.get_template("agent.ail.j2").render(
            source=node_src, node=node.name, environment_class=cfg.environment_class, model=cfg.model))
        jpf_tpl = env.get_template("agent.jpf.j2")
        current = set()
        for p in props:
            jpf_path = art / f"agent_{p.number}.jpf"
            current.add(jpf_path.name)
            atomic_write_text(jpf_path, jpf_tpl.render(
                source=node_src, node=node.name, number=p.number, text=p.text, comments=p.comments,
                psl=psl_rel, ail=ail_rel, log_info=cfg.log_info,
                command=runner.user_command(target.rel(jpf_path), self._log_rel(cfg, target, p.number))))
        for old in art.glob("agent_*.jpf"):
            if old.name not in current:
                old.unlink()

        texts = {(g, inst.label): psl.to_text(inst.formula) for g, _, inst in planned if inst.formula is not None}
        coverage = coverage_notes(cfg.rows, [(g, inst) for g, _, inst in planned], texts)
        per_guarantee: dict[int, list[str]] = {}
        for g, _, inst in planned:
            for u in inst.unmapped:
                if u not in per_guarantee.setdefault(g, []):
                    per_guarantee[g].append(u)
        from rclverify.backends.model_checking.backend import extra_obligations  # deferred: start-up (loads rclverify.backends.model_checking, rclverify.lang.source and more only when called)
        return [self._obligation(target, cfg, g, clause, inst, numbers, psl_rel, ail_rel, per_guarantee.get(g, []),
                                 coverage.get((g, inst.label), []))
                for g, clause, inst in planned] + extra_obligations(target, cfg.spin, cfg.agent, cfg.model)

    def _obligation(self, target: NodeTarget, cfg: AjpfConfig, g: int, clause: ast.Clause, inst: Instance,
                    numbers: Mapping[str, int], psl_rel: str, ail_rel: str, g_unmapped: Sequence[str],
                    partial: Sequence[str] = ()) -> Obligation:
        node = target.node.name
        values = "_".join(f"{k}{v}" for k, v in inst.values)
        file, line, col = self._src_parts(target, clause.loc)
        data: AjpfData = {
            "instance": dict(inst.values), "rows": list(inst.rows), "notes": list(inst.notes),
            "unmapped": list(inst.unmapped), "guarantee_unmapped": list(g_unmapped), "agent": cfg.agent,
        }
        if inst.formula is None:
            shown = f" at {inst.label}" if inst.label else ""
            return Obligation(
                id=make_obligation_id(node, g, self.name, f"unmapped_{values}" if values else "unmapped"),
                node=node, guarantee=g, backend=self.name, kind=self.kind,
                statement=(f"no AJPF property for guarantee {g}{shown}: RCL atoms without a mapping row: "
                           + "; ".join(inst.unmapped)),
                source=SourceRef(file, line, col), instance=inst.label, artifact=psl_rel,
                inputs=tuple(sorted(set(target.contract_files) | {target.plan_file})), data=data)
        text = psl.to_text(inst.formula)
        n = numbers[text]
        jpf_rel = target.rel(target.artifacts / f"agent_{n}.jpf")
        log_rel = self._log_rel(cfg, target, n)
        data["property"], data["psl"], data["trivial"], data["jpf"] = n, text, inst.trivial, jpf_rel
        data["ail"], data["log"], data["command"] = ail_rel, log_rel, runner.user_command(jpf_rel, log_rel)
        if partial:
            data["coverage"], data["coverage_notes"] = "partial", list(partial)
        return Obligation(
            id=make_obligation_id(node, g, self.name, f"p{n}_{values}" if values else f"p{n}"),
            node=node, guarantee=g, backend=self.name, kind=self.kind, statement=f"{n}: {text}",
            source=SourceRef(file, line, col), instance=inst.label, artifact=jpf_rel,
            inputs=(cfg.model, psl_rel, jpf_rel, ail_rel, log_rel), data=data)

    # -- run ---------------------------------------------------------------
    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Evidence for one exported obligation (:meth:`_run_one`), with the
        obligation's partial coverage (see :mod:`.coverage`) stated first in
        its explanation; a verified property that covers its guarantee only
        partially is ``inconclusive``, not ``discharged``."""
        ev = self._run_one(obligation, target)
        notes = obligation.data.get("coverage_notes") or []
        if not notes:
            return ev
        status = "inconclusive" if ev.status == "discharged" else ev.status
        prefix = "PARTIAL COVERAGE of guarantee " + str(obligation.guarantee) + ": " + "; ".join(notes) + ". "
        if ev.status == "discharged":
            prefix += f"{ev.tool.split()[0]} verified the property, but it does not check the whole guarantee. "
        return replace(ev, status=status, explanation=prefix + ev.explanation)

    def _run_one(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Evidence for one exported obligation.

        Order: an obligation with unmapped atoms is ``pending``; with
        ``model_checker: spin`` SPIN gives the evidence; a log at
        ``data["log"]`` is imported; else AJPF runs when MCAPL is installed;
        else ``pending`` with the command to run.  Never ``discharged``
        without a log of a completed AJPF search saying "no errors detected".
        """
        clock = Stopwatch()
        data = obligation.data
        if "property" not in data and "claim" not in data:
            return make_evidence(
                target, obligation, "pending", tool=TOOL, tool_version="", clock=clock,
                explanation=("no AJPF property: " + "; ".join(data.get("unmapped", []))
                             + " -- add mapping rows for these atoms to the plan"),
                details=AjpfPayload.checked({"unmapped": list(data.get("unmapped", []))}))
        from rclverify.backends.model_checking.backend import run_spin  # deferred: start-up (loads rclverify.backends.model_checking, rclverify.lang.source and more only when called)
        from rclverify.backends.model_checking.spin_config import chosen_checker, spin_timeout  # deferred: start-up (loads rclverify.backends.model_checking, rclverify.lang.source and more only when called)
        if chosen_checker(target.config) == "spin":
            return run_spin(obligation, target, str(target.config["model"]), spin_timeout(target.config))
        if "log" not in data:  # a property of the plan's `properties` files
            return make_evidence(
                target, obligation, "pending", tool=TOOL, tool_version="", clock=clock,
                explanation=(f"the AJPF runner checks the derived properties of agent.psl only; check "
                             f"{data.get('property_file')} with model_checker: spin, or run AJPF on it yourself"))
        log_rel = str(data["log"])
        log_path = target.root / log_rel
        if log_path.is_file():
            return self._import(obligation, target, log_path, clock)
        cfg_home = target.config.get("mcapl_home")
        install, reason = runner.locate(cfg_home if isinstance(cfg_home, str) else None, target.root)
        if install is None:
            return make_evidence(
                target, obligation, "pending", tool=TOOL, tool_version="not installed", clock=clock,
                explanation=(f"{reason}. Run from the workspace root: {data['command']} "
                             f"(then re-run the verification to import {log_rel})"),
                artifacts=(str(data["jpf"]),),
                details=AjpfPayload.checked({"command": data["command"], "reason": reason}))
        return self._run(obligation, target, install, clock)

    def _import(self, obligation: Obligation, target: NodeTarget, log_path: Path, clock: Stopwatch) -> Evidence:
        data = obligation.data
        log_rel = str(data["log"])
        text = log_path.read_text(encoding="utf-8", errors="replace")
        res = parse_log(text)
        n = str(data["property"])
        arts = (str(target.rel(target.artifacts / "agent.psl")), str(data["jpf"]), log_rel)
        if res.property_name is not None and (res.property_name != n
                                              or Path(res.psl_file or "").name != "agent.psl"):
            return make_evidence(
                target, obligation, "pending", tool=TOOL, tool_version=res.tool_version, clock=clock,
                log=text, artifacts=arts,
                explanation=(f"the log {log_rel} is of property {res.property_name!r} of {res.psl_file}, "
                             f"not of property {n} of agent.psl; run: {data['command']}"))
        echo = res.checks(str(data["psl"]))
        if echo is False:
            return make_evidence(
                target, obligation, "stale", tool=TOOL, tool_version=res.tool_version, clock=clock, log=text,
                artifacts=arts,
                explanation=(f"the log {log_rel} checked another text of property {n} than the current one "
                             f"(the contract, mapping or numbering changed since); run: {data['command']}"))
        status, why = _status(res, timed_out=False, returncode=None)
        note = "" if echo else " (the log does not echo the property text, so it was matched by number only)"
        return make_evidence(
            target, obligation, status, tool=TOOL, tool_version=res.tool_version, clock=clock, log=text,
            artifacts=arts, counterexample=res.counterexample(),
            explanation=f"imported AJPF log {log_rel}: {why}{note}",
            details=AjpfPayload.checked({"verdict": res.verdict, "property": data["property"], "psl": data["psl"],
                                         "errors": list(res.errors), "constraints": res.constraints,
                                         "elapsed": res.elapsed, "imported": True, "property_echoed": echo}))

    def _run(self, obligation: Obligation, target: NodeTarget, install: runner.McaplInstall,
             clock: Stopwatch) -> Evidence:
        data = obligation.data
        jpf_rel = str(data["jpf"])
        n = int(data["property"])
        key = (jpf_rel, _digest(target.root, obligation.inputs[:4]))
        timeout = float(target.config.get("timeout_s", DEFAULT_TIMEOUT_S))
        if key not in self._runs:
            try:
                outcome = runner.run(install, target.root, jpf_rel, timeout, where=target.config_loc("backend"))
            except OSError as exc:
                return make_evidence(target, obligation, "error", tool=TOOL, tool_version="", clock=clock,
                                     explanation=f"AJPF could not be started: {exc}")
            out_log = target.artifacts / f"agent_{n}.log"
            atomic_write_text(out_log, outcome.log)
            self._runs[key] = (outcome, parse_log(outcome.log), target.rel(out_log))
        outcome, res, out_rel = self._runs[key]
        status, why = _status(res, outcome.timed_out, outcome.returncode, timeout)
        return make_evidence(
            target, obligation, status, tool=TOOL, tool_version=res.tool_version, clock=clock, log=outcome.log,
            artifacts=(str(target.rel(target.artifacts / "agent.psl")), jpf_rel, out_rel),
            counterexample=res.counterexample(), explanation=f"AJPF run ({install.source}): {why}",
            details=AjpfPayload.checked({
                "verdict": res.verdict, "property": n, "psl": data["psl"], "errors": list(res.errors),
                "constraints": res.constraints, "elapsed": res.elapsed, "returncode": outcome.returncode,
                "timed_out": outcome.timed_out, "duration_s": outcome.duration_s, "log_file": out_rel}))

    # -- internals ---------------------------------------------------------
    @staticmethod
    def _log_rel(cfg: AjpfConfig, target: NodeTarget, n: int) -> str:
        return f"{cfg.results}/{target.node.name}/agent_{n}.log"

    @staticmethod
    def _src_parts(target: NodeTarget, loc: ast.Loc) -> tuple[str, int, int]:
        p = Path(loc.file)
        file = loc.file
        if p.is_absolute():
            try:
                file = p.resolve().relative_to(target.root.resolve()).as_posix()
            except ValueError:
                file = p.name
        return file, loc.line, loc.col

    def _src(self, target: NodeTarget, loc: ast.Loc, col: bool = False) -> str:
        file, line, c = self._src_parts(target, loc)
        return f"{file}:{line}:{c}" if col else f"{file}:{line}"


def _digest(root: Path, paths: Sequence[str]) -> str:
    h = hashlib.sha256()
    for p in paths:
        try:
            h.update((root / p).read_bytes())
        except OSError:
            h.update(b"missing")
    return h.hexdigest()


def _status(res: AjpfResult, timed_out: bool, returncode: int | None, timeout: float | None = None
            ) -> tuple[str, str]:
    """Evidence status and a sentence for one AJPF result."""
    if res.verdict == "verified":
        return "discharged", "no errors detected: the property holds on every path of the agent program"
    if res.verdict == "violated":
        steps = len(res.accepting_path)
        return "failed", f"property violated: AJPF found an accepting path of {steps} states (counterexample)"
    if res.verdict == "incomplete-search":
        return "inconclusive", (f"no errors detected, but {res.constraints} search constraint(s) were hit, "
                                "so the state space was not fully explored")
    if res.verdict == "error":
        return "error", "AJPF reported an error other than a property violation: " + "; ".join(res.errors)
    if timed_out:
        return "inconclusive", f"AJPF did not finish within {timeout:g} s"
    if returncode is None:
        return "inconclusive", "the log has no results section: the search did not finish"
    return "error", f"AJPF stopped without a results section (exit code {returncode})"
