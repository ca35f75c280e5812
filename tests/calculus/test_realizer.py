"""Realizability witnesses (calculus/health/realizer.py): output terms answering every
admissible input, checked against enumeration on small random contracts; the
second solver decides the witness's quantifier-free query in its shared
solver (stages/crosscheck/items.py), and a contract without a witness keeps the
realizability query."""
from __future__ import annotations

import itertools
import json
import re
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from rclverify.calculus.health.realizable import realizability_findings
from rclverify.semantics import world
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check

from test_realizable import D, _holds, _random_contract


def _findings(text: str, facts: list[str] = ()):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "c.rcl")])
    world.fresh()
    node = next(iter(checked.nodes))
    return realizability_findings(checked, node, [(parse_formula(f), parse_formula(f).loc) for f in facts])


def _value(term: str, ins: dict[str, object]) -> object:
    """An RCL witness term (``in.a + 1``, ``-2 * in.b``, ``3``, ``TRUE``) at the inputs ``ins``."""
    py = re.sub(r"\bin\.(\w+)", lambda m: f"v['{m.group(1)}']", term).replace("TRUE", "True").replace("FALSE", "False")
    return eval(py, {"v": ins})  # noqa: S307 (terms this module's contracts produced)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_every_witness_answers_every_admissible_input_by_enumeration(seed: int) -> None:
    """The oracle: the witness terms, evaluated at every input of the small domain its assumption and
    facts admit, satisfy every guarantee and the facts over the outputs."""
    text, facts = _random_contract(seed)
    found = [f for f in _findings(text, facts) if f.status == "ok"]
    if not found or found[0].witness is None:
        return
    w = found[0].witness
    assert set(w) == {"out.y", "out.z"} or set(w) <= {"out.y", "out.z"}, w
    a = re.search(r"assume\( (.*?) \)", text).group(1)  # type: ignore[union-attr]
    gs = re.findall(r"guarantee\( (.*?) \)", text)
    dom = range(D + 1)
    for x, y in itertools.product(dom, dom):
        ins = {"a": x, "b": y}
        if not all(_holds(p, ins) for p in a.split(" and ")):
            continue
        outs = {k.split(".")[1]: _value(t, ins) for k, t in w.items()}
        v = {**ins, "y": outs.get("y", 0), "z": outs.get("z", False)}
        assert 0 <= v["y"] <= D, (text, w, ins)
        assert all(_holds(g, v) for g in gs), (text, w, ins, v)


def test_witnesses_are_found_on_the_random_contracts() -> None:
    """The oracle above is not vacuous: most realizable contracts of its family get a witness."""
    ok = with_witness = 0
    for seed in range(40):
        text, facts = _random_contract(seed)
        for f in _findings(text, facts):
            if f.status == "ok":
                ok += 1
                with_witness += f.witness is not None
    assert ok >= 10 and with_witness >= ok * 3 // 4, (ok, with_witness)


def test_constant_affine_enumeration_and_none() -> None:
    chain = ("node N { inputs( x : REAL ) outputs( y : REAL ) assume( 0 <= in.x and in.x <= 1000 ) "
             "guarantee( out.y <= in.x + 1 ) guarantee( 0 <= out.y ) }")
    [f] = _findings(chain)
    assert f.status == "ok" and f.witness == {"out.y": "0"} and "For instance out.y = 0 answers" in f.message
    assert "(check-sat)" in f.witness_smt2 and "forall" not in f.witness_smt2
    [f] = _findings("node S { inputs( r : REAL ) outputs( d : REAL ) assume( TRUE ) guarantee( out.d == 1000 * in.r ) }")
    assert f.witness == {"out.d": "1000 * in.r"}
    [f] = _findings("context { S : {a, b, c} ; } node E { inputs( x : REAL ) outputs( s : S ) assume( TRUE ) "
                    "guarantee( out.s != a ) guarantee( out.s != c ) }")
    assert f.witness == {"out.s": "b"}
    # |x| is no constant or affine function of x: realizable, no witness, the query stays quantified
    [f] = _findings("node A { inputs( x : REAL ) outputs( y : REAL ) assume( TRUE ) guarantee( out.y >= in.x ) "
                    "guarantee( out.y >= 0 - in.x ) }")
    assert f.status == "ok" and f.witness is None and not f.witness_smt2 and "For instance" not in f.message
    # a quantifier in the contract: no witness (cvc5 would need a fresh solver either way)
    [f] = _findings("node Q { inputs( x : INTEGER ) outputs( y : INTEGER ) assume( TRUE ) "
                    "guarantee( forall(k in INTEGER | (0 <= k and k <= 3) -> out.y >= k) ) }")
    assert f.status == "ok" and f.witness is None


def test_an_unrealizable_contract_has_no_witness() -> None:
    [f] = _findings("node C { inputs( x : INTEGER ) outputs( y : INTEGER ) assume( TRUE ) "
                    "guarantee( out.y == in.x ) guarantee( out.y <= 10 ) }")
    assert f.status == "problem" and f.witness is None and f.to_json()["witness"] is None


def test_the_second_solver_decides_the_witness_query_and_the_report_believes_it(tmp_path: Path) -> None:
    """A chain's realizable nodes are decided from their witness scripts (two solvers, a checked
    proof); a node without a witness keeps the realizability query; the report's findings carry the
    witness row's agreement."""
    from rclverify.cli.commands import main
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/c.rcl").write_text(
        "node P { inputs( x : REAL ) outputs( y : REAL ) topics( t/X x matches(in.x), t/Y y matches(out.y) ) "
        "assume( 0 <= in.x ) guarantee( out.y == in.x + 1 ) }\n"
        "node A { inputs( y : REAL ) outputs( z : REAL ) topics( t/Y y matches(in.y), t/Z z matches(out.z) ) "
        "assume( TRUE ) guarantee( out.z >= in.y and out.z >= 0 - in.y ) }\n")
    (tmp_path / "contracts/plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    assert main(["verify", "-w", str(tmp_path)]) == 0
    rows = {r["id"]: r for r in json.loads((tmp_path / "artifacts/crosscheck/index.json").read_text())["items"]}
    p, a = rows["P.realizable"], rows["A.realizable"]
    assert p["via"] == "witness" and p["smt2"] == "artifacts/health/P.realizable.witness.smt2"
    assert p["agreement"] == "two solvers" and p["cvc5"]["proof_checked"] and "witness query" in p["why"]
    assert "via" not in a and a["smt2"] == "artifacts/health/A.realizable.smt2" and a["agreement"] == "two solvers"
    findings = {f["id"]: f for f in json.loads((tmp_path / "reports/assurance.json").read_text())["findings"]}
    assert findings["P.realizable"]["witness"] == {"out.y": "in.x + 1"}
    assert findings["P.realizable"]["solvers"]["agreement"] == "two solvers"
    assert findings["P.realizable"]["solvers"]["smt2"] == "artifacts/health/P.realizable.witness.smt2"
