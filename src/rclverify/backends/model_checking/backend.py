"""The ``ajpf`` plan entry checked by SPIN on rclverify's exploration of the agent program.

The ``ajpf`` backend (:mod:`rclverify.backends.model_checking.ajpf.backend`) exports one
obligation per guarantee instance and renders them as the numbered
properties of ``agent.psl``; with ``model_checker: spin`` this module gives
their evidence, in two stages as AJPF's own SPIN export does (paper lines
1338-1475 for the case study's properties):

1. stage one explores the Gwendolen program under the plan's verification
   ``environment`` into a :class:`StateGraph` (:mod:`.explore`), once per
   program text, environment and bounds in a process (:data:`_GRAPHS`);
2. stage two renders the graph with every property of the entry as one
   Promela model (:mod:`.promela`), compiles its verifier once
   (:mod:`.spin`) and runs it per property; a violation's trail is mapped
   back to the graph and the Gwendolen source (:mod:`.trail`).

Plan entry keys this module reads (besides the ``ajpf`` ones)::

    model_checker: spin        # or ajpf; default: ajpf when MCAPL is configured
                               # (mcapl_home, MCAPL_HOME, AJPF_HOME) or no
                               # environment is declared, else spin
    environment: {percepts: [...], after: [...], ...}   # see .environment
    max_states: 100000         # exploration bounds (a cut graph is inconclusive)
    max_depth: 10000
    properties: [backends/ajpf/authors.psl]   # extra property files

The SPIN keys of an entry are checked by :mod:`.spin_config`.
"""
from __future__ import annotations

import hashlib
import json
import shutil
import time
from pathlib import Path
from typing import Any, Callable

from rclverify.model.plan.declarations import DECLARATIONS
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.lang.ast import Loc
from rclverify.lang.errors import RclError
from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.model_checking.payload import AjpfPayload
from rclverify.backends.model_checking import spin
from rclverify.backends.model_checking.graph import StateGraph
from rclverify.backends.model_checking.identifiers import named_identifiers, numbers
from rclverify.backends.model_checking.ltl import Propositions, parse_psl_text, read_psl_file
from rclverify.backends.model_checking.promela import Claim, PromelaModel, build_model
from rclverify.backends.model_checking.trail import counterexample, read_replay, summary
from rclverify.backends.model_checking.vacuity import antecedents, check_vacuity, temporal_checks
from rclverify.backends.shapes import SpinDetails
from rclverify.backends.model_checking.spin_config import SpinConfig, read_spin_config


TOOL = "SPIN"
WHAT = "checked by SPIN on rclverify's exploration of the Gwendolen program"

#: Explored graphs of this process: key (program text, environment, bounds) -> (graph or the error, seconds).
_GRAPHS: dict[str, tuple[StateGraph | RclError, float]] = {}
#: Built models: key (graph key, claims) -> (model, its verifier's directory, exploration seconds, build seconds).
_MODELS: dict[str, tuple[PromelaModel, Path, float]] = {}
#: Claims of an entry: key (the property files' texts) -> (claims, digest of their names and texts).
_CLAIMS: dict[str, tuple[list[Claim], str]] = {}
#: pan results: (model key, claim) -> result.
_RESULTS: dict[tuple[str, str], spin.CheckResult] = {}
#: Atom truth per graph, for the vacuity check: graph key -> atom -> states where it holds.
_MEMO: dict[str, dict[psl.Formula, frozenset[int]]] = {}


