"""The suite's tiers, the order its modules are handed to the workers, and the
Hypothesis profile of the tests (issues 66 and 67; docs/ci.md, "The test suite").

Tiers.  Two markers are applied here, by module, so that a module's tier is
read in one place:

- ``live``: the module starts real outside processes and talks to them over
  the network or a pipe and waits on them: a ROS 1 master, rclpy nodes or
  DDS participants, a WebSocket oracle, Chromium, the language server;
- ``slow``: the module costs more than about two CPU seconds, or runs the
  whole pipeline (``doit verify`` or ``rclverify verify``) on a workspace.

``python3 -m pytest -m "not slow and not live"`` is the inner tier (about 110
CPU s, docs/ci.md); plain ``python3 -m pytest`` runs everything, as CI does.
A module whose tier ``-m`` deselects whatever its tests' other marks are is
not imported at all (:func:`pytest_ignore_collect`): the inner tier imports
its own modules only.

Order.  With ``--dist loadfile`` each module goes to one worker whole, and a
worker takes the next module when it is free.  pytest-xdist's default hands
out the modules with the most tests first, which leaves the modules of one
or two long tests (a colcon build, a live ROS system, a whole oracle run) to
the end, where one worker runs them while the others have nothing left:
the classic tail of list scheduling.  ``pyproject.toml`` turns that reordering
off (``--no-loadscope-reorder``) and this file sorts the modules by the CPU
seconds measured for them (:data:`SECONDS`, longest first; Graham's LPT rule),
the modules not listed after them in their usual order (a live module by its
wall-clock seconds, :data:`WALL`, when they are longer).  The figures are
the CPU seconds of each module's tests taken inside a whole run on the 2-core
development machine (``RCLVERIFY_TEST_CPU``, below); only their order
matters, so a rough figure is enough, and a module that grows past two
seconds belongs in :data:`SLOW` and here.

Memory.  A test module keeps what it computes once in a module-scoped
fixture, never in a cache of the module: a worker runs many modules, and what
a module cache holds (tests/project/test_rooms.py held the package's syntax trees, two
million objects) is walked by every later full garbage collection of the
worker, and by the five pytest makes at its end.  The suite freezes nothing
itself: rclverify's own heap handling (``core/cache/heap.py``) freezes and
gives back the whole heap of a process around an in-process doit run, and
tests/core/test_heap.py checks it from an unfrozen start.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

#: Modules that start live systems or subprocesses they talk to (``live``).
LIVE = frozenset({
    "test_bench_smoke_live", "test_browser_report", "test_dds_wire", "test_generate_names_ros2",
    "test_lsp_fuzz", "test_lsp_hostile", "test_lsp_invalid", "test_lsp_nvim", "test_lsp_server",
    "test_monitor_live_dds", "test_monitor_live_hostile", "test_monitor_live_ros1", "test_monitor_oracle",
    "test_ros2_diff", "test_ros2_generated", "test_ros2_services_actions", "test_ros2_silence_deadlines",
    "test_ros2_declarations", "test_robot_generator_declarations_live", "test_ros2_sequences", "test_ros2_types_record", "test_ros_diff_dds", "test_ros_diff_live", "test_ros_live",
    "test_ros_master_hostile", "test_services_live_ros1", "test_ros_names_rclpy", "test_names_rcl", "test_names_fleet_live", "test_ros2_calls_paired", "test_ros2_carried",
    "test_ros2_bag_calls", "test_ros2_event_time", "test_example_manipulator",
    "test_ros2_undefined_type", "test_ros2_call_endpoints", "test_ros2_declared_types", "test_nodl_live",
    "test_live_stops", "test_lifecycle_live", "test_instances_live", "test_lsp_code_repair", "test_fleet_example_live",
    "test_run_repair_rclpy", "test_ros2_run_end", "test_ros2_thresholds_clocks_stamps",
    "test_ros2_rclpy_discovers_nobody", "test_ros2_robots_other_clocks", "test_ros2_dds_server_restart",
    "test_live_exit", "test_ros2_clock_heard", "test_ros2_sim_time_deadlines", "test_ros2_sim_time_calls",
    "test_services_live_ros1_sim_time",
})

#: CPU seconds of each module that costs more than about two: its tests' user + system seconds, children
#: included, summed within a whole run (``RCLVERIFY_TEST_CPU``, below; three workers on the shared 2-core
#: machine under a load of about 3.5, so a little high; the import of the module not counted).
SECONDS: dict[str, float] = {
    "test_example_ros2_robot": 30.0,  # 12.5 CPU s, but its colcon build and live run wait: started early
    "test_target_unread_field_copy": 2.0,
    "test_bench_help": 7.0,  # every bench started once with --help, a process each
    "test_monitor_startup": 3.0,  # three monitor runs, two of them processes of their own (a cold start)
    "test_bench_smoke_live": 64.0, "test_pipeline_e2e": 112.0, "test_integrity": 24.8,
    "test_example_warehouse": 29.7, "test_bench_smoke": 48.0, "test_generate_names_ros2": 35.1,
    "test_example_delivery": 48.6, "test_ros2_generated": 23.7, "test_inputs_faults": 13.2,
    "test_lsp_server": 10.8, "test_temporal_requirements": 9.8, "test_hardening_greens": 9.8,
    "test_generate_names": 22.1, "test_stage_records": 26.3, "test_temporal_semantics_oracle": 8.0,
    "test_solver_session": 8.0, "test_one_evaluator": 13.7, "test_generate_ros2": 7.1,
    "test_spin_no_wrong_green": 7.0, "test_spin": 7.0, "test_temporal_pdr": 6.8, "test_ros2_types_record": 6.7,
    "test_dafny": 9.0, "test_calculus_summary": 6.6, "test_summary_incremental": 6.4,
    "test_temporal_progress": 6.1, "test_response_pattern": 6.1, "test_property_tests": 6.0,
    "test_spin_oracle": 5.6, "test_generate_cpp": 5.5, "test_browser_report": 5.4, "test_cluster": 5.4,
    "test_cache_poison": 5.2, "test_hardening_misc": 5.2, "test_health": 5.2, "test_temporal_oracle": 5.1,
    "test_rcl_printer": 4.8, "test_diagnosis": 4.7, "test_lsp_fuzz": 4.5, "test_ros_hostile": 4.4,
    "test_property_tests_facts": 4.4, "test_property_tests_seqs": 2.9, "test_ros2_silence_deadlines": 4.0, "test_query_ladder": 3.8,
    "test_services_live_ros1": 3.7, "test_report_problems_roots": 3.7, "test_rooms": 3.7,
    "test_findings_context": 3.6, "test_rcl_fuzz": 3.6, "test_monitor_live_ros1": 3.5, "test_jsonl_blocks": 3.3,
    "test_declarations_verified": 3.3, "test_calculus_context": 3.1, "test_ros_diff_live": 3.0,
    "test_temporal_ranking": 3.0, "test_monitor_batch": 3.0, "test_bag_open": 3.0, "test_advice": 2.9,
    "test_quotient": 2.9, "test_ros2_services_actions": 2.8, "test_monitor_fuzz": 2.8, "test_rcl_language": 2.7,
    "test_ros2_diff": 2.6, "test_requirements": 2.6, "test_cli_newuser": 2.6, "test_report_unverified": 2.4,
    "test_second_solver": 2.4, "test_statistics_plan": 2.3, "test_generate_example": 2.3, "test_experiment": 2.2,
    "test_generate_cpp_candidates": 2.2, "test_jsonl_columns": 2.2, "test_realizable": 2.1,
    "test_bench_compose_pacti": 2.1, "test_deterministic_queries": 2.1, "test_findings_health": 2.1,
    "test_health_fast": 3.3, "test_requirements_own_nodes": 2.0, "test_bundle_ties": 3.0,
    "test_paths_rechecked": 3.5, "test_incremental_equivalence": 6.8, "test_server_targets": 2.3, "test_ros2_bag_calls": 7.0, "test_nodl_live": 4.0,
    "test_definedness": 6.6, "test_run_identity": 5.0,
    "test_ros2_declared_types": 10.0, "test_ros2_call_endpoints": 4.0, "test_widths_forms": 2.5,
    "test_margins_batch": 3.6, "test_example_manipulator": 12.5, "test_ros2_event_time": 6.0, "test_widths_paths": 3.3,
    "test_property_tests_plugins": 4.2, "test_numeric": 4.1, "test_startup_cache": 3.7,
    "test_refinement_oracle": 3.6, "test_diagnosis_stage": 3.0, "test_widths_ints": 2.7,
    "test_sequences_of_messages": 2.5, "test_layers": 2.5, "test_trace_fifo": 2.1,
    "test_health_beside_evidence": 2.1, "test_straightline": 2.1,
    "test_realizable_under_load": 12.0,  # two CPU burners beside three runs
    "test_realizable_sequences": 2.4,
    "test_nodl_verify": 3.3,
    "test_property_tests_thresholds": 9.0,  # 68 property-test runs: 17 forms, two widths, a correct node and its slip
    "test_write_bounds_cli": 30.0, "test_read_bounds": 2.5,  # one verify, every output path tried three ways
    "test_live_stops": 18.0,  # six starts of the live monitor, each a ROS 2 Python or a DDS participant
    # Out of the inner tier by the two-second rule (docs/ci.md, "Round fifteen"): each over 3 CPU s in the inner
    # tier's own run (three workers, load about 10) and again run alone (one process), so over two on the
    # quieter machine these figures were first taken on.
    "test_record_shapes": 4.3, "test_logic": 3.5, "test_candidates": 3.9, "test_gwendolen": 3.5,
    "test_temporal_traces": 3.0, "test_extras": 3.5, "test_evidence": 3.5, "test_generate_contract_layer": 3.1,
    "test_robustness": 3.0,
    # this round's modules over two CPU seconds (run alone, one process, the import of pytest not counted)
    "test_repair_examples": 30.0, "test_repair_oracle": 7.0, "test_repair_cli": 5.0, "test_hoare_token_repairs": 3.0,
    "test_fret_example": 18.0, "test_instances": 3.5, "test_fleet_example": 6.0,
    "test_lifecycle_recorded": 2.6,  # seven replays of a recorded run through the live run's judge
    "test_ros_init_lifecycle": 3.8,  # init --from-ros, check and ros check on the bringup corpus
    "test_fret_scopes": 19.0,  # 191 FRET scope/timing combinations, each run against FRET's formula on 12 traces
    # round seventeen's new modules over two CPU seconds, and one that grew (a third test runs the pipeline)
    "test_fret_lustre": 2.3, "test_graph_bag": 2.5, "test_monitors_lifecycle": 2.2,
    "test_math_functions": 3.5, "test_temporal_math": 5.0,  # sqrt/sin/cos end to end; a pipeline's requirements
    # Out of the inner tier by the two-second rule (docs/ci.md, "Round sixteen"): over 2 CPU s in three inner-tier
    # runs of round fifteen (the median) and again run alone, one process, at a fixed commit (load about 17).
    "test_report_as_written": 3.4, "test_startup_imports": 3.1, "test_monitor_skew": 3.0, "test_monitor_order": 2.9,
    "test_jobs": 2.6, "test_widths": 2.5, "test_summary_store": 2.4, "test_report_textfmt": 2.4,
    "test_bag_blocks": 2.4, "test_evaluate_shortcuts": 2.3, "test_ros_bringup": 2.0,
    # a pipeline module (slow already) measured in round seventeen (docs/ci.md)
    "test_example_fleet_trials": 8.5,
    "test_batch_triggered": 7.0,  # a triggered node's batch judgement against the engine on 80 random runs
    # Out of the inner tier by the two-second rule (docs/ci.md, "Round eighteen"): over 2 CPU s in each of this
    # round's inner-tier runs (two workers, load 10 to 17); the grouping of the stored case-study report over 2
    # run alone too, once its three readers shared it
    "test_statistics": 2.3, "test_batch_deadlines": 2.3, "test_monitors": 2.5, "test_units": 2.1,
    "test_witness": 2.1, "test_problems_model_checking": 2.3,
    "test_generated_seed_faults": 6.0,  # two generated robots' recorded runs judged offline, one replayed online
    "test_bag_run_end": 9.0,  # seed 545's bag recorded again three times (both storages, one without the end), judged
    # Out of the inner tier by the two-second rule: over 3 CPU s in a whole run (three workers, a load of about 8)
    # and again in the inner tier's own run (three workers, load 3 to 7)
    "test_copied_stamps_shared_seeds": 3.5, "test_batch_violations": 3.2,
    # an oracle over 500 random call runs against the rule enumerated, each replayed from its log
    "test_call_deadlines_sim_time": 3.5,
}

#: Wall-clock seconds of the live modules, serial (they wait on masters, nodes, a browser: their CPU
#: seconds understate how long they hold a worker).  Taken on a loaded machine, so rather long: which
#: only hands them out earlier, where a long module belongs.
WALL: dict[str, float] = {
    "test_bench_smoke_live": 49.4, "test_ros2_generated": 48.2, "test_lsp_server": 27.2,
    "test_ros2_types_record": 19.5, "test_monitor_live_ros1": 16.6, "test_generate_names_ros2": 50.0,
    "test_monitor_live_hostile": 15.0, "test_ros2_diff": 13.4, "test_ros_diff_live": 12.9,
    "test_lsp_fuzz": 11.9, "test_ros2_services_actions": 11.5, "test_browser_report": 10.5,
    "test_services_live_ros1": 10.0, "test_ros2_silence_deadlines": 8.6, "test_ros_live": 6.7,
    "test_ros2_declarations": 25.4, "test_monitor_live_dds": 6.1, "test_lsp_hostile": 5.0,
    "test_ros_master_hostile": 5.0, "test_ros_diff_dds": 4.7, "test_lsp_invalid": 3.3, "test_lsp_nvim": 2.7, "test_monitor_oracle": 2.2,
    "test_ros_names_rclpy": 3.2, "test_ros2_bag_calls": 15.0, "test_ros2_event_time": 38.0,
    "test_example_manipulator": 77.0, "test_ros2_call_endpoints": 35.0, "test_ros2_declared_types": 27.0,
    "test_ros2_undefined_type": 6.0, "test_nodl_live": 45.0, "test_ros2_carried": 36.0,
    "test_live_stops": 45.0, "test_names_rcl": 5.0, "test_names_fleet_live": 17.0, "test_lifecycle_live": 40.0,
    "test_instances_live": 35.0, "test_lsp_code_repair": 20.0, "test_fleet_example_live": 30.0,
    "test_run_repair_rclpy": 60.0,  # 40-60 s measured in round seventeen (two re-runs of the node per repair)
    # three live runs of generated robots, about 20 s each on an idle machine (its live tests are marked in the
    # module; its other tests are the inner tier's): started early, not left to the end
    "test_robot_generator": 60.0,
    # real rclpy robots through both sources; measured at -n 2 beside other work (load 12-16)
    "test_ros2_robots_other_clocks": 120.0, "test_ros2_thresholds_clocks_stamps": 60.0,
    "test_ros2_rclpy_discovers_nobody": 40.0, "test_ros2_dds_server_restart": 36.0,
    "test_live_exit": 20.0,  # a ROS 1 master and two stopped runs beside a CPU burner, two held controls
    "test_ros2_clock_heard": 45.0,  # five live runs (both sources with /clock, one without; ROS 1 with and without)
    "test_ros2_sim_time_deadlines": 30.0,  # two live runs (a source each, factors 0.5 and 2), each log read 4 times
    "test_ros2_sim_time_calls": 35.0,  # the same for a SetBool server's calls
    "test_services_live_ros1_sim_time": 20.0,  # a ROS 1 master under /use_sim_time, two runs of the proxy (16-18 s)
}

#: Modules weighed by their wall-clock time (in :data:`WALL`) whose live tests are marked in the module
#: itself (``@pytest.mark.live``), the rest of the module in the inner tier.
MARKED_IN_MODULE = frozenset({"test_robot_generator"})

#: Modules that run the whole pipeline although they cost less than two seconds: still ``slow``.
PIPELINE = frozenset({
    "test_confidence", "test_deadlines", "test_deadlines_report", "test_evidence_staleness",
    "test_generate_example", "test_inputs_paths", "test_locations_cause",
    "test_monitor_periods", "test_monitor_silence", "test_one_root_one_repair", "test_problems_shared",
    "test_realizer", "test_ros_init", "test_temporal_deadlock", "test_temporal_progress",
    "test_units_inferred", "test_deadline_monitors", "test_monitor_floats", "test_acknowledged",
    "test_blame_line", "test_deadline_timing_measured", "test_example_fleet_trials", "test_mapping_hygiene",
    "test_one_row_per_cause", "test_repairs_units", "test_report_hygiene", "test_report_schema",
    "test_example_safety_stop", "test_init", "test_stage_records", "test_what_runs_is_hashed", "test_write_bounds_cli",
    "test_example_ros2_robot",  # its one live test is marked in the module (the rest is offline)
    "test_margins_monitor", "test_margins_chain", "test_near_misses", "test_margin_targets",
    "test_margins_report", "test_near_miss_units_report",
    "test_code_repairs", "test_standards_fresh", "test_design_verify",
    "test_trace_steps",  # three `rclverify verify` runs of one small workspace (3.1 CPU s in the inner tier)
})

#: The ``slow`` tier: every module measured above two CPU seconds, and the pipeline runs.
SLOW = frozenset({name for name, s in SECONDS.items() if s >= 2.0}) | PIPELINE


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark each item with its module's tiers and order the modules longest first (stable within a module)."""
    first: dict[str, int] = {}
    for k, item in enumerate(items):
        module = item.path.stem
        first.setdefault(module, k)
        if module in LIVE:
            item.add_marker(pytest.mark.live)
        if module in SLOW:
            item.add_marker(pytest.mark.slow)
    items.sort(key=lambda item: (-_weight(item.path.stem), first[item.path.stem]))


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """Leave a test module unimported when ``-m`` deselects every test its tier marks.

    A module of the ``slow`` or ``live`` tier is imported only to have all its tests deselected by the
    inner tier's ``-m "not slow and not live"``: collecting all 400 modules of the suite cost each worker
    about 10 CPU s, collecting the inner tier's 182 about 5.  A module is left out only when the
    expression is false for its tiers whatever the other marks named in it are (each tried both ways),
    so no test the expression selects is lost.
    Returns True to leave the module out, None to let pytest decide as usual."""
    if collection_path.suffix != ".py" or not collection_path.name.startswith("test_"):
        return None
    marks = {name for name, tier in (("slow", SLOW), ("live", LIVE)) if collection_path.stem in tier}
    expression = config.getoption("markexpr", "")
    if not marks or not expression:
        return None
    return True if _never_selected(expression, marks) else None


