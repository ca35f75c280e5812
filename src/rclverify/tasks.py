"""doit task generators for a workspace (``dodo.py`` only calls :func:`build_tasks`).

Stages and their real file dependencies, per node ``N``:

``check``          contracts + plan -> artifacts/contracts/N.json (one snapshot per
                   node, rewritten only when that node's text changes), model, lint
``graph``          model -> model.dot, model.svg (when graphviz is installed); not part of
                   ``verify`` (the report lays out its own diagram, with statuses):
                   ``doit graph`` runs it
``node:N``         three stages, each run only when one of its own inputs changed:
                   compose  snapshot of N and of N's producers + model -> calculus/N.json
                   health   snapshot of N (+ replacement contract) -> health/N.json
                   export   snapshot of N + the backend input files -> obligations/N.json
``evidence:ID``     one obligation's record + the files it reads -> its evidence record
                   (created after ``node`` ran, when the obligations are known)
``report:html``    every artifact above -> reports/assurance.{html,json}, the CI formats
                   reports/assurance.sarif, assurance.junit.xml, argument.svg
``report:text``    every artifact above -> reports/assurance.md, argument.{json,gsn.yaml,dot}
                   (two tasks rendered at once by ``doit -n 2``: report/parts.py)
``verify``         the whole pipeline; ``doit verify --strict`` fails unless every
                   obligation is discharged

doit compares file contents (md5), so editing one node's contract changes
only that node's snapshot: its node task (all three stages) and run tasks,
its consumers' node tasks (the compose stage only: their side conditions)
and the report re-run.  The three stages share one doit task per node
because doit's own cost per task (defining it, checking its dependencies)
was most of a no-op run of a large system (docs/scale.md); the task's
action gets doit's list of changed dependencies and runs the stages that
read one of them (:func:`stages_to_run`).
Actions are module-level functions with plain arguments, so ``doit -n 2``
(parallel processes) behaves like a serial run.

With the environment variable ``RCLVERIFY_CLUSTER=ADDRESS`` the ``evidence``
tasks send their backend jobs to that Dask scheduler (:mod:`rclverify.cluster`);
the records are stored locally as in a local run.
"""
from __future__ import annotations

import glob
import inspect
import json
import os
import shutil
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence, TypeVar, cast

from doit import create_after as _create_after
from doit.exceptions import TaskFailed
from doit.tools import config_changed

from . import heap, wscache
from .pipeline import REPORT_PARTS, TaskIndex, Workspace
from .rcl.errors import RclError

_F = TypeVar("_F", bound=Callable[..., Any])


def create_after(executed: str) -> Callable[[_F], _F]:
    """doit's ``create_after`` (delayed task creation), typed."""
    return cast(Callable[[_F], _F], _create_after(executed=executed))


REPORTS = ["reports/assurance.html", "reports/assurance.md", "reports/assurance.json"]


_WORKSPACES: dict[str, Workspace] = {}


def _ws(root: str) -> Workspace:
    """The workspace at ``root``, loaded once per doit run: every action would
    otherwise parse and check the contracts again.

    :func:`build_tasks` (called at the start of every run, also by
    ``rclverify verify``) puts the workspace it loaded here, so the actions of
    a run see the contracts and plan as they were when the run started -- the
    state its ``check`` task snapshots and every later task depends on.  A
    contract edited while a run is under way is therefore picked up by the
    next run, whose ``check`` sees the changed file.  Without a seeded entry
    (a worker process that did not inherit it) the workspace is loaded here.
    """
    heap.freeze_inherited()  # a doit -n worker: its inherited heap stays live (rclverify.heap)
    ws = _WORKSPACES.get(root)
    if ws is None:
        ws = Workspace(Path(root))
        ws.model  # load now: raises RclError for bad input and then caches nothing
        _WORKSPACES[root] = ws
    return ws


def _fail(exc: RclError) -> TaskFailed:
    return TaskFailed("\n".join(str(d) for d in exc.diagnostics))


