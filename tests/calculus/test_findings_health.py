"""Health findings about what guarantees constrain (calculus/health/shape.py)."""
from __future__ import annotations

from pathlib import Path

from rclverify.calculus.health.checks import check_node
from rclverify.calculus.health.shape import shape_findings
from rclverify.lang.lint import lint
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check, load

TEXT = """
node N {
  inputs( a : REAL )
  outputs( o : REAL, spare : REAL )
  assume( 0 <= in.a )
  guarantee( out.o >= in.a and (out.o == out.o or in.a > 3) )
  guarantee( in.a >= 0 )
  guarantee( out.o >= 0 )
}
"""


def _findings(text: str = TEXT):
    checked = check([parse_text(text, "n.rcl")])
    return {f.id: f for f in shape_findings(checked, "N")}


def test_a_tautological_guarantee_conjunct_is_a_problem_with_its_location():
    fs = _findings()
    f = fs["N.g1.c2.tautology"]
    assert f.status == "problem" and f.guarantee == 1
    assert "n.rcl:6:" in f.message and "always true" in f.message
    assert "N.g1.c1.tautology" not in fs  # out.o >= in.a is a real constraint


def test_an_output_no_guarantee_constrains_is_reported_once_by_the_lint():
    # one finding, one place: the lint's W-unconstrained-output (located at the
    # output's declaration) says it; the health checks do not say it again
    spec = parse_text(TEXT, "n.rcl")
    diags = [d for d in lint(spec) if d.code == "W-unconstrained-output"]
    assert [(d.loc.line, "spare" in d.message) for d in diags] == [(4, True)]
    assert not any(f.check == "unconstrained-output" or "out.spare" in f.id for f in _findings().values())
    checked = check([parse_text(TEXT, "n.rcl")])
    assert not any("constrained by no guarantee" in f.message or "out.spare" in f.id for f in check_node(checked, "N"))


def test_a_guarantee_about_inputs_only_constrains_no_output():
    fs = _findings()
    f = fs["N.g2.constrains-no-output"]
    assert f.status == "problem" and f.guarantee == 2
    assert [k for k in fs if k.endswith("constrains-no-output")] == ["N.g2.constrains-no-output"]


def test_a_conjunct_implied_by_the_others_is_redundant():
    fs = _findings()
    # out.o >= 0 follows from out.o >= in.a and the assumption 0 <= in.a
    assert fs["N.g3.c1.redundant"].status == "warning"
    # the tautology is reported as such, not again as redundant
    assert "N.g1.c2.redundant" not in fs
    assert "N.g1.c1.redundant" not in fs


def test_check_node_includes_the_shape_findings():
    checked = check([parse_text(TEXT, "n.rcl")])
    ids = [f.id for f in check_node(checked, "N")]
    assert "N.g1.c2.tautology" in ids and "N.g2.constrains-no-output" in ids


def test_the_case_study_has_no_such_finding():
    checked = load([Path(__file__).resolve().parents[2] / "contracts" / "remote_inspection.rcl"])
    for n in ("Localisation", "Navigation", "RadiationSensor"):
        assert shape_findings(checked, n) == [], n


def test_a_lone_tautological_conjunct_is_found():
    text = "node N {\n  inputs( a : REAL )\n  outputs( o : REAL )\n  guarantee( out.o == out.o )\n}\n"
    assert _findings(text)["N.g1.c1.tautology"].status == "problem"


def test_validity_is_asked_only_of_a_conjunct_the_others_imply(monkeypatch):
    # a counterexample to "implied by the others" falsifies the conjunct alone too, so the
    # tautology query runs only for the conjuncts that are implied (or undecided)
    from rclverify.calculus.health import shape
    asked: list[str] = []
    real = shape.prove

    def spy(goal, hyps, enc, **kw):
        asked.append(kw["comment"].split(": ", 1)[1])
        return real(goal, hyps, enc, **kw)
    monkeypatch.setattr(shape, "prove", spy)
    fs = _findings()
    valid_asked = sorted(q for q in asked if "valid on its own" in q)
    # of the four conjuncts g1.c1 is the one the rest do not imply (g1.c2 is a tautology,
    # g2.c1 restates the assumption, g3.c1 follows from g1.c1 and the assumption)
    assert valid_asked == [f"is conjunct {j} of guarantee {k} valid on its own?" for k, j in ((2, 1), (3, 1))] + [
        "is conjunct 2 of guarantee 1 valid on its own?"]
    assert len(asked) == 4 + 3
    assert {k for k in fs if k.endswith((".tautology", ".redundant"))} == {
        "N.g1.c2.tautology", "N.g2.c1.redundant", "N.g3.c1.redundant"}
