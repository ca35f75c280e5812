"""Tests of the experiment backend: the paper's Navigation figures, criteria,
summary-statistics consistency, per-trial data and plots, located plan errors."""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.backends.experiment.consistency import check
from rclverify.backends.experiment.criterion import evaluate
from rclverify.backends.experiment.figures import DataError, load_summary, load_trials, quantity
from rclverify.backends.experiment.plot import render_svg
from rclverify.records.store import EvidenceStore
from rclverify.app.pipeline import Workspace, stage_check, stage_export, stage_run
from rclverify.lang.parser import parse_formula
from rclverify.backends.payloads import payload_of
from rclverify.report.evidence_rows import evidence_extras as _evidence_extras
from rclverify.app.tasks import act_check

from _evidence_ws import copy_workspace, plan_line, replace_in_plan

PAPER = "count: 47\nmean: 21.4 cm\nstd: 4 mm\nbest: 8 cm\nworst: 43 cm\n"
E0 = "Navigation.g1.experiment.e0"
E1 = "Navigation.g1.experiment.e1"


@pytest.fixture()
def ws(tmp_path: Path) -> Workspace:
    copy_workspace(tmp_path)
    return Workspace(tmp_path)


def run_navigation(ws: Workspace) -> dict[str, object]:
    stage_check(ws)
    obligations = stage_export(ws, "Navigation")
    return {o.id: stage_run(ws, "Navigation", o.id) for o in obligations}


def test_quantities_are_exact_in_base_units() -> None:
    assert quantity("4 mm").value == Fraction(1, 250) and quantity("4 mm").dim == "length"
    assert quantity("21.4 cm").value == Fraction(214, 1000)
    assert quantity(47).dim == "1"
    with pytest.raises(DataError, match="unknown unit 'furlong'"):
        quantity("3 furlong")


def test_paper_figures_miss_the_worst_case_criterion_with_the_figures(ws: Workspace) -> None:
    ev = run_navigation(ws)[E0]
    assert ev.status == "failed"  # type: ignore[attr-defined]
    text = ev.explanation  # type: ignore[attr-defined]
    assert "misses the criterion worst <= tolerance" in text
    for fig in ("count 47", "mean 21.4 cm", "std 4 mm", "best 8 cm", "worst 43 cm", "tolerance (constant) 25 cm"):
        assert fig in text
    assert ev.details["criterion_holds"] is False  # type: ignore[attr-defined]
    bounds = {f["bound"] for f in ev.details["flags"]}  # type: ignore[attr-defined]
    assert bounds == {"Samuelson's inequality", "spread of best and worst"}


def test_paper_mean_argument_holds_but_is_not_discharged(ws: Workspace) -> None:
    ev = run_navigation(ws)[E1]
    assert ev.details["criterion_holds"] is True  # type: ignore[attr-defined]
    assert ev.status == "inconclusive"  # type: ignore[attr-defined]
    assert "cannot all be true together" in ev.explanation  # type: ignore[attr-defined]


def test_paper_statistics_are_flagged_with_the_bound_in_words() -> None:
    flags = check(load_summary(PAPER, "nav.yaml"))
    spread = next(f for f in flags if f["bound"] == "spread of best and worst")["explanation"]
    assert "47 trials with smallest 8 cm, largest 43 cm and mean 21.4 cm" in spread
    assert "at least 3.712 cm (population; 3.752 cm as a sample deviation)" in spread
    assert spread.endswith("the reported deviation is 4 mm")


@pytest.mark.parametrize("text, bound", [
    ("count: 47\nmean: 21.4 cm\nstd: 4 cm\nbest: 8 cm\nworst: 43 cm\n", None),
    ("count: 10\nmean: 5 cm\nstd: 6 cm\nbest: 0 cm\nworst: 10 cm\n", "Bhatia-Davis inequality"),
    ("count: 10\nmean: 50 cm\nstd: 1 cm\nbest: 8 cm\nworst: 43 cm\n", "mean between extremes"),
    ("count: 3\nmean: 1.1 cm\nstd: 1 cm\nbest: 1 cm\nworst: 3 cm\n", "mean with one trial at each extreme"),
    ("count: 1\nmean: 2 cm\nstd: 1 cm\nbest: 2 cm\nworst: 2 cm\n", "single trial"),
])
def test_consistency_bounds(text: str, bound: str | None) -> None:
    flags = check(load_summary(text, "s.yaml"))
    assert [f["bound"] for f in flags][:1] == ([bound] if bound else [])


