"""The actions of the ``doit verify`` tasks: what each task runs (:mod:`rclverify.app.tasks` defines the tasks).

Each action is a module-level function with plain arguments (a workspace
root, a node or obligation name), so ``doit -n 2`` (parallel processes)
behaves like a serial run.  An action runs one stage of
:mod:`rclverify.app.pipeline` on the workspace loaded once per run
(:func:`_ws`), prints one line saying what it did, and returns ``None``, or
a doit ``TaskFailed`` holding the located messages of bad input
(:class:`rclverify.lang.errors.RclError`) or the plain line of a machine
fault (:mod:`rclverify.core.faults`); it never lets a traceback through.
"""
from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence, TypeVar

from doit.exceptions import TaskFailed

from rclverify.core.cache import heap
from rclverify.core.extras import MissingExtra
from rclverify.stages.workspace import Workspace
from rclverify.lang.errors import RclError
from rclverify.app.pipeline import stage_check, stage_graph, stage_run, stage_report, stage_requirements, stage_deadlines
from rclverify.records.store import atomic_write_text
from rclverify.app import pipeline

if TYPE_CHECKING:
    from rclverify.records.report_record import AssuranceReport


#: The workspace of each root loaded for this run (:func:`_ws`); :func:`rclverify.app.tasks.build_tasks` seeds it.
WORKSPACES: dict[str, Workspace] = {}


def _ws(root: str, plan_file: str | None = None) -> Workspace:
    """The workspace at ``root``, loaded once per doit run: every action would
    otherwise parse and check the contracts again.

    :func:`rclverify.app.tasks.build_tasks` (called at the start of every run, also by
    ``rclverify verify``) puts the workspace it loaded here, so the actions of
    a run see the contracts and plan as they were when the run started -- the
    state its ``check`` task snapshots and every later task depends on.  A
    contract edited while a run is under way is therefore picked up by the
    next run, whose ``check`` sees the changed file.  Without a seeded entry
    (a worker process that did not inherit it) the workspace is loaded here,
    with ``plan_file`` (the ``check`` task passes the run's plan file; the
    default plan otherwise).
    """
    heap.freeze_inherited()  # a doit -n worker: its inherited heap stays live (rclverify.core.cache.heap)
    heap.executing()  # a task executes here: full collections again (rclverify.core.cache.heap)
    ws = WORKSPACES.get(root)
    if ws is None or (plan_file is not None and ws.plan_file != plan_file):
        ws = Workspace(Path(root), plan_file or "contracts/plan.yaml")
        ws.model  # load now: raises RclError for bad input and then caches nothing
        WORKSPACES[root] = ws
    return ws



_A = TypeVar("_A", bound=Callable[..., Any])


def _extras_said(action: _A) -> _A:
    """``action`` with a missing optional part (:class:`MissingExtra`) turned
    into a doit failure of one line naming the extra, never a traceback."""
    @functools.wraps(action)
    def run(*args: Any, **kwargs: Any) -> Any:
        try:
            return action(*args, **kwargs)
        except MissingExtra as exc:
            return TaskFailed(f"error: {exc}")
    return run  # type: ignore[return-value]  # functools.wraps keeps the signature doit reads

def _fail(exc: RclError) -> TaskFailed:
    return TaskFailed("\n".join(str(d) for d in exc.diagnostics))


def _io_fail(exc: OSError, root: str, place: str = "artifacts/") -> TaskFailed:
    """A fault of the machine (read-only directory, full disk) as one plain line
    (:mod:`rclverify.core.faults`; ``place``: where the action writes, for an
    error without a file name): the writes are atomic, nothing recorded changed."""
    from rclverify.core.faults import describe_os_error  # deferred: start-up (loads rclverify.core.faults only when called)
    return TaskFailed(describe_os_error(exc, Path(root), place=place))


@_extras_said
def act_check(root: str, plan_file: str = "contracts/plan.yaml") -> Any:
    try:
        out = stage_check(_ws(root, plan_file))
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    for w in out["warnings"]:
        print(f"{w['file']}:{w['line']}:{w['col']}: warning: {w['message']}")
    return None


@_extras_said
def act_graph(root: str) -> Any:
    from rclverify.report.diagram import dot_to_svg  # deferred: start-up (loads jinja2, rclverify.report and more only when called)
    try:
        dot = stage_graph(_ws(root))
        svg = dot_to_svg(dot)
        if svg is None:
            print(f"graphviz 'dot' not found: {Workspace.DOT} written, model.svg not drawn")
            return None
        atomic_write_text(Path(root) / "artifacts/system/model.svg", svg)
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    return None