def extra_obligations(target: NodeTarget, cfg: SpinConfig, agent: str, model: str) -> list[Obligation]:
    """One obligation per property of the entry's ``properties`` files,
    ``<Node>.g0.ajpf.<file stem>_<label>`` (guarantee 0: not derived from a
    guarantee).  Raises a located :class:`PlanError` for a bad file."""
    out = []
    declared = DECLARATIONS["ajpf"]  # the model-checking backend's declaration (model_checking/ajpf/)
    for k, rel in enumerate(cfg.properties):
        stem = Path(rel).stem
        for p in read_psl_file(target.root, rel):
            out.append(Obligation(
                id=make_obligation_id(target.node.name, 0, declared.name, f"{stem}_{p.label}"),
                node=target.node.name, guarantee=0, backend=declared.name, kind=declared.evidence_kind, statement=f"{p.label}: {p.text}",
                source=SourceRef(rel, p.line, p.col), instance=f"{stem}:{p.label}", artifact=rel,
                inputs=(model, rel),
                data={"agent": agent, "psl": psl.to_text(p.formula), "property_file": rel, "label": p.label,
                      "claim": f"x{k}_{p.label}"}))
    return out


def _claims(target: NodeTarget, cfg: SpinConfig) -> tuple[list[Claim], str]:
    """Every property of the entry: ``agent.psl``'s (``p<n>``) and the extra files' (``x<k>_<label>``),
    and a digest of their names and texts (read once per content in a process)."""
    psl_path = target.artifacts / "agent.psl"
    texts = [psl_path.read_bytes() if psl_path.is_file() else b""]
    texts += [(target.root / rel).read_bytes() for rel in cfg.properties]
    key = hashlib.sha256(repr((target.rel(psl_path), cfg.properties, texts)).encode()).hexdigest()
    if key not in _CLAIMS:
        derived = parse_psl_text(texts[0].decode("utf-8"), target.rel(psl_path))
        claims = [Claim(f"p{p.label}", p.formula, f"property {p.label} of agent.psl") for p in derived]
        for k, rel in enumerate(cfg.properties):
            claims += [Claim(f"x{k}_{p.label}", p.formula, f"{rel}:{p.line} {p.label}")
                       for p in read_psl_file(target.root, rel)]
        _CLAIMS[key] = (claims, hashlib.sha256(repr([(c.name, psl.to_text(c.formula))
                                                     for c in claims]).encode()).hexdigest())
    return _CLAIMS[key]


def _numbers_of(claims: list[Claim]) -> tuple[float, ...]:
    """Every number in the claims' atoms (a fresh identifier differs from them)."""
    terms = [a.term for c in claims for a in psl.propositions(c.formula) if isinstance(a, (psl.Modal, psl.Percept))]
    return tuple(sorted(numbers(terms)))


def _graph(target: NodeTarget, model: str, cfg: SpinConfig, time_limit_s: float, avoid: tuple[float, ...] = ()
           ) -> tuple[str, StateGraph | RclError, float]:
    """The graph of ``model`` under the entry's environment and bounds (explored once per
    process): its cache key, the graph (or the program's error) and the seconds it took."""
    text = (target.root / model).read_bytes()
    key = hashlib.sha256(text + json.dumps([model, cfg.environment_raw, cfg.max_states, cfg.max_depth,
                                            time_limit_s, avoid], sort_keys=True, default=str).encode()).hexdigest()
    if key not in _GRAPHS:
        from rclverify.backends.model_checking.explore import explore  # stage one; deferred: optional or conditional (inside a block)
        assert cfg.environment is not None  # run_spin checked it
        t0 = time.perf_counter()
        graph: StateGraph | RclError
        try:
            graph = explore(target.root / model, model, cfg.environment, cfg.max_states, cfg.max_depth,
                            time_limit_s, avoid)
        except RclError as exc:  # an error in the program, located in it
            graph = exc
        _GRAPHS[key] = (graph, round(time.perf_counter() - t0, 3))
    return key, *_GRAPHS[key]


