"""``rclverify quotient`` (issue 43; docs/calculus.md, "The quotient"): the
weakest contract of a node declared by its interface only, exact for linear
arithmetic, re-checked by Z3; its result checked against brute-force
enumeration on small random systems."""
from __future__ import annotations

import contextlib
import io
import random
import re
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _chain import write_chain
from rclverify.calculus.quotient import QuotientError, quotient
from rclverify.cli.commands import main
from rclverify.semantics import world
from rclverify.semantics.evaluate import evaluate
from rclverify.lang.parser import parse_formula
from rclverify.stages.workspace import Workspace


def _rclverify(ws: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """``rclverify ARGS -w WS`` in this process (the CLI's entry point, its output captured)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([args[0], "-w", str(ws), *args[1:]])
    return subprocess.CompletedProcess(list(args), code, out.getvalue(), err.getvalue())


def test_the_middle_node_of_a_chain_gets_the_weakest_contract_which_puts_in_place_proves_everything(tmp_path: Path) -> None:
    ws = write_chain(tmp_path / "ws", 3, missing=[1], requirements=[("REQ", "N2.out.x3 <= 60")])
    proc = _rclverify(ws, "quotient", "N1", "-o", str(tmp_path / "n1.rcl"))
    assert proc.returncode == 0, proc.stderr
    text = (tmp_path / "n1.rcl").read_text(encoding="utf-8")
    # exact: x1 in [0, 51] from x0 in [0, 50] and N0; N2's side conditions need 0 <= x2 <= 100, REQ x2 <= 59
    assert "assume( 0 <= in.x1 and in.x1 <= 51 )" in text
    assert "guarantee( 0 <= out.x2 and out.x2 <= 59 )" in text
    assert "exact" in text and "REQ proved" in text and "N2.sc2 discharged" in text
    # every proved re-check decided again by cvc5 from its script (issue 50; docs/second-solver.md)
    said = re.search(r"// Second solver \(cvc5\) on each proved re-check: (.*)\.\n", text)
    assert said and "REQ two solvers" in said.group(1) and "N2.sc2 two solvers" in said.group(1), text
    # put in place by hand: every side condition discharged (compose exits 0), the requirement met
    rcl = ws / "contracts/chain.rcl"
    block = re.search(r"node N1 \{.*?\n\}\n", text, re.S).group(0)  # type: ignore[union-attr]
    rcl.write_text(re.sub(r"node N1 \{.*?\n\}\n", block, rcl.read_text(encoding="utf-8"), flags=re.S),
                   encoding="utf-8")
    proc = _rclverify(ws, "compose")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "[failed]" not in proc.stdout and "N1.sc2 [discharged in context]" in proc.stdout
    proc = _rclverify(ws, "requirements")
    assert proc.returncode == 0 and "REQ" in proc.stdout and "proved" in proc.stdout, proc.stdout + proc.stderr


def test_a_re_check_the_second_solver_does_not_confirm_is_not_a_contract(tmp_path: Path) -> None:
    """cvc5 given a satisfiable query for each proved re-check (a planted wrong script): it disagrees, and the
    contract does not re-check."""
    pytest.importorskip("cvc5")
    from rclverify.stages.crosscheck.stage import confirm_proof
    ws = Workspace(write_chain(tmp_path / "ws", 3, missing=[1]), interface_only=("N1",))
    with pytest.raises(QuotientError, match=r"does not re-check with Z3 and cvc5: .*inconclusive \(second solver: "
                                            r"Z3 answered unsat, cvc5 sat\)"):
        quotient(ws.checked, ws.model, ws.plan, "N1",
                 confirm=lambda _: confirm_proof("(declare-fun x () Real)\n(assert (> x 1.0))\n(check-sat)\n"))
    world.fresh()


def test_stdout_without_output_option_and_the_errors(tmp_path: Path) -> None:
    ws = write_chain(tmp_path / "ws", 3, missing=[1])
    proc = _rclverify(ws, "quotient", "N1")
    assert proc.returncode == 0 and proc.stdout.startswith("// rclverify quotient N1")
    assert "guarantee( 0 <= out.x2 and out.x2 <= 100 )" in proc.stdout  # no requirement: N2's side conditions only
    # only the node asked about may lack its contract; the pipeline itself still wants a guarantee, and says
    # where the missing one comes from
    for args in (("quotient", "N2"), ("compose",)):
        proc = _rclverify(ws, *args)
        assert proc.returncode == 1 and "node N1 has no guarantee" in proc.stderr, proc.stderr
        assert "rclverify quotient N1" in proc.stderr and "Traceback" not in proc.stderr
    full = write_chain(tmp_path / "full", 3)
    proc = _rclverify(full, "quotient", "N9")
    assert proc.returncode == 1 and "no node named 'N9'" in proc.stderr and "Traceback" not in proc.stderr
    proc = _rclverify(full, "quotient", "N2")  # the last node: nothing downstream, no requirement
    assert proc.returncode == 1 and "any contract serves" in proc.stderr


LOOP = """node Ctl {
  inputs( y : REAL )
  outputs( u : REAL )
  assume( 0 <= in.y and in.y <= 10 )
  guarantee( 0 <= out.u and out.u <= 1 )
}
node Plant {
  inputs( u : REAL )
  outputs( y : REAL )
  assume( 0 <= in.u and in.u <= 1 )
  guarantee( 0 <= out.y and out.y <= 10 * in.u )
}
"""


def test_a_node_on_a_loop_is_computed_with_the_loop_opened_by_r4(tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/loop.rcl").write_text(LOOP)
    (tmp_path / "contracts/plan.yaml").write_text("name: loop\ncontracts:\n  - contracts/loop.rcl\n")
    proc = _rclverify(tmp_path, "quotient", "Plant")
    assert proc.returncode == 0, proc.stderr
    assert "lies on the loop {Ctl, Plant}" in proc.stdout or "lies on the loop {Plant, Ctl}" in proc.stdout
    assert "R4" in proc.stdout and "Ctl.sc1 discharged; Ctl.sc2 discharged" in proc.stdout
    assert "guarantee( 0 <= out.y and out.y <= 10 )" in proc.stdout


ENUM = """
context { Level : {lo, hi} ; }
node S { inputs( e : REAL ) outputs( v : REAL ) assume( TRUE ) guarantee( out.v == in.e ) }
node M { inputs( v : REAL ) outputs( level : Level ) }
node C { inputs( level : Level ) outputs( w : REAL ) assume( in.level == lo ) guarantee( out.w == 0 ) }
"""


def test_beyond_linear_arithmetic_a_sound_approximation_is_offered_and_said(tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts/sys.rcl").write_text(ENUM, encoding="utf-8")
    (tmp_path / "contracts/plan.yaml").write_text("name: enum\ncontracts:\n  - contracts/sys.rcl\n", encoding="utf-8")
    proc = _rclverify(tmp_path, "quotient", "M")
    assert proc.returncode == 0, proc.stderr
    assert "sound approximation, not the weakest contract" in proc.stdout
    assert "guarantee( out.level == lo )" in proc.stdout and "C.sc1 discharged" in proc.stdout


def test_a_replaced_node_is_compared_with_the_computed_contract(tmp_path: Path) -> None:
    ws = write_chain(tmp_path / "ws", 3, weak={1: 70})  # N1 has a contract: x2 <= x1 + 70 is too weak for N2
    proc = _rclverify(ws, "quotient", "N1")
    assert proc.returncode == 0, proc.stderr
    assert "current assumption of N1 holds wherever the computed one does: yes" in proc.stdout
    assert "current guarantee of N1 gives what the neighbours need: no" in proc.stdout


# ---- the oracle: the quotient against brute-force enumeration ---------------------------------------

D = 3


def _atom(rng: random.Random, a: str, b: str | None) -> str:
    c = rng.randint(0, D)
    if b is None:
        return rng.choice([f"{a} <= {c}", f"{a} >= {c}"])
    return rng.choice([f"{a} <= {b} + {c % 2}", f"{a} + {c % 2} >= {b}", f"{a} == {b}", f"{a} <= {c}"])


def _system(seed: int) -> tuple[str, list[str], str | None]:
    """N0 (e -> y0), M (y0 -> y1, interface only), N2 (y1 -> y2); integers
    bounded to 0..D by plan facts; maybe a requirement over y2 and y0."""
    rng = random.Random(seed)
    text = (f"node N0 {{ inputs( e : INTEGER ) outputs( y0 : INTEGER ) assume( {_atom(rng, 'in.e', None)} ) "
            f"guarantee( {_atom(rng, 'out.y0', 'in.e')} ) }}\n"
            "node M { inputs( y0 : INTEGER ) outputs( y1 : INTEGER ) }\n"
            f"node N2 {{ inputs( y1 : INTEGER ) outputs( y2 : INTEGER ) assume( {_atom(rng, 'in.y1', None)} ) "
            f"guarantee( {_atom(rng, 'out.y2', 'in.y1')} ) }}\n")
    facts = [f"0 <= in.e and in.e <= {D} and 0 <= out.y0 and out.y0 <= {D}",
             f"0 <= in.y0 and in.y0 <= {D} and 0 <= out.y1 and out.y1 <= {D}",
             f"0 <= in.y1 and in.y1 <= {D} and 0 <= out.y2 and out.y2 <= {D}"]
    req = rng.choice([None, f"N2.out.y2 <= {rng.randint(0, D)}", f"N2.out.y2 <= N0.out.y0 + {rng.randint(0, 1)}"])
    return text, facts, req


def _holds(text: str, v: dict[str, int]) -> bool:
    """An RCL atom of :func:`_system` on integers (independent of rclverify's evaluator)."""
    py = re.sub(r"\b(in|out)\.(\w+)", lambda m: f"v['{m.group(2)}']", text)
    return bool(eval(py.replace("N2.v", "v").replace("N0.v", "v"), {"v": v}))  # noqa: S307 (our own atoms)


def _brute(text: str, facts: list[str], req: str | None) -> tuple[dict[int, bool], dict[tuple[int, int], bool]]:
    """A(i) and G(i, o) by enumeration, as docs/calculus.md defines them."""
    nodes = re.findall(r"node (\w+) \{.*?assume\( (.*?) \) guarantee\( (.*?) \) \}", text)
    n0, n2 = nodes[0], nodes[1]
    rng = range(D + 1)
    # A(i): some environment input meets N0's assumption (an environment assumption) and its guarantee gives i
    a = {i: any(_holds(n0[1], {"e": e}) and _holds(n0[2], {"e": e, "y0": i}) for e in rng) for i in rng}
    g = {}
    for i in rng:
        for o in rng:
            ok = True
            for e in rng:  # N2's side condition: premises N0 (conditional) and the env assumption of N0
                if _holds(n0[1], {"e": e}) and _holds(n0[2], {"e": e, "y0": i}) and not _holds(n2[1], {"y1": o}):
                    ok = False
            if req is not None:
                for e in rng:
                    for y2 in rng:  # the requirement: N0's and N2's guarantees unconditional, N0's env assumption
                        if (_holds(n0[1], {"e": e}) and _holds(n0[2], {"e": e, "y0": i})
                                and _holds(n2[2], {"y1": o, "y2": y2})
                                and not _holds(req.replace("N2.out.y2", "out.y2").replace("N0.out.y0", "out.y0"),
                                               {"y2": y2, "y0": i})):
                            ok = False
            g[(i, o)] = ok
    return a, g


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_the_quotient_equals_brute_force_enumeration(tmp_path_factory: pytest.TempPathFactory, seed: int) -> None:
    text, facts, req = _system(seed)
    root = tmp_path_factory.mktemp("q")
    (root / "contracts").mkdir()
    (root / "contracts/sys.rcl").write_text(text, encoding="utf-8")
    plan = ["name: q", "contracts:", "  - contracts/sys.rcl"]
    if req:
        plan += ["requirements:", "  - id: R", "    text: r", f'    formal: "{req}"']
    plan += ["environment:"] + [x for n, f in zip(("N0", "M", "N2"), facts) for x in (f"  {n}:", "    facts:", f'      - "{f}"')]
    (root / "contracts/plan.yaml").write_text("\n".join(plan) + "\n", encoding="utf-8")
    ws = Workspace(root, interface_only=("M",))
    world.fresh()
    a_exp, g_exp = _brute(text, facts, req)
    try:
        q = quotient(ws.checked, ws.model, ws.plan, "M")
    except QuotientError as exc:  # only when no contract can serve: a reachable input has no good output
        assert "no contract of M can serve" in str(exc), str(exc)
        i = int(re.search(r"in\.y0 = (\d+)", str(exc)).group(1))  # type: ignore[union-attr]
        assert a_exp[i] and not any(g_exp[(i, o)] for o in range(D + 1)), (text, req, str(exc))
        return
    assert q.exact, q.how
    cm = ws.checked.nodes["M"]
    a_f, g_f = parse_formula(q.assumption), parse_formula(q.guarantee)
    for i in range(D + 1):
        assert evaluate(a_f, ws.checked, cm, {"in.y0": i}) == a_exp[i], (text, req, q.assumption, i)
        if not a_exp[i]:
            continue
        for o in range(D + 1):
            assert evaluate(g_f, ws.checked, cm, {"in.y0": i, "out.y1": o}) == g_exp[(i, o)], \
                (text, req, q.guarantee, i, o)