#: The stages of a node, in the order they run: ``compose`` and ``export`` in its ``node:<Node>`` task,
#: ``health`` in its ``health:<Node>`` task (app/task_table.py).
NODE_STAGES = ("compose", "health", "export")


def stages_to_run(deps: Mapping[str, Sequence[str]], changed: Sequence[str]) -> list[str]:
    """The stages of a node task whose own file dependencies are among
    ``changed`` (doit's ``dep_changed``), in :data:`NODE_STAGES` order.

    ``deps`` maps each of the task's stages (a subset of
    :data:`NODE_STAGES`) to its file dependencies.  An empty ``changed``
    means doit gave no reason by file (a forced run, ``doit -a``, a changed
    ``uptodate`` check): every stage of the task runs.  A missing target makes doit list
    every dependency as changed, so every stage runs then too.
    """
    if not changed:
        return [stage for stage in NODE_STAGES if stage in deps]
    hit = set(changed)
    return [stage for stage in NODE_STAGES if stage in deps and hit.intersection(deps[stage])]


@_extras_said
def act_node(root: str, node: str, deps: dict[str, list[str]], changed: list[str]) -> Any:
    """Run the stages of ``node`` whose inputs changed (:func:`stages_to_run`).

    ``changed`` is filled by doit (the task's file dependencies that changed
    since its last successful run)."""
    stages = stages_to_run(deps, changed)
    try:
        for stage in stages:
            getattr(pipeline, f"stage_{stage}")(_ws(root), node)
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    print(f"{node}: {', '.join(stages)}")
    return None


@_extras_said
def act_run(root: str, node: str, obligation_id: str) -> Any:
    from rclverify.app import cluster  # deferred: start-up (loads rclverify.app.cluster only when called)
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
    except OSError as exc:
        return _io_fail(exc, root, "artifacts/evidence/")
    print(f"{ev.obligation}: {ev.status}")
    return None


#: The report dict built by the first report part of a run, for the other parts the same process
#: runs (a serial run): keyed by workspace root, valid for the workspace object of that run.
_REPORTS: dict[str, tuple[Workspace, AssuranceReport]] = {}
#: The report dict without diagnoses the diagnosis task built, for the report part the same process runs
#: next (a serial run: no task between them changes an artifact the report reads); as :data:`_REPORTS`.
_UNDIAGNOSED: dict[str, tuple[Workspace, dict[str, Any]]] = {}


@_extras_said
def act_diagnosis(root: str) -> Any:
    """Explain every problem of the report, repairs checked by Z3, into the
    sealed record ``artifacts/diagnosis/index.json`` (:func:`rclverify.app.pipeline.stage_diagnosis`)."""
    from rclverify.report.build import undiagnosed_report  # deferred: start-up (loads jinja2, lark and more only when called)
    try:
        ws = _ws(root)
        report = undiagnosed_report(ws)
        record = pipeline.stage_diagnosis(ws, report)
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    _UNDIAGNOSED[root] = (ws, report)
    rows = record["diagnoses"]
    print(f"diagnosis: {len(rows)} problem(s) explained, {sum(len(d['repairs']) for d in rows)} repair(s) checked")
    return None


@_extras_said
def act_report(root: str, part: str) -> Any:
    """Write one part of the report (:mod:`rclverify.report.parts`).  The
    parts run after every backend, from the same artifacts, so a process
    that runs both (``doit`` without ``-n``) builds the report dict once:
    it is kept for the workspace object of this run (:func:`_ws`), which
    a later run (a new :func:`rclverify.app.tasks.build_tasks`) replaces."""
    try:
        ws = _ws(root)
        kept = _REPORTS.get(root)
        pre = _UNDIAGNOSED.pop(root, None)
        report, _ = stage_report(ws, (part,), kept[1] if kept is not None and kept[0] is ws else None,
                                 pre[1] if pre is not None and pre[0] is ws else None)
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root, "reports/")
    _REPORTS[root] = (ws, report)
    if part == "html":
        print(f"report: reports/assurance.html  ({report.summary.headline})")
    else:
        print("report: reports/assurance.md, reports/argument.{json,gsn.yaml,dot}")
    return None


@_extras_said
def act_requirements(root: str) -> Any:
    """Check the requirements whose inputs changed (:mod:`rclverify.stages.requirements`)."""
    try:
        rows = stage_requirements(_ws(root))
        from rclverify.stages.instances import stage_instances  # deferred: start-up; the plan's instances per robot
        fleet = stage_instances(_ws(root))
    except RclError as exc:
        return _fail(exc)
    if fleet is not None:
        print(f"instances: {len(fleet['instances'])}, requirements per namespace: {len(fleet['requirements'])}")
    again = [rec["id"] for rec, now in rows if now]
    print(f"requirements: {len(again)} of {len(rows)} checked" + (f" ({', '.join(again[:10])}"
                                                                  + (", ..." if len(again) > 10 else "") + ")" if again else ""))
    return None