def run_spin(obligation: Obligation, target: NodeTarget, model: str, timeout_s: float) -> Evidence:
    """Evidence for one obligation of an ``ajpf`` entry checked by SPIN.

    ``pending`` when SPIN or gcc is missing (with the install command);
    ``error`` for an error in the program or a failed build;
    ``inconclusive`` when the exploration was cut by a bound (SPIN is then
    not run), when pan's search was cut, when the property passes vacuously
    or names an identifier value; ``failed`` with the lasso for a violated
    property; ``discharged`` only when pan searched the whole product of a
    complete graph without error and the property's antecedents hold
    somewhere.  ``timeout_s`` bounds the exploration and each tool run.
    Raises :class:`~rclverify.backends.bounded.ToolInterrupted` when a tool
    was stopped from outside (nothing is recorded then).
    """
    clock = Stopwatch()
    data = obligation.data
    tools, reason = spin.find_tools()
    if tools is None:
        return make_evidence(target, obligation, "pending", tool=TOOL, tool_version="not installed", clock=clock,
                             explanation=f"{reason}; then re-run the verification",
                             details=AjpfPayload.checked({"reason": reason, "install": spin.INSTALL}))
    cfg = read_spin_config(target)
    if cfg.environment is None:
        return make_evidence(target, obligation, "error", tool=TOOL, tool_version=tools.version, clock=clock,
                             explanation="stage one of the model checking (rclverify.backends.model_checking."
                                         "explore, the Gwendolen explorer) is not part of this installation")
    claims, digest = _claims(target, cfg)
    gkey, graph, explore_s = _graph(target, model, cfg, timeout_s, _numbers_of(claims))
    if isinstance(graph, RclError):
        return make_evidence(target, obligation, "error", tool=TOOL, tool_version=tools.version, clock=clock,
                             explanation=f"the agent program could not be explored: {graph}")
    claim = str(data.get("claim") or f"p{data.get('property')}")
    mine = next((c for c in claims if c.name == claim), None)
    if mine is None or psl.to_text(mine.formula) != data.get("psl"):
        return make_evidence(target, obligation, "stale", tool=TOOL, tool_version=tools.version, clock=clock,
                             explanation=f"property {claim} is no longer the one exported; export again")
    return check_graph(obligation, target, graph, claims, claim, tools=tools, graph_key=gkey, claims_key=digest,
                       bounds=(cfg.max_states, cfg.max_depth), explore_s=explore_s, timeout_s=timeout_s, clock=clock,
                       percepts=cfg.environment.percepts)


def _where(target: NodeTarget, graph: StateGraph) -> Loc:
    """Where a stopped tool is reported: the entry's ``model_checker`` key in the plan, else the program."""
    try:
        return target.config_loc("model_checker")
    except (AttributeError, TypeError):  # a target without a plan (tests, a graph checked on its own)
        return Loc(graph.source, 1, 1)


def _vacuity_claims(claims: list[Claim]) -> list[Claim]:
    """For every claim, one claim per temporal antecedent: true exactly when that
    antecedent never holds where it is evaluated (:func:`.vacuity.temporal_checks`)."""
    out = []
    for c in claims:
        for k, a in enumerate(x for x in antecedents(c.formula) if not x.state):
            out.append(Claim(f"v_{c.name}_{k}", temporal_checks(a), f"vacuity of {c.name}: {a.text} never holds"))
    return out


#: How :func:`check_graph` words its evidence: ``(status, why, **make_evidence keywords)``.
_Say = Callable[..., Evidence]


def _not_run(graph: StateGraph, mine: Claim, percepts: tuple[psl.Term, ...], details: SpinDetails) -> str | None:
    """Why SPIN is not run on ``graph`` for the claim ``mine`` (the evidence is
    inconclusive): the exploration was cut, or the claim names an identifier
    value; ``None`` when it is run."""
    if not graph.complete:
        details["spin_verdict"] = "not run"
        details["bounded"] = True
        return (f"the exploration was cut ({graph.cut}), so the graph is not the program's whole state space and "
                "SPIN was not run on it (bounded: raise the bound named to decide)")
    named = named_identifiers(mine.formula, percepts)
    if named:
        details["spin_verdict"] = "not run"
        return (f"the property names an identifier value ({', '.join(named)}); an identifier is any fresh value "
                "(docs/model-checking.md, Identifiers), so the property has no meaning: write '_' at the "
                "identifier's place")
    return None


