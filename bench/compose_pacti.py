"""rclverify's calculus and quotient beside Pacti's on the chain of issue 43.

The chain (tests/_chain.py): node ``N<i>`` reads ``x<i>``, writes
``x<i+1>``, assumes ``0 <= x_i <= 100``, guarantees ``x_{i+1} <= x_i + 1``
and ``0 <= x_{i+1}``; the environment gives ``0 <= x0 <= 50``.  In context
``x_i <= 50 + i``, so every assumption holds up to node 50 and node 51's
first fails.

For each N (default 10, 50, 200) and for the chain at N = 10 with node 3's
guarantee weakened to ``x_4 <= x_3 + 70``, in one process:

* **rclverify**: every node's calculus (:func:`rclverify.calculus.compose.compose_node`,
  side conditions locally, then in context), each in a fresh Z3 context as
  the pipeline runs it; the time, how many side conditions were discharged
  locally / in context / failed, and the first node with a failed one;
* **Pacti** (``pip install '.[bench]'``, an optional dependency): the
  environment's contract composed with ``N0``, then ``N1``, ... (polyhedral
  contracts); a node whose assumption the composition so far cannot
  discharge stops it (``IncompatibleArgsError``); the time and that node;
* whether the two verdicts agree: the same first node whose assumption the
  context does not meet (or none).

A last case, the longest chain with every assumption widened to ``x_i <=
300``, holds in context throughout while no side condition holds locally:
the in-context check's cost on a correct design.

Then the quotients (:data:`QUOTIENTS`): ``N1`` declared by its interface
only, after ``N0`` with the requirement ``x2 <= 59``, and between ``N0``
and ``N2`` with the requirement ``x3 <= 60``: ``rclverify quotient`` (in
process) against Pacti's quotient of the top-level contract (``0 <= x0 <=
50``, the requirement) by the other nodes' composition; both times, both
contracts, and whether they agree (Z3: the assumptions equal, or which is
stronger; the guarantees equal where both assumptions hold).  Pacti's
quotient adds the divisor's guarantees to the assumption only when the
top-level assumption refines the divisor's, which ``N2``'s assumption over
the quotient's output prevents in the 3-node case: there its assumption is
``TRUE`` and rclverify's keeps ``0 <= x1 <= 51`` (what ``N0`` guarantees),
a contract Pacti's refines.

    python bench/compose_pacti.py                 # N = 10, 50, 200 and the quotient
    python bench/compose_pacti.py --sizes 10,20   # other sizes
    python bench/compose_pacti.py --smoke         # N = 5, the weakened chain and the quotient: seconds (CI)

Times are CPU seconds of the process (``time.process_time``: the work each
tool does, whatever else the machine runs).  Figures are printed, not asserted; the exit status is 1 only when the two
tools disagree (or the smoke run's own checks fail), so CI can run
``--smoke``.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "tests"))

import z3  # noqa: E402

from _chain import write_chain  # noqa: E402


def rclverify_chain(n: int, weak: dict[int, int] | None = None, bound: int = 100) -> dict[str, Any]:
    """Every side condition of the chain decided by rclverify's calculus."""
    from rclverify.calculus.compose import IN_CONTEXT, compose_node
    from rclverify.semantics import world
    from rclverify.stages.workspace import Workspace
    with tempfile.TemporaryDirectory() as d:
        ws = Workspace(write_chain(Path(d) / "ws", n, weak=weak, bound=bound))
        checked, model = ws.checked, ws.model
        facts = {m: [f.expr for f in fs] for m, fs in ws.plan.facts.items()}
        t0 = time.process_time()
        local = context = failed = 0
        first = None
        for node in checked.nodes:
            world.fresh()
            for sc in compose_node(checked, model, node, facts=facts).side_conditions:
                if sc.verdict == IN_CONTEXT:
                    context += 1
                elif sc.status == "discharged":
                    local += 1
                else:
                    failed += 1
                    first = first if first is not None else int(node[1:])
        return {"seconds": time.process_time() - t0, "local": local, "in context": context, "failed": failed,
                "first": first}


def _pacti() -> Any:
    try:
        import pacti  # noqa: F401
        from pacti.contracts import PolyhedralIoContract
    except ImportError:
        return None
    return PolyhedralIoContract