def _never_selected(expression: str, marks: set[str]) -> bool:
    """Whether the ``-m`` ``expression`` is false for a test carrying ``marks`` whatever its other marks.

    Each other mark the expression names is tried present and absent (up to 2**8 assignments); an
    expression with arguments (``mark(key=value)``), or one naming more marks, is never decided here
    (False: the module is collected and pytest's own ``-m`` selects as usual)."""
    from _pytest.mark.expression import Expression  # deferred: inside a function (pytest's own parser of -m, read only here)

    compiled = Expression.compile(expression)
    free = sorted(compiled.idents() - marks)
    if len(free) > 8:
        return False
    for bits in range(2 ** len(free)):
        present = marks | {name for k, name in enumerate(free) if bits >> k & 1}

        def matcher(name: str, /, **kwargs: object) -> bool:
            if kwargs:
                raise _Undecided
            return name in present

        try:
            if compiled.evaluate(matcher):
                return False
        except _Undecided:
            return False
    return True


class _Undecided(Exception):
    """An ``-m`` expression this file does not decide (a mark with arguments)."""


def _weight(module: str) -> float:
    """How long ``module`` holds a worker, in seconds: its CPU seconds, or its wall-clock seconds when longer."""
    return max(SECONDS.get(module, 0.0), WALL.get(module, 0.0))


