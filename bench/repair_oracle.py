"""A random oracle for the checked repairs of the code (issue 111; diagnosis/code_repair.py, docs/diagnosis.md
"The random oracle of the code repairs").

Small nodes are generated at random, each a contract and the Python function that meets it, on a small
integer domain, from five families:

* ``threshold``: ``ok = x OP c`` against ``in.x OP c -> out.ok`` and its negation ``-> not out.ok``;
* ``band``: ``ok = lo <= x and x <= hi`` against the band and its outside;
* ``offset``: ``y = x + k`` against ``out.y == in.x + k``;
* ``clamp``: ``y = min(x, c)`` against ``out.y <= c`` and ``in.x <= c -> out.y == in.x``;
* ``order``: ``ok = x <= y`` (two inputs) against ``in.x <= in.y -> out.ok`` and its negation.

One token of the function is slipped (a comparison's strictness, a constant moved by one, ``and`` for
``or``, ``-`` for ``+``, ``max`` for ``min``), kept only when the oracle shows the slipped function wrong.
Then the tool runs as the pipeline runs it, in process: every guarantee's property test
(:func:`rclverify.backends.property_tests.harness.run_guarantee`, the plan's seed) until one fails with an
implementation line as its cause, and :func:`rclverify.diagnosis.code_repair.checked_repairs` on it.

**The oracle** judges each repair offered without the tool: the edited function is run on every input of
the domain (brute force; ``0..10``, ``0..6`` for two inputs) and each guarantee, written in Python by the
generator beside its RCL, is evaluated on it.  A repair is *right* when every guarantee holds on every
input, *wrong* otherwise.

Figures: cases, the first repair right (%, the aim at least 80), wrong repairs offered (the aim 0), no
repair offered (the property tests found no failure, or no candidate passed), seconds per case.
``tests/diagnosis/test_repair_oracle.py`` asserts that no wrong repair is offered on a fixed seed.

Usage::

    python bench/repair_oracle.py                 # 40 cases, seed 1
    python bench/repair_oracle.py --cases 100 --seed 7
    python bench/repair_oracle.py --smoke         # 3 cases, a few seconds
    python bench/repair_oracle.py --two --cases 20  # two slips on one line: the two-token repairs

The figures are printed, not asserted.
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import random
import re
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

#: (op, its negation, Python's function of it)
_OPS: dict[str, tuple[str, Callable[[int, int], bool]]] = {
    "<": (">=", lambda a, b: a < b), "<=": (">", lambda a, b: a <= b),
    ">": ("<=", lambda a, b: a > b), ">=": ("<", lambda a, b: a >= b),
}
_STRICT = {"<": "<=", "<=": "<", ">": ">=", ">=": ">"}

Spec = Callable[[dict[str, int], dict[str, Any]], bool]


@dataclass
class Case:
    """One generated node: its ``family``, RCL ``contract`` (one node ``N``), the right ``code`` and the
    ``slipped`` code (one token changed: ``slip`` says which), the input ``domain`` (name -> values), the
    output names, and the guarantees as Python predicates over (inputs, outputs) (``specs``)."""

    family: str
    contract: str
    code: str
    slipped: str
    slip: str
    domain: dict[str, range]
    specs: list[Spec] = field(default_factory=list)


def _node(inputs: str, outputs: str, assume: str, guarantees: list[str]) -> str:
    body = "".join(f"  guarantee( {g} )\n" for g in guarantees)
    return f"node N {{\n  inputs( {inputs} )\n  outputs( {outputs} )\n  assume( {assume} )\n{body}}}\n"


def _code(args: str, body: str) -> str:
    return f'"""A generated node."""\n\n\ndef n({args}):\n{body}'


def generate(rng: random.Random) -> Case:
    """One case of a family drawn from ``rng`` with one slip (see the module docstring); the slip may
    leave the function right: :func:`cases` keeps only the ones the oracle shows wrong."""
    family = rng.choice(["threshold", "band", "offset", "clamp", "order"])
    x10 = {"x": range(0, 11)}
    a10 = "0 <= in.x and in.x <= 10"
    if family == "threshold":
        op, c = rng.choice(list(_OPS)), rng.randint(2, 8)
        neg, f = _OPS[op]
        line = f'    return {{"ok": x {op} {c}}}\n'
        slips = [(f"x {_STRICT[op]} {c}", "strictness"), (f"x {op} {c + rng.choice([-1, 1])}", "constant")]
        new, what = rng.choice(slips)
        return Case(family, _node("x : INTEGER", "ok : BOOL", a10, [f"in.x {op} {c} -> out.ok",
                                                                    f"in.x {neg} {c} -> not out.ok"]),
                    _code("x", line), _code("x", line.replace(f"x {op} {c}", new)), what, x10,
                    [lambda i, o, f=f, c=c: not f(i["x"], c) or o["ok"] is True,
                     lambda i, o, f=f, c=c: f(i["x"], c) or o["ok"] is False])
    if family == "band":
        lo = rng.randint(1, 4)
        hi = rng.randint(lo + 2, 9)
        line = f'    return {{"ok": {lo} <= x and x <= {hi}}}\n'
        slips = [(f"{lo} <= x or x <= {hi}", "and/or"), (f"{lo} < x and x <= {hi}", "strictness"),
                 (f"{lo} <= x and x < {hi}", "strictness"), (f"{lo} <= x and x <= {hi + rng.choice([-1, 1])}", "constant")]
        new, what = rng.choice(slips)
        return Case(family, _node("x : INTEGER", "ok : BOOL", a10, [
            f"in.x >= {lo} and in.x <= {hi} -> out.ok", f"in.x < {lo} or in.x > {hi} -> not out.ok"]),
            _code("x", line), _code("x", line.replace(f"{lo} <= x and x <= {hi}", new)), what, x10,
            [lambda i, o, lo=lo, hi=hi: not (lo <= i["x"] <= hi) or o["ok"] is True,
             lambda i, o, lo=lo, hi=hi: lo <= i["x"] <= hi or o["ok"] is False])
    if family == "offset":
        k = rng.randint(1, 5)
        line = f'    y = x + {k}\n    return {{"y": y}}\n'
        new, what = rng.choice([(f"x - {k}", "operator"), (f"x + {k + rng.choice([-1, 1])}", "constant")])
        return Case(family, _node("x : INTEGER", "y : INTEGER", a10, [f"out.y == in.x + {k}"]),
                    _code("x", line), _code("x", line.replace(f"x + {k}", new)), what, x10,
                    [lambda i, o, k=k: o["y"] == i["x"] + k])
    if family == "clamp":
        c = rng.randint(3, 7)
        line = f'    y = min(x, {c})\n    return {{"y": y}}\n'
        new, what = rng.choice([(f"max(x, {c})", "max/min"), (f"min(x, {c + 1})", "constant")])
        return Case(family, _node("x : INTEGER", "y : INTEGER", a10, [f"out.y <= {c}", f"in.x <= {c} -> out.y == in.x"]),
                    _code("x", line), _code("x", line.replace(f"min(x, {c})", new)), what, x10,
                    [lambda i, o, c=c: o["y"] <= c, lambda i, o, c=c: i["x"] > c or o["y"] == i["x"]])
    op = rng.choice(list(_OPS))
    neg, f = _OPS[op]
    line = f'    return {{"ok": x {op} y}}\n'
    return Case("order", _node("x : INTEGER, y : INTEGER", "ok : BOOL", "0 <= in.x and in.x <= 6 and 0 <= in.y and in.y <= 6",
                               [f"in.x {op} in.y -> out.ok", f"in.x {neg} in.y -> not out.ok"]),
                _code("x, y", line), _code("x, y", line.replace(f"x {op} y", f"x {_STRICT[op]} y")), "strictness",
                {"x": range(0, 7), "y": range(0, 7)},
                [lambda i, o, f=f: not f(i["x"], i["y"]) or o["ok"] is True,
                 lambda i, o, f=f: f(i["x"], i["y"]) or o["ok"] is False])


def generate_two(rng: random.Random) -> Case:
    """One case with two slips on one line (``--two``): a comparison's strictness and its constant, both
    ends of a band, an operator and its constant, ``max`` for ``min`` and its constant, or the two
    operands of an order swapped; built on :func:`generate`'s case of the same family."""
    while True:
        c = generate(rng)
        code = c.code
        if c.family == "threshold":
            op, k = re.search(r"x (<=|>=|<|>) (\d+)", code).groups()
            return _two(c, f"x {op} {k}", f"x {_STRICT[op]} {int(k) + rng.choice([-1, 1])}", "strictness+constant")
        if c.family == "band":
            lo, hi = re.search(r"(\d+) <= x and x <= (\d+)", code).groups()
            new, what = rng.choice([(f"{lo} < x and x < {hi}", "both ends"),
                                    (f"{lo} < x and x <= {int(hi) + rng.choice([-1, 1])}", "strictness+constant"),
                                    (f"{lo} <= x or x < {hi}", "and/or+strictness")])
            return _two(c, f"{lo} <= x and x <= {hi}", new, what)
        if c.family == "offset":
            k = int(re.search(r"x \+ (\d+)", code).group(1))
            return _two(c, f"x + {k}", f"x - {k + rng.choice([-1, 1])}", "operator+constant")
        if c.family == "clamp":
            k = int(re.search(r"min\(x, (\d+)\)", code).group(1))
            return _two(c, f"min(x, {k})", f"max(x, {k + 1})", "max/min+constant")
        op = re.search(r"x (<=|>=|<|>) y", code).group(1)
        return _two(c, f"x {op} y", f"y {op} x", "operands")


