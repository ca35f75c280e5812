"""The ``experiment`` backend: experiment figures judged by an acceptance criterion.

The paper verifies the Navigation node by simulation experiments against the
move_base goal tolerance and reports only summary statistics (47 runs, mean
21.4 cm, standard deviation 4 mm, best 8 cm, worst 43 cm, tolerance 25 cm;
shared/reference lines 1318-1329).  This backend records such evidence:

* ``export`` checks the plan entry (:mod:`.config`) and exports one
  obligation: the criterion over the data file, supporting one guarantee;
* ``run`` evaluates the criterion exactly with Z3 (:mod:`.criterion`), checks
  summary statistics for consistency (:mod:`.consistency`), draws the plot
  ``artifacts/experiment/<Node>/<obligation>.svg`` (:mod:`.plot`) and
  decides the status:

  - criterion false -> ``failed``, with the figures (and the failing trials);
  - criterion true but the statistics cannot all be true together ->
    ``inconclusive`` (the figures do not establish anything);
  - criterion true, figures consistent -> ``discharged``;
  - Z3 undecided -> ``inconclusive``; a plan/data problem at run time -> ``error``.
"""
from __future__ import annotations

from typing import Any

import z3

from rclverify.model.plan.declarations import declared_in
from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.store import atomic_write_text
from rclverify.model.plan.errors import PlanError
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.experiment.config import ExperimentConfig, read_config
from rclverify.backends.experiment.consistency import check, figures_json
from rclverify.backends.experiment.criterion import evaluate
from rclverify.backends.experiment.figures import format_value
from rclverify.backends.experiment.plot import render_svg
from rclverify.core.extras import MissingExtra
from rclverify.backends.experiment.payload import ExperimentPayload
from rclverify.backends.experiment.target import run_target, target_obligations
from rclverify.backends.shapes import ExperimentDetails

#: this backend's name and evidence kind, as its declaration.yaml states them
_DECLARED = declared_in(__file__)
NAME, KIND = _DECLARED.name, _DECLARED.evidence_kind


def load(target: NodeTarget) -> ExperimentConfig:
    """The checked plan entry of ``target``.  Raises :class:`PlanError`."""
    def loc(*path: Any, key: bool = False) -> ast.Loc:
        return target.config_loc(*path, key=key)
    return read_config(target.root, target.config, len(target.node.node.guarantees), loc)


def _figure_rows(cfg: ExperimentConfig) -> list[list[str]]:
    rows = [[k, q.show()] for k, q in cfg.figures.stats.items()]
    rows += [[f"{k} (constant)", q.show()] for k, q in sorted(cfg.constants.items())]
    return rows


def _failing_trials(cfg: ExperimentConfig, failing: tuple[int, ...]) -> dict[str, str] | None:
    """The trials that miss a per-trial criterion (at most 20), value in base units."""
    if not failing:
        return None
    return {f"trial {i}": format_value(cfg.figures.trials[i - 1], cfg.figures.dim) for i in failing[:20]}


