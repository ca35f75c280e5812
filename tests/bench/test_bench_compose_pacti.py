"""bench/compose_pacti.py --smoke runs in seconds and agrees with itself (and
with Pacti when the optional ``bench`` extra is installed): the smoke mode
CI runs (issue 43)."""
from __future__ import annotations

import contextlib
import importlib.util
import io
from pathlib import Path

BENCH = Path(__file__).resolve().parents[2] / "bench" / "compose_pacti.py"


def test_the_smoke_run_of_the_pacti_comparison_passes() -> None:
    spec = importlib.util.spec_from_file_location("compose_pacti", BENCH)
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = bench.main(["--smoke"])
    text = out.getvalue()
    assert code == 0, text
    assert "chain N=5" in text and "node 3 weakened" in text and "quotient of N1" in text
    if importlib.util.find_spec("pacti") is not None:  # the comparison itself ran
        assert " NO" not in text and "assumptions: equal; guarantees: equal" in text
