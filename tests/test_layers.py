"""The import graph of src/rclverify follows the layers of docs/architecture.md.

The graph is read from the source with :mod:`ast` (nothing is imported):
every ``import`` and ``from ... import`` anywhere in a module counts, at
module level and inside functions alike (a function-level import is still a
dependency; it only delays it).  ``from pkg import name`` is an edge to the
module ``pkg.name`` when that is a module, else to ``pkg``.  Importing
``a.b.c`` also runs ``a/__init__`` and ``a/b/__init__``; those implicit
edges are not counted, only the module named.

Two rules, each a test:

* no import runs from a lower layer to a higher one (:data:`LAYERS`, lowest
  first; modules of one layer may import each other);
* the graph has no cycle (also not inside one layer).

:data:`KNOWN_VIOLATIONS` lists edges allowed to break the rules; it is
empty (issue 25's three import circles are gone), and every listed edge must
still exist, so the set cannot keep an edge that has gone.
"""
from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx
import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = "rclverify"

#: The layers, lowest first: a module may import modules of its own layer and
#: of the layers before it.  An entry names a module or a package (a package
#: covers every module under it); the longest matching entry decides.  The
#: named layers are issue 25's order, rcl -> plan -> system/logic ->
#: calculus/health -> backends -> evidence -> report/argument ->
#: pipeline/tasks -> cli; the other modules are placed by what they are and
#: what they import:
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    # Process-wide utilities that know nothing of RCL: the package's version
    # (``rclverify/__init__``; this entry is that module only, not the
    # package), machine faults worded as one line (faults.py).  They import
    # no other module of the package.
    ("foundation", ("rclverify", "rclverify.faults")),
    # The evidence record format (records.py: obligations, evidence records,
    # input hashes) and its atomic store (store.py).  Every stage writes
    # these records and the report reads them, so the format sits below all
    # of them; it imports nothing of the package.  The "evidence" step of
    # the data flow (backends -> evidence -> report) is the pipeline's
    # evidence stage, which lives in the pipeline layer.
    ("evidence records", ("rclverify.evidence",)),
    # cache/: everything kept between runs (one keying function, one file
    # format, one rule of what is kept), the workspace's load among it
    # (cache/workspace.py, which sees the workspace only through its
    # attributes), when the garbage collector runs (cache/heap.py, used by
    # the parser) and the one-entry result memo (cache/memo.py).  It writes
    # through the evidence store's atomic writer and knows nothing of RCL.
    ("cache", ("rclverify.cache",)),
    ("rcl", ("rclverify.rcl",)),
    # values.py: the Python convention for RCL values (built on rcl's types),
    # shared by the logic (evaluation on concrete values), the traces and the
    # backends.  traces/: reading recorded runs (JSONL, rosbag) into events of
    # such values; it needs only rcl types and values.
    ("values", ("rclverify.values", "rclverify.traces")),
    ("plan", ("rclverify.plan",)),
    # ros/: the ROS computation graph read from the robot's software and the
    # contracts grounded in it, the system as its code shows it, beside the
    # system model (system/); its stage, command and skeleton writer are
    # placed below with the pipeline and the commands.  The readers of real
    # code (issue 42) are in this layer too, below the graph (graph.py,
    # assemble.py) that uses them: programs.py, link.py, link_values.py,
    # symbols.py, emit.py, cpp_scope.py, cpp_values.py, cpp_types.py,
    # cpp_prep.py, cpp_helpers.py, py_helpers.py, pyconst.py, namespaces.py;
    # and the drivers' idioms: unit_names.py (classes defined out of line through
    # using/typedef), cpp_members.py and link_members.py (helpers held as members
    # and base classes), nodelets.py (ROS 1 nodelets), lifecycle.py (the
    # management interface of lifecycle nodes, for the grounding);
    # they import only ros/ modules, the standard library and tree-sitter.
    # logic/evaluate.py is the direct evaluator's entry point over its parts by
    # job (issue 44): evaluator.py (context, names, expressions), eval_values.py,
    # eval_shapes.py, eval_search.py, eval_quant.py, eval_closures.py; each imports
    # only the parts below it (values <- shapes <- search <- quant <- evaluator).
    # logic/straightline.py (a formula compiled into straight-line Python for the
    # monitors) builds on the evaluator's values; logic/judges.py puts it before
    # floatsem.judge (issue 44).
    # logic/encode.py likewise holds the Encoder over sorts.py (sorts, coercions,
    # operators), symbols.py (the error, symbol names), translate.py (formulas
    # node by node) and modeltext.py (Z3 values as RCL text).
    # logic/floatsem.py (issue 40): a formula judged on recorded values in
    # exact, IEEE-754 double or tolerant arithmetic, built on the evaluator
    # and Z3's concrete check beside it, with logic/floatsens.py (which
    # formulas those semantics can change); the monitors (backends) call it.
    # ros/dds.py, ros/dds_qos.py, ros/dds_discovery.py, ros/diff_dds.py: ROS 2's
    # conventions on DDS (names, the participant and node announcements, QoS
    # matching) and the running ROS 2 graph; read by ``ros diff --ros2`` here and
    # by the live monitor above (backends), so they sit with the graph they feed.
    ("system/logic", ("rclverify.system", "rclverify.logic", "rclverify.ros", "rclverify.ros.dds",
                      "rclverify.ros.dds_qos", "rclverify.ros.dds_discovery", "rclverify.ros.diff_dds")),
    # requirements/: formal requirements decided from the composed contracts
    # (check.py, beside the calculus it builds on) and their roll-up with the
    # evidence (rollup.py); its stage (stage.py) sits with the workspace it
    # writes into, its terminal listing (show.py) with the commands.
    # calculus/context.py and calculus/smttext.py (side conditions in context)
    # build on the system model and the logic only; calculus/quotient.py and
    # calculus/linear.py (the weakest contract of a node) re-check with the
    # calculus and requirements/check.py, so they sit in this layer too;
    # health/realizable.py is a peer of the other health checks.
    ("calculus/health", ("rclverify.calculus", "rclverify.health", "rclverify.requirements")),
    # backends/monitors/fieldpaths.py (issue 40): a mapping's field paths
    # checked against the message definitions through ros/interfaces.py (the
    # grounding's reader, a lower layer); entry_checks.py calls it.
    # backends/monitors/dds_*.py: the live monitor over DDS (types made from
    # the .msg files, the bus and its readers, calls checked one by one with
    # the monitors' engine, --enforce, the bag recorder); monitors' code,
    # beside the ROS 1 glue (ros1.py, live.py).
    ("backends", ("rclverify.backends", "rclverify.backends.monitors.dds_types", "rclverify.backends.monitors.dds_bus",
                  "rclverify.backends.monitors.dds_calls", "rclverify.backends.monitors.dds_services",
                  "rclverify.backends.monitors.dds_enforce", "rclverify.backends.monitors.dds_bag",
                  "rclverify.backends.monitors.dds_live")),
    # diagnosis/: each problem of the report explained and repairs checked by
    # re-running the calculus, health checks and Hoare triples on edited text
    # (so above the backends); the report shows the records.
    ("diagnosis", ("rclverify.diagnosis",)),
    # The workspace (workspace.py: the loaded plan and contracts, artifact
    # paths, snapshots and what makes a result stale): read by the report,
    # the stages and the commands; it imports the layers below only.
    # The deadlines stage (calculus/deadline_stage.py) writes and reads its sealed record
    # in the workspace, as the requirements stage does.
    # crosscheck/ (issue 50): the second solver's stage reads the stages' sealed records and re-decides their
    # queries with cvc5; the report folds its verdicts in, so it sits with the workspace's stages.
    ("workspace", ("rclverify.workspace", "rclverify.requirements.stage", "rclverify.calculus.deadline_stage",
                   "rclverify.crosscheck")),
    # report/ and argument/ render the results; contract_texts.py makes the
    # texts of the contracts the report shows (RCL, LaTeX, lint), so it
    # belongs with the report.
    ("report/argument", ("rclverify.report", "rclverify.argument", "rclverify.contract_texts")),
    # The stages and their drivers: pipeline.py and tasks.py (doit), the Dask scheduler's jobs
    # (cluster.py), the progress line over the report's summary
    # (progress.py), doit's state saved after each task (doitstate.py), one
    # run at a time (runlock.py), the ROS grounding stage (ros/stage.py), the
    # replay of one property test from a workspace (replay.py, what generated
    # pytest files call).
    # conetask.py: the doit uptodate check that re-runs a node's calculus when the part of its upstream
    # cone it read changed (beside tasks.py, which uses it; it reads the evidence layer's seals only).
    ("pipeline/tasks", ("rclverify.pipeline", "rclverify.tasks", "rclverify.cluster",
                        "rclverify.progress", "rclverify.doitstate", "rclverify.runlock", "rclverify.ros.stage",
                        "rclverify.replay", "rclverify.conetask")),
    # Commands: the CLI, and what only commands use: scaffold/ (``rclverify
    # init``: a new workspace from templates), bundle/ (``rclverify bundle``:
    # an archive of the evidence with its manifest), ``rclverify ros ...``
    # (ros/cli.py) and ``init --from-ros`` (ros/skeleton.py, on scaffold's
    # templates), and the language server (lsp/, ``rclverify lsp``: beside the CLI, it reads what
    # every layer below gives and the last run's report files).
    ("cli", ("rclverify.cli", "rclverify.lsp", "rclverify.requirements.show", "rclverify.scaffold", "rclverify.generate", "rclverify.bundle", "rclverify.ros.cli",
             "rclverify.ros.skeleton")),
]

