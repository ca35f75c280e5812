"""The monitor's start-up cache (core/cache/startup.py, issue 67): every entry is found only under the
content it was computed from, so an edited contract, plan or formula is computed again, never served
from a stale entry; and the command judges and prints the same with the cache cold, warm, poisoned or
unwritable (incremental equals clean)."""
from __future__ import annotations

import hashlib
import io
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest

from _classifier import CLASSIFIER
from rclverify.backends.monitors.needs_answer import answer_decides
from rclverify.core.cache import keys
from rclverify.core.cache.safeload import load
from rclverify.core.cache.startup import active, keeping
from rclverify.lang.printer import expr_to_rcl
from rclverify.model.plan.errors import PlanError
from rclverify.semantics.straightline import compile_exact
from rclverify.stages.workspace import Workspace

SRC = Path(__file__).resolve().parents[2] / "src"
PLAN = "name: classifier\ncontracts: [contracts/classifier.rcl]\nnodes:\n  Classifier:\n    evidence: []\n"
MAPPING = "horizon: 0.005\ntopics:\n  reading: {fields: [data]}\n  status: {fields: [data]}\n"
#: Readings and the statuses answering them: two wrong (100 is green, 300 red), one missing its answer.
TRACE = [(0.0, 100.0, "green"), (0.01, 130.0, "orange"), (0.02, 100.0, "orange"), (0.03, 300.0, "red"),
         (0.04, 300.0, "orange"), (0.05, 260.0, None)]


def _workspace(root: Path, contract: str = CLASSIFIER) -> Path:
    (root / "contracts").mkdir(parents=True)
    (root / "backends/monitors").mkdir(parents=True)
    (root / "contracts/classifier.rcl").write_text(contract)
    (root / "contracts/plan.yaml").write_text(PLAN)
    (root / "backends/monitors/mapping.yaml").write_text(MAPPING)
    lines = []
    for t, r, status in TRACE:
        lines.append(json.dumps({"topic": "reading", "time": t, "data": r}))
        if status is not None:
            lines.append(json.dumps({"topic": "status", "time": t, "data": status}))
    lines.append(json.dumps({"topic": "tick", "time": 1.0}))
    (root / "run.jsonl").write_text("\n".join(lines) + "\n")
    return root


