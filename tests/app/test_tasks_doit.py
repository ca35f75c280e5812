"""rclverify's replacement of doit's implicit-dependency scan (app/doit_patches.py) adds
the same task dependencies in the same order as doit's own."""
from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path
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
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n")
    out = subprocess.run([sys.executable, "-m", "doit", "list", "--all", "--status"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=60)
    assert "Traceback" not in out.stderr + out.stdout, out.stderr
    assert [line.split()[:2] for line in out.stdout.splitlines()] == [["R", "check"], ["U", "verify"]]


#: 16 tasks waiting for one slow task, in two doit processes, with release_in_order installed.
WAITING_DODO = """\
import time
from rclverify.app.doit_patches import release_in_order
DOIT_CONFIG = {"verbosity": 0, "dep_file": ".doit.db", "backend": "json"}
release_in_order()


def _nap(s):
    time.sleep(s)


def task_first():
    return {"actions": [(_nap, [0.3])], "uptodate": [False]}


def task_x():
    for k in range(16):
        yield {"name": f"{k:02d}", "actions": [(_nap, [0.1])], "task_dep": ["first"], "uptodate": [False]}


def task_all():
    return {"actions": None, "task_dep": ["first", "x"]}
"""


def _started(tmp_path: Path) -> list[str]:
    """The waiting tasks in the order they started (doit's console reporter's ``.  name`` lines,
    printed when a worker starts a task)."""
    (tmp_path / "dodo.py").write_text(WAITING_DODO)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2] / "src")}
    r = subprocess.run([sys.executable, "-m", "doit", "-n", "2", "all"], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    return [line[3:] for line in r.stdout.splitlines() if line.startswith(".  x:")]


def _inversions(names: list[str]) -> int:
    return sum(a > b for i, a in enumerate(names) for b in names[i + 1:])


def test_tasks_that_waited_for_one_start_in_the_order_they_began_to_wait(tmp_path) -> None:
    """doit keeps the tasks waiting for a task in a set: once it ended, they started in the order of
    the objects' addresses.  With release_in_order they start in the order the dispatcher met them
    (``verify``'s task dependencies: the node tasks before the health checks and the requirements).
    The reporter's line comes when a worker starts its task, so two workers may swap a neighbouring
    pair, every pair on a loaded machine: each task is at most one place from its turn (of the 16!
    orders of 16 tasks, 1,597 are, about one in ten billion; a random order has 60 pairs out of order
    on average)."""
    got = _started(tmp_path)
    assert sorted(got) == [f"x:{k:02d}" for k in range(16)]
    assert all(abs(int(name[2:]) - k) <= 1 for k, name in enumerate(got)) and _inversions(got) <= 8, got


def test_build_tasks_installs_the_release_in_order(tmp_path) -> None:
    from doit.control import ExecNode
    tasks.build_tasks(tmp_path)
    assert getattr(ExecNode.__init__, "_rclverify_in_order", False)


def test_the_digested_config_is_the_value_doit_stores_for_the_config() -> None:
    """``digested`` hands doit the digest it would take itself: a workspace verified before keeps its
    tasks up to date, and a changed value is a changed digest."""
    from doit.tools import config_changed
    from rclverify.app.doit_glue import digested
    rnd = random.Random(11)
    for _ in range(200):
        config = {f"k{rnd.randrange(9)}": rnd.choice([None, rnd.random(), "v" * rnd.randrange(4), [1, "é"]])
                  for _ in range(rnd.randrange(6))}
        assert digested(config)._calc_digest() == config_changed(config)._calc_digest()
    assert digested({"a": 1})._calc_digest() != digested({"a": 2})._calc_digest()