def test_bounds_accept_a_real_sample() -> None:
    # the summary of an actual sample can never be flagged (population or sample std)
    values = [8, 20, 21, 22, 21, 43, 19, 18, 24, 21]
    n, m = len(values), Fraction(sum(values), len(values))
    ss = sum((v - m) ** 2 for v in values)
    for var in (ss / n, ss / (n - 1)):
        s = float(var) ** 0.5 + 1e-9 if var == ss / n else float(var) ** 0.5
        text = f"count: {n}\nmean: {float(m)} cm\nstd: {s:.9f} cm\nbest: {min(values)} cm\nworst: {max(values)} cm\n"
        assert check(load_summary(text, "s.yaml")) == []


def _crit(text: str) -> object:
    return parse_formula(text, "plan.yaml", 1, 1)


def test_per_trial_criterion_names_the_failing_trials() -> None:
    fig = load_trials("trial,error\n1,10\n2,30\n3,20\n4,26\n", "runs.csv", "error", "cm")
    consts = {"tolerance": quantity("25 cm")}
    v = evaluate(_crit("error <= tolerance"), fig, consts)  # type: ignore[arg-type]
    assert v.holds is False and v.failing == (2, 4) and v.per_trial
    assert evaluate(_crit("mean <= tolerance"), fig, consts).holds is True  # type: ignore[arg-type]


def test_mean_plus_two_std_is_exact() -> None:
    # values 0 and 2 cm: mean 1 cm, sample std sqrt(2) cm; 1 + 2*sqrt(2) = 3.828... cm
    fig = load_trials("e\n0\n2\n", "r.csv", "e", "cm")
    below, above = {"tolerance": quantity("3.828 cm")}, {"tolerance": quantity("3.829 cm")}
    assert evaluate(_crit("mean + 2 * std <= tolerance"), fig, below).holds is False  # type: ignore[arg-type]
    assert evaluate(_crit("mean + 2 * std <= tolerance"), fig, above).holds is True  # type: ignore[arg-type]


#: the text of the Navigation's guarantee 1 (contracts/remote_inspection.rcl), as rclverify prints it
NAVIGATION_G1 = ("forall(x, y in REAL | in.command == move(x, y) and in.position(x, y) == TRUE <=> "
                 "out.at(x, y) == TRUE)")


def test_per_trial_data_end_to_end_with_plot(ws: Workspace) -> None:
    root = ws.root
    (root / "backends/experiment/runs.csv").write_text("trial,error\n1,10\n2,12\n3,9\n", encoding="utf-8")
    replace_in_plan(root, "summary: backends/experiment/navigation.yaml\n        constants: {tolerance: 25 cm}\n"
                    "        criterion: \"worst <= tolerance\"",
                    "data: backends/experiment/runs.csv\n        column: error\n        unit: cm\n"
                    "        constants: {tolerance: 25 cm}\n        criterion: \"error <= tolerance\"\n"
                    f"        answers: \"{NAVIGATION_G1}\"")
    ev = run_navigation(Workspace(root))[E0]
    assert ev.status == "discharged", ev.explanation  # type: ignore[attr-defined]
    svg = root / ev.details["plot"]  # type: ignore[attr-defined]
    first = svg.read_bytes()
    assert first.lstrip().startswith(b"<?xml") and b"tolerance (25 cm)" in first
    stage_run(Workspace(root), "Navigation", E0)
    assert svg.read_bytes() == first  # deterministic
    figures, plot_svg = _evidence_extras(Workspace(root), payload_of("experiment", ev.details))  # type: ignore[attr-defined]
    assert plot_svg.startswith("<svg") and ["worst", "0.12 m"] in figures
    # a trial beyond the tolerance makes it failed, naming the trial
    (root / "backends/experiment/runs.csv").write_text("trial,error\n1,10\n2,31\n3,9\n", encoding="utf-8")
    assert EvidenceStore(root).current_status(ev) == "stale"  # type: ignore[arg-type]
    ev2 = stage_run(Workspace(root), "Navigation", E0)
    assert ev2.status == "failed" and "on 1 of 3 trials (trials 2)" in ev2.explanation
    assert ev2.counterexample == {"trial 2": "0.31 m"}


