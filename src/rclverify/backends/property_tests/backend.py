"""The ``property_tests`` backend: a Python implementation of a node tested
with Hypothesis against the node's contract, every example checked by Z3.

* ``export`` reads the plan entry ``{backend: property_tests, implementation:
  <file.py>:<callable>, max_examples, seed, deadline_ms, steps, bounds, timeout_s}``,
  makes one obligation per guarantee of the node (all guarantees are tested
  on the same examples: same seed, same strategy) and renders one readable
  pytest file, ``artifacts/property_tests/<Node>/test_<node>_e<entry>.py``;
* ``run`` runs Hypothesis for one guarantee (:mod:`.harness`): every valid
  example passed -> ``discharged`` (kind ``testing``: evidence from tests,
  not a proof); a violation -> ``failed`` with the shrunk counterexample;
  Z3 unknown on some example -> ``inconclusive``; an assumption filtering
  cannot satisfy or an implementation that cannot be loaded -> ``error``.

Calling convention and decisions: docs/property-tests.md.  The paper
verifies the case study's nodes by other means (Agent: AJPF, lines
1338-1475; Radiation Sensor: Hoare logic, lines 1476-1541); this backend adds
testing of executable models of the same nodes against the same contracts.
"""
from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

import jinja2

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.model.plan.errors import PlanError
from rclverify.lang.printer import expr_to_rcl
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.timelimit import TimeLimitExceeded, wall_clock_limit
from rclverify.backends.property_tests.closure import import_closure, outside_versions, resolve_closure
from rclverify.backends.property_tests.importpath import on_harness_path
from rclverify.backends.property_tests.declared import declaration_rows, has_declarations
from rclverify.backends.property_tests.seeding import SeedingCut, split_facts
from rclverify.backends.property_tests.at_width import mapping_inputs
from rclverify.backends.property_tests.harness import Config, ConfigError, Outcome, load_implementation, read_config, run_guarantee, versions
import inspect
from rclverify.backends.property_tests.payload import PropertyTestsPayload
from rclverify.backends.shapes import DeclarationRow

#: this backend's name and evidence kind, as its declaration.yaml states them
_DECLARED = declared_in(__file__)
NAME, KIND = _DECLARED.name, _DECLARED.evidence_kind


@lru_cache(maxsize=1)
def _templates() -> jinja2.Environment:
    """One environment per process, so each template is compiled once (as in the other backends)."""
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.property_tests", "templates"),
                              undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True)


def _config(target: NodeTarget) -> Config:
    try:
        return read_config(target.config, target.node, target.root)
    except ConfigError as exc:
        raise target.config_error(str(exc), *exc.path) from None


def _source(target: NodeTarget, loc: Any) -> SourceRef:
    file = Path(str(loc.file))
    text = str(loc.file)
    if file.is_absolute():
        try:
            text = file.resolve().relative_to(target.root.resolve()).as_posix()
        except ValueError:
            pass
    return SourceRef(text, loc.line, loc.col)


def test_file(target: NodeTarget) -> Path:
    """Path of the pytest file rendered for ``target``."""
    stem = re.sub(r"[^0-9a-zA-Z_]", "_", target.node.name).lower()
    return target.artifacts / f"test_{stem}_e{target.index}.py"


def render_tests(target: NodeTarget, cfg: Config, stateful: bool) -> str:
    """Text of the generated pytest file (deterministic: no timestamps)."""
    node = target.node
    guarantees = [dict(index=k, source=str(_source(target, g.loc)), text=expr_to_rcl(g.formula))
                  for k, g in enumerate(node.node.guarantees, 1)]
    assumes = [dict(text=expr_to_rcl(a.formula), source=str(_source(target, a.loc))) for a in node.node.assumes]
    used, unused = split_facts(target.facts, node)
    return _templates().get_template("test_node.py.j2").render(
        node=node.name, implementation=cfg.implementation, plan_file=target.plan_file, entry=target.index,
        seed=cfg.seed, max_examples=cfg.max_examples, steps=cfg.steps, stateful=stateful,
        inputs=[(n, str(t)) for n, t in node.inputs.items()], outputs=[(n, str(t)) for n, t in node.outputs.items()],
        assumes=assumes, guarantees=guarantees, artifact=target.rel(test_file(target)),
        facts=[dict(text=expr_to_rcl(f), source=str(_source(target, f.loc))) for f in used],
        facts_not_used=[dict(text=expr_to_rcl(f), source=str(_source(target, f.loc))) for f in unused])