def _pacti_node(pc: Any, i: int, slope: int, bound: int = 100) -> Any:
    return pc.from_strings(input_vars=[f"x{i}"], output_vars=[f"x{i + 1}"],
                           assumptions=[f"x{i} <= {bound}", f"-x{i} <= 0"],
                           guarantees=[f"x{i + 1} - x{i} <= {slope}", f"-x{i + 1} <= 0"])


def pacti_chain(pc: Any, n: int, weak: dict[int, int] | None = None, bound: int = 100) -> dict[str, Any]:
    """The environment composed with N0, N1, ... by Pacti until an assumption is not met."""
    from pacti.utils.errors import IncompatibleArgsError
    env = pc.from_strings(input_vars=[], output_vars=["x0"], assumptions=[], guarantees=["x0 <= 50", "-x0 <= 0"])
    t0 = time.process_time()
    system, first = env, None
    for i in range(n):
        try:
            system = system.compose(_pacti_node(pc, i, (weak or {}).get(i, 1), bound))
        except (IncompatibleArgsError, ValueError):
            first = i
            break
        if system.a.terms:  # an assumption the composition so far does not discharge is left on the system
            first = i
            break
    return {"seconds": time.process_time() - t0, "first": first}


def _z3_terms(terms: Any, xs: dict[str, z3.ArithRef]) -> z3.BoolRef:
    out = []
    for t in terms:
        lhs = z3.Sum([z3.RealVal(str(c)) * xs.setdefault(v.name, z3.Real(v.name)) for v, c in t.variables.items()]) \
            if t.variables else z3.RealVal(0)
        out.append(lhs <= z3.RealVal(str(t.constant)))
    return z3.And(*out) if out else z3.BoolVal(True)


def _valid(f: z3.BoolRef) -> bool:
    s = z3.Solver()
    s.add(z3.Not(f))
    return s.check() == z3.unsat


#: The quotient cases: (name, chain length, missing node, requirements, Pacti's top-level contract
#: (inputs, outputs, assumptions, guarantees) and the nodes of the divisor).
QUOTIENTS = [
    ("2-node chain N0 -> N1, requirement x2 <= 59", 2, 1, [("REQ", "N1.out.x2 <= 59")],
     (["x0"], ["x2"], ["x0 <= 50", "-x0 <= 0"], ["x2 <= 59"]), [0]),
    ("3-node chain N0 -> N1 -> N2, requirement x3 <= 60", 3, 1, [("REQ", "N2.out.x3 <= 60")],
     (["x0"], ["x3"], ["x0 <= 50", "-x0 <= 0"], ["x3 <= 60"]), [0, 2]),
]


def quotient_case(pc: Any, n: int, missing: int, reqs: Any, top_spec: Any, divisor_nodes: Any) -> dict[str, Any]:
    """One quotient case by rclverify's quotient and, when installed, by Pacti's."""
    from rclverify.calculus.quotient import quotient
    from rclverify.semantics import world
    from rclverify.stages.workspace import Workspace
    with tempfile.TemporaryDirectory() as d:
        ws = Workspace(write_chain(Path(d) / "ws", n, missing=[missing], requirements=reqs),
                       interface_only=(f"N{missing}",))
        world.fresh()
        t0 = time.process_time()
        q = quotient(ws.checked, ws.model, ws.plan, f"N{missing}")
        ours = {"seconds": time.process_time() - t0, "assume": q.assumption, "guarantee": q.guarantee,
                "exact": q.exact}
    if pc is None:
        return {"rclverify": ours}
    t0 = time.process_time()
    ins, outs, a, g = top_spec
    top = pc.from_strings(input_vars=ins, output_vars=outs, assumptions=a, guarantees=g)
    divisor = _pacti_node(pc, divisor_nodes[0], 1)
    for k in divisor_nodes[1:]:
        divisor = divisor.compose(_pacti_node(pc, k, 1))
    theirs = top.quotient(divisor)
    secs = time.process_time() - t0
    world.fresh()
    xs = {f"x{i}": z3.Real(f"x{i}") for i in range(n + 1)}
    a_p, g_p = _z3_terms(theirs.a.terms, xs), _z3_terms(theirs.g.terms, xs)
    ns = {f"in.x{missing}": xs[f"x{missing}"], f"out.x{missing + 1}": xs[f"x{missing + 1}"]}
    a_r, g_r = _rcl_z3(ours["assume"], ns, missing), _rcl_z3(ours["guarantee"], ns, missing)
    if _valid(a_r == a_p):
        assumption = "equal"
    elif _valid(z3.Implies(a_r, a_p)):
        assumption = "rclverify's is stronger: it keeps what the upstream guarantees give (Pacti's contract refines it)"
    else:
        assumption = "DIFFER"
    guarantee = "equal where both assumptions hold" if _valid(z3.Implies(z3.And(a_r, a_p), g_r == g_p)) else "DIFFER"
    return {"rclverify": ours, "pacti": {"seconds": secs, "assume": [str(t) for t in theirs.a.terms],
                                         "guarantee": [str(t) for t in theirs.g.terms]},
            "assumption": assumption, "guarantee": guarantee,
            "agree": "DIFFER" not in assumption + guarantee}