class ExperimentBackend:
    """Experiments judged against an acceptance criterion (``kind`` ``experiment``).

    Paper: Navigation node, lines 1318-1329.
    """

    name = NAME
    kind = KIND

    def export(self, target: NodeTarget) -> list[Obligation]:
        """One obligation for the entry.  Raises :class:`PlanError` (located)."""
        cfg = load(target)
        g = target.node.node.guarantees[cfg.guarantee - 1]
        oid = make_obligation_id(target.node.name, cfg.guarantee, NAME, f"e{target.index}")  # a target: one more (target.py)
        statement = (f"criterion {cfg.criterion_text} holds on {cfg.file} "
                     f"(supports guarantee {cfg.guarantee}: {expr_to_rcl(g.formula)})")
        ob = Obligation(
            id=oid, node=target.node.name, guarantee=cfg.guarantee, backend=NAME, kind=KIND, statement=statement,
            source=SourceRef(g.loc.file, g.loc.line, g.loc.col), instance=f"e{target.index}",
            artifact=target.rel(target.artifacts / f"{oid}.svg") if target.artifacts.is_absolute() else "",
            inputs=tuple(sorted({cfg.file, *target.contract_files, target.plan_file})),
            data={"criterion": cfg.criterion_text, "file": cfg.file,
                  "constants": {k: q.show() for k, q in sorted(cfg.constants.items())}})
        return [ob, *target_obligations(target, ob)]

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Evaluate the criterion and return the evidence record (never raises
        for a user-caused problem)."""
        clock = Stopwatch()

        def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
            return make_evidence(target, obligation, status, tool="z3", tool_version=z3.get_version_string(),
                                 clock=clock, explanation=explanation, **kw)

        try:
            cfg = load(target)
        except PlanError as exc:
            return evidence("error", f"the experiment entry no longer checks: {exc}", log=str(exc))
        verdict = evaluate(cfg.criterion, cfg.figures, cfg.constants, cfg.timeout_ms)
        if obligation.data.get("target") is not None:  # the entry's target over its trials (target.py)
            return run_target(obligation, target, cfg, verdict, "z3", z3.get_version_string())
        flags = check(cfg.figures)
        svg_path = target.artifacts / f"{obligation.id}.svg"
        title = f"{target.node.name}: {cfg.criterion_text}"
        try:
            atomic_write_text(svg_path, render_svg(cfg.figures, cfg.constants, title))
            plot, plot_note = target.rel(svg_path), ""
        except MissingExtra as exc:  # the plot illustrates; the verdict below does not rest on it
            svg_path.unlink(missing_ok=True)
            plot, plot_note = None, f"; no plot drawn: {exc}"
        figures = ", ".join(f"{k} {v}" for k, v in _figure_rows(cfg))
        details: ExperimentDetails = {
            "criterion": cfg.criterion_text, "file": cfg.file, "figures": figures_json(cfg.figures),
            "constants": {k: q.show() for k, q in sorted(cfg.constants.items())},
            "criterion_holds": verdict.holds, "flags": flags, "per_trial": verdict.per_trial,
            "failing_trials": list(verdict.failing),
            "figures_table": _figure_rows(cfg) + [[f"flag: {f['bound']}", f["explanation"]] for f in flags],
            "plot": plot,
        }
        log = "\n".join([f"criterion: {cfg.criterion_text}", f"figures: {figures}",
                         f"criterion holds: {verdict.holds}"] + [f"flag: {f['bound']}: {f['explanation']}" for f in flags])
        log += plot_note.replace("; ", "\n", 1)
        kw: dict[str, object] = dict(log=log, artifacts=(plot,) if plot else (),
                                   details=ExperimentPayload.checked(details))
        flag_text = ("; the summary statistics cannot all be true together: "
                     + "; ".join(f"{f['bound']}: {f['explanation']}" for f in flags)) if flags else ""
        if verdict.holds is False:
            where = (f" on {len(verdict.failing)} of {len(cfg.figures.trials)} trials "
                     f"(trials {', '.join(map(str, verdict.failing[:20]))}{' ...' if len(verdict.failing) > 20 else ''})"
                     if verdict.per_trial else "")
            return evidence("failed", f"the data in {cfg.file} misses the criterion {cfg.criterion_text}{where}: "
                            f"{figures}{flag_text}", counterexample=_failing_trials(cfg, verdict.failing), **kw)
        if verdict.holds is None:
            return evidence("inconclusive", f"Z3 could not decide the criterion {cfg.criterion_text} on "
                            f"{figures} (timeout of {cfg.timeout_ms} ms, or a division by a figure that is zero)"
                            f"{flag_text}", **kw)
        if flags:
            return evidence("inconclusive", f"the criterion {cfg.criterion_text} holds on the reported figures "
                            f"({figures}), but they establish nothing{flag_text}", **kw)
        text = expr_to_rcl(target.node.node.guarantees[cfg.guarantee - 1].formula)
        if cfg.answers is None:  # bound to a number only: the text may have changed under it
            return evidence("pending", f"the criterion {cfg.criterion_text} holds on the data in {cfg.file} "
                            f"({figures}), but the plan entry does not say which text of guarantee {cfg.guarantee} "
                            f"the experiments support: add answers: \"{text}\" if they support it", **kw)
        if " ".join(cfg.answers.split()) != " ".join(text.split()):
            return evidence("stale", f"the experiments support {cfg.answers.strip()!r}; guarantee {cfg.guarantee} now "
                            f"reads {text!r}: judge the experiments against it again and update answers", **kw)
        return evidence("discharged", f"the criterion {cfg.criterion_text} holds on the data in {cfg.file}: {figures}",
                        **kw)
