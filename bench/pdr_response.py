"""How the proof of a bounded response scales when k-induction alone cannot finish it (issue 64).

The system is the one-node planner of tests/calculus/test_temporal_pdr.py, built as a
transition system directly: a cycle counter ``c`` from 0 that wraps at ``W``
(above ``W``, a state no run reaches, it counts on for ever), and the
requirement

    always (request >= 90 and c >= W - 3 -> eventually[<= 6] c == 0)

which holds (the wrap comes 4 steps after ``c = W - 3``) and is not
k-inductive for any k (the counting branch above ``W`` keeps a trigger
pending as long as one likes).  For each ``W`` the bench prints the wall
seconds of:

* **k-ind**: BMC and k-induction up to k = 10 (inconclusive);
* **pdr**: Spacer's query and the independent re-check of its certificate
  (:func:`rclverify.calculus.requirements.safety.by_pdr`), and the verdict;
* **whole**: what the requirement check runs (k-induction, then the
  invariant generated from the constants, then Spacer), and its method;
* **wrong**: the same with the wrap at ``W + 5`` (refuted by Spacer, then
  the shortest run found by BMC: its length is printed; Spacer's time
  limit, 6 s, is reached near W = 200: inconclusive, with the reason).

Usage::

    python bench/pdr_response.py                  # W = 15, 50, 100, 200, 400
    python bench/pdr_response.py --sizes 15 1000
    python bench/pdr_response.py --smoke          # W = 15: a second

Wall-clock seconds are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import time

import z3

from rclverify.calculus.requirements.response import check_response, with_counter
from rclverify.calculus.requirements.safety import by_pdr
from rclverify.calculus.requirements.tsys import TransitionSystem


def planner(wrap: int) -> TransitionSystem:
    """The cycle counter and the environment's request as a transition system."""
    def trans(s: dict[str, z3.ExprRef], t: dict[str, z3.ExprRef]) -> z3.BoolRef:
        c = s["c"]
        return z3.And(t["c"] == z3.If(c == wrap, 0, c + 1), t["request"] >= 0, t["request"] <= 100)
    return TransitionSystem({"c": z3.IntSort(), "request": z3.RealSort()},
                            lambda s: z3.And(s["c"] == 0, s["request"] >= 0, s["request"] <= 100), trans)


def one(w: int, start: int) -> str:
    """The three timings for wrap ``w`` (the trigger from ``c = start``), as one line."""
    def trigger(s: dict[str, z3.ExprRef]) -> z3.BoolRef:
        return z3.And(s["request"] >= 90, s["c"] >= start)

    def goal(s: dict[str, z3.ExprRef]) -> z3.BoolRef:
        return s["c"] == 0
    t0 = time.perf_counter()
    kind = check_response(planner(w), trigger, goal, 6, deep=False, timeout_ms=2_000)
    t1 = time.perf_counter()
    # the monitor system check_response builds, asked of Spacer directly
    ts = with_counter(planner(w), "<pending>", lambda s: z3.If(z3.And(trigger(s), z3.Not(goal(s))), 0, -1),
                      lambda s, t: z3.If(goal(t), -1, z3.If(s["<pending>"] >= 0,
                                                            z3.If(s["<pending>"] + 1 > 6, 6, s["<pending>"] + 1),
                                                            z3.If(z3.And(trigger(t), z3.Not(goal(t))), 0, -1))))
    ok = by_pdr(ts, lambda s: s["<pending>"] < 6, max_k=10, timeout_ms=2_000)
    t2 = time.perf_counter()
    late = check_response(planner(w + 5), trigger, goal, 6, timeout_ms=2_000)
    t3 = time.perf_counter()
    full = check_response(planner(w), trigger, goal, 6, timeout_ms=2_000)
    t4 = time.perf_counter()
    assert kind.status != "refuted"  # k-induction alone never refutes a correct one
    return (f"W = {w:5d}  k-ind {t1 - t0:6.2f} s ({kind.status})  pdr {t2 - t1:6.2f} s ({ok.status})  "
            f"wrong {t3 - t2:6.2f} s ({late.status}"
            + (f", run of {late.bound} steps)" if late.status == "refuted" else f": {next(x for x in late.detail.split('; ') if 'IC3/PDR' in x)})")
            + f"  whole {t4 - t3:6.2f} s ({full.status} by {full.method})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[15, 50, 100, 200, 400])
    ap.add_argument("--smoke", action="store_true")
    a = ap.parse_args()
    for w in [15] if a.smoke else a.sizes:
        print(one(w, w - 3), flush=True)


if __name__ == "__main__":
    main()
