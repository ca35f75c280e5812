"""CPU time of one formula judged many times by each evaluator of the formula
core (docs/semantics.md, "One formula core"): the reference tree walk, the
compiled closures, the straight-line code and the double reading.

Usage: python3 bench/formula_core.py [N]   (N evaluations each, default 20000)
       python3 bench/formula_core.py --smoke   (200 evaluations: CI's check that it runs)
Prints CPU seconds (process time, steadier than wall time under load) and
microseconds per evaluation.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import random
import sys
import time
from typing import Any, Callable

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.evaluator import Evaluator
from rclverify.semantics.floatsem import holds_in
from rclverify.semantics.straightline import compile_exact

SPEC = """
context { Mode : {idle, run, stop} ; Limit = 2.5 ; }
node n {
  inputs(a : INTEGER, b : REAL, p : BOOL, m : Mode)
  outputs(q : BOOL, v : REAL)
  topics()
  guarantee((in.a * 2 + in.b / 4 <= Limit or in.p) and (in.m == stop -> out.v == 0)
            and (out.q <=> in.a - 1 > 0) and 0 <= out.v + 1 <= 10 and not (in.m == idle and out.v > Limit))
}
"""


class _Walk(Evaluator):
    compiled = False


def _time(label: str, n: int, run: Callable[[dict[str, Any]], Any], rows: list[dict[str, Any]]) -> None:
    start = time.process_time()
    for k in range(n):
        run(rows[k % len(rows)])
    cpu = time.process_time() - start
    print(f"{label:<22} {cpu:7.3f} s CPU  {cpu / n * 1e6:7.2f} us/evaluation")


def main() -> None:
    arg = sys.argv[1] if len(sys.argv) > 1 else "20000"
    if arg in ("-h", "--help"):
        print(__doc__)
        return
    if arg != "--smoke" and not arg.isdigit():
        sys.exit(f"formula_core: N must be a whole number of evaluations, or --smoke (got {arg!r}); see --help")
    n = 200 if arg == "--smoke" else int(arg)
    spec = parse_text(SPEC, "bench.rcl")
    checked = check([spec])
    node = checked.nodes["n"]
    formula = spec.nodes[0].guarantees[0].formula
    rng = random.Random(7)
    rows = [{"in.a": rng.randint(-3, 3), "in.b": rng.choice([0.5, 1.25, -2.0, 3.0]), "in.p": rng.random() < 0.3,
             "in.m": rng.choice(["idle", "run", "stop"]), "out.q": rng.random() < 0.5,
             "out.v": rng.choice([0.0, 1.5, 3.0, 9.5])} for _ in range(64)]
    straight = compile_exact(formula, checked, node)
    assert straight.fn is not None
    fn = straight.fn
    _time("tree walk (reference)", n, lambda v: _Walk(checked, node, v).eval(formula, {}), rows)
    _time("compiled closures", n, lambda v: Evaluator(checked, node, v).eval(formula, {}), rows)
    _time("straight-line code", n, fn, rows)
    _time("double reading", n, lambda v: holds_in("double", formula, checked, node, v), rows)


if __name__ == "__main__":
    main()