def _violated(evidence: _Say, target: NodeTarget, graph: StateGraph, mine: Claim, res: spin.CheckResult,
              trail_path: Path, arts: list[str], details: SpinDetails) -> Evidence:
    """SPIN's violation of ``mine`` mapped back to a lasso of ``graph``, its
    steps written to ``trail_path``: failed evidence with the counterexample."""
    props = Propositions([mine.formula])
    try:
        cex = counterexample(graph, read_replay(res.trail), props)
    except ValueError as exc:
        return evidence("error", f"SPIN's trail does not map back to the graph: {exc}", log=res.output + res.trail)
    details["lasso"] = cex
    atomic_write_text(trail_path, "\n".join(cex["trace"]) + "\n")
    arts.append(target.rel(trail_path))
    # the counterexample as AJPF's results give it (a summary and the path, one line per step);
    # the steps as data are details["lasso"]
    return evidence("failed", f"property violated; counterexample: {summary(cex)}", log=res.output,
                    artifacts=tuple(arts), counterexample={"lasso": summary(cex), "trace": cex["trace"]})


def _holds(evidence: _Say, graph: StateGraph, graph_key: str, pml: PromelaModel, mine: Claim,
           run: Callable[[str], spin.CheckResult], res: spin.CheckResult, arts: list[str],
           details: SpinDetails) -> Evidence:
    """The claim holds on every path: discharged unless an antecedent never
    holds (vacuous) or whether it ever holds was not decided (inconclusive)."""
    memo = _MEMO.setdefault(graph_key, {})
    memo.update({a: ks for a, ks in pml.truth.items() if a not in memo})  # the model's own truth table
    vac = check_vacuity(graph, mine.formula, memo)
    vacuous = list(vac.vacuous)
    undecided = []
    aux = [c for c in _vacuity_claims([mine])]
    for a, c in zip(vac.pending, aux):
        r = run(c.name)
        if r.verdict == "holds":
            vacuous.append(f"the antecedent {a.text} holds on no path" + ("" if a.temporal_context else
                                                                          " from the initial state"))
        elif r.verdict != "violated":
            undecided.append(f"whether the antecedent {a.text} ever holds: {r.reason or r.verdict}")
    details["antecedents"] = [{"antecedent": t, "holds_in_state": k} for t, k in vac.witnessed]
    if vacuous:
        details["vacuous"] = vacuous
        return evidence("inconclusive", "the property holds on every path (pan: errors: 0, full search), but "
                                        "vacuously: " + "; ".join(vacuous) + " -- it says nothing about what the "
                                        "agent does (vacuous)", log=res.output, artifacts=tuple(arts))
    if undecided:
        return evidence("inconclusive", "the property holds on every path (pan: errors: 0, full search), but its "
                                        "vacuity was not decided: " + "; ".join(undecided),
                        log=res.output, artifacts=tuple(arts))
    return evidence("discharged", "the property holds on every path (pan: errors: 0, full search), and every "
                                  "antecedent holds in some state (not vacuous)", log=res.output, artifacts=tuple(arts))


