"""How the RCL front end scales with the size of the system model.

Generates synthetic RCL systems of N nodes chained output -> input (node k
reads the outputs of node k-1 under the same names), each node using
quantifiers (forall, exists, exists_unique), function-typed inputs and
outputs, an enumeration and a constructor set, chained comparisons,
arithmetic and topics.  For each N it prints:

* the file size,
* the LALR(1) parse time, text to AST (``rclverify.lang.parser.parse_text``;
  best of ``--repeat`` runs for N <= 1000) and the time per node,
* the type-check time (``rclverify.lang.typecheck.check``; the column is
  skipped with a note when the checker cannot be imported),
* the peak Python memory of parse + check (tracemalloc, in a separate run so
  the tracing does not distort the times),
* for N <= ``--earley-max``: the Earley parse time of the same grammar
  (``Lark(parser='earley')``, text to parse tree only, so Earley is spared
  the AST construction) and the speed-up of LALR over it; the Earley tree
  is turned into an AST and compared with the LALR one.  The Earley lexer
  is lark's default for Earley (``dynamic``); ``--earley-lexer basic``
  measures the faster basic-lexer Earley, a lower bound on the speed-up.

* the same parse and type-check with the front end as it was before the
  full-language work (the old grammar, AST builder and checker, read from
  the git history at commit b59aa9d and loaded as modules), and the ratio new / old of each
  (1.00 = same speed; below 1 = faster now).

Times are CPU seconds of the benchmark process (less disturbed by other
work on a shared machine than wall-clock time; still expect +-25%).
Finally it prints the log-log slope of the LALR parse time against N
(1.0 = linear growth).  The figures are printed, not asserted.  The
synthetic text avoids the variable name ``x`` (a keyword of types), which
the basic Earley lexer cannot tell from the keyword.

Usage::

    python bench/parse_scale.py                 # N = 10 40 160 640 1000 5000
    python bench/parse_scale.py --sizes 10 100  # or --sizes 10,100
    python bench/parse_scale.py --smoke         # N = 5, 10, one run each (Earley: 5): a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import importlib
import math
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any, Callable, Sequence, TypeVar

from lark import Lark

from rclverify.lang import ast
from rclverify.core.cache.heap import no_collection as gc_paused
from rclverify.lang.parser import ast_from_tree, grammar_text, parse_text

T = TypeVar("T")

CONTEXT = """\
// Synthetic system for the front-end scaling benchmark.
context {
  Mode : {idle, busy, fault} ;
  Cmd : { go(NATURAL, REAL), hold(REAL), halt } ;
  Grid : REAL x REAL --> BOOL ;
  Index : NATURAL --> REAL ;
  Limit : REAL = 100 ;
}
"""

NODE = """\
/* Node {k}: consumes the outputs of node {p}. */
node Stage{k} {{
  inputs( level{p} : REAL, mode{p} : Mode, cmd{p} : Cmd, grid{p} : Grid, index{p} : Index )
  outputs( level{k} : REAL, mode{k} : Mode, cmd{k} : Cmd, grid{k} : Grid, index{k} : Index )
  topics( bench_msgs/State level matches(in.level{p}),
          bench_msgs/State mode matches(in.mode{p}),
          bench_msgs/Command cmd matches(out.cmd{k}),
          bench_msgs/State level_out matches(out.level{k}) )
  assume( 0 <= in.level{p} <= Limit and in.mode{p} in {{idle, busy}} )
  assume( forall(i in NATURAL | 0 <= in.index{p}(i)) )
  guarantee( forall(u, v in REAL | (in.grid{p}(u, v) == TRUE) -> out.grid{k}(u, v) == TRUE) )
  guarantee( (in.mode{p} == idle -> out.level{k} == in.level{p} + 1)
             and (in.mode{p} != idle -> 0 <= out.level{k} < Limit * 2 - 1) )
  guarantee( (exists(i in NATURAL | in.cmd{p} == go(i, 0.5))
               -> exists_unique(j in NATURAL; out.cmd{k} == go(j, in.level{p} / 2)))
             and (in.cmd{p} == halt -> out.cmd{k} == halt) )
  guarantee( out.mode{k} in {{idle, busy, fault}} and not (out.mode{k} == fault and in.mode{p} == idle) )
  guarantee( forall(i in NATURAL | out.index{k}(i) >= in.index{p}(i) - -1.5e-1 * {k}) )
}}
"""


#: The last commit before the full-language work; its front end is read from
#: the repository's history at run time rather than kept as a second copy.
BEFORE_COMMIT = "b59aa9d"
BEFORE_FILES = ("__init__.py", "ast.py", "errors.py", "parser.py", "rcl.lark", "typecheck.py", "types.py", "walk.py")


def before_front_end() -> tuple[Callable[[str, str], Any], Callable[[list[Any]], Any]] | None:
    """``(parse_text, check)`` of the front end before the full-language
    work: ``src/rclverify/lang/`` at commit ``BEFORE_COMMIT``, written by
    ``git show`` into a temporary package ``before_issue11`` and imported
    (old AST, parser, checker and types), its parser reading the old grammar.

    Returns ``None`` (and says why) when the git history is not there (a
    shallow clone, a copy without ``.git``): the old columns are skipped.
    """
    repo = Path(__file__).resolve().parent.parent
    pkg = Path(tempfile.mkdtemp(prefix="rcl-before-")) / "before_issue11"
    pkg.mkdir()
    for name in BEFORE_FILES:
        try:
            text = subprocess.run(["git", "-C", str(repo), "show", f"{BEFORE_COMMIT}:src/rclverify/lang/{name}"],
                                  check=True, capture_output=True, text=True).stdout
        except (OSError, subprocess.CalledProcessError) as exc:
            print(f"note: old front end columns skipped: it is read from the git history (commit "
                  f"{BEFORE_COMMIT}), not here ({str(exc).strip() or type(exc).__name__}); run this in a full clone")
            return None
        (pkg / name).write_text(text, encoding="utf-8")
    sys.path.insert(0, str(pkg.parent))
    try:
        parser = importlib.import_module("before_issue11.parser")
        checker = importlib.import_module("before_issue11.typecheck")
    finally:
        sys.path.remove(str(pkg.parent))
    grammar = (pkg / "rcl.lark").read_text(encoding="utf-8")
    parser.grammar_text = lambda: grammar
    parser._lark.cache_clear()
    return parser.parse_text, checker.check


def generate(n: int) -> str:
    """RCL text of an ``n``-node chain: one context clause and nodes
    ``Stage1`` .. ``Stage<n>``; node k's inputs are node k-1's outputs
    (node 1 reads the environment's ``*0`` variables)."""
    return CONTEXT + "\n".join(NODE.format(k=k, p=k - 1) for k in range(1, n + 1))


def best_of(repeat: int, fn: Callable[[], T]) -> tuple[float, T]:
    """Smallest CPU time of this process over ``repeat`` calls of ``fn``
    (seconds) and the last result.  CPU time rather than wall-clock time, so
    that other work on a shared machine disturbs the figures less."""
    best, result = math.inf, None
    for _ in range(repeat):
        t0 = time.process_time()
        result = fn()
        best = min(best, time.process_time() - t0)
    return best, result  # type: ignore[return-value]


def slope(xs: Sequence[float], ys: Sequence[float]) -> float:
    """Least-squares slope of log(ys) against log(xs)."""
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    den = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / den if den else float("nan")


def _sizes(values: Sequence[str]) -> list[int]:
    out = []
    for v in values:
        out += [int(p) for p in v.split(",") if p.strip()]
    if not out or min(out) < 1:
        raise argparse.ArgumentTypeError("sizes must be positive integers")
    return out


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["10", "40", "160", "640", "1000", "5000"],
                    help="numbers of nodes (space or comma separated)")
    ap.add_argument("--earley-max", type=int, default=160, help="largest N also parsed with Earley")
    ap.add_argument("--earley-lexer", choices=["dynamic", "basic"], default="dynamic",
                    help="Earley lexer: 'dynamic' (lark's default for Earley; default) or 'basic' "
                         "(the faster Earley, hence a smaller, conservative speed-up)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="timing runs of the parses and checks for N <= 1000, the best is kept "
                         "(larger N, and Earley: one run)")
    ap.add_argument("--smoke", action="store_true", help="N = 5 and 10, one run each, Earley at 5 only (CI)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.sizes, args.repeat, args.earley_max = ["5,10"], 1, 5
    sizes = _sizes(args.sizes)

    check: Callable[[list[ast.Spec]], object] | None
    try:
        from rclverify.lang.typecheck import check
    except ImportError as exc:  # the checker is optional for this benchmark
        check = None
        print(f"note: type-check column skipped ({exc})")

    earley = Lark(grammar_text(), parser="earley", lexer=args.earley_lexer, keep_all_tokens=True,
                  maybe_placeholders=True)
    parse_text("context { }")  # build the LALR tables outside the measurements
    before = before_front_end()
    if before is not None:
        before[0]("context { }", "warm-up")

    header = (f"{'N':>5} {'size KB':>8} {'parse s':>8} {'ms/node':>8} {'check s':>8} {'peak MB':>8} "
              f"{'old parse':>9} {'old check':>9} {'parse new/old':>13} {'check new/old':>13} "
              f"{'Earley s':>9} {'speed-up':>9}  same AST")
    print(f"CPU seconds. parse = LALR(1), text -> AST; Earley = {args.earley_lexer}-lexer Earley, "
          "text -> parse tree only")
    print(header)
    print("-" * len(header))
    ns, times = [], []
    for n in sizes:
        text = generate(n)
        name = f"stage{n}.rcl"
        repeat = args.repeat if n <= 1000 else 1
        t_parse, spec = best_of(repeat, lambda: parse_text(text, name))
        t_old_parse = t_old_check = None
        if before is not None:
            old_parse, old_check = before
            t_old_parse, old_spec = best_of(repeat, lambda: old_parse(text, name))
        # The checks run with the cyclic GC paused (both alike): otherwise a
        # collection of the large heap lands in one or the other at random.
        with gc_paused():
            t_check = best_of(repeat, lambda: check([spec]))[0] if check is not None else None
            if before is not None:
                t_old_check = best_of(repeat, lambda: old_check([old_spec]))[0]
                del old_spec

        tracemalloc.start()
        spec2 = parse_text(text, name)
        if check is not None:
            check([spec2])
        peak = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
        del spec2

        earley_col, speed_col, same = f"{'-':>9}", f"{'-':>9}", "-"
        if n <= args.earley_max:
            with gc_paused():  # as parse_text does
                t_earley, tree = best_of(1, lambda: earley.parse(text, start="start"))
            earley_col, speed_col = f"{t_earley:9.3f}", f"{t_earley / t_parse:8.1f}x"
            same = "yes" if ast_from_tree(tree, name) == spec else "NO"
            del tree
        check_col = f"{t_check:8.3f}" if t_check is not None else f"{'n/a':>8}"
        if t_old_parse is not None and t_old_check is not None:
            old_cols = (f"{t_old_parse:9.3f} {t_old_check:9.3f} {t_parse / t_old_parse:13.2f} "
                        + (f"{t_check / t_old_check:13.2f}" if t_check is not None else f"{'n/a':>13}"))
        else:
            old_cols = f"{'-':>9} {'-':>9} {'-':>13} {'-':>13}"
        print(f"{n:5d} {len(text.encode()) / 1024:8.1f} {t_parse:8.3f} {1000 * t_parse / n:8.2f} "
              f"{check_col} {peak:8.1f} {old_cols} {earley_col} {speed_col}  {same}", flush=True)
        ns.append(n)
        times.append(t_parse)
    if len(ns) >= 2:
        print(f"\ngrowth of the LALR parse: time ~ N^{slope(ns, times):.2f} (1.00 = linear)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