def _is_class(target: NodeTarget, cfg: Config) -> bool:
    return inspect.isclass(_load(target, cfg))


def _load(target: NodeTarget, cfg: Config) -> Any:
    """The implementation of ``cfg``, imported afresh (:func:`load_implementation`); a file that does not
    import, or lacks the name, is a :class:`~rclverify.model.plan.errors.PlanError` located in the plan."""
    try:
        return load_implementation(target.root, cfg)
    except ConfigError as exc:
        raise target.config_error(str(exc), *exc.path) from None


def _declarations(outcome: Outcome, cfg: Config, target: NodeTarget, k: int) -> tuple[str, str, list[DeclarationRow]]:
    """The declaration rows of guarantee ``k``'s run and the record's status
    and message with them: an initial value outside ``initially`` fails the
    record of guarantee 1 (:mod:`.declared`)."""
    try:  # no initial values from code the evidence does not hash
        impl = load_implementation(target.root, cfg) if target.node.node.initially and not outcome.unhashed else None
    except ConfigError:
        impl = None
    with on_harness_path(target.root, cfg.file):  # the initial values are read as the run calls the code
        rows = declaration_rows(target.checked, target.node, impl, outcome.status, outcome.counterexample,
                                outcome.counts.valid)
    bad = [r for r in rows if r["verdict"] == "false" and r["premise"] == "initial value"]
    if bad and k == 1 and outcome.status != "failed":
        r = bad[0]
        return "failed", f"{cfg.implementation} declares {r['text']} ({r['source']}) but {r['reason']}; {outcome.message}", rows
    held = [r["text"] for r in rows if r["verdict"] == "true"]
    return outcome.status, outcome.message + ("; declarations held: " + ", ".join(held) if held else ""), rows