def _rcl_z3(text: str, names: dict[str, z3.ArithRef], k: int) -> z3.BoolRef:
    """An RCL formula of the quotient (linear, over in.x<k> / out.x<k+1>) in Z3, through rclverify's encoder."""
    from rclverify.semantics.encode import Encoder
    from rclverify.lang.parser import parse_formula
    from rclverify.lang.types import REAL, CheckedNode
    from rclverify.lang.typecheck import check
    checked = check([])
    node = CheckedNode(None, {f"x{k}": REAL}, {f"x{k + 1}": REAL})  # type: ignore[arg-type]
    return Encoder(checked.env).formula(parse_formula(text), node, symbols=names)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", default="10,50,200", help="chain lengths (default 10,50,200)")
    p.add_argument("--smoke", action="store_true", help="N = 5, the weakened chain and the quotient: seconds")
    args = p.parse_args(argv)
    pc = _pacti()
    if pc is None:
        print("Pacti is not installed (pip install '.[bench]'): rclverify's figures only")
    sizes = [5] if args.smoke else [int(x) for x in args.sizes.split(",")]
    cases = [(f"chain N={n}", n, None, 100) for n in sizes] + [("chain N=10, node 3 weakened to +70", 10, {3: 70}, 100)]
    if not args.smoke:  # every assumption `x_i <= 300`: all hold in context, none locally
        cases.append((f"chain N={max(sizes)}, assumptions x_i <= 300", max(sizes), None, 300))
    ok = True
    print("CPU seconds of this process (the machine's load does not count)")
    print(f"{'case':38} {'rclverify s':>11} {'local':>5} {'context':>7} {'failed':>6} {'first':>5} "
          f"{'pacti s':>8} {'first':>5}  agree")
    for name, n, weak, bound in cases:
        r = rclverify_chain(n, weak, bound)
        line = (f"{name:38} {r['seconds']:11.3f} {r['local']:5} {r['in context']:7} {r['failed']:6} "
                f"{str(r['first']):>5}")
        if pc is not None:
            pr = pacti_chain(pc, n, weak, bound)
            agree = pr["first"] == r["first"]
            ok = ok and agree
            line += f" {pr['seconds']:8.3f} {str(pr['first']):>5}  {'yes' if agree else 'NO'}"
        print(line)
        if args.smoke and weak is None:  # the smoke run's own check: the chain's side conditions hold in context
            ok = ok and r["failed"] == 0 and r["in context"] == n - 1
        if args.smoke and weak is not None:
            ok = ok and r["first"] == 4
    for name, n, missing, reqs, top, divisor in QUOTIENTS:
        q = quotient_case(pc, n, missing, reqs, top, divisor)
        ours = q["rclverify"]
        print(f"\nquotient of N{missing}, {name}:\n  rclverify {ours['seconds']:.3f} s "
              f"({'exact' if ours['exact'] else 'approximation'}): assume {ours['assume']}; "
              f"guarantee {ours['guarantee']}")
        if "pacti" in q:
            print(f"  Pacti     {q['pacti']['seconds']:.3f} s: assume {q['pacti']['assume'] or 'TRUE'}; "
                  f"guarantee {q['pacti']['guarantee']}")
            print(f"  assumptions: {q['assumption']}; guarantees: {q['guarantee']}")
            ok = ok and q["agree"]
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