def test_svg_has_no_date() -> None:
    svg = render_svg(load_summary(PAPER, "n.yaml"), {"tolerance": quantity("25 cm")}, "t")
    assert "<dc:date>" not in svg and "tolerance (25 cm)" in svg


def test_missing_data_file_is_a_located_error_at_check_time(ws: Workspace) -> None:
    replace_in_plan(ws.root, "summary: backends/experiment/navigation.yaml", "summary: backends/experiment/nope.yaml")
    line, col = plan_line(ws.root, "backends/experiment/nope.yaml")
    out = act_check(str(ws.root))
    assert out is not None
    assert (f"contracts/plan.yaml:{line}:{col}: error: experiment summary file "
            "'backends/experiment/nope.yaml' does not exist") in str(out)


def test_bad_criterion_is_located_inside_the_criterion(ws: Workspace) -> None:
    replace_in_plan(ws.root, 'criterion: "worst <= tolerance"', 'criterion: "worst <= tolerence"')
    line, col = plan_line(ws.root, "tolerence")
    out = str(act_check(str(ws.root)))
    assert f"contracts/plan.yaml:{line}:{col}: error: experiment criterion: unknown name 'tolerence'" in out


def test_criterion_comparing_a_length_with_a_number_is_refused(ws: Workspace) -> None:
    replace_in_plan(ws.root, 'criterion: "worst <= tolerance"', 'criterion: "worst <= 25"')
    assert "a comparison needs quantities of one dimension" in str(act_check(str(ws.root)))


def test_bundled_plan_checks(ws: Workspace) -> None:
    assert act_check(str(ws.root)) is None


def test_division_by_a_zero_figure_is_undecided_not_failed() -> None:
    fig = load_summary("count: 3\nmean: 0 cm\nstd: 0 cm\nbest: 0 cm\nworst: 0 cm\n", "z.yaml")
    v = evaluate(_crit("worst / mean <= 2"), fig, {})  # type: ignore[arg-type]
    assert v.holds is None


def test_experiments_support_one_text_not_a_guarantee_number(ws: Workspace) -> None:
    """Issue 63: an experiment judged good supports the guarantee text its
    plan entry names (``answers:``); without one it discharges nothing, and
    once the guarantee reads otherwise it is stale."""
    root = ws.root
    (root / "backends/experiment/runs.csv").write_text("trial,error\n1,10\n2,12\n3,9\n", encoding="utf-8")
    data = ("data: backends/experiment/runs.csv\n        column: error\n        unit: cm\n"
            "        constants: {tolerance: 25 cm}\n        criterion: \"error <= tolerance\"")
    replace_in_plan(root, "summary: backends/experiment/navigation.yaml\n        constants: {tolerance: 25 cm}\n"
                    "        criterion: \"worst <= tolerance\"", data)
    ev = run_navigation(Workspace(root))[E0]
    assert ev.status == "pending" and "does not say which text of guarantee 1" in ev.explanation  # type: ignore[attr-defined]
    assert f'answers: "{NAVIGATION_G1}"' in ev.explanation  # type: ignore[attr-defined]
    replace_in_plan(root, data, data + f'\n        answers: "{NAVIGATION_G1}"')
    assert run_navigation(Workspace(root))[E0].status == "discharged"  # type: ignore[attr-defined]
    rcl = root / "contracts/remote_inspection.rcl"
    text = rcl.read_text(encoding="utf-8")
    assert text.count("out.at(x, y) == TRUE)") == 1
    rcl.write_text(text.replace("out.at(x, y) == TRUE)", "out.at(x, y) == TRUE and in.command == move(x, y))"),
                   encoding="utf-8")
    ev = run_navigation(Workspace(root))[E0]
    assert ev.status == "stale" and "the experiments support 'forall(x, y in REAL" in ev.explanation  # type: ignore[attr-defined]
