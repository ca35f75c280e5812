"""What runs is what is hashed: a property test's import closure finds each
module where the interpreter running the tests finds it (the harness's
folders first on sys.path: the implementation's folder, then the workspace
root), hashes that file, and names what it cannot follow, which makes the
evidence inconclusive (docs/property-tests.md, "What runs is what is
hashed")."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, Iterator

import pytest

from _restore import restored
from rclverify.app.pipeline import Workspace
from rclverify.backends.property_tests.backend import PropertyTestsBackend
from rclverify.backends.property_tests.closure import resolve_closure
from rclverify.backends.property_tests.config import Config, load_implementation
from rclverify.backends.property_tests.importpath import harness_path

IMPL = "backends/property_tests/agent.py"
PLAN = f"""name: shadow
contracts: [contracts/c.rcl]
requirements:
  - id: R1
    text: y is at most 100
    formal: "Agent.out.y <= 100"
    supported_by:
      - {{node: Agent, guarantees: [1]}}
nodes:
  Agent:
    evidence:
      - backend: property_tests
        implementation: {IMPL}:agent
        max_examples: 30
"""
DODO = """from pathlib import Path
from rclverify.app.tasks import build_tasks, doit_config
DOIT_CONFIG = doit_config()
globals().update(build_tasks(Path(__file__).parent))
"""
GOOD = "def cap(x):\n    return min(x, 100)\n"
BAD = "def cap(x):\n    return 1000\n"


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def _workspace(root: Path, files: dict[str, str],
               impl: str = "from helper import cap\n\ndef agent(x):\n    return {'y': cap(x)}\n") -> Path:
    _write(root, {"contracts/plan.yaml": PLAN, "dodo.py": DODO, IMPL: impl,
                  "contracts/c.rcl": "node Agent { inputs(x : INTEGER) outputs(y : INTEGER) guarantee(out.y <= 100) }\n",
                  **files})
    return root


@pytest.fixture
def doit_path(tmp_path: Path) -> Iterator[Path]:
    """The workspace root first on sys.path, as doit puts it (the dodo file's folder); its modules forgotten after."""
    sys.path.insert(0, str(tmp_path))
    try:
        yield tmp_path
    finally:
        sys.path.remove(str(tmp_path))
        for name, mod in list(sys.modules.items()):
            where = getattr(mod, "__file__", None) or ""
            if where.startswith(str(tmp_path)) or name.startswith("rclverify_impl_"):
                del sys.modules[name]


def _load(root: Path, file: str = IMPL, attr: str = "agent") -> Any:
    return load_implementation(root, Config(f"{file}:{attr}", file, attr))


# ---------------------------------------------------------------- the interpreter's order


def test_the_helper_that_runs_is_the_one_hashed_when_two_have_its_name(doit_path: Path) -> None:
    root = _workspace(doit_path, {"backends/property_tests/helper.py": "def cap(x):\n    return 'beside'\n",
                                  "helper.py": "def cap(x):\n    return 'root'\n"})
    assert harness_path(root, IMPL) == [str(root / "backends/property_tests"), str(root)]
    ran = _load(root)(1)["y"]
    files = resolve_closure(root, IMPL).files
    ran_file = {"beside": "backends/property_tests/helper.py", "root": "helper.py"}[ran]
    other = ({"backends/property_tests/helper.py", "helper.py"} - {ran_file}).pop()
    assert ran_file in files and other not in files  # what runs is what is hashed, and only that
    assert ran == "beside"  # the implementation's folder comes first, as `python agent.py` has it


def test_control_a_single_helper_at_the_root_runs_and_is_hashed(doit_path: Path) -> None:
    root = _workspace(doit_path, {"helper.py": "def cap(x):\n    return 'root'\n"})
    assert _load(root)(1)["y"] == "root"
    closure = resolve_closure(root, IMPL)
    assert closure.files == ("backends/property_tests/agent.py", "helper.py") and not closure.unresolved


def test_control_the_root_under_another_spelling_on_sys_path_is_the_root(tmp_path: Path) -> None:
    real = _workspace(tmp_path / "real", {"helper.py": GOOD})
    (tmp_path / "link").symlink_to(real)
    sys.path.insert(0, str(tmp_path / "link"))  # doit's spelling of the root; the backend's is resolved
    try:
        closure = resolve_closure(real, IMPL)
    finally:
        sys.path.remove(str(tmp_path / "link"))
    assert "helper.py" in closure.files and not closure.unresolved  # the same file, not a second helper


def test_another_implementations_helper_loaded_under_the_same_name_is_not_what_runs(doit_path: Path) -> None:
    root = _workspace(doit_path, {"a/impl.py": "import helper\n\ndef f(x):\n    return helper.cap(x)\n",
                                  "a/helper.py": "def cap(x):\n    return 'a'\n",
                                  "b/impl.py": "import helper\n\ndef f(x):\n    return helper.cap(x)\n",
                                  "b/helper.py": "def cap(x):\n    return 'b'\n"})
    assert _load(root, "a/impl.py", "f")(0) == "a"
    assert _load(root, "b/impl.py", "f")(0) == "b"  # not a's helper, still in sys.modules as `helper`
    assert "b/helper.py" in resolve_closure(root, "b/impl.py").files


def test_a_relative_import_is_found_from_the_package_of_the_module_that_holds_it(doit_path: Path) -> None:
    root = _workspace(
        doit_path, {
            "backends/property_tests/pkg/__init__.py": "",
            "backends/property_tests/pkg/mod.py": ("from . import helper\nfrom .m import y\n\n"
                                                   "def value():\n    return helper.cap(y)\n"),
            "backends/property_tests/pkg/helper.py": "def cap(x):\n    return ('pkg', x)\n",
            "backends/property_tests/pkg/m.py": "y = 7\n",
            "backends/property_tests/helper.py": "def cap(x):\n    return 'decoy beside'\n",
            "helper.py": "def cap(x):\n    return 'decoy root'\n"},
        impl="import pkg.mod\n\ndef agent(x):\n    return {'y': pkg.mod.value()}\n")
    assert _load(root)(0)["y"] == ("pkg", 7)
    closure = resolve_closure(root, IMPL)
    assert closure.files == ("backends/property_tests/agent.py", "backends/property_tests/pkg/__init__.py",
                             "backends/property_tests/pkg/helper.py", "backends/property_tests/pkg/m.py",
                             "backends/property_tests/pkg/mod.py")
    assert not closure.unresolved


def test_a_relative_import_of_the_implementation_itself_runs_nothing_and_hashes_nothing(doit_path: Path) -> None:
    root = _workspace(doit_path, {"backends/property_tests/fast.py": ""},
                      impl=("try:\n    from . import fast\nexcept ImportError:\n    fast = None\n\n"
                            "def agent(x):\n    return {'y': fast}\n"))
    assert _load(root)(0) == {"y": None}  # loaded as a top-level module: no parent package
    assert resolve_closure(root, IMPL).files == (IMPL,)


def test_a_literal_dynamic_import_is_followed(doit_path: Path) -> None:
    root = _workspace(doit_path, {"helper.py": GOOD},
                      impl="import importlib\n\ndef agent(x):\n    return importlib.import_module('helper').cap(x)\n")
    closure = resolve_closure(root, IMPL)
    assert "helper.py" in closure.files and not closure.unresolved


# ---------------------------------------------------------------- what cannot be followed: named, inconclusive


def _evidence(root: Path) -> Any:
    target = Workspace(root).target("Agent", 0)
    backend = PropertyTestsBackend()
    return backend.run(backend.export(target)[0], target)


@pytest.mark.parametrize("impl, named", [
    ("import importlib\n\ndef agent(x):\n    m = importlib.import_module('hel' + 'per')\n    return {'y': m.cap(x)}\n",
     f"{IMPL}:4: importlib.import_module() of a name computed when it runs"),
    ("try:\n    import fast_cap as helper\nexcept ImportError:\n    import helper\n\n"
     "def agent(x):\n    return {'y': helper.cap(x)}\n",
     f"{IMPL}:2: fast_cap is found nowhere: not in backends/property_tests/, the workspace root, the standard library "
     "or an installed distribution"),
    ("import sys\nsys.path.insert(0, '/elsewhere')\nimport helper\n\ndef agent(x):\n    return {'y': helper.cap(x)}\n",
     f"{IMPL}:2: changes sys.path, so imports are not found where the harness's path says"),
    ("import pkg\n\ndef agent(x):\n    return {'y': pkg.cap(x)}\n",
     "backends/property_tests/pkg/__init__.py:2: changes __path__, so imports are not found where the harness's path "
     "says"),
    ("import json\n\ndef agent(x):\n    return {'y': json.cap(x)}\n",
     f"{IMPL}:1: backends/property_tests/json.py has the name of a module of the standard library outside the "
     "workspace: which of the two runs depends on what the process imported before"),
])
def test_an_import_that_cannot_be_followed_is_named_and_the_evidence_is_inconclusive(
        tmp_path: Path, impl: str, named: str) -> None:
    root = _workspace(tmp_path, {"helper.py": GOOD, "backends/property_tests/json.py": GOOD,
                                 "backends/property_tests/pkg/__init__.py": (
                                     "import pkgutil\n__path__ = pkgutil.extend_path(__path__, __name__)\n" + GOOD)},
                      impl=impl)
    assert named in resolve_closure(root, IMPL).unresolved
    ev = _evidence(root)
    assert ev.status == "inconclusive" and named in ev.explanation, ev.explanation
    assert named in ev.details["imports_not_hashed"]


def test_control_the_same_implementation_with_literal_imports_is_discharged(tmp_path: Path) -> None:
    root = _workspace(tmp_path, {"helper.py": GOOD})
    ev = _evidence(root)
    assert ev.status == "discharged", ev.explanation
    assert "helper.py" in ev.input_hashes and "imports_not_hashed" not in ev.details


def test_a_module_imported_since_the_export_is_not_run_unhashed(tmp_path: Path) -> None:
    root = _workspace(tmp_path, {"helper.py": GOOD, "other.py": BAD})
    target = Workspace(root).target("Agent", 0)
    backend = PropertyTestsBackend()
    obligation = backend.export(target)[0]
    assert backend.run(obligation, target).status == "discharged"  # control: the closure the export hashed
    (root / IMPL).write_text("from other import cap\n\ndef agent(x):\n    return {'y': cap(x)}\n")
    ev = backend.run(obligation, target)  # the obligation of before: other.py is not among its inputs
    assert ev.status == "inconclusive" and "now imports other.py" in ev.explanation, ev.explanation


# ---------------------------------------------------------------- doit verify: incremental agrees with clean


def _verify(ws: Path) -> tuple[str, str]:
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True, timeout=300)
    assert "Traceback" not in r.stderr, r.stderr
    rep = json.loads((ws / "reports/assurance.json").read_text())
    return rep["requirements"][0]["status"], rep["obligations"][0]["status"]


