"""The generated C++ checks decide quantifiers over unbounded numeric domains at the same candidate
points as rclverify's double reading (``semantics/candidates.py``, ``targets/cpp/candidates.py``): the
contract of ``test_candidates.py`` (function tables, a constructor term, nested quantifiers,
``exists_unique`` over REAL, INTEGER and NATURAL, three clauses outside the fragment) compiled with
``g++ -std=c++17 -Wall -Wextra -Werror``, each clause's C++ truth on random tables equal to
``floatsem.holds_in("double")``, which ``test_candidates.py`` checks against brute force and Z3."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from hypothesis import Phase, given, settings, strategies as st
from test_candidates import CLAUSES, SHARP, TEXT, _values
from test_generate_cpp import CXX, _run, _text

from rclverify.cli.commands import main
from rclverify.semantics.floatsem import holds_in
from rclverify.app.pipeline import Workspace

pytestmark = pytest.mark.skipif(shutil.which("g++") is None, reason="g++ is not installed")


def test_candidate_points_in_cpp_are_the_double_readings(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "q.rcl").write_text(TEXT)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/q.rcl]\n")
    out = ws / "gen"
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--lang", "cpp"]) == 0
    header = (out / "q_node" / "include" / "q_node" / "contract_checks.hpp").read_text()  # node Q: REP 144
    assert "// not translated" not in header and header.count("rclverify_rt::real_points(cand_bp, ") >= 10, header
    src = tmp_path / "q.cpp"
    src.write_text('#include "q_node/contract_driver.hpp"\n#include <iostream>\n'
                   "int main() { return q_node::drive(std::cin, std::cout); }\n")
    subprocess.run(CXX + ["-O1", f"-I{out / 'q_node' / 'include'}", str(src), "-o", str(tmp_path / "q")],
                   check=True, capture_output=True, text=True)
    checked = Workspace(ws, "contracts/plan.yaml").checked
    cn = checked.nodes["Q"]
    io = {f"in.{k}": t for k, t in cn.inputs.items()} | {f"out.{k}": t for k, t in cn.outputs.items()}
    seen: set[str] = set()

    @settings(max_examples=2, deadline=None, database=None, derandomize=True,
              phases=[Phase.explicit, Phase.generate])
    @given(st.lists(_values(), min_size=30, max_size=30))
    def agree(batch: list) -> None:
        batch = SHARP + batch
        lines = [" ".join(_text(q, v, io[q]) for q, v in vals.items()) for vals in batch]
        for line, vals, (_, _, truths) in zip(lines, batch, _run(tmp_path / "q", "", lines)):
            for k, g in enumerate(cn.node.guarantees):
                want = holds_in("double", g.formula, checked, cn, vals)
                assert truths[1 + k] == {True: "T", False: "F", None: "U"}[want], (CLAUSES[k], line)
                seen.add(f"{k}{truths[1 + k]}")

    agree()
    # (truths: the assumption TRUE, then the guarantees) every clause of the fragment reaches true and false; the three outside it stay undecided
    n = len(CLAUSES)
    constant = {CLAUSES.index(c): t for c, t in (  # one point, and infinitely many integers: a gap's count
        ("exists_unique(x in REAL | in.a <= x and x <= in.a)", "T"), ("exists_unique(i in INTEGER | i < in.n)", "F"),
        ("exists_unique(i in INTEGER | i > in.n)", "F"))}
    assert {f"{k}{t}" for k in range(n - 3) if k not in constant for t in "TF"} <= seen, sorted(seen)
    assert {f"{k}{t}" for k, t in constant.items()} <= seen, sorted(seen)
    assert {f"{k}U" for k in range(n - 3, n)} <= seen, sorted(seen)
