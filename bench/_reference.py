"""The fixed pure-Python reference loop of the benches.

On a shared machine a bench's CPU seconds move with the processor's clock
and its neighbours (caches, memory bandwidth); the same loop run in the
same process just before shows how fast the machine is at that moment, and
a bench prints its figures also as a multiple of it (issue 44: "each
figure a ratio inside one run").  The loop is integer arithmetic on one
local variable: no allocation beyond small ints, no I/O, no library.
"""
from __future__ import annotations

import time

#: Iterations of the loop (about 1 CPU second on a 2020s core with CPython 3.11).
ITERATIONS = 20_000_000


def reference_cpu(iterations: int = ITERATIONS) -> float:
    """CPU seconds (``time.process_time``: user + system of this process)
    of ``iterations`` rounds of ``acc = (acc + i * i) % 1000003``."""
    t0 = time.process_time()
    acc = 0
    for i in range(iterations):
        acc = (acc + i * i) % 1_000_003
    if acc < 0:  # never: keeps the loop's result alive
        raise AssertionError(acc)
    return time.process_time() - t0


if __name__ == "__main__":
    import argparse
    argparse.ArgumentParser(description="Time the benches' reference loop once and print its CPU seconds.").parse_args()
    print(f"reference loop: {reference_cpu():.3f} CPU s")
