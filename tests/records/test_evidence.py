"""Evidence records, roll-up order, atomic storage and staleness (shared/DESIGN.md "Evidence")."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from rclverify.records.records import SEVERITY, Evidence, Obligation, SourceRef, hash_inputs, \
    make_obligation_id, worst
from rclverify.records.store import EvidenceStore, atomic_write_text, read_obligations, write_obligations


def _obligation(**kw: object) -> Obligation:
    base = dict(id="N.g1.hoare.p", node="N", guarantee=1, backend="hoare", kind="proof", statement="{A} P {Q}",
                source=SourceRef("c.rcl", 3, 5), inputs=("prog.imp",), data={"entry": 0})
    base.update(kw)
    return Obligation(**base)  # type: ignore[arg-type]


def _evidence(root: Path, status: str = "discharged") -> Evidence:
    return Evidence(obligation="N.g1.hoare.p", backend="hoare", kind="proof", status=status, tool="z3",
                    tool_version="4", started="2026-01-01T00:00:00+00:00", duration_s=0.5,
                    input_hashes=hash_inputs(root, ["prog.imp"]), counterexample={"x": "1"})


def test_roll_up_takes_the_worst_and_missing_is_pending() -> None:
    assert worst(["discharged", "pending", "failed", "stale"]) == "failed"
    assert worst(["discharged", "inconclusive"]) == "inconclusive"
    assert worst([]) == "pending"
    assert [s for s, _ in sorted(SEVERITY.items(), key=lambda kv: kv[1])] == \
        ["discharged", "pending", "unverified", "inconclusive", "stale", "error", "failed"]
    with pytest.raises(KeyError):
        worst(["proved"])


def test_obligation_ids_are_stable_and_file_safe() -> None:
    assert make_obligation_id("Agent", 2, "ajpf", "p3 i=4") == "Agent.g2.ajpf.p3_i_4"
    assert make_obligation_id("Agent", 1, "dafny") == "Agent.g1.dafny"


def test_records_round_trip_through_json(tmp_path: Path) -> None:
    o = _obligation()
    assert Obligation.from_json(json.loads(json.dumps(o.to_json()))) == o
    (tmp_path / "prog.imp").write_text("skip")
    e = _evidence(tmp_path)
    assert Evidence.from_json(json.loads(json.dumps(e.to_json()))) == e
    with pytest.raises(ValueError):
        Evidence.from_json({**e.to_json(), "status": "passed"})
    write_obligations(tmp_path / "o.json", [o])
    assert read_obligations(tmp_path / "o.json") == [o]


def test_atomic_write_replaces_whole_and_skips_identical_content(tmp_path: Path) -> None:
    p = tmp_path / "d" / "f.json"
    assert atomic_write_text(p, "one") is True
    assert atomic_write_text(p, "one") is False
    assert atomic_write_text(p, "two") is True and p.read_text() == "two"
    assert [f.name for f in p.parent.iterdir()] == ["f.json"]  # no temporary file left behind


def test_a_failing_write_keeps_the_record_already_there(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "prog.imp").write_text("skip")
    store = EvidenceStore(tmp_path)
    store.put(_evidence(tmp_path))
    before = store.path("N.g1.hoare.p").read_bytes()

    def broken(*a: object, **k: object) -> None:
        raise OSError("disk full")
    monkeypatch.setattr("os.replace", broken)
    with pytest.raises(OSError):
        store.put(_evidence(tmp_path, "failed"))
    assert store.path("N.g1.hoare.p").read_bytes() == before
    assert [f.name for f in store.dir.iterdir()] == ["N.g1.hoare.p.json"]


def test_evidence_is_stale_once_an_input_changes(tmp_path: Path) -> None:
    (tmp_path / "prog.imp").write_text("skip")
    store = EvidenceStore(tmp_path)
    store.put(_evidence(tmp_path, "failed"))
    ev = store.get("N.g1.hoare.p")
    assert ev is not None and store.current_status(ev) == "failed"
    (tmp_path / "prog.imp").write_text("skip; skip")
    assert store.current_status(ev) == "stale"
    (tmp_path / "prog.imp").unlink()
    assert store.current_status(ev) == "stale"
    assert store.get("missing") is None


def test_kept_input_hashes_are_taken_once_per_file(tmp_path: Path) -> None:
    (tmp_path / "prog.imp").write_text("skip")
    store = EvidenceStore(tmp_path)
    ev = _evidence(tmp_path, "failed")
    hashes: dict[str, str] = {}
    assert store.current_status(ev, hashes) == "failed" and set(hashes) == {"prog.imp"}
    (tmp_path / "prog.imp").write_text("skip; skip")
    # the caller promised no change while it keeps the hashes: the kept one answers
    assert store.current_status(ev, hashes) == "failed"
    assert store.current_status(ev, {}) == store.current_status(ev) == "stale"


def test_a_target_relates_artifact_paths_to_the_workspace_root(tmp_path: Path) -> None:
    from rclverify.backends.base import NodeTarget
    art = tmp_path / "artifacts" / "hoare" / "N"
    t = NodeTarget(root=tmp_path, checked=None, node=None, config={}, artifacts=art)  # type: ignore[arg-type]
    assert t.rel(art / "g1.txt") == "artifacts/hoare/N/g1.txt"
    assert t.rel(art / "sub" / ".." / "g2.txt") == "artifacts/hoare/N/g2.txt"  # resolved
    assert t.rel(tmp_path / "backends" / "p.imp") == "backends/p.imp"
    link = tmp_path / "ws-link"
    link.symlink_to(tmp_path)
    t2 = NodeTarget(root=link, checked=None, node=None, config={}, artifacts=link / "artifacts" / "x")  # type: ignore[arg-type]
    assert t2.rel(link / "artifacts" / "x" / "f.txt") == "artifacts/x/f.txt"


# ---- the sealed text, encoded once (records/store.py: sealed_dumps) -------------------------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_KEYS = st.one_of(st.sampled_from(["a", "record", "record_sha25", "record_sha256x", "record_sha256 ", "z", "Ω",
                                   "", '": ', '\\"', '\n  "x']), st.text(max_size=6))
_VALUES = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=5),
                       lambda c: st.lists(c, max_size=3) | st.dictionaries(_KEYS, c, max_size=3), max_leaves=8)


@settings(max_examples=400, deadline=None)
@given(st.dictionaries(_KEYS, _VALUES, max_size=6))
def test_the_sealed_text_is_the_sealed_record_encoded(record: dict) -> None:
    """The seal's line spliced into the one encoding equals encoding the record with its seal: keys
    before and after the seal's, none after it, none at all, keys holding quotes, colons and the
    indentation of a key line."""
    from rclverify.records.store import SEAL, dumps, seal_of, sealed_dumps
    record.pop(SEAL, None)
    assert sealed_dumps(record) == dumps({**record, SEAL: seal_of(record)})