def _two(c: Case, old: str, new: str, what: str) -> Case:
    return Case(c.family, c.contract, c.code, c.code.replace(old, new), what, c.domain, c.specs)


def _one_token_fixes(case: Case) -> bool:
    """Whether one token of the slipped line (the culprit search's corrections, ``max``/``min``) already makes
    ``case`` right: then it is no two-slip case."""
    from fractions import Fraction

    from rclverify.diagnosis.code_repair import candidate_edits
    line = next(k for k, x in enumerate(case.slipped.splitlines(), 1) if "x" in x and "def " not in x
                and '"""' not in x)
    nums = [Fraction(int(n)) for n in re.findall(r"\d+", case.contract)]
    return any(right(case, e.apply(case.slipped)) for e in candidate_edits(case.slipped, "nodes/n.py", line, nums))


def right(case: Case, code: str) -> bool:
    """The oracle: ``code``'s function ``n`` meets every guarantee of ``case`` on every input of its
    domain (brute force); a function that does not load or raises is wrong."""
    import itertools
    scope: dict[str, Any] = {}
    try:
        exec(compile(code, "<repaired>", "exec"), scope)  # noqa: S102 - the generated node, in this process
        names = list(case.domain)
        for values in itertools.product(*(case.domain[n] for n in names)):
            inputs = dict(zip(names, values))
            out = scope["n"](**inputs)
            if not all(spec(inputs, out) for spec in case.specs):
                return False
    except Exception:  # noqa: BLE001 - an edit that breaks the code is a wrong repair
        return False
    return True


