"""Hypothesis imported by rclverify without the entry-point plugins of other packages
(src/rclverify/backends/property_tests/hypothesis_lib.py): a plugin installed beside it is
not run, the environment is as it was before, and no module of rclverify imports Hypothesis
any other way."""
from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "rclverify"
LIB = SRC / "backends" / "property_tests" / "hypothesis_lib.py"

PLUGIN = '''
import os
from pathlib import Path

def setup():
    Path(os.environ["PLUGIN_RAN"]).write_text("ran")
'''

PROBE = '''
import json, os, sys
import {module}
print(json.dumps({{"no_plugins": os.environ.get("HYPOTHESIS_NO_PLUGINS"), "loaded": "hypothesis" in sys.modules}}))
'''


@pytest.fixture()
def plugin_dir(tmp_path: Path) -> Path:
    """A directory holding a module and a distribution whose ``hypothesis`` entry point runs it."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "probe_plugin.py").write_text(PLUGIN, encoding="utf-8")
    info = site / "probe_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: probe-plugin\nVersion: 1.0\n", encoding="utf-8")
    (info / "entry_points.txt").write_text("[hypothesis]\nprobe = probe_plugin:setup\n", encoding="utf-8")
    return site


def _probe(module: str, site: Path, ran: Path, **extra: str) -> dict[str, object]:
    env = {k: v for k, v in os.environ.items() if k != "HYPOTHESIS_NO_PLUGINS"}
    env.update(PYTHONPATH=os.pathsep.join([str(site), env.get("PYTHONPATH", "")]), PLUGIN_RAN=str(ran), **extra)
    r = subprocess.run([sys.executable, "-c", PROBE.format(module=module)], env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    out: dict[str, object] = json.loads(r.stdout.strip().splitlines()[-1])
    return out


def test_the_plugin_runs_when_hypothesis_is_imported_plainly(plugin_dir: Path, tmp_path: Path) -> None:
    """The probe's plugin is real: a plain ``import hypothesis`` runs it."""
    ran = tmp_path / "ran"
    _probe("hypothesis", plugin_dir, ran)
    assert ran.read_text() == "ran"


@pytest.mark.parametrize("module", ["rclverify.backends.property_tests.harness",
                                    "rclverify.backends.property_tests.strategies"])
def test_rclverify_imports_hypothesis_without_plugins(plugin_dir: Path, tmp_path: Path, module: str) -> None:
    ran = tmp_path / "ran"
    got = _probe(module, plugin_dir, ran)
    assert got == {"no_plugins": None, "loaded": True}
    assert not ran.exists()


def test_the_users_setting_is_restored(plugin_dir: Path, tmp_path: Path) -> None:
    got = _probe("rclverify.backends.property_tests.harness", plugin_dir, tmp_path / "ran", HYPOTHESIS_NO_PLUGINS="yes")
    assert got["no_plugins"] == "yes"


def _imports_hypothesis(node: ast.AST) -> bool:
    if isinstance(node, ast.Import):
        return any(a.name.split(".")[0] == "hypothesis" for a in node.names)
    return isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "hypothesis" and not node.level


def test_every_import_of_hypothesis_goes_through_the_one_module() -> None:
    """Only hypothesis_lib imports Hypothesis at module level; a module importing one of
    Hypothesis's internals inside a function has imported hypothesis_lib at module level."""
    wrong = []
    for path in sorted(SRC.rglob("*.py")):
        if path == LIB:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top = [n for n in tree.body if _imports_hypothesis(n)]
        nested = [n for n in ast.walk(tree) if _imports_hypothesis(n) and n not in top]
        through = any(isinstance(n, ast.ImportFrom) and n.module == "rclverify.backends.property_tests.hypothesis_lib"
                      for n in tree.body)
        wrong += [f"{path.relative_to(SRC)}:{n.lineno}" for n in top]
        if not through:
            wrong += [f"{path.relative_to(SRC)}:{n.lineno}" for n in nested]
    assert not wrong, wrong