@_extras_said
def act_deadlines(root: str) -> Any:
    """Decide the end-to-end deadlines (rule D3, :mod:`rclverify.stages.deadlines`)."""
    try:
        records = stage_deadlines(_ws(root))
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    print("deadlines: " + ", ".join(f"{r['requirement']} {r['status']}" for r in records))
    return None


@_extras_said
def act_crosscheck(root: str, nodes: list[str]) -> Any:
    """Decide every discharging query again with cvc5 (:mod:`rclverify.stages.crosscheck.stage`)."""
    from rclverify.stages.crosscheck.stage import stage_crosscheck  # deferred: start-up (loads rclverify.stages.crosscheck, rclverify.stages.requirements and more only when called)
    heap.executing()  # a task executes here (the other actions: _ws)
    try:
        index = stage_crosscheck(Path(root), nodes)
    except OSError as exc:
        return _io_fail(exc, root)
    counts = index.get("counts", {})
    print("second solver: " + (", ".join(f"{v} {k}" for k, v in counts.items()) or "nothing to re-decide")
          + ("" if index.get("solver") else " (cvc5 is not installed)"))
    return None


@_extras_said
def act_ground(root: str) -> Any:
    """The grounding stage (docs/ros.md): scan the plan's ``ros:`` section,
    hold the contracts against it; findings go to the report, never to a verdict."""
    from rclverify.app.ros_stage import stage_ground  # deferred: start-up (loads rclverify.app.ros_stage, rclverify.lang.ast only when called)
    try:
        data = stage_ground(_ws(root))
    except RclError as exc:
        return _fail(exc)
    c = data["counts"]
    print(f"grounding: {c['error']} error(s), {c['warning']} warning(s) (rclverify ros check lists them)")
    return None


def act_design(root: str) -> Any:
    """The design stage (docs/nodl.md, "The design stage", :mod:`rclverify.stages.design`): the plan's design's
    monitoring fields decided against the contracts; prints the counts, the record (findings located) goes to the report."""
    from rclverify.stages.design import stage_design  # deferred: start-up (loads yaml and the design reader only when called)
    try:
        data = stage_design(_ws(root))
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    c = data["counts"]
    print(f"design {data['design']}: {len(data['decided'])} monitoring field(s): {c['proved']} proved, {c['refuted']} "
          f"refuted, {c['undecided']} undecided; {c['error']} error(s), {c['warning']} warning(s) "
          f"(rclverify import autoware-design {data['design']} --check lists them)")
    return None


def act_nodl(root: str) -> Any:
    """The NoDL stage (docs/nodl.md, :mod:`rclverify.stages.nodl`): the workspace's documents
    against its contracts and each other; findings go to the report."""
    from rclverify.stages.nodl import stage_nodl  # deferred: start-up (loads jsonschema, yaml and z3 only when called)
    try:
        data = stage_nodl(_ws(root))
    except RclError as exc:
        return _fail(exc)
    except OSError as exc:
        return _io_fail(exc, root)
    c = data["counts"]
    print(f"NoDL: {len(data['documents'])} node document(s), {c['error']} error(s), {c['warning']} warning(s) "
          "(rclverify nodl check lists them)")
    return None


@_extras_said
def act_verify(root: str, strict: bool) -> Any:
    """The ``verify`` task: print the run's status, problems and summary table
    (:func:`rclverify.report.summary.print_last_run`); with ``strict``, fail
    unless every item holds."""
    from rclverify.app.progress import PlainFailure  # deferred: start-up (loads doit, rclverify.app.doitstate and more only when called)
    from rclverify.report.strict import strict_sentence  # deferred: start-up (loads rclverify.report, rclverify.report.strict only when called)
    from rclverify.report.summary import print_last_run  # deferred: start-up (loads rclverify.report, rclverify.report.summary only when called)
    heap.executing()  # a task executes here (the other actions: _ws)
    try:
        data = print_last_run(Path(root))
    except RclError as exc:  # the last run's summary is missing or of another shape: one located line
        return PlainFailure("\n".join(str(d) for d in exc.diagnostics))
    if strict and not data["meta"]["strict_ok"]:
        return PlainFailure(strict_sentence(data))  # one sentence naming why
    return None