def check_graph(obligation: Obligation, target: NodeTarget, graph: StateGraph, claims: list[Claim], claim: str, *,
                tools: spin.Tools, graph_key: str, bounds: tuple[int, int], claims_key: str | None = None,
                explore_s: float = 0.0, timeout_s: float = spin.DEFAULT_TIMEOUT_S, clock: Stopwatch | None = None,
                percepts: tuple[psl.Term, ...] = ()) -> Evidence:
    """Evidence that ``graph`` satisfies the claim named ``claim`` (one of
    ``claims``, all of which go into one model, built once per
    ``graph_key`` (what identifies the graph) and ``claims_key`` (the claims;
    computed when ``None``)): see :func:`run_spin` for the statuses.
    ``bounds`` are the exploration bounds ``(max_states, max_depth)`` the
    graph was made with, for the record; ``percepts`` the environment's
    declared percepts (a claim naming one of their identifier values is
    inconclusive).  Writes ``spin/model.pml`` and, for a counterexample,
    ``spin/<claim>.trail.txt`` under ``target.artifacts``; the verifier is
    built in the user's cache (:func:`.spin.cache_dir`), never in the
    workspace.  Raises :class:`~rclverify.backends.bounded.ToolInterrupted`
    when a tool was stopped from outside.
    """
    clock = clock or Stopwatch()
    mine = next(c for c in claims if c.name == claim)
    if claims_key is None:
        claims_key = repr([(c.name, psl.to_text(c.formula)) for c in claims])
    spin_dir = target.artifacts / "spin"
    shutil.rmtree(spin_dir / "build", ignore_errors=True)  # verifiers built by earlier versions: never run
    what = (f"{WHAT} {graph.source} under its verification environment ({len(graph.states)} states, "
            f"{len(graph.transitions)} transitions; bounds max_states={bounds[0]}, max_depth={bounds[1]}, "
            f"timeout_s={timeout_s:g})")
    details: SpinDetails = {
        "model_checker": "spin", "claim": claim, "psl": psl.to_text(mine.formula), "states": len(graph.states),
        "transitions": len(graph.transitions), "complete": graph.complete, "cut": graph.cut, "depth": graph.depth,
        "max_states": bounds[0], "max_depth": bounds[1], "timeout_s": timeout_s, "explore_s": explore_s,
        "identifiers": graph.identifiers}

    def evidence(status: str, why: str, **kw: Any) -> Evidence:
        return make_evidence(target, obligation, status, tool=TOOL, tool_version=tools.version, clock=clock,
                             details=AjpfPayload.checked(details), explanation=f"{what}: {why}", **kw)

    refused = _not_run(graph, mine, percepts, details)
    if refused is not None:
        return evidence("inconclusive", refused)
    mkey = hashlib.sha256((graph_key + claims_key).encode()).hexdigest()
    where = _where(target, graph)
    t0 = time.perf_counter()
    if mkey not in _MODELS or not (_MODELS[mkey][1] / "pan").is_file():
        pml = build_model(graph, list(claims) + _vacuity_claims(claims))
        atomic_write_text(spin_dir / "model.pml", pml.text)
        try:
            built = spin.compile_model(tools, pml.text, None, timeout_s, where)
        except spin.CompileError as exc:
            details["spin_verdict"] = "not run"
            return evidence("inconclusive" if exc.timed_out else "error",
                            f"SPIN could not build the verifier: {exc}", log=str(exc))
        _MODELS[mkey] = (pml, built, round(time.perf_counter() - t0, 3))
    pml, built, build_s = _MODELS[mkey]
    depth_bound = max(10_000, 20 * (pml.states + pml.transitions))

    def run(name: str) -> spin.CheckResult:
        if (mkey, name) not in _RESULTS:
            _RESULTS[(mkey, name)] = spin.check(tools, built, name, depth_bound, timeout_s,
                                                size=pml.states + pml.transitions, where=where)
        return _RESULTS[(mkey, name)]

    res = run(claim)
    details["spin_verdict"], details["spin_states_stored"], details["build_s"] = res.verdict, res.stored, build_s
    details["pan_s"], details["promela"] = res.duration_s, target.rel(spin_dir / "model.pml")
    details["propositions"] = dict(pml.props)
    arts = [target.rel(spin_dir / "model.pml")]
    if res.verdict == "violated":
        return _violated(evidence, target, graph, mine, res, spin_dir / f"{claim}.trail.txt", arts, details)
    if res.verdict == "incomplete":
        return evidence("inconclusive", f"SPIN's search was cut: {res.reason}", log=res.output, artifacts=tuple(arts))
    if res.verdict != "holds":
        return evidence("error", f"SPIN failed: {res.reason}", log=res.output, artifacts=tuple(arts))
    return _holds(evidence, graph, graph_key, pml, mine, run, res, arts, details)


def clear_caches() -> None:
    """Forget explored graphs, built models and results (tests; a long-lived process)."""
    _MEMO.clear()
    _GRAPHS.clear()
    _MODELS.clear()
    _RESULTS.clear()
    _CLAIMS.clear()

