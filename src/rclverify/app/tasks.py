"""doit task generators for a workspace (``dodo.py`` only calls :func:`build_tasks`).

Stages and their real file dependencies, per node ``N``:

``check``          contracts + plan -> artifacts/contracts/N.json (one snapshot per
                   node, rewritten only when that node's text changes), artifacts/cones/N.sha256
                   (a digest of N's upstream cone's snapshots), model, lint
``graph``          model -> model.dot, model.svg (when graphviz is installed); not part of
                   ``verify`` (the report lays out its own diagram, with statuses):
                   ``doit graph`` runs it
``node:N``         three stages, each run only when one of its own inputs changed:
                   compose  snapshot of N and of N's producers + model -> calculus/N.json;
                            run again too when the part of N's cone digest it read changed
                            (app/conetask.py: the whole cone when a side condition was decided in
                            context, the cone's environment assumptions otherwise)
                   health   snapshot of N (+ replacement contract) -> health/N.json
                   export   snapshot of N + the backend input files -> obligations/N.json
``evidence:ID``     one obligation's record + the files it reads -> its evidence record
                   (created after ``node`` ran, when the obligations are known)
``requirements``   plan + model + contract snapshots (+ Doorstop files, recorded runs) ->
                   artifacts/requirements/<ID>.json; inside, only requirements whose
                   cone's snapshots or statements changed are checked again
``deadlines``      plan + model + snapshots of the nodes between a deadline's ends ->
                   artifacts/deadlines/index.json (rule D3, every end-to-end deadline;
                   only when the plan has one)
``report:html``    every artifact above -> reports/assurance.{html,json}, the CI formats
                   reports/assurance.sarif, assurance.junit.xml, argument.svg
``report:text``    every artifact above -> reports/assurance.md, argument.{json,gsn.yaml,dot}
                   (two tasks rendered at once by ``doit -n 2``: report/parts.py)
``verify``         the whole pipeline; ``doit verify --strict`` fails unless every
                   obligation is discharged

doit compares file contents (md5), so editing one node's contract changes
only that node's snapshot: its node task (all three stages) and run tasks,
its consumers' node tasks (the compose stage only: their side conditions), the
node tasks downstream whose side conditions were decided in context against
the cone (app/conetask.py)
and the report re-run.  The three stages share one doit task per node
because doit's own cost per task (defining it, checking its dependencies)
was most of a no-op run of a large system (docs/scale.md); the task's
action gets doit's list of changed dependencies and runs the stages that
read one of them (:func:`stages_to_run`).
Actions are module-level functions with plain arguments, so ``doit -n 2``
(parallel processes) behaves like a serial run.

With the environment variable ``RCLVERIFY_CLUSTER=ADDRESS`` the ``evidence``
tasks send their backend jobs to that Dask scheduler (:mod:`rclverify.app.cluster`);
the records are stored locally as in a local run.
"""
from __future__ import annotations

import inspect
import os
import shutil
from pathlib import Path
from typing import Any, Callable, Iterator, TypeVar, cast

from doit import create_after as _create_after
from doit.tools import config_changed

from rclverify.core.cache import code_stamp, heap
from rclverify.core.cache import workspace as wscache
from rclverify.app.pipeline import REPORT_PARTS, TaskIndex, Workspace
from rclverify.lang.errors import RclError
from rclverify.stages.workspace import check_input_files
import sys
from rclverify.records.sealed import TargetsSealed, obligation_list
from rclverify.app.doit_patches import guard_dep_writes, use_linear_implicit_task_dep
from rclverify.app.task_actions import (NODE_STAGES, WORKSPACES, act_check, act_crosscheck, act_deadlines, act_graph,
                                        act_ground, act_node, act_report, act_requirements, act_run, act_verify,
                                        stages_to_run)
from rclverify.app.task_checks import (RecordIntact, entry_inputs, ros_fingerprint, strict_uptodate, tool_fingerprint,
                                       z3_version)

__all__ = ["build_tasks", "doit_config", "DEP_FILE", "REPORTS", "DEADLINES_INDEX", "CROSSCHECK_INDEX", "NODE_STAGES",
           "stages_to_run", "act_check", "act_report", "act_verify"]

_F = TypeVar("_F", bound=Callable[..., Any])


def create_after(executed: str) -> Callable[[_F], _F]:
    """doit's ``create_after`` (delayed task creation), typed."""
    return cast(Callable[[_F], _F], _create_after(executed=executed))