def _clean(ws: Path, where: Path) -> tuple[str, str]:
    shutil.copytree(ws, where, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))
    return _verify(where)


def _record(ws: Path) -> bytes:
    return b"".join(p.read_bytes() for p in sorted((ws / "artifacts/evidence").glob("*.json")))


@pytest.fixture(scope="module")
def both_good(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, tuple[str, str]]:
    """A helper beside the implementation and one at the root, both correct, verified once for the module:
    ``(workspace, its first run's statuses)``.  The tests that edit it do so in place and put it back
    (tests/_restore.py), so that their second run is the incremental one a user's edit gets."""
    ws = _workspace(tmp_path_factory.mktemp("both-good") / "ws",
                    {"backends/property_tests/helper.py": GOOD, "helper.py": GOOD})
    return ws, _verify(ws)


@pytest.fixture(scope="module")
def clean_front_bad(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    """A clean run of the workspace the two edits below end in (a wrong helper beside the implementation, a
    correct one at the root): what their incremental runs must agree with.  One run for both: their
    workspaces hold the same files (``_clean`` copies inputs only, never records)."""
    ws = _workspace(tmp_path_factory.mktemp("front-bad") / "clean",
                    {"backends/property_tests/helper.py": BAD, "helper.py": GOOD})
    return _verify(ws)


def test_editing_the_helper_that_runs_re_runs_and_agrees_with_a_clean_run(
        tmp_path: Path, both_good: tuple[Path, tuple[str, str]], clean_front_bad: tuple[str, str]) -> None:
    assert both_good[1] == ("discharged", "discharged")
    with restored(both_good[0], tmp_path / "before") as ws:
        (ws / "backends/property_tests/helper.py").write_text(BAD)  # the one earlier on the harness's path
        assert _verify(ws) == ("failed", "failed")
        assert _inputs(ws) == _inputs(_front_bad(tmp_path / "same"))  # the clean run's files
    assert clean_front_bad == ("failed", "failed")


def test_control_editing_the_shadowed_helper_leaves_the_evidence_current(
        tmp_path: Path, both_good: tuple[Path, tuple[str, str]]) -> None:
    assert both_good[1] == ("discharged", "discharged")
    with restored(both_good[0], tmp_path / "before") as ws:
        before = _record(ws)
        (ws / "helper.py").write_text(BAD)  # behind the implementation's own helper: it never runs
        assert _verify(ws) == ("discharged", "discharged")
        assert _record(ws) == before  # not stale, not run again
        assert _clean(ws, tmp_path / "clean") == ("discharged", "discharged")


def test_a_helper_created_in_front_of_the_hashed_one_re_runs_the_tests(
        tmp_path: Path, clean_front_bad: tuple[str, str]) -> None:
    ws = _workspace(tmp_path / "ws", {"helper.py": GOOD})
    assert _verify(ws) == ("discharged", "discharged")
    (ws / "backends/property_tests/helper.py").write_text(BAD)  # now found first: what runs changed
    assert _verify(ws) == ("failed", "failed")
    assert _inputs(ws) == _inputs(_front_bad(tmp_path / "same"))  # the clean run's files
    assert clean_front_bad == ("failed", "failed")


def _front_bad(root: Path) -> Path:
    """The inputs of :func:`clean_front_bad`'s workspace, written again (not run)."""
    return _workspace(root, {"backends/property_tests/helper.py": BAD, "helper.py": GOOD})


def _inputs(ws: Path) -> dict[str, bytes]:
    """The workspace's inputs as ``_clean`` copies them: every file but records, reports, doit's state, bytecode."""
    skip = ("artifacts", "reports", "__pycache__")
    return {str(p.relative_to(ws)): p.read_bytes() for p in sorted(ws.rglob("*")) if p.is_file()
            and not any(part in skip or part.startswith(".doit") for part in p.relative_to(ws).parts)}


@pytest.mark.parametrize("own", [
    "os.path.dirname(os.path.abspath(__file__))", "os.path.dirname(__file__)",
    "os.path.abspath(os.path.dirname(__file__))", "str(pathlib.Path(__file__).resolve().parent)",
    "str(pathlib.Path(__file__).parent)",
])
def test_the_ros_idiom_of_putting_its_own_folder_on_sys_path_is_followed(tmp_path: Path, own: str) -> None:
    """``sys.path.insert(0, <its own folder>)`` then ``import helper`` (a ROS script's idiom): the folder is the
    harness's first already, so the helper beside it is what runs and is hashed, and a correct helper is
    discharged (it was inconclusive: 'changes sys.path'); a wrong one fails."""
    impl = (f"import os, pathlib, sys\nsys.path.insert(0, {own})\nimport helper\n\n"
            "def agent(x):\n    return {'y': helper.cap(x)}\n")
    root = _workspace(tmp_path, {"backends/property_tests/helper.py": GOOD}, impl=impl)
    closure = resolve_closure(root, IMPL)
    assert closure.unresolved == () and "backends/property_tests/helper.py" in closure.files
    if own == "os.path.dirname(os.path.abspath(__file__))":  # the tests run and decide (one form: each costs a run)
        ev = _evidence(root)
        assert ev.status == "discharged", ev.explanation
        (root / "backends/property_tests/helper.py").write_text(BAD)
        assert _evidence(root).status == "failed"


def test_control_another_folder_put_on_sys_path_is_still_named(tmp_path: Path) -> None:
    impl = ("import os, sys\nsys.path.insert(0, os.path.join(os.path.dirname(__file__), 'lib'))\nimport helper\n\n"
            "def agent(x):\n    return {'y': helper.cap(x)}\n")
    root = _workspace(tmp_path, {"backends/property_tests/lib/helper.py": GOOD}, impl=impl)
    assert f"{IMPL}:2: changes sys.path, so imports are not found where the harness's path says" in \
        resolve_closure(root, IMPL).unresolved