def act_check(root: str) -> Any:
    from .pipeline import stage_check
    try:
        out = stage_check(_ws(root))
    except RclError as exc:
        return _fail(exc)
    for w in out["warnings"]:
        print(f"{w['file']}:{w['line']}:{w['col']}: warning: {w['message']}")
    return None


def act_graph(root: str) -> Any:
    from .evidence.store import atomic_write_text
    from .pipeline import stage_graph
    from .report.diagram import dot_to_svg
    try:
        dot = stage_graph(_ws(root))
    except RclError as exc:
        return _fail(exc)
    svg = dot_to_svg(dot)
    if svg is None:
        print(f"graphviz 'dot' not found: {Workspace.DOT} written, model.svg not drawn")
        return None
    atomic_write_text(Path(root) / "artifacts/system/model.svg", svg)
    return None


#: The stages of a ``node:<Node>`` task, in the order they run.
NODE_STAGES = ("compose", "health", "export")


def stages_to_run(deps: Mapping[str, Sequence[str]], changed: Sequence[str]) -> list[str]:
    """The stages of a node task whose own file dependencies are among
    ``changed`` (doit's ``dep_changed``), in :data:`NODE_STAGES` order.

    ``deps`` maps each stage to its file dependencies.  An empty ``changed``
    means doit gave no reason by file (a forced run, ``doit -a``, a changed
    ``uptodate`` check): every stage runs.  A missing target makes doit list
    every dependency as changed, so every stage runs then too.
    """
    if not changed:
        return list(NODE_STAGES)
    hit = set(changed)
    return [stage for stage in NODE_STAGES if hit.intersection(deps[stage])]


def act_node(root: str, node: str, deps: dict[str, list[str]], changed: list[str]) -> Any:
    """Run the stages of ``node`` whose inputs changed (:func:`stages_to_run`).

    ``changed`` is filled by doit (the task's file dependencies that changed
    since its last successful run)."""
    from . import pipeline
    stages = stages_to_run(deps, changed)
    try:
        for stage in stages:
            getattr(pipeline, f"stage_{stage}")(_ws(root), node)
    except RclError as exc:
        return _fail(exc)
    print(f"{node}: {', '.join(stages)}")
    return None


def act_run(root: str, node: str, obligation_id: str) -> Any:
    from . import cluster
    from .pipeline import stage_run
    addr = cluster.address()  # RCLVERIFY_CLUSTER: the backend job runs on that Dask cluster
    try:
        if addr is None:
            ev = stage_run(_ws(root), node, obligation_id)
        else:
            ev = cluster.run_on_cluster(addr, _ws(root), node, obligation_id)
    except RclError as exc:
        return _fail(exc)
    except cluster.ClusterError as exc:
        return TaskFailed(f"error: {exc}")
    print(f"{ev.obligation}: {ev.status}")
    return None


#: The report dict built by the first report part of a run, for the other parts the same process
#: runs (a serial run): keyed by workspace root, valid for the workspace object of that run.
_REPORTS: dict[str, tuple[Workspace, dict[str, Any]]] = {}


def act_report(root: str, part: str) -> Any:
    """Write one part of the report (:mod:`rclverify.report.parts`).  The
    parts run after every backend, from the same artifacts, so a process
    that runs both (``doit`` without ``-n``) builds the report dict once:
    it is kept for the workspace object of this run (:func:`_ws`), which
    a later run (a new :func:`build_tasks`) replaces."""
    from .pipeline import stage_report
    try:
        ws = _ws(root)
        kept = _REPORTS.get(root)
        report, _ = stage_report(ws, (part,), kept[1] if kept is not None and kept[0] is ws else None)
    except RclError as exc:
        return _fail(exc)
    _REPORTS[root] = (ws, report)
    if part == "html":
        print(f"report: reports/assurance.html  ({report['summary']['headline']})")
    else:
        print("report: reports/assurance.md, reports/argument.{json,gsn.yaml,dot}")
    return None