REPORTS = ["reports/assurance.html", "reports/assurance.md", "reports/assurance.json"]
#: The deadlines' and the second solver's records (stages/deadlines.py, stages/crosscheck/stage.py: ``INDEX``),
#: named here so that defining the tasks imports neither stage (tests/test_scale.py holds them equal).
DEADLINES_INDEX = "artifacts/deadlines/index.json"
CROSSCHECK_INDEX = "artifacts/crosscheck/index.json"


#: The name older callers import (tests, ``from rclverify.app.tasks import _inputs``): :func:`entry_inputs`.
_inputs = entry_inputs


#: Where doit keeps the state of each task (its file_dep signatures), relative to the workspace.
DEP_FILE = ".doit.sqlite"


def doit_config(dep_file: str = DEP_FILE) -> dict[str, Any]:
    """``DOIT_CONFIG`` of a workspace's ``dodo.py`` (and of ``rclverify verify``):
    ``verify`` by default, the progress reporter, and doit's SQLite
    dependency store in ``dep_file``.

    SQLite rather than doit's default ``dbm`` store: with Python's fallback
    ``dbm.dumb`` (no gdbm on many systems) opening the store parses one line
    per task with ``ast.literal_eval``, about 0.3 CPU s of a 1000-node no-op
    run when it had 5000 tasks (docs/scale.md).  A workspace that switches store runs
    every task once, as doit knows no earlier state in the new file."""
    from rclverify.app.progress import ProgressReporter  # deferred: start-up (loads doit, rclverify.app.doitstate and more only when called)
    return {"default_tasks": ["verify"], "verbosity": 2, "dep_file": dep_file, "backend": "sqlite3",
            "reporter": ProgressReporter}


def build_tasks(root: str | Path, plan_file: str = "contracts/plan.yaml", *,
                wait: bool | None = None) -> dict[str, Callable[[], Any]]:
    """The ``task_*`` functions for a dodo.py of the workspace at ``root``.

    First takes the workspace's run lock (:mod:`rclverify.core.runlock`: one run
    at a time; a second run waits with the message ``waiting for the run in
    progress (pid N)``, or with ``wait=False`` / ``RCLVERIFY_NO_WAIT=1``
    does not wait).  The lock is given back when doit completes the run
    (the progress reporter) or the process ends.  When the lock cannot be
    had without waiting, or its file cannot be created, prints one
    ``error:`` line and raises ``SystemExit(1)`` (``dodo.py`` has no other
    way to end a doit command cleanly).

    The loaded workspace stays live for the run: it is loaded without
    cyclic garbage collection and then frozen for the run
    (:mod:`rclverify.core.cache.heap`; the progress reporter gives it back to the
    collector when doit completes the run)."""
    from rclverify.core import runlock  # deferred: start-up (loads rclverify.core.runlock only when called)
    from rclverify.core.faults import describe_os_error  # deferred: start-up (loads rclverify.core.faults only when called)
    rootp = Path(root)
    if not rootp.is_dir():
        print(f"{root}: error: no such workspace directory", file=sys.stderr)
        raise SystemExit(1)
    try:
        runlock.acquire(rootp, wait=wait)
    except runlock.RunInProgress as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
    except OSError as exc:
        print(describe_os_error(exc, rootp.resolve(), "cannot take the run lock in"), file=sys.stderr)
        raise SystemExit(1) from None
    with heap.no_collection():
        creators = _build_tasks(root, plan_file)
        heap.freeze_for_run()  # before collecting again: what was made while loading is not looked at
    return creators


