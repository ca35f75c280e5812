"""The lean install: each optional part is an extra, and a missing one is said in
one line naming it, never a traceback (core/extras.py, docs/install.md).

A missing package is made missing for real: the command runs in a fresh
interpreter whose import system refuses the package's top-level name, as an
interpreter without it installed does.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from _blocked import cli_without
from rclverify.core.extras import EXTRA_OF, MissingExtra, missing_message, require

ROOT = Path(__file__).resolve().parents[2]

def test_every_optional_module_belongs_to_an_extra_of_the_distribution() -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"]
    core = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["dependencies"]
    assert set(EXTRA_OF.values()) <= set(extras)
    for module, extra in EXTRA_OF.items():
        wanted = module.replace("_", "-")
        names = " ".join(extras[extra]).lower().replace("_", "-")
        assert wanted in names or module == "distributed", (module, extra)
        assert not any(d.lower().replace("_", "-").startswith(wanted) for d in core), module
    assert set(extras["all"][0].split("[")[1].rstrip("]").split(",")) == set(extras) - {"all", "test", "dev", "bench"}


def test_a_missing_extra_is_one_line_naming_it() -> None:
    msg = missing_message("matplotlib", "the experiment's plot")
    assert msg == ("the experiment's plot needs rclverify's [plots] extra (matplotlib is not installed): "
                   "pip install 'rclverify[plots]'")
    with pytest.raises(MissingExtra) as info:
        require("rclverify_no_such_module_here", "a test")
    assert "\n" not in str(info.value) and isinstance(info.value, ImportError)


def test_an_import_error_inside_an_installed_package_is_not_hidden(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "brokenpkg_rclv").mkdir()
    (tmp_path / "brokenpkg_rclv" / "__init__.py").write_text("import rclverify_absent_dependency\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ImportError) as info:
        require("brokenpkg_rclv", "a test")
    assert not isinstance(info.value, MissingExtra)


def test_the_language_server_without_its_extra_says_so_in_one_line() -> None:
    r = cli_without("pygls,lsprotocol", "lsp")
    assert r.returncode == 1, r.stderr
    assert r.stderr.strip().splitlines() == [
        "error: the RCL language server needs rclverify's [lsp] extra (pygls is not installed): "
        "pip install 'rclverify[lsp]'"]


def test_a_workspace_that_needs_the_ros_extra_says_so_in_one_line(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(ROOT / "examples" / "warehouse", ws, ignore=shutil.ignore_patterns("artifacts", "reports"))
    r = cli_without("rosbags", "verify", cwd=ws)
    assert r.returncode == 1, r.stderr
    assert r.stderr.strip().splitlines()[-1].startswith("error: reading the standard ROS message types needs "
                                                          "rclverify's [ros] extra"), r.stderr
    assert "Traceback" not in r.stderr


def test_the_live_ros2_monitor_without_its_extra_is_one_line_and_exit_1(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples" / "ros2_robot" / "contracts", tmp_path / "contracts")
    r = cli_without("cyclonedds", "monitor", "--live", "--ros2", "--source", "dds", cwd=tmp_path)
    assert (r.returncode, r.stdout) == (1, ""), (r.stdout, r.stderr)
    assert r.stderr.strip().splitlines() == [
        "rclverify monitor --live: error: ROS 2 over DDS needs rclverify's [ros2] extra (cyclonedds is not "
        "installed): pip install 'rclverify[ros2]'"]
    # control: with the extra, a problem of the workspace (an action type it does not define) stays exit 2
    c = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "monitor", "--live", "--ros2", "--source",
                        "dds"], cwd=tmp_path, capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert c.returncode == 2 and "robot_msgs/action/Dock_Goal" in c.stderr, (c.stdout, c.stderr)


def test_a_statistical_target_without_scipy_is_inconclusive_with_the_reason() -> None:
    code = """
import importlib.abc, sys
class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "scipy":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None
sys.meta_path.insert(0, Refuse())
import json
from rclverify.model.plan.target_text import parse_target
from rclverify.records.statistics import decide, trivial_or_exact, upper_bound
t = parse_target("violation probability <= 0.1 at 95 % per run")
clean = decide({"runs": 40, "violating_runs": 0, "undecided_runs": 0}, t)
some = decide({"runs": 40, "violating_runs": 2, "undecided_runs": 0}, t)
print(json.dumps([clean["status"], some["status"], some["explanation"], some["bound"], trivial_or_exact(2, 40, 0.95)]))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    import json
    clean, some, why, bound, trivial = json.loads(r.stdout)
    assert clean == "discharged"  # no violation: the closed form, no scipy needed
    assert some == "inconclusive" and "rclverify[stats]" in why and bound == 1.0
    assert trivial[0] == 1.0 and "[stats]" in trivial[1]