def cases(seed: int, n: int, two: bool = False) -> list[Case]:
    """``n`` cases from ``seed``, each right as written and wrong as slipped (both by the oracle); ``two``:
    two slips on one line, kept only when no one-token correction of the line makes the case right."""
    rng = random.Random(seed)
    out: list[Case] = []
    while len(out) < n:
        c = generate_two(rng) if two else generate(rng)
        if right(c, c.code) and not right(c, c.slipped) and not (two and _one_token_fixes(c)):
            out.append(c)
    return out


@dataclass
class Outcome:
    """What the tool did on one case: the failing guarantee's ``cause`` (``""``: no property test
    failed), the repairs offered (their edited code), and the oracle's judgement of each."""

    cause: str
    offered: list[str]
    judged: list[bool]
    seconds: float


def run_case(case: Case, where: Path) -> Outcome:
    """Write ``case``'s slipped node as a workspace under ``where`` and run the tool on it (module
    docstring): the property tests until one fails with a cause, then the checked repairs, each judged."""
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.property_tests.harness import read_config, run_guarantee
    from rclverify.diagnosis.code_repair_check import checked_repairs
    from rclverify.diagnosis.edits import Edit
    t0 = time.perf_counter()
    (where / "contracts").mkdir(parents=True)
    (where / "nodes").mkdir()
    (where / "contracts/robot.rcl").write_text(case.contract, encoding="utf-8")
    (where / "nodes/n.py").write_text(case.slipped, encoding="utf-8")
    (where / "contracts/plan.yaml").write_text(
        "contracts: [contracts/robot.rcl]\nnodes:\n  N:\n    evidence:\n"
        "      - {backend: property_tests, implementation: \"nodes/n.py:n\", max_examples: 60}\n", encoding="utf-8")
    ws = Workspace(where)
    target = ws.target("N", 0)
    cfg = read_config(target.config, target.node, target.root)
    for k in range(1, len(target.node.node.guarantees) + 1):
        got = run_guarantee(target.checked, target.node, k, cfg, where, target.facts, None, target.mapping)
        cause = (got.counterexample or {}).get("cause", "") if got.status == "failed" else ""
        if cause:
            oid = f"N.g{k}.property_tests.e0"
            reps = checked_repairs(ws, "N", oid, cause, {oid: "failed"})
            offered = [Edit(r["file"], r["edit"]["line"], r["edit"]["col"], r["edit"]["end_line"],
                            r["edit"]["end_col"], r["edit"]["inserted"]).apply(case.slipped) for r in reps]
            return Outcome(cause, offered, [right(case, code) for code in offered], time.perf_counter() - t0)
    return Outcome("", [], [], time.perf_counter() - t0)


