"""rclverify's replacement of doit's implicit-dependency scan (app/doit_patches.py) adds
the same task dependencies in the same order as doit's own."""
from __future__ import annotations

import random
from types import SimpleNamespace

from doit.control import TaskControl

from rclverify.app import doit_patches, tasks


def test_the_linear_scan_adds_what_doits_own_adds() -> None:
    doit_patches.use_linear_implicit_task_dep()
    doits = doit_patches.DOIT_IMPLICIT_TASK_DEP[0]
    assert doits is not doit_patches.linear_implicit_task_dep
    rnd = random.Random(7)
    for _ in range(200):
        targets = {f"f{k}": f"t{rnd.randrange(8)}" for k in range(rnd.randrange(30))}
        deps = [f"f{rnd.randrange(40)}" for _ in range(rnd.randrange(40))]
        start = [f"t{rnd.randrange(8)}" for _ in range(rnd.randrange(3))]
        a, b = SimpleNamespace(task_dep=list(start)), SimpleNamespace(task_dep=list(start))
        doits(targets, a, deps)
        doit_patches.linear_implicit_task_dep(targets, b, deps)
        assert a.task_dep == b.task_dep


def test_build_tasks_installs_it(tmp_path) -> None:
    tasks.build_tasks(tmp_path)  # an empty directory: no plan, only check and verify are defined
    assert TaskControl.add_implicit_task_dep is doit_patches.linear_implicit_task_dep


def test_doit_list_with_status_answers_for_verify(tmp_path) -> None:
    """``doit list --all --status`` asks ``verify``'s uptodate check without parsing its options:
    one line per task, no traceback (the check read ``task.options`` as a dict)."""
    import subprocess
    import sys
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n")
    out = subprocess.run([sys.executable, "-m", "doit", "list", "--all", "--status"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=60)
    assert "Traceback" not in out.stderr + out.stdout, out.stderr
    assert [line.split()[:2] for line in out.stdout.splitlines()] == [["R", "check"], ["U", "verify"]]
