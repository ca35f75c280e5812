"""Diagnostics latency of the RCL language server (issue 52: within 200 ms
for a 20-node file).

Starts ``rclverify lsp`` as its own process over stdio (pygls's client,
lsprotocol's types), opens a synthetic system of N nodes (the generator of
bench/parse_scale.py: quantifiers, functions, enumerations, constructors,
topics) in a fresh workspace, then edits it ``--repeat`` times, each edit a
new text (one constant changed) sent as ``didChange``, and measures the
wall-clock time from sending the edit to receiving the diagnostics of that
text (``textDocument/publishDiagnostics``).  Prints p50 and p99 per N, in
milliseconds, and the file size.  The figures are printed, not asserted.

Usage::

    python bench/lsp_latency.py                  # N = 20 and 160, 50 edits each
    python bench/lsp_latency.py --sizes 20 640 --repeat 100
    python bench/lsp_latency.py --smoke          # N = 5, 5 edits (CI)
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import asyncio
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Sequence

from lsprotocol import types as lsp
from pygls.lsp.client import LanguageClient

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "bench"))
from parse_scale import generate  # noqa: E402  (the same synthetic systems as the parse benchmark)


def percentile(xs: Sequence[float], p: float) -> float:
    """The ``p``-th percentile (nearest rank) of ``xs``."""
    s = sorted(xs)
    return s[min(len(s) - 1, max(0, round(p / 100 * len(s) + 0.5) - 1))]


async def measure(n: int, repeat: int) -> tuple[int, list[float]]:
    """``(file size, latencies in seconds)`` for an ``n``-node file."""
    root = Path(tempfile.mkdtemp(prefix="lsp-bench-"))
    (root / "contracts").mkdir()
    text = generate(n)
    f = root / "contracts" / "system.rcl"
    f.write_text(text, encoding="utf-8")
    uri = f.as_uri()
    client = LanguageClient("lsp-bench", "1")
    got: dict[int, asyncio.Event] = {}
    current = {"version": 0}

    @client.feature(lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def _diags(params: lsp.PublishDiagnosticsParams) -> None:
        if params.uri == uri and current["version"] in got:
            got[current["version"]].set()

    env = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
    await client.start_io(sys.executable, "-m", "rclverify.cli.commands", "lsp", env=env, cwd=str(root))
    await client.initialize_async(lsp.InitializeParams(capabilities=lsp.ClientCapabilities(), root_uri=root.as_uri()))
    client.initialized(lsp.InitializedParams())
    got[0] = asyncio.Event()
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(uri, "rcl", 0, text)))
    await asyncio.wait_for(got[0].wait(), 60)
    times = []
    for k in range(1, repeat + 1):
        edited = text.replace("= 100 ;", f"= {100 + k} ;", 1) if "= 100 ;" in text else text + f"\n// edit {k}\n"
        current["version"] = k
        got[k] = asyncio.Event()
        t = time.perf_counter()
        client.text_document_did_change(lsp.DidChangeTextDocumentParams(
            lsp.VersionedTextDocumentIdentifier(uri=uri, version=k),
            [lsp.TextDocumentContentChangeWholeDocument(text=edited)]))
        await asyncio.wait_for(got[k].wait(), 60)
        times.append(time.perf_counter() - t)
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    return len(text.encode("utf-8")), times


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", type=int, default=[20, 160], help="node counts (default 20 160)")
    ap.add_argument("--repeat", type=int, default=50, help="edits per size (default 50)")
    ap.add_argument("--smoke", action="store_true", help="N = 5, 5 edits (CI)")
    args = ap.parse_args(argv)
    sizes, repeat = ([5], 5) if args.smoke else (args.sizes, args.repeat)
    print(f"{'nodes':>6} {'bytes':>9} {'edits':>6} {'p50 ms':>8} {'p99 ms':>8} {'max ms':>8}")
    for n in sizes:
        size, times = asyncio.run(measure(n, repeat))
        ms = [t * 1000 for t in times]
        print(f"{n:>6} {size:>9} {len(ms):>6} {statistics.median(ms):>8.1f} {percentile(ms, 99):>8.1f} {max(ms):>8.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