def test_an_edited_contract_is_parsed_again_not_served_from_the_cache(tmp_path: Path,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    root, kept_dir = _workspace(tmp_path / "ws"), tmp_path / "kept"
    with keeping(kept_dir) as kept:
        first = Workspace(root).checked
    assert kept.misses >= 1 and any(kept_dir.iterdir())
    import rclverify.lang.parser as parser
    with monkeypatch.context() as m:  # the same text: its tree comes from the cache, the parser is not asked
        m.setattr(parser, "parse_text", lambda *a, **k: pytest.fail("parsed although the text is kept"))
        with keeping(kept_dir) as kept:
            again = Workspace(root).checked
    assert kept.hits >= 1 and again.specs == first.specs
    # the same file name, another text: a key without the text would serve the old tree (120)
    (root / "contracts/classifier.rcl").write_text(CLASSIFIER.replace("in.r < 120", "in.r < 100"))
    with keeping(kept_dir):
        edited = Workspace(root).checked
    guarantee = expr_to_rcl(edited.nodes["Classifier"].node.guarantees[0].formula)
    assert "in.r < 100" in guarantee and "in.r < 120" not in guarantee


def test_a_yaml_file_is_read_again_when_its_text_changes_and_an_error_is_never_kept(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The mapping's data is kept by its file's text (``read_kept``): the same text is not parsed again, an
    edited one is (the control: a key without the text would serve the old horizon), and malformed YAML gives
    the same located error on every run, none of them kept."""
    from rclverify.backends.monitors.config import ConfigError, load_mapping
    import rclverify.model.plan.yamlguard as yamlguard
    root, kept_dir = _workspace(tmp_path / "ws"), tmp_path / "kept"
    with keeping(kept_dir) as kept:
        assert load_mapping(root, None).horizon == 0.005
    assert kept.misses == 1 and kept.hits == 0
    with monkeypatch.context() as m:  # the same text: its data comes from the cache, the parser is not asked
        m.setattr(yamlguard, "compose_guarded", lambda *a: pytest.fail("parsed although the text is kept"))
        with keeping(kept_dir) as kept:
            assert load_mapping(root, None).horizon == 0.005
    assert kept.hits == 1 and kept.misses == 0
    (root / "backends/monitors/mapping.yaml").write_text(MAPPING.replace("0.005", "0.25"))
    with keeping(kept_dir) as kept:
        assert load_mapping(root, None).horizon == 0.25
    assert kept.misses == 1
    (root / "backends/monitors/mapping.yaml").write_text("horizon: [0.25\n")
    said = []
    for _ in range(2):
        with keeping(kept_dir) as kept, pytest.raises(ConfigError) as err:
            load_mapping(root, None)
        said.append(str(err.value))
        assert kept.hits == 0
    assert said[0] == said[1] and said[0].startswith("backends/monitors/mapping.yaml:2:1: error: not valid YAML")
    assert len(list(kept_dir.glob("*.pickle"))) == 2  # the two texts read, not the malformed one


def test_a_syntax_error_is_never_kept(tmp_path: Path) -> None:
    root, kept_dir = _workspace(tmp_path / "ws", CLASSIFIER.replace("guarantee(", "guarantee((")), tmp_path / "kept"
    for _ in range(2):
        with keeping(kept_dir) as kept, pytest.raises(Exception, match="unexpected"):
            Workspace(root).checked
    assert kept.hits == 2 and kept.misses == 1  # the plan (its YAML read, its schema's pass) was kept, the contract never
    assert len(list(kept_dir.glob("*.pickle"))) == 2


def test_a_plan_edited_to_break_the_schema_is_refused_after_a_kept_pass(tmp_path: Path) -> None:
    root, kept_dir = _workspace(tmp_path / "ws"), tmp_path / "kept"
    with keeping(kept_dir) as kept:
        assert Workspace(root).plan.name == "classifier"
    passed = kept.misses
    with keeping(kept_dir) as kept:
        assert Workspace(root).plan.name == "classifier"
    assert kept.hits == passed and kept.misses == 0  # the pass is kept
    # a key without the plan's data would say "passed" again
    (root / "contracts/plan.yaml").write_text(PLAN + "unknown_section: 1\n")
    for _ in range(2):  # and a failure is never kept
        with keeping(kept_dir), pytest.raises(PlanError, match="unknown_section"):
            Workspace(root).plan


def _checked(text: str):  # type: ignore[no-untyped-def]
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    return check([parse_text(text, "contracts/classifier.rcl")])


def test_z3s_answer_is_kept_for_the_formulas_it_was_asked_of(tmp_path: Path) -> None:
    # every band's guarantee needs the answer; a lone `in.r < 120 -> ...` is decided by in.r >= 120 alone
    one_band = CLASSIFIER.replace("(in.r < 120 -> out.status == green)\n         and (120 <= in.r and in.r < 250 "
                                  "-> out.status == orange)\n         and (250 <= in.r -> out.status == red)",
                                  "in.r < 120 -> out.status == green")
    assert one_band != CLASSIFIER
    answers = []
    for _ in range(2):  # cold, then warm: the same answers
        with keeping(tmp_path) as kept:
            for text in (CLASSIFIER, one_band):
                c = _checked(text)
                node = c.nodes["Classifier"]
                answers.append(answer_decides(c, node, [g.formula for g in node.node.guarantees]))
        assert kept.misses + kept.hits == 2
    assert answers == [True, False, True, False]
    assert kept.hits == 2


def test_a_kept_formula_source_is_found_only_for_its_own_formula(tmp_path: Path) -> None:
    c = _checked(CLASSIFIER)
    node = c.nodes["Classifier"]
    from rclverify.lang.parser import parse_formula
    texts = ("in.r < 120 -> out.status == green", "in.r < 100 -> out.status == green")
    fresh = [compile_exact(parse_formula(t), c, node).source for t in texts]
    for _ in range(2):  # cold, then warm
        with keeping(tmp_path):
            made = [compile_exact(parse_formula(t), c, node) for t in texts]
        assert [m.source for m in made] == fresh
        # 110 answered orange: false where 110 is below the bound (120), true where it is not (100)
        assert [m.fn({"in.r": 110, "out.status": "orange"}) for m in made] == [False, True]
    assert active() is None


def test_the_code_stamp_is_the_digest_of_the_package_walked_by_pathlib() -> None:
    pkg = Path(keys.__file__).resolve().parents[2]
    h = hashlib.sha256(f"{keys.FORMAT} {sys.version}".encode())
    for p in sorted(pkg.rglob("*")):
        if p.suffix in (".py", ".lark", ".json", ".j2", ".yaml"):
            st = p.stat()
            h.update(f"{p.relative_to(pkg)} {st.st_size} {st.st_mtime_ns}\n".encode())
    assert keys.code_stamp() == h.hexdigest()
    assert keys.library_stamp("lark").startswith("lark ") and keys.library_stamp("no_such_library_x") == \
        "no_such_library_x -"


PROBE = ("import json, sys\nfrom rclverify.cli.commands import main\ncode = main(sys.argv[1:])\n"
         "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})), file=sys.stderr)\nsys.exit(code)\n")


def _monitor(root: Path, cache: Path, *extra: str) -> tuple[int, str, set[str]]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache),
           "PYTHONPATH": os.pathsep.join([str(SRC)] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH")
                                                       else []))}
    p = subprocess.run([sys.executable, "-c", PROBE, "monitor", "-w", str(root), str(root / "run.jsonl"), *extra],
                       capture_output=True, text=True, env=env, timeout=300)
    loaded = set(json.loads(p.stderr.strip().splitlines()[-1]))
    return p.returncode, p.stdout, loaded


def _poison(folder: Path, marker: Path) -> int:
    """Every kept entry under ``folder`` rewritten as its own valid header followed by a pickle that
    creates ``marker`` when unpickled; returns how many."""
    class Opens:
        def __reduce__(self) -> tuple[object, tuple[str, str]]:
            return (open, (str(marker), "w"))
    files = list(folder.glob("*.pickle"))
    for f in files:
        with open(f, "rb") as fh:
            header = load(fh)
        buf = io.BytesIO()
        pickle.dump(header, buf)
        pickle.dump(Opens(), buf)
        f.write_bytes(buf.getvalue())
    return len(files)


def test_the_command_judges_the_same_with_the_cache_cold_warm_poisoned_or_unwritable(tmp_path: Path) -> None:
    root, cache = _workspace(tmp_path / "ws"), tmp_path / "cache"
    cold = _monitor(root, cache)
    warm = _monitor(root, cache)
    assert cold[0] == 1 and "2 violated" in cold[1], cold
    assert warm[:2] == cold[:2]
    # a warm start loads none of the libraries whose results are kept
    assert {"lark", "jsonschema", "jinja2", "z3"} <= cold[2]
    assert not {"lark", "jsonschema", "jinja2", "z3"} & warm[2], warm[2]
    assert _monitor(root, cache, "--json")[:2] == _monitor(root, cache, "--json")[:2]
    marker = tmp_path / "ran"
    assert _poison(cache / "rclverify" / "start-up", marker) >= 5
    poisoned = _monitor(root, cache)
    assert poisoned[:2] == cold[:2] and not marker.exists()
    unwritable = tmp_path / "file"
    unwritable.write_text("not a folder")
    assert _monitor(root, unwritable)[:2] == cold[:2]  # no cache at all: computed as before