def _build_tasks(root: str | Path, plan_file: str) -> dict[str, Callable[[], Any]]:
    use_linear_implicit_task_dep()
    guard_dep_writes()
    rootp = Path(root).resolve()
    r = str(rootp)
    ws = Workspace(rootp, plan_file)
    restored = wscache.restore(ws)  # the loaded workspace of an earlier run, when no input changed
    index: TaskIndex | None
    try:
        index = ws.index  # from the cache (no-op runs) or the loaded plan and model
    except RclError:
        index = None
    ok = index is not None
    nodes = list(index.nodes) if index is not None else []
    if ok:
        WORKSPACES[r] = ws
        if not restored:
            wscache.save_in_background(ws)
    else:
        WORKSPACES.pop(r, None)
    try:
        contract_deps = [f"{r}/{c}" for c in (index.contracts if index is not None else ws.plan.contracts)]
    except RclError:
        contract_deps = []

    def at(rel: str) -> str:
        """The absolute path of a workspace-relative artifact path (string
        joining: ``pathlib`` cost 0.3 s of a 1000-node no-op run)."""
        return f"{r}/{rel}"

    snap = {n: at(ws.snapshot(n)) for n in nodes}
    # Every task that makes a result depends on the rclverify code that makes it: another version
    # (an upgrade, a changed module) makes every result again, as a clean run would.
    code_version = {"rclverify": code_stamp(), "z3": z3_version()}
    code = config_changed(code_version)
    code.__signature__ = inspect.signature(code)  # answered at once by doit (see task_evidence)

    # Only files that exist are file dependencies (doit refuses a missing one with a DependencyError):
    # a missing plan or contract makes `check` run, and fail with the located message, every time.
    named = [str(rootp / plan_file)] + contract_deps
    check_deps = [d for d in named if os.path.isfile(d)]
    sealed = TargetsSealed()
    check_extra: dict[str, Any] = {"uptodate": [False] if len(check_deps) < len(named) or not ok else [code, sealed]}

    def task_check() -> dict[str, Any]:
        """Parse and type-check the contracts, check the plan, lint, build the system model."""
        return {"actions": [(act_check, [r, plan_file])], "file_dep": check_deps,
                "targets": list(snap.values()) + [at(ws.cone(n)) for n in nodes]
                + [str(rootp / p) for p in (ws.MODEL, ws.DIAGNOSTICS)],
                "verbosity": 2, "clean": True, **check_extra}

    def task_graph() -> dict[str, Any]:
        """Write the system model as DOT and, with graphviz, draw it as SVG (doit graph)."""
        return {"actions": [(act_graph, [r])], "file_dep": [str(rootp / ws.MODEL)], "targets": [str(rootp / ws.DOT)],
                "task_dep": ["check"], "uptodate": [config_changed(shutil.which("dot") or "")], "verbosity": 2}

    def task_node() -> Iterator[dict[str, Any]]:
        """One task per node: its calculus, health checks and exported obligations."""
        from rclverify.app.conetask import ConeUnchanged  # deferred: start-up (loads rclverify.app.conetask only when called)
        assert index is not None  # registered only when ok, i.e. the model was built
        model_json, seen = at(ws.MODEL), dict[str, tuple[str, ...]]()
        yield {"basename": "node", "name": None,
               "doc": "Per node, each when its own inputs changed: apply the calculus (R1-R4, side conditions "
                      "discharged with Z3), check contract health, export the guarantees as obligations."}
        for n in nodes:
            repl = index.replacement.get(n)
            deps = {
                "compose": [snap[n], *(snap[p] for p in index.producers[n]), model_json],
                "health": [snap[n]] + ([str(rootp / repl)] if repl and (rootp / repl).is_file() else []),
                "export": [snap[n]] + [at(f) for config in index.entries.get(n, ()) for f in entry_inputs(config, rootp, seen)],
            }
            # the upstream cone: a file the check writes, read by an uptodate check (app/conetask.py), not a
            # file_dep: only a composition that read the cone runs again when the cone changes
            cone = ConeUnchanged(at(ws.cone(n)), at(ws.provenance(n)), ws.cone(n))
            yield {"name": n, "actions": [(act_node, [r, n, deps])],
                   "file_dep": sorted({d for ds in deps.values() for d in ds}),
                   "targets": [at(ws.calculus(n)), at(ws.health(n)), at(ws.obligations(n))],
                   "uptodate": [code, sealed, cone], "verbosity": 2, "clean": True}

    def task_requirements() -> dict[str, Any]:
        """Check each requirement's formal statement with Z3 from the guarantees of its cone.  Defined before
        the evidence and report tasks: doit orders tasks by where their creators are defined, and the
        report parts must run in their usual order after it (their fragment caches, report/fragments.py)."""
        assert index is not None
        from rclverify.stages.requirements import INDEX  # deferred: start-up (loads rclverify.stages.requirements only when called)
        extra: list[str] = []
        if index.requirement_dirs:
            from rclverify.model.plan.doorstop import doorstop_files  # deferred: optional or conditional (inside a block)
            for d in index.requirement_dirs:
                extra += [str(rootp / f) for f in doorstop_files(rootp, d)]
        for configs in index.entries.values():  # recorded runs checked against temporal requirements (docs/plan.md)
            for c in configs:
                if hasattr(c, "get") and c.get("traces") and isinstance(c.get("mapping"), str) \
                        and (rootp / c["mapping"]).is_file():
                    extra.append(str(rootp / c["mapping"]))
            for tr in (t for c in configs if hasattr(c, "get") for t in c.get("traces") or () if isinstance(t, str)):
                p = rootp / tr
                extra += sorted(str(f) for f in p.rglob("*") if f.is_file()) if p.is_dir() else [str(p)] if p.is_file() else []
        return {"actions": [(act_requirements, [r])],
                "file_dep": [str(rootp / plan_file), at(ws.MODEL)] + list(snap.values()) + sorted(set(extra)),
                "targets": [at(INDEX)], "uptodate": [code, sealed], "verbosity": 2, "clean": True}

    deadline_nodes = list(index.deadline_nodes) if index is not None else []

    def task_deadlines() -> dict[str, Any]:
        """Decide each requirement's end-to-end deadline with Z3 (rule D3: deadlines add along its path)."""
        # the record's path as text: importing the deadline stage for it loaded Z3 and the deadline rules in
        # every doit run, the no-op included (0.08 s)
        return {"actions": [(act_deadlines, [r])],
                "file_dep": [str(rootp / plan_file), at(ws.MODEL)] + [snap[n] for n in deadline_nodes if n in snap],
                "targets": [at(DEADLINES_INDEX)], "uptodate": [code, sealed], "task_dep": ["check"], "verbosity": 2,
                "clean": True}

    exported_memo: list[list[tuple[str, dict[str, Any]]]] = []

    def exported() -> list[tuple[str, dict[str, Any]]]:
        """(node, obligation JSON) of every exported obligation (read after export ran;
        once per run: the evidence and report tasks are both created after it)."""
        if not exported_memo:
            exported_memo.append(read_exported())
        return exported_memo[0]

    def read_exported() -> list[tuple[str, dict[str, Any]]]:
        out: list[tuple[str, dict[str, Any]]] = []
        for n in nodes:
            records, _ = obligation_list(at(ws.obligations(n)))  # sealed: an altered list is made again first
            out.extend((n, o) for o in records or [])
        return out

    @create_after(executed="node")
    def task_evidence() -> Iterator[dict[str, Any]]:
        """Run the backends: one task per obligation, one evidence record each."""
        yield {"basename": "evidence", "name": None, "doc": "Run each backend on its obligations and record evidence."}
        # One check for every evidence task: the tools found on PATH (searched once, not per
        # obligation).  doit inspects an uptodate callable's signature for every task on every run
        # (2000 `inspect.signature` calls, a third of a second at 1000 nodes); a precomputed
        # `__signature__` (PEP 362) answers it at once.
        # One config_changed per task: doit saves every config_changed of a task under one key, so a
        # second one would overwrite the first's value and the task would never be up to date.
        tools_unchanged = config_changed({**tool_fingerprint(), **code_version})
        tools_unchanged.__signature__ = inspect.signature(tools_unchanged)
        record_intact = RecordIntact()
        input_file: dict[str, str | None] = {}  # input -> its absolute path when it is a file (one stat per input)

        def input_dep(rel: str) -> str | None:
            if rel not in input_file:
                p = rel if os.path.isabs(rel) else at(rel)  # strings, not pathlib: 0.1 s of a 1000-node no-op
                input_file[rel] = p if os.path.isfile(p) else None
            return input_file[rel]
        for n, o in exported():
            deps = [at(ws.obligation(n, o["id"]))]
            deps += [d for d in map(input_dep, o["inputs"]) if d is not None]
            yield {"name": o["id"], "actions": [(act_run, [r, n, o["id"]])], "file_dep": sorted(set(deps)),
                   "targets": [at(ws.evidence(o["id"]))], "uptodate": [tools_unchanged, record_intact],
                   "verbosity": 2, "clean": True}

    ros_section = dict(index.ros) if index is not None else {}  # from the index: a no-op run loads no contract

    @create_after(executed="evidence")
    def task_crosscheck() -> dict[str, Any]:
        """Decide every discharging Z3 query again with cvc5 from its SMT-LIB2 text (docs/second-solver.md)."""
        deps = [at(ws.calculus(n)) for n in nodes] + [at(ws.health(n)) for n in nodes]
        deps += [at(ws.obligations(n)) for n in nodes]
        deps += [at(ws.evidence(o["id"])) for _, o in exported() if o.get("backend") == "hoare"]
        deps.append(at("artifacts/requirements/index.json"))
        if deadline_nodes:
            deps.append(at(DEADLINES_INDEX))
        return {"actions": [(act_crosscheck, [r, list(nodes)])], "file_dep": deps,
                "targets": [at(CROSSCHECK_INDEX)], "uptodate": [code, sealed], "verbosity": 2, "clean": True}

    def task_ground() -> dict[str, Any]:
        """Ground the contracts in the ROS software of the plan's ros: section (docs/ros.md)."""
        return {"actions": [(act_ground, [r])], "file_dep": [str(rootp / plan_file)] + contract_deps,
                "uptodate": [config_changed({"files": ros_fingerprint(rootp, ros_section)}), sealed],
                "targets": [at("artifacts/ros/grounding.json"), at("artifacts/ros/graph.json")],
                "task_dep": ["check"], "verbosity": 2, "clean": True}

    @create_after(executed="evidence")
    def task_report() -> Iterator[dict[str, Any]]:
        """Roll everything up into the report files: two parts, rendered at once by doit -n 2."""
        yield {"basename": "report", "name": None,
               "doc": "Roll everything up into reports/ (assurance.{html,md,json}, the CI formats, the argument)."}
        # The plan itself: the report shows its name, requirements and their tracing, which no
        # other artifact holds (a plan edit that changes only those re-renders the report).
        deps = [str(rootp / plan_file)] + [at(p) for p in (ws.MODEL, ws.DIAGNOSTICS)] + list(snap.values())
        # The files meta.inputs_sha256 hashes (workspace.check_inputs): the contract and replacement files
        # themselves, not only the snapshots they give. An edit that changes none of the snapshots (a comment
        # after the last node) left the report naming the old files' sha256, and the bundle then refused a
        # report `doit verify` called up to date.
        deps += [d for d in (at(f) for f in check_input_files(ws)) if d not in deps and os.path.isfile(d)]
        for n in nodes:
            deps += [at(ws.calculus(n)), at(ws.health(n)), at(ws.obligations(n))]
        deps += [at(ws.evidence(o["id"])) for _, o in exported()]
        deps.append(at("artifacts/requirements/index.json"))  # the requirements task's target
        if ros_section:
            deps.append(at("artifacts/ros/grounding.json"))
        if deadline_nodes:
            deps.append(at(DEADLINES_INDEX))  # the deadlines task's target
        deps.append(at(CROSSCHECK_INDEX))  # the second solver's verdicts
        for part, files in REPORT_PARTS.items():
            # task_dep on crosscheck: both are created after `evidence`, and when the report's loader runs
            # first doit does not yet know which task makes the second solver's index (its file_dep alone
            # then let doit -n 2 render the report beside crosscheck, from no index)
            yield {"name": part, "doc": "reports/" + ", ".join(files), "actions": [(act_report, [r, part])],
                   "file_dep": deps, "task_dep": ["crosscheck"], "uptodate": [code, sealed],
                   "targets": [at(f"reports/{f}") for f in files if f != "argument.svg"]
                   + ([at(ws.SUMMARY)] if part == "html" else []),
                   "verbosity": 2, "clean": True}

    def task_verify() -> dict[str, Any]:
        """The whole pipeline: check, compose, health, export, run, report.  --strict fails on any open evidence."""
        # `requirements` (and `ground`) before `report`: reached only through the report's file dependencies,
        # they would make report:html wait and report:text run first (their fragment caches expect html first)
        before = (["requirements"] + (["deadlines"] if deadline_nodes else []) + ["crosscheck"]
                  + (["ground"] if ros_section else []))
        return {"actions": [(act_verify, [r])], "task_dep": ["check", *before, "report"] if ok else ["check"],
                "file_dep": [str(rootp / REPORTS[2])] if ok else [],
                "params": [{"name": "strict", "long": "strict", "type": bool, "default": False,
                            "help": "fail unless every obligation, side condition, health check and formal requirement holds"}],
                "uptodate": [strict_uptodate], "verbosity": 2}

    creators: dict[str, Callable[[], Any]] = {"task_check": task_check, "task_verify": task_verify}
    if ok:
        creators.update({"task_graph": task_graph, "task_node": task_node, "task_requirements": task_requirements,
                         "task_evidence": task_evidence, "task_report": task_report,
                         "task_crosscheck": task_crosscheck})
        if ros_section:
            creators["task_ground"] = task_ground
        if deadline_nodes:
            creators["task_deadlines"] = task_deadlines
    return creators