def act_verify(root: str, strict: bool) -> Any:
    from .report.summary import print_summary, summary_data
    try:  # written by the report's html part with assurance.json
        data = json.loads((Path(root) / Workspace.SUMMARY).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = summary_data(json.loads((Path(root) / REPORTS[2]).read_text(encoding="utf-8")))
    from .diagnosis.text import status_lines
    print("\n".join(status_lines(data)))
    print_summary(data, "reports/assurance.html", rows=data["rows"])
    if strict and not data["meta"]["strict_ok"]:
        return TaskFailed("--strict: some evidence is failed, inconclusive, pending, stale or error, or a side condition "
                          "or contract health check is not proved (see reports/assurance.html)")
    return None


class RecordIntact:
    """doit ``uptodate`` check of an evidence task: its record is as rclverify
    wrote it.  A record changed by anything else (a hand edit of its status)
    makes the task run again, so ``doit verify`` produces the evidence anew
    instead of believing it (the report of a run that does not re-run it,
    ``rclverify report``, shows it as ``error``: evidence altered).

    Cheap on a no-op run: after the task ran, the record's size and
    modification time are saved with doit's task values; while they are the
    same the record is not read.  Otherwise its seal is checked
    (:meth:`rclverify.evidence.store.EvidenceStore.read`)."""

    __signature__ = inspect.Signature([inspect.Parameter("task", inspect.Parameter.POSITIONAL_OR_KEYWORD),
                                       inspect.Parameter("values", inspect.Parameter.POSITIONAL_OR_KEYWORD)])

    def __call__(self, task: Any, values: Mapping[str, Any]) -> bool:
        target = task.targets[0]

        def stat() -> dict[str, Any]:
            try:
                st = os.stat(target)
            except OSError:
                return {}
            return {"_record_stat": [st.st_mtime_ns, st.st_size]}
        task.value_savers.append(stat)
        now = stat()
        if not now:
            return False
        if values.get("_record_stat") == now["_record_stat"]:
            return True
        from .evidence.store import EvidenceStore
        root, _, name = target.rpartition("/artifacts/evidence/")
        ev, problem = EvidenceStore(Path(root)).read(name[:-len(".json")])
        if problem:
            print(f"{os.path.relpath(target, root)}: {problem}: producing it again")
            return False
        return ev is not None


def strict_uptodate(task: Any, values: Any) -> bool:
    """``verify`` is up to date unless ``--strict`` asks for the check again."""
    return not bool(task.options.get("strict"))


def _inputs(config: Any, root: Path, seen: dict[str, tuple[str, ...]]) -> list[str]:
    """Workspace files named in a plan evidence entry (strings that are existing paths).

    ``seen`` memoises the files of each path string across calls (the
    entries of many nodes name the same program or directory: one stat or
    directory walk per distinct string)."""
    out: set[str] = set()

    def files(v: str) -> tuple[str, ...]:
        if v not in seen:
            p = root / v
            if not p.exists():
                seen[v] = ()
            elif p.is_dir():
                seen[v] = tuple(os.path.relpath(f, root) for f in glob.glob(str(p / "**" / "*"), recursive=True)
                                if os.path.isfile(f))
            else:
                seen[v] = (v,)
        return seen[v]

    def walk(v: Any) -> None:
        if isinstance(v, str) and "/" in v:
            out.update(files(v))
        elif isinstance(v, dict):
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)
    walk(dict(config))
    return sorted(out)


