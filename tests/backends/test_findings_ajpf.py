"""Partial coverage of AJPF properties (backends/model_checking/ajpf/coverage.py)."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
from test_ajpf import make_target


def test_a_mapping_row_to_a_constant_is_reported_as_partial_coverage(tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("MCAPL_HOME", raising=False)
    monkeypatch.delenv("AJPF_HOME", raising=False)
    target = make_target(tmp_path)
    obs = AjpfBackend().export(target)
    g3 = {o.data["instance"]["i"]: o for o in obs if o.guarantee == 3}
    # "there is no waypoint i + 1" is decided by rows 7 and 8 (T/F), not by the agent
    for i in (0, 11, 12):
        assert g3[i].data.get("coverage") == "partial", i
        assert any("mapping row 8 maps `forall(x'', y'' in REAL | in.wayP(x'', y'') != i)`" in n
                   or "mapping row 7 maps" in n for n in g3[i].data["coverage_notes"]), g3[i].data["coverage_notes"]
    # instances 0..11 of guarantee 3 collapse to one formula
    assert any("collapse to one AJPF formula" in n and "i=0" in n for n in g3[0].data["coverage_notes"])
    # guarantee 2 maps every predicate to the agent's beliefs: full coverage
    assert all("coverage" not in o.data for o in obs if o.guarantee == 2)
    ev = AjpfBackend().run(g3[0], target)
    assert ev.status == "pending"
    assert ev.explanation.startswith("PARTIAL COVERAGE of guarantee 3: ")


def test_a_fully_covered_verified_property_is_discharged(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from test_ajpf import _place_log, verified_log
    monkeypatch.delenv("MCAPL_HOME", raising=False)
    monkeypatch.delenv("AJPF_HOME", raising=False)
    target = make_target(tmp_path)
    ob = next(o for o in AjpfBackend().export(target) if o.guarantee == 2 and o.data["instance"]["i"] == 4)
    assert "coverage" not in ob.data
    n = ob.data["property"]
    _place_log(target, n, verified_log(n, ob.data["psl"]))
    ev = AjpfBackend().run(ob, target)
    assert ev.status == "discharged", ev.explanation
    assert "PARTIAL" not in ev.explanation
