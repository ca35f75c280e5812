"""The plan entry of the ``experiment`` backend, read and checked with locations.

::

    - backend: experiment
      guarantee: 1                       # the guarantee the experiments support
      answers: "<the guarantee's RCL>"   # the text they support: another text now -> stale
      summary: backends/experiment/navigation.yaml   # summary statistics, or
      # data: runs.csv + column: error + unit: cm    # one row per trial
      better: lower                      # per-trial data: lower is better (default)
      constants: {tolerance: 25 cm}      # named bounds, with units
      criterion: "worst <= tolerance"    # RCL expression over the figures
      timeout_ms: 10000                  # Z3 budget per evaluation

Every mistake is a :class:`~rclverify.model.plan.errors.PlanError` located in the
plan (the criterion's own errors at the offending sub-expression).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import read_yaml_text
from rclverify.lang.source import read_text as read_source
from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_formula
from rclverify.backends.experiment.criterion import CriterionError, allowed_dims, dimension
from rclverify.backends.experiment.figures import DataError, Figures, Quantity, load_summary, load_trials, quantity

Locate = Callable[..., ast.Loc]


@dataclass(frozen=True)
class ExperimentConfig:
    """A checked plan entry: ``file`` is the data file (workspace-relative)."""

    guarantee: int
    file: str
    figures: Figures
    constants: Mapping[str, Quantity]
    criterion_text: str
    criterion: ast.Expr
    timeout_ms: int
    answers: str | None = None  # the guarantee text the plan says the experiments support


def _err(loc: ast.Loc, msg: str) -> PlanError:
    return plan_error(loc.file, loc.line, loc.col, msg, "E-plan")


def read_config(root: Path, config: Mapping[str, Any], guarantees: int, loc: Locate) -> ExperimentConfig:
    """Check the entry ``config`` of a node with ``guarantees`` guarantee clauses.

    ``loc(*path, key=False)`` gives where a value of the entry is written.
    Raises :class:`PlanError`.
    """
    g = config.get("guarantee", 1 if guarantees == 1 else None)
    if g is None:
        raise _err(loc(key=False), f"experiment: name the guarantee the experiments support (guarantee: 1..{guarantees})")
    if isinstance(g, bool) or not isinstance(g, int) or not 1 <= g <= guarantees:
        raise _err(loc("guarantee"), f"experiment: guarantee must be 1..{guarantees}, found {g!r}")
    kinds = [k for k in ("summary", "data") if k in config]
    if len(kinds) != 1:
        raise _err(loc(), "experiment: give exactly one of 'summary' (summary statistics, YAML) or 'data' "
                   "(one row per trial, CSV)")
    key = kinds[0]
    rel = config[key]
    if not isinstance(rel, str) or not (root / rel).is_file():
        raise _err(loc(key), f"experiment {key} file {rel!r} does not exist")
    if key == "summary":
        text = read_yaml_text(root / rel, rel)  # size bound and UTF-8 rules; errors located in the file
    else:  # a CSV file: the UTF-8 rules, no YAML size bound
        try:
            text = read_source(root / rel, rel)
        except RclError as exc:
            raise PlanError(exc.diagnostics) from None
    try:
        if key == "summary":
            figures = load_summary(text, rel)
        else:
            for k in ("column", "unit"):
                if not isinstance(config.get(k), str):
                    raise _err(loc(), f"experiment: per-trial data needs '{k}' (the measured column and its unit)")
            better = str(config.get("better", "lower"))
            if better not in ("lower", "higher"):
                raise _err(loc("better"), f"experiment: better must be 'lower' or 'higher', found {better!r}")
            figures = load_trials(text, rel, config["column"], config["unit"], better)
    except DataError as exc:
        raise _err(loc(key), f"experiment data: {exc}") from None
    raw_consts = config.get("constants", {}) or {}
    if not isinstance(raw_consts, dict):
        raise _err(loc("constants"), "experiment: constants must be a mapping name: quantity (e.g. tolerance: 25 cm)")
    constants: dict[str, Quantity] = {}
    for name, raw in raw_consts.items():
        if name in figures.stats or name == figures.column:
            raise _err(loc("constants", name, key=True), f"experiment: constant {name!r} hides a figure of the same name")
        try:
            constants[str(name)] = quantity(raw)
        except DataError as exc:
            raise _err(loc("constants", name), f"experiment: constant {name}: {exc}") from None
    text_c = config.get("criterion")
    if not isinstance(text_c, str) or not text_c.strip():
        raise _err(loc(), "experiment: give the acceptance criterion, e.g. criterion: \"worst <= tolerance\"")
    cl = loc("criterion")
    try:
        expr = parse_formula(text_c, cl.file, cl.line, cl.col)
    except RclError as exc:
        raise PlanError(exc.diagnostics) from None
    try:
        dimension(expr, allowed_dims(figures, constants))
    except CriterionError as exc:
        l = exc.loc if exc.loc.line else cl
        raise _err(l, f"experiment criterion: {exc.message}") from None
    timeout = config.get("timeout_ms", 10000)
    if isinstance(timeout, bool) or not isinstance(timeout, int) or timeout <= 0:
        raise _err(loc("timeout_ms"), f"experiment: timeout_ms must be a positive whole number, found {timeout!r}")
    answers = config.get("answers")
    if answers is not None and (not isinstance(answers, str) or not answers.strip()):
        raise _err(loc("answers"), "experiment: answers is the text of the guarantee the experiments support, "
                   "as RCL (a string)")
    return ExperimentConfig(g, rel, figures, constants, text_c.strip(), expr, timeout, answers)