class PropertyTestsBackend:
    """Hypothesis property tests of a Python implementation, outputs checked by Z3.

    ``name`` ``"property_tests"``, ``kind`` ``"testing"``.
    """

    name = NAME
    kind = KIND

    def export(self, target: NodeTarget) -> list[Obligation]:
        """Render the pytest file; return one obligation per guarantee.

        Raises :class:`~rclverify.model.plan.errors.PlanError` (located in the plan)
        for a bad entry or an implementation that does not import.
        """
        cfg = _config(target)
        path = test_file(target)
        atomic_write_text(path, render_tests(target, cfg, _is_class(target, cfg)))
        closure, outside = import_closure(target.root, cfg.file)  # every workspace module the code imports
        # the mapping and the message definitions tell what each field carries: the inputs' widths
        carried = mapping_inputs(target.root, target.mapping)
        inputs = tuple(sorted({cfg.file, *closure, *target.contract_files, target.plan_file, *carried}))
        imported = outside_versions(outside)
        out = []
        for k, g in enumerate(target.node.node.guarantees, 1):
            out.append(Obligation(
                id=make_obligation_id(target.node.name, k, NAME, f"e{target.index}"), node=target.node.name,
                guarantee=k, backend=NAME, kind=KIND,
                statement=f"{cfg.implementation} meets guarantee {k} of {target.node.name} on every tested input "
                          f"satisfying the assumption: {expr_to_rcl(g.formula)}",
                source=_source(target, g.loc), instance=f"e{target.index}", artifact=target.rel(path),
                inputs=inputs, data={"implementation": cfg.implementation, "max_examples": cfg.max_examples,
                                     "imports_outside_workspace": imported,
                                     "seed": cfg.seed, "guarantee": k}))
        return out

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Run Hypothesis for the obligation's guarantee; return its evidence (never raises
        for a user-caused problem)."""
        clock = Stopwatch()

        def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="hypothesis", tool_version=versions(),
                                 clock=clock, explanation=explanation, **kw)

        try:
            cfg = read_config(target.config, target.node, target.root)
            k = int(obligation.data.get("guarantee", obligation.guarantee))
            if not 1 <= k <= len(target.node.node.guarantees):
                return evidence("error", "the contract no longer has this guarantee; export again")
            path = test_file(target)
            runs = sorted(set(resolve_closure(target.root, cfg.file).files) - set(obligation.inputs))
            if runs:  # the evidence would not hash them
                return evidence("inconclusive", f"{cfg.implementation} now imports {', '.join(runs)}, which the "
                                "obligation does not list as inputs: export again (`doit verify` does)")
            impl = _load(target, cfg)  # imported once for the run: the test file's kind and the run itself
            atomic_write_text(path, render_tests(target, cfg, inspect.isclass(impl)))
            with wall_clock_limit(cfg.timeout_s):
                outcome = run_guarantee(target.checked, target.node, k, cfg, target.root, target.facts, impl,
                                        target.mapping)
        except TimeLimitExceeded as exc:
            return evidence("inconclusive", f"{cfg.implementation}: the run of guarantee {k} {exc} (timeout_s of "
                            f"the plan entry, {target.config_loc('timeout_s') if 'timeout_s' in target.config else 'default'}"
                            "); does the implementation loop forever?",
                            details=PropertyTestsPayload(timeout_s=cfg.timeout_s).details())
        except SeedingCut as exc:  # a loaded machine: no other seed in its place (docs/decisions.md)
            return evidence("inconclusive", f"{cfg.implementation}: the first example of guarantee {k} under the "
                            f"environment facts was not found: Z3's search for it {exc}",
                            details=PropertyTestsPayload(seeding=str(exc)).details())
        except ConfigError as exc:
            return evidence("error", f"{target.config_loc(*exc.path)}: error: {exc}")
        except PlanError as exc:  # the implementation no longer imports
            return evidence("error", str(exc))
        return self._evidence(evidence, outcome, cfg, target, path, k)

    @staticmethod
    def _evidence(evidence: Callable[..., Evidence], outcome: Outcome, cfg: Config, target: NodeTarget, path: Path, k: int) -> Evidence:
        replay = f"python3 -m pytest {target.rel(path)}::test_guarantee_{k}"
        used, unused = split_facts(target.facts, target.node)
        log = "; ".join(f"{a} {b}" for a, b in outcome.counts.as_dict().items())
        cex = outcome.counterexample
        if cex is not None:
            cex = {**cex, "replay": replay}
        status, message = outcome.status, outcome.message
        declarations: list[DeclarationRow] | None = None
        if has_declarations(target.node):  # progress and initial values on the implementation (declared.py)
            status, message, declarations = _declarations(outcome, cfg, target, k)
        payload = PropertyTestsPayload(
            examples=outcome.counts.as_dict(), seed=cfg.seed, max_examples=cfg.max_examples,
            implementation=cfg.implementation, deadline_ms=cfg.deadline_ms, replay=replay,
            facts=[f"{expr_to_rcl(f)} ({_source(target, f.loc)})" for f in used],
            facts_not_used=[f"{expr_to_rcl(f)} ({_source(target, f.loc)}): names an output" for f in unused],
            coverage=outcome.coverage,  # the valid examples' coverage of the assumption's ranges (.coverage)
            unknown_reasons=list(outcome.unknown_reasons), health_check=outcome.health or "",
            imports_not_hashed=list(outcome.unhashed), declarations=declarations)
        return evidence(status, message, log=log, artifacts=(target.rel(path),),
                        counterexample=cex, details=payload.details())