#: Edges (importer, imported) of import circles 1 and 2 of issue 25, being
#: removed on other branches.  Each one breaks a rule today; remove an edge
#: here when its import goes (the last test fails while a listed edge no
#: longer exists).
KNOWN_VIOLATIONS: frozenset[tuple[str, str]] = frozenset({
    # Empty: circle 1 (the plan importing the backend registry) went with
    # plan/entries.py, circle 2 (pipeline, report, contract texts and
    # workspace cache importing each other) with workspace.py, and the plan
    # loader's own circles with plan/model.py.  Keep it empty.
})


def modules() -> dict[str, tuple[Path, bool]]:
    """Every module of the package: dotted name -> (file, is a package's __init__)."""
    out: dict[str, tuple[Path, bool]] = {}
    for path in sorted((SRC / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (path, is_pkg)
    return out


def _targets(module: str, is_pkg: bool, node: ast.Import | ast.ImportFrom, known: set[str]) -> list[str]:
    """The package's modules an import statement names."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name == PACKAGE or a.name.startswith(PACKAGE + ".")]
    if node.level == 0:
        base = node.module or ""
        if not (base == PACKAGE or base.startswith(PACKAGE + ".")):
            return []
    else:
        here = module.split(".") if is_pkg else module.split(".")[:-1]
        here = here[:len(here) - (node.level - 1)]
        base = ".".join(here + ([node.module] if node.module else []))
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]


def import_graph() -> nx.DiGraph:
    """The package's import graph (module -> module it imports), read with ``ast``."""
    mods = modules()
    g = nx.DiGraph()
    g.add_nodes_from(mods)
    for name, (path, is_pkg) in mods.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in _targets(name, is_pkg, node, set(mods)):
                    while target not in mods and "." in target:  # `import a.b.attr`: the module a.b
                        target = target.rsplit(".", 1)[0]
                    if target in mods and target != name:
                        g.add_edge(name, target)
    return g


def layer_of(module: str) -> int:
    """Index in :data:`LAYERS` of the longest entry that ``module`` is or lies under."""
    best, rank = -1, None
    for k, (_, entries) in enumerate(LAYERS):
        for entry in entries:
            covers = module == entry or (entry != PACKAGE and module.startswith(entry + "."))
            if covers and len(entry) > best:
                best, rank = len(entry), k
    if rank is None:
        raise AssertionError(f"{module} has no layer: place it in LAYERS (tests/test_layers.py)")
    return rank


@pytest.fixture(scope="module")
def graph() -> nx.DiGraph:
    return import_graph()


def test_the_graph_is_read_from_the_source(graph: nx.DiGraph) -> None:
    """Known imports of both kinds are found: module level and inside a function."""
    assert graph.has_edge("rclverify.logic.decide", "rclverify.logic.evaluate")  # module level, relative
    assert graph.has_edge("rclverify.cli", "rclverify.pipeline")  # inside a function
    assert graph.has_edge("rclverify.health.checks", "rclverify.health.finding")
    assert len(graph) > 60 and graph.number_of_edges() > 300


def test_every_module_has_a_layer(graph: nx.DiGraph) -> None:
    for m in graph:
        layer_of(m)


def test_no_import_from_a_lower_layer_to_a_higher_one(graph: nx.DiGraph) -> None:
    upward = sorted((a, b) for a, b in graph.edges if layer_of(a) < layer_of(b) and (a, b) not in KNOWN_VIOLATIONS)
    assert not upward, "imports from a lower layer to a higher one:\n" + "\n".join(
        f"  {a} ({LAYERS[layer_of(a)][0]}) -> {b} ({LAYERS[layer_of(b)][0]})" for a, b in upward)


def test_no_import_cycle(graph: nx.DiGraph) -> None:
    rest = graph.copy()
    rest.remove_edges_from(KNOWN_VIOLATIONS)
    cycles = [sorted(c) for c in nx.strongly_connected_components(rest) if len(c) > 1]
    assert not cycles, "import cycles:\n" + "\n".join(
        "  " + " -> ".join(nx.find_cycle(rest.subgraph(c))[k][0] for k in range(len(nx.find_cycle(rest.subgraph(c)))))
        for c in cycles)


def test_known_violations_still_exist(graph: nx.DiGraph) -> None:
    """A listed edge whose import has gone must leave KNOWN_VIOLATIONS."""
    gone = sorted(e for e in KNOWN_VIOLATIONS if not graph.has_edge(*e))
    assert not gone, f"no longer imported, remove from KNOWN_VIOLATIONS: {gone}"


def test_the_rules_catch_a_violation() -> None:
    """The checks are not vacuous: an upward edge and a cycle added to a copy are found."""
    g = import_graph()
    g.add_edge("rclverify.rcl.ast", "rclverify.pipeline")
    assert layer_of("rclverify.rcl.ast") < layer_of("rclverify.pipeline")
    g.remove_edges_from(KNOWN_VIOLATIONS)
    assert any(len(c) > 1 for c in nx.strongly_connected_components(g))