# Hypothesis: no per-example deadline (a loaded 2-core machine makes a slow example a false alarm,
# and the suite's speed is measured by bench/ scripts, not by timed tests) and no "too slow" health
# check for the same reason.  The number of examples is each test's own setting or Hypothesis's.
settings.register_profile("tests", deadline=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "tests"))

# A pipeline run without ``-n`` uses one doit process per CPU (app/jobs.py).  The suite's three
# workers already fill the two cores, so its runs stay serial unless a test asks for more (``-n 2``,
# or RCLVERIFY_JOBS in the test's own environment: tests/app/test_jobs.py): the same CPU seconds, and
# doit's task lines in their serial order, which several tests read.  Subprocesses inherit it.
os.environ.setdefault("RCLVERIFY_JOBS", "1")


#: ``RCLVERIFY_TEST_CPU=FILE``: append each test's CPU seconds (user + system of the worker and of the
#: children it waited for, setup to teardown) as ``module<TAB>test<TAB>seconds<TAB>end<TAB>worker`` lines
#: to FILE (``end``: the wall clock when the test ended, Unix seconds, to see the workers' idle tail), so the
#: figures of :data:`SECONDS` can be taken inside a whole run: CPU seconds, unlike pytest's durations,
#: do not grow with the other workers' load (docs/ci.md, "The test suite").
_CPU_LOG = os.environ.get("RCLVERIFY_TEST_CPU")


if _CPU_LOG:
    import resource  # deferred: inside a block (only when the figures are asked for)
    import time

    def _cpu() -> float:
        own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):  # type: ignore[no-untyped-def]
        start = _cpu()
        yield
        with open(_CPU_LOG, "a", encoding="utf-8") as f:
            f.write(f"{item.path.stem}\t{item.name}\t{_cpu() - start:.3f}\t{time.time():.3f}\t"
                    f"{os.environ.get('PYTEST_XDIST_WORKER', 'main')}\n")


def pytest_configure(config: pytest.Config) -> None:
    """One full garbage collection when a worker's session ends, not pytest's five.

    pytest's unraisable-exception plugin collects five times at the end of a session so that an object
    whose finaliser raises is found on interpreters without reference counting (its own comment: PyPy);
    on CPython one collection frees what the others would.  Each collection walks the worker's whole
    heap: the five cost the suite's three workers about 5 CPU s, at the end of the run, where they add
    to its wall clock.  The iteration count is pytest's own configuration key; without it (another
    pytest), nothing changes."""
    try:
        from _pytest.unraisableexception import gc_collect_iterations_key  # deferred: inside a function (pytest's private key, read only here)
    except ImportError:
        return
    config.stash[gc_collect_iterations_key] = 1