def _z3_version() -> str:
    """The installed z3-solver's version (from its metadata: importing Z3 costs a no-op run
    a fifth of a second).  Every verdict comes from Z3, so another version makes them again."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("z3-solver")
    except PackageNotFoundError:
        return "-"


def _tool_fingerprint() -> dict[str, Any]:
    from . import __version__
    return {"rclverify": __version__, "dafny": shutil.which("dafny"), "mcapl": os.environ.get("MCAPL_HOME") or os.environ.get("AJPF_HOME"),
            "dot": shutil.which("dot")}


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
    from .progress import ProgressReporter
    return {"default_tasks": ["verify"], "verbosity": 2, "dep_file": dep_file, "backend": "sqlite3",
            "reporter": ProgressReporter}


def _linear_implicit_task_dep(targets: dict[str, str], task: Any, deps_list: Sequence[str]) -> None:
    """doit's ``TaskControl.add_implicit_task_dep`` with a set for the
    membership test: the same task dependencies in the same order.  doit's
    own tests ``name not in task.task_dep`` on a list, which is quadratic
    for a task whose file dependencies are the targets of thousands of
    tasks (each report task of a 1000-node system: 5,000 file dependencies
    from 3,000 tasks, a seventh of a second per task per run)."""
    have = set(task.task_dep)
    for dep in deps_list:
        name = targets.get(dep)
        if name is not None and name not in have:
            task.task_dep.append(name)
            have.add(name)


def _use_linear_implicit_task_dep() -> None:
    """Install :func:`_linear_implicit_task_dep` in doit (idempotent), when
    doit's own has the signature it replaces (``pyproject.toml`` pins the
    doit versions it was checked against; ``tests/test_tasks_doit.py``
    compares the two)."""
    from doit.control import TaskControl
    current = TaskControl.add_implicit_task_dep
    if current is _linear_implicit_task_dep:
        return
    if list(inspect.signature(current).parameters) == ["targets", "task", "deps_list"]:
        DOIT_IMPLICIT_TASK_DEP.append(current)
        TaskControl.add_implicit_task_dep = staticmethod(_linear_implicit_task_dep)


#: doit's own implicit-dependency scan, once replaced (for the test that compares the two).
DOIT_IMPLICIT_TASK_DEP: list[Callable[..., None]] = []


def build_tasks(root: str | Path, plan_file: str = "contracts/plan.yaml") -> dict[str, Callable[[], Any]]:
    """The ``task_*`` functions for a dodo.py of the workspace at ``root``.

    The loaded workspace stays live for the run: it is loaded without
    cyclic garbage collection and then frozen for the run
    (:mod:`rclverify.heap`; the progress reporter gives it back to the
    collector when doit completes the run)."""
    with heap.no_collection():
        creators = _build_tasks(root, plan_file)
        heap.freeze_for_run()  # before collecting again: what was made while loading is not looked at
    return creators


def _build_tasks(root: str | Path, plan_file: str) -> dict[str, Callable[[], Any]]:
    _use_linear_implicit_task_dep()
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
        _WORKSPACES[r] = ws
        if not restored:
            wscache.save_in_background(ws)
    else:
        _WORKSPACES.pop(r, None)
    try:
        contract_deps = [str(rootp / c) for c in (index.contracts if index is not None else ws.plan.contracts)]
    except RclError:
        contract_deps = []

    def at(rel: str) -> str:
        """The absolute path of a workspace-relative artifact path (string
        joining: ``pathlib`` cost 0.3 s of a 1000-node no-op run)."""
        return f"{r}/{rel}"

    snap = {n: at(ws.snapshot(n)) for n in nodes}
    # Every task that makes a result depends on the rclverify code that makes it: another version
    # (an upgrade, a changed module) makes every result again, as a clean run would.
    code_version = {"rclverify": wscache.code_stamp(), "z3": _z3_version()}
    code = config_changed(code_version)
    code.__signature__ = inspect.signature(code)  # answered at once by doit (see task_evidence)

    def task_check() -> dict[str, Any]:
        """Parse and type-check the contracts, check the plan, lint, build the system model."""
        return {"actions": [(act_check, [r])], "file_dep": [str(rootp / plan_file)] + contract_deps,
                "targets": list(snap.values()) + [str(rootp / p) for p in (ws.MODEL, ws.DIAGNOSTICS)],
                "uptodate": [code], "verbosity": 2, "clean": True}

    def task_graph() -> dict[str, Any]:
        """Write the system model as DOT and, with graphviz, draw it as SVG (doit graph)."""
        return {"actions": [(act_graph, [r])], "file_dep": [str(rootp / ws.MODEL)], "targets": [str(rootp / ws.DOT)],
                "task_dep": ["check"], "uptodate": [config_changed(shutil.which("dot") or "")], "verbosity": 2}

    def task_node() -> Iterator[dict[str, Any]]:
        """One task per node: its calculus, health checks and exported obligations."""
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
                "export": [snap[n]] + [at(f) for config in index.entries.get(n, ()) for f in _inputs(config, rootp, seen)],
            }
            yield {"name": n, "actions": [(act_node, [r, n, deps])],
                   "file_dep": sorted({d for ds in deps.values() for d in ds}),
                   "targets": [at(ws.calculus(n)), at(ws.health(n)), at(ws.obligations(n))],
                   "uptodate": [code], "verbosity": 2, "clean": True}

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
            try:
                with open(at(ws.obligations(n)), encoding="utf-8") as fh:
                    out.extend((n, o) for o in json.load(fh))
            except (OSError, ValueError):
                continue
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
        tools_unchanged = config_changed({**_tool_fingerprint(), **code_version})
        tools_unchanged.__signature__ = inspect.signature(tools_unchanged)
        record_intact = RecordIntact()
        input_file: dict[str, str | None] = {}  # input -> its absolute path when it is a file (one stat per input)

        def input_dep(rel: str) -> str | None:
            if rel not in input_file:
                p = rootp / rel
                input_file[rel] = str(p) if p.is_file() else None
            return input_file[rel]
        for n, o in exported():
            deps = [at(ws.obligation(n, o["id"]))]
            deps += [d for d in map(input_dep, o["inputs"]) if d is not None]
            yield {"name": o["id"], "actions": [(act_run, [r, n, o["id"]])], "file_dep": sorted(set(deps)),
                   "targets": [at(ws.evidence(o["id"]))], "uptodate": [tools_unchanged, record_intact],
                   "verbosity": 2, "clean": True}

    @create_after(executed="evidence")
    def task_report() -> Iterator[dict[str, Any]]:
        """Roll everything up into the report files: two parts, rendered at once by doit -n 2."""
        yield {"basename": "report", "name": None,
               "doc": "Roll everything up into reports/ (assurance.{html,md,json}, the CI formats, the argument)."}
        # The plan itself: the report shows its name, requirements and their tracing, which no
        # other artifact holds (a plan edit that changes only those re-renders the report).
        deps = [str(rootp / plan_file)] + [at(p) for p in (ws.MODEL, ws.DIAGNOSTICS)] + list(snap.values())
        for n in nodes:
            deps += [at(ws.calculus(n)), at(ws.health(n)), at(ws.obligations(n))]
        deps += [at(ws.evidence(o["id"])) for _, o in exported()]
        for part, files in REPORT_PARTS.items():
            yield {"name": part, "doc": "reports/" + ", ".join(files), "actions": [(act_report, [r, part])],
                   "file_dep": deps, "uptodate": [code],
                   "targets": [at(f"reports/{f}") for f in files if f != "argument.svg"]
                   + ([at(ws.SUMMARY)] if part == "html" else []),
                   "verbosity": 2, "clean": True}

    def task_verify() -> dict[str, Any]:
        """The whole pipeline: check, compose, health, export, run, report.  --strict fails on any open evidence."""
        return {"actions": [(act_verify, [r])], "task_dep": ["check", "report"] if ok else ["check"],
                "file_dep": [str(rootp / REPORTS[2])] if ok else [],
                "params": [{"name": "strict", "long": "strict", "type": bool, "default": False,
                            "help": "fail unless every obligation, side condition and health check holds"}],
                "uptodate": [strict_uptodate], "verbosity": 2}

    creators: dict[str, Callable[[], Any]] = {"task_check": task_check, "task_verify": task_verify}
    if ok:
        creators.update({"task_graph": task_graph, "task_node": task_node, "task_evidence": task_evidence,
                         "task_report": task_report})
    return creators