def run(seed: int, n: int, two: bool = False) -> list[tuple[Case, Outcome]]:
    """Every case of ``seed`` and ``n`` (``two``: two slips a line) with the tool's outcome (workspaces in a
    temporary folder)."""
    tmp = Path(tempfile.mkdtemp(prefix="rclverify-repair-oracle-"))
    try:
        return [(c, run_case(c, tmp / f"case{k}")) for k, c in enumerate(cases(seed, n, two))]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", type=int, default=40)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--smoke", action="store_true", help="3 cases")
    p.add_argument("--two", action="store_true", help="two slips on one line (the two-token repairs)")
    a = p.parse_args()
    n = 3 if a.smoke else a.cases
    results = run(a.seed, n, a.two)
    first = sum(1 for _, o in results if o.judged and o.judged[0])
    wrong = sum(1 for _, o in results for j in o.judged if not j)
    offered = sum(len(o.judged) for _, o in results)
    undetected = sum(1 for _, o in results if not o.cause)
    none = sum(1 for _, o in results if o.cause and not o.offered)
    print(f"{'family':<10} {'slip':<11} {'cause':<14} {'offered':>7} {'right':>5}  s")
    for c, o in results:
        print(f"{c.family:<10} {c.slip:<11} {o.cause or '-':<14} {len(o.offered):>7} "
              f"{sum(o.judged):>5}  {o.seconds:.2f}")
    print(f"cases: {n} (seed {a.seed}); first repair right: {first}/{n} = {100 * first / n:.0f}% (aim >= 80%)")
    print(f"repairs offered: {offered}; wrong by the oracle: {wrong} (aim 0); no failure found: {undetected}; "
          f"no repair offered: {none}; seconds per case: {sum(o.seconds for _, o in results) / n:.2f}")


if __name__ == "__main__":
    main()
