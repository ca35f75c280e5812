"""The doit task table of ``doit verify``: one method per task family (docs/architecture.md, "Small rooms").

:class:`TaskTable` holds what every task definition of one run reads (the
workspace, its :class:`~rclverify.app.pipeline.TaskIndex`, the contract
snapshots, the code-version check) and defines the tasks that
:mod:`rclverify.app.tasks` lists in its docstring, each by a ``task_*``
method that doit calls as a task creator (doit accepts bound methods, also
with ``create_after``).  doit orders the tasks by the line where each
creator is defined, so the methods stand in the order the tasks run:
check, graph, node, health, requirements, deadlines, evidence, crosscheck, ground,
nodl, diagnosis, report, verify.  The actions the tasks run are in
:mod:`rclverify.app.task_actions`, the ``uptodate`` checks in
:mod:`rclverify.app.task_checks`, the hand-over to doit in
:mod:`rclverify.app.doit_glue`.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any, Callable, Iterator

from doit.tools import config_changed

from rclverify.core.cache import code_stamp
from rclverify.app.task_actions import (act_check, act_crosscheck, act_deadlines, act_design, act_diagnosis, act_graph,
                                        act_ground, act_node, act_nodl, act_report, act_requirements, act_run, act_verify)
from rclverify.app.doit_glue import create_after, digested, signed
from rclverify.app.shapes import DoitTask
from rclverify.app.task_checks import (RecordIntact, TargetsAsWritten, entry_inputs, ros_fingerprint, strict_uptodate,
                                       tool_fingerprint, z3_version)
from rclverify.stages.provenance import check_input_files
from rclverify.stages.workspace import REPORT_PARTS, TaskIndex, Workspace
from rclverify.records.sealed import TargetsSealed, obligation_list

#: One exported obligation: its node and its JSON object (artifacts/obligations/<Node>.json).
Exported = list[tuple[str, dict[str, Any]]]


REPORTS = ["reports/assurance.html", "reports/assurance.md", "reports/assurance.json"]
#: The deadlines' and the second solver's records (stages/deadlines.py, stages/crosscheck/stage.py: ``INDEX``),
#: named here so that defining the tasks imports neither stage (tests/app/test_scale.py holds them equal).
DEADLINES_INDEX = "artifacts/deadlines/index.json"
CROSSCHECK_INDEX = "artifacts/crosscheck/index.json"
#: The diagnosis stage's record (stages/diagnoses.py: ``INDEX``), named here for the same reason.
DIAGNOSIS_INDEX = "artifacts/diagnosis/index.json"
#: The NoDL stage's record (stages/nodl.py: ``INDEX``) and its documents' folder (model/nodl/check.py: ``FOLDER``).
NODL_INDEX = "artifacts/nodl/index.json"
NODL_FOLDER = "nodl"
NODL_SUFFIXES = (".nodl.yaml", ".nodl.yml", ".nodl.json")
#: The design stage's record (stages/design.py: ``INDEX``).
DESIGN_INDEX = "artifacts/design/index.json"


class TaskTable:
    """The tasks of one doit run over the workspace ``ws`` (rooted at an
    absolute, resolved path), whose plan is ``plan_file`` (workspace-relative).

    ``index`` is ``None`` when the contracts or plan do not load: only
    ``check`` (which then fails with the located message) and ``verify`` are
    defined.  ``contract_deps`` are the absolute paths of the plan's
    contract files.  Paths in the task dicts are absolute strings.
    """

    def __init__(self, ws: Workspace, index: TaskIndex | None, plan_file: str, contract_deps: list[str]) -> None:
        self.ws, self.index, self.plan_file, self.contract_deps = ws, index, plan_file, contract_deps
        self.ok = index is not None
        self.rootp = Path(ws.root)
        self.r = str(self.rootp)
        self.nodes = list(index.nodes) if index is not None else []
        self.snap = {n: self.at(ws.snapshot(n)) for n in self.nodes}
        # Every task that makes a result depends on the rclverify code that makes it: another version
        # (an upgrade, a changed module) makes every result again, as a clean run would.
        self.code_version = {"rclverify": code_stamp(), "z3": z3_version()}
        self.code = signed(digested(self.code_version))
        # Only files that exist are file dependencies (doit refuses a missing one with a DependencyError):
        # a missing plan or contract makes `check` run, and fail with the located message, every time.
        named = [str(self.rootp / plan_file)] + contract_deps
        self.check_deps = [d for d in named if os.path.isfile(d)]
        self.sealed = signed(TargetsSealed())
        self.check_uptodate: list[Any] = [False] if len(self.check_deps) < len(named) or not self.ok \
            else [self.code, self.sealed]
        self.deadline_nodes = list(index.deadline_nodes) if index is not None else []
        self.ros_section = dict(index.ros) if index is not None else {}  # from the index: a no-op run loads no contract
        self.nodl_files = self._nodl_files()
        self.design = str(getattr(index, "design", "") or "") if index is not None else ""  # the plan's design folder
        self._exported: Exported | None = None
        self._report_deps: list[str] | None = None

    def at(self, rel: str) -> str:
        """The absolute path of a workspace-relative artifact path (string
        joining: ``pathlib`` cost 0.3 s of a 1000-node no-op run)."""
        return f"{self.r}/{rel}"

    def task_check(self) -> DoitTask:
        """Parse and type-check the contracts, check the plan, lint, build the system model."""
        ws, at = self.ws, self.at
        return {"actions": [(act_check, [self.r, self.plan_file])], "file_dep": self.check_deps,
                "targets": list(self.snap.values()) + [at(ws.cone(n)) for n in self.nodes]
                + [str(self.rootp / p) for p in (ws.MODEL, ws.DIAGNOSTICS)],
                "verbosity": 2, "clean": True, "uptodate": self.check_uptodate}

    def task_graph(self) -> DoitTask:
        """Write the system model as DOT and, with graphviz, draw it as SVG (doit graph)."""
        return {"actions": [(act_graph, [self.r])], "file_dep": [str(self.rootp / self.ws.MODEL)],
                "targets": [str(self.rootp / self.ws.DOT)],
                "task_dep": ["check"], "uptodate": [config_changed(shutil.which("dot") or "")], "verbosity": 2}

    def task_node(self) -> Iterator[DoitTask]:
        """One task per node: its calculus and exported obligations (its health checks are ``health:<Node>``)."""
        from rclverify.app.conetask import ConeUnchanged  # deferred: start-up (loads rclverify.app.conetask only when called)
        index, ws, at, rootp, snap = self.index, self.ws, self.at, self.rootp, self.snap
        assert index is not None  # registered only when ok, i.e. the model was built
        model_json, seen = at(ws.MODEL), dict[str, tuple[str, ...]]()
        yield {"basename": "node", "name": None,
               "doc": "Per node, each when its own inputs changed: apply the calculus (R1-R4, side conditions "
                      "discharged with Z3), export the guarantees as obligations."}
        for n in self.nodes:
            deps = {
                "compose": [snap[n], *(snap[p] for p in index.producers[n]), model_json],
                "export": [snap[n]] + [at(f) for config in index.entries.get(n, ())
                                       for f in entry_inputs(config, rootp, seen)],
            }
            # the upstream cone: a file the check writes, read by an uptodate check (app/conetask.py), not a
            # file_dep: only a composition that read the cone runs again when the cone changes
            cone = ConeUnchanged(at(ws.cone(n)), at(ws.provenance(n, "compose")), ws.cone(n))
            yield {"name": n, "actions": [(act_node, [self.r, n, deps])],
                   "file_dep": sorted({d for ds in deps.values() for d in ds}),
                   "targets": [at(ws.calculus(n)), at(ws.obligations(n))],
                   "uptodate": [self.code, self.sealed, cone], "verbosity": 2, "clean": True}

    def task_health(self) -> Iterator[DoitTask]:
        """One task per node: its contract health checks.  A task family of its own, not a stage of
        ``node:<Node>``: the evidence tasks are created once every ``node`` task ran (they need the
        exported obligations, not the health findings), so a node's long health checks (the case
        study's Agent: 4-9 s of vacuity, realizability and repair search) run beside the other nodes'
        evidence in ``doit -n 2`` instead of keeping every evidence task waiting (docs/scale.md)."""
        index, ws, at, rootp, snap = self.index, self.ws, self.at, self.rootp, self.snap
        assert index is not None  # registered only when ok, i.e. the model was built
        yield {"basename": "health", "name": None,
               "doc": "Per node, when its contract or replacement changed: check contract health (consistency, "
                      "vacuity, realizability, refinement of its replacement)."}
        for n in self.nodes:
            repl = index.replacement.get(n)
            deps = {"health": [snap[n]] + ([str(rootp / repl)] if repl and (rootp / repl).is_file() else [])
                    + [str(rootp / f) for f in index.bound_inputs.get(n, ())]}  # the output sequences' bounds
            yield {"name": n, "actions": [(act_node, [self.r, n, deps])], "file_dep": deps["health"],
                   "targets": [at(ws.health(n))], "uptodate": [self.code, self.sealed], "verbosity": 2,
                   "clean": True}

    def task_requirements(self) -> DoitTask:
        """Check each requirement's formal statement with Z3 from the guarantees of its cone.  Defined before
        the evidence and report tasks: doit orders tasks by where their creators are defined, and the
        report parts must run in their usual order after it (their fragment caches, report/fragments.py)."""
        from rclverify.stages.requirements import INDEX  # deferred: start-up (loads rclverify.stages.requirements only when called)
        return {"actions": [(act_requirements, [self.r])],
                "file_dep": [str(self.rootp / self.plan_file), self.at(self.ws.MODEL)] + list(self.snap.values())
                + sorted(set(self._requirement_inputs())),
                "targets": [self.at(INDEX)], "uptodate": [self.code, self.sealed], "verbosity": 2, "clean": True}

    def task_deadlines(self) -> DoitTask:
        """Decide each requirement's end-to-end deadline with Z3 (rule D3: deadlines add along its path)."""
        # the record's path as text: importing the deadline stage for it loaded Z3 and the deadline rules in
        # every doit run, the no-op included (0.08 s)
        return {"actions": [(act_deadlines, [self.r])],
                "file_dep": [str(self.rootp / self.plan_file), self.at(self.ws.MODEL)]
                + [self.snap[n] for n in self.deadline_nodes if n in self.snap],
                "targets": [self.at(DEADLINES_INDEX)], "uptodate": [self.code, self.sealed], "task_dep": ["check"],
                "verbosity": 2, "clean": True}

    @create_after(executed="node")
    def task_evidence(self) -> Iterator[DoitTask]:
        """Run the backends: one task per obligation, one evidence record each."""
        yield {"basename": "evidence", "name": None, "doc": "Run each backend on its obligations and record evidence."}
        # One check for every evidence task: the tools found on PATH (searched once, not per
        # obligation).  doit inspects an uptodate callable's signature for every task on every run
        # (2000 `inspect.signature` calls, a third of a second at 1000 nodes); a precomputed
        # `__signature__` (PEP 362) answers it at once.
        # One config_changed per task: doit saves every config_changed of a task under one key, so a
        # second one would overwrite the first's value and the task would never be up to date.
        tools_unchanged = signed(digested({**tool_fingerprint(), **self.code_version}))
        record_intact = RecordIntact()
        input_file: dict[str, str | None] = {}  # input -> its absolute path when it is a file (one stat per input)
        ws, at, r = self.ws, self.at, self.r

        def input_dep(rel: str) -> str | None:
            if rel not in input_file:
                p = rel if os.path.isabs(rel) else at(rel)  # strings, not pathlib: 0.1 s of a 1000-node no-op
                input_file[rel] = p if os.path.isfile(p) else None
            return input_file[rel]
        for n, o in self.exported():
            deps = [at(ws.obligation(n, o["id"]))]
            deps += [d for d in map(input_dep, o["inputs"]) if d is not None]
            yield {"name": o["id"], "actions": [(act_run, [r, n, o["id"]])], "file_dep": sorted(set(deps)),
                   "targets": [at(ws.evidence(o["id"]))], "uptodate": [tools_unchanged, record_intact],
                   "verbosity": 2, "clean": True}

    @create_after(executed="evidence")
    def task_crosscheck(self) -> DoitTask:
        """Decide every discharging Z3 query again with cvc5 from its SMT-LIB2 text (docs/second-solver.md)."""
        ws, at, nodes = self.ws, self.at, self.nodes
        deps = [at(ws.calculus(n)) for n in nodes] + [at(ws.health(n)) for n in nodes]
        deps += [at(ws.obligations(n)) for n in nodes]
        deps += [at(ws.evidence(o["id"])) for _, o in self.exported() if o.get("backend") == "hoare"]
        deps.append(at("artifacts/requirements/index.json"))
        if self.deadline_nodes:
            deps.append(at(DEADLINES_INDEX))
        return {"actions": [(act_crosscheck, [self.r, list(nodes)])], "file_dep": deps,
                "targets": [at(CROSSCHECK_INDEX)], "uptodate": [self.code, self.sealed], "verbosity": 2, "clean": True}

    def task_ground(self) -> DoitTask:
        """Ground the contracts in the ROS software of the plan's ros: section (docs/ros.md)."""
        return {"actions": [(act_ground, [self.r])], "file_dep": [str(self.rootp / self.plan_file)] + self.contract_deps,
                "uptodate": [config_changed({"files": ros_fingerprint(self.rootp, self.ros_section)}), self.sealed],
                "targets": [self.at("artifacts/ros/grounding.json"), self.at("artifacts/ros/graph.json")],
                "task_dep": ["check"], "verbosity": 2, "clean": True}

    def task_nodl(self) -> DoitTask:
        """Check the NoDL documents of nodl/ against the contracts and each other (docs/nodl.md)."""
        # every file under nodl/: a document's includes in sub-folders are read too
        return {"actions": [(act_nodl, [self.r])],
                "file_dep": [str(self.rootp / self.plan_file)] + list(self.snap.values()) + self.nodl_files,
                "targets": [self.at(NODL_INDEX)], "uptodate": [self.code, self.sealed], "task_dep": ["check"],
                "verbosity": 2, "clean": True}

    def task_design(self) -> DoitTask:
        """Decide the monitoring fields of the plan's design against the contracts (docs/nodl.md, "The design stage")."""
        from rclverify.stages.design import design_inputs  # deferred: start-up (loads the design reader only when the plan names a design)
        files = [str(self.rootp / f) for f in design_inputs(self.rootp, self.design)]
        return {"actions": [(act_design, [self.r])],
                "file_dep": [str(self.rootp / self.plan_file)] + list(self.snap.values()) + files,
                "targets": [self.at(DESIGN_INDEX)], "uptodate": [self.code, self.sealed], "task_dep": ["check"],
                "verbosity": 2, "clean": True}

    @create_after(executed="evidence")
    def task_diagnosis(self) -> DoitTask:
        """Explain every problem of the report, repairs checked by Z3, as a sealed record the report reads
        (docs/diagnosis.md).  It reads what the report reads (the same file dependencies): the report dict
        without diagnoses is what it explains."""
        return {"actions": [(act_diagnosis, [self.r])], "file_dep": self._report_inputs(),
                "task_dep": ["crosscheck"], "targets": [self.at(DIAGNOSIS_INDEX)],
                "uptodate": [self.code, self.sealed], "verbosity": 2, "clean": True}

    @create_after(executed="evidence")
    def task_report(self) -> Iterator[DoitTask]:
        """Roll everything up into the report files: two parts, rendered at once by doit -n 2."""
        yield {"basename": "report", "name": None,
               "doc": "Roll everything up into reports/ (assurance.{html,md,json}, the CI formats, the argument)."}
        deps, at = self._report_inputs() + [self.at(DIAGNOSIS_INDEX)], self.at
        as_written = TargetsAsWritten()  # the files as the task wrote them, not as `rclverify report` did since
        for part, files in REPORT_PARTS.items():
            # task_dep on crosscheck: both are created after `evidence`, and when the report's loader runs
            # first doit does not yet know which task makes the second solver's index (its file_dep alone
            # then let doit -n 2 render the report beside crosscheck, from no index)
            yield {"name": part, "doc": "reports/" + ", ".join(files), "actions": [(act_report, [self.r, part])],
                   "file_dep": deps, "task_dep": ["crosscheck", "diagnosis"], "uptodate": [self.code, self.sealed, as_written],
                   "targets": [at(f"reports/{f}") for f in files if f != "argument.svg"]
                   + ([at(self.ws.SUMMARY)] if part == "html" else []),
                   "verbosity": 2, "clean": True}

    def task_verify(self) -> DoitTask:
        """The whole pipeline: check, compose, health, export, run, report.  --strict fails on any open evidence."""
        # `requirements` (and `ground`) before `report`: reached only through the report's file dependencies,
        # they would make report:html wait and report:text run first (their fragment caches expect html first).
        # Every node task, then every health task, named one by one before the rest: doit starts the tasks
        # that waited for `check` in the order they began to wait (app/doit_patches.py, release_in_order),
        # and a group name (`node`) is expanded only after the tasks named beside it began to wait.  The
        # node tasks first, since every evidence task is created after them; the health tasks before the
        # rest, since the report and crosscheck (created after the evidence) are otherwise the only tasks
        # that reach them, which made them start after the evidence instead of beside it
        before = ([f"node:{n}" for n in self.nodes] + [f"health:{n}" for n in self.nodes] + ["requirements"]
                  + (["deadlines"] if self.deadline_nodes else []) + ["crosscheck"] + (["ground"] if self.ros_section else []) + (["nodl"] if self.nodl_files else []) + (["design"] if self.design else []) + ["diagnosis"])
        ok = self.ok
        return {"actions": [(act_verify, [self.r])], "task_dep": ["check", *before, "report"] if ok else ["check"],
                "file_dep": [str(self.rootp / REPORTS[2])] if ok else [],
                "params": [{"name": "strict", "long": "strict", "type": bool, "default": False,
                            "help": "fail unless every obligation, side condition, health check and formal requirement holds"}],
                "uptodate": [strict_uptodate], "verbosity": 2}

    def creators(self) -> dict[str, Callable[[], Any]]:
        """The ``task_*`` creators of this run, by the names a ``dodo.py`` gives them: ``check`` and
        ``verify`` always; the rest when the workspace loaded (``ground`` with a ``ros:`` section,
        ``deadlines`` with an end-to-end deadline, ``nodl`` with a NoDL document in nodl/, ``design`` with a plan naming a design)."""
        creators: dict[str, Callable[[], Any]] = {"task_check": self.task_check, "task_verify": self.task_verify}
        if self.ok:
            creators.update({"task_graph": self.task_graph, "task_node": self.task_node, "task_health": self.task_health,
                             "task_requirements": self.task_requirements, "task_evidence": self.task_evidence,
                             "task_report": self.task_report, "task_crosscheck": self.task_crosscheck,
                             "task_diagnosis": self.task_diagnosis})
            if self.ros_section:
                creators["task_ground"] = self.task_ground
            if self.deadline_nodes:
                creators["task_deadlines"] = self.task_deadlines
            if self.nodl_files:
                creators["task_nodl"] = self.task_nodl
            if self.design:
                creators["task_design"] = self.task_design
        return creators

    def exported(self) -> Exported:
        """(node, obligation JSON) of every exported obligation (read after export ran;
        once per run: the evidence and report tasks are both created after it)."""
        if self._exported is None:
            out: Exported = []
            for n in self.nodes:
                records, _ = obligation_list(self.at(self.ws.obligations(n)))  # sealed: an altered list is made again first
                out.extend((n, o) for o in records or [])
            self._exported = out
        return self._exported

    def _nodl_files(self) -> list[str]:
        """Every file under nodl/ when a NoDL document lies directly in it (stages/nodl.py: the
        discovery rule of ``rclverify nodl check``), else none: the NoDL task's file dependencies."""
        folder = self.rootp / NODL_FOLDER
        if not self.ok or not folder.is_dir() \
                or not any(p.is_file() and p.name.endswith(NODL_SUFFIXES) for p in folder.iterdir()):
            return []
        return sorted(str(p) for p in folder.rglob("*") if p.is_file())

    def _requirement_inputs(self) -> list[str]:
        """The files besides the plan, model and snapshots that the requirements read: the Doorstop
        files of the plan's ``requirements_from`` folders, and the mappings and recorded runs
        (files, or every file under a folder) of evidence entries with traces (docs/plan.md)."""
        index, rootp = self.index, self.rootp
        assert index is not None
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
        return extra

    def _report_inputs(self) -> list[str]:
        """The file dependencies of the diagnosis task and both report parts: every artifact the report
        reads (made once per run: a new list each call)."""
        if self._report_deps is None:
            self._report_deps = self._report_files()
        return list(self._report_deps)

    def _report_files(self) -> list[str]:
        ws, at, rootp = self.ws, self.at, self.rootp
        # The plan itself: the report shows its name, requirements and their tracing, which no
        # other artifact holds (a plan edit that changes only those re-renders the report).
        deps = [str(rootp / self.plan_file)] + [at(p) for p in (ws.MODEL, ws.DIAGNOSTICS)] + list(self.snap.values())
        # The files meta.inputs_sha256 hashes (provenance.check_inputs): the contract and replacement files
        # themselves, not only the snapshots they give. An edit that changes none of the snapshots (a comment
        # after the last node) left the report naming the old files' sha256, and the bundle then refused a
        # report `doit verify` called up to date.
        have = set(deps)  # a set: the list holds a snapshot per node (quadratic at 5000 nodes, 0.2 s a run)
        deps += [d for d in (at(f) for f in check_input_files(ws)) if d not in have and os.path.isfile(d)]
        deps += [at(f) for f in getattr(ws.index, "profiles", ())]  # the plan's own standard profiles (docs/standards.md)
        for n in self.nodes:
            deps += [at(ws.calculus(n)), at(ws.health(n)), at(ws.obligations(n))]
        deps += [at(ws.evidence(o["id"])) for _, o in self.exported()]
        deps.append(at("artifacts/requirements/index.json"))  # the requirements task's target
        if self.ros_section:
            deps.append(at("artifacts/ros/grounding.json"))
        if self.deadline_nodes:
            deps.append(at(DEADLINES_INDEX))  # the deadlines task's target
        if self.nodl_files:
            deps.append(at(NODL_INDEX))  # the NoDL task's target
        if self.design:
            deps.append(at(DESIGN_INDEX))  # the design task's target
        deps.append(at(CROSSCHECK_INDEX))  # the second solver's verdicts
        return deps
