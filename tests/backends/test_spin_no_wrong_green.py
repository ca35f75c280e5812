"""No wrong green from the SPIN model checking of the agent (issue 39, "SPIN model checking of the agent").

Each case of the issue, reproduced: a planted ``pan`` in the workspace, a
model path that injects Promela, a vacuous pass, constant mapping rows that
are not literally ``T``/``F``, identifiers a program remembers, a tool
killed from outside, terms and rules that grow without bound, a graph cut
by a bound, two ``ajpf`` entries on one node, and rclverify itself killed
while SPIN and gcc run.  Each ends in a located error, ``inconclusive`` or
``failed``, never ``discharged``.  Verifiers are built in a cache of this
module's own (``XDG_CACHE_HOME``), never in the user's.
"""
from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable, Iterator

import pytest
import yaml

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.ajpf.config import DEFAULT_TIMEOUT_S as AJPF_TIMEOUT_S
from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
from rclverify.backends.bounded import ToolInterrupted, run_bounded
from rclverify.backends.model_checking import backend as mc, spin_config
from rclverify.backends.model_checking import spin
from rclverify.backends.model_checking.environment import environment_from_plan
from rclverify.backends.model_checking.explore import explore
from rclverify.backends.model_checking.gwendolen import GwendolenError
from rclverify.records.records import Evidence, Obligation
from rclverify.model.plan.errors import PlanError
from rclverify.lang.errors import RclError

from test_spin import HAVE_SPIN

REPO = Path(__file__).resolve().parents[2]
needs_spin = pytest.mark.skipif(not HAVE_SPIN, reason="spin or gcc not installed (apt-get install spin)")
needs_proc = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads processes from /proc (Linux)")

NOTHING = "GWENDOLEN\n:name: jackal\n"
DONE = "GWENDOLEN\n:name: jackal\n:Initial Goals:\ngo [perform]\n:Plans:\n+!go [perform] <- +done;\n"
BAD = "bad: [] ~B(jackal, done)\n"


@pytest.fixture(autouse=True, scope="module")
def own_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """Verifiers of this module go to a cache of its own; no MCAPL (SPIN is the checker)."""
    cache = tmp_path_factory.mktemp("xdg-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("XDG_CACHE_HOME", str(cache))
        mp.delenv("MCAPL_HOME", raising=False)
        mp.delenv("AJPF_HOME", raising=False)
        yield cache


def case_entry() -> dict[str, Any]:
    plan = yaml.safe_load((REPO / "contracts/plan.yaml").read_text())
    return dict(next(e for e in plan["nodes"]["Agent"]["evidence"] if e["backend"] == "ajpf"))


def workspace(root: Path, program: str | None = None, model: str = "backends/ajpf/agent.gwen",
              properties: dict[str, str] | None = None, entries: int = 1, **changes: Any) -> Any:
    """A workspace with the case study's Agent contract and ajpf entry (SPIN), ``program``
    (default: the case study's agent) at ``model``, ``properties`` files, the entry changed by
    ``changes``; returns the Agent's target of entry 0."""
    from rclverify.stages.workspace import Workspace
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "contracts/remote_inspection.rcl").write_text((REPO / "contracts/remote_inspection.rcl").read_text())
    (root / model).parent.mkdir(parents=True, exist_ok=True)
    (root / model).write_text(program if program is not None else (REPO / "backends/ajpf/jackal.gwen").read_text())
    entry = {**case_entry(), "model": model, **changes}
    for rel, text in (properties or {}).items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    if properties:
        entry["properties"] = list(properties)
    (root / "contracts/plan.yaml").write_text(yaml.safe_dump(
        {"contracts": ["contracts/remote_inspection.rcl"], "nodes": {"Agent": {"evidence": [dict(entry) for _ in range(entries)]}}}))
    return Workspace(root).target("Agent", 0)


def run(target: Any, keep: Callable[[Obligation], bool] = lambda o: True) -> dict[str, Evidence]:
    obligations = AjpfBackend().export(target)
    mc.clear_caches()
    return {o.id: AjpfBackend().run(o, target) for o in obligations if keep(o)}


def g2(o: Obligation) -> bool:
    return o.guarantee == 2


def extra(o: Obligation) -> bool:
    return o.guarantee == 0


# -- a pan found in the workspace is never run ---------------------------------------------

@needs_spin
def test_a_planted_pan_in_the_workspace_is_never_executed(tmp_path: Path) -> None:
    target = workspace(tmp_path / "ws", DONE, properties={"backends/ajpf/extra.psl": BAD},
                       environment={"percepts": ["x"]})
    [first] = run(target, extra).values()
    assert first.status == "failed", first.explanation
    model = (target.artifacts / "spin/model.pml").read_text()
    marker = tmp_path / "planted-pan-ran"
    script = f"#!/bin/sh\ntouch '{marker}'\necho 'State-vector 20 byte, depth reached 1, errors: 0'\n"
    # where earlier versions kept (and ran) the verifier: spin/build/<sha256 of the model>[:16]/pan
    for name in (hashlib.sha256(model.encode()).hexdigest()[:16], hashlib.sha256(model.encode()).hexdigest()):
        planted = target.artifacts / "spin/build" / name
        planted.mkdir(parents=True, exist_ok=True)
        (planted / "model.pml").write_text(model)
        (planted / "pan").write_text(script)
        (planted / "pan").chmod(0o755)
    [again] = run(target, extra).values()
    assert again.status == "failed", again.explanation
    assert not marker.exists()
    assert not (target.artifacts / "spin/build").exists()  # old build products are removed, not kept
    assert list((Path(os.environ["XDG_CACHE_HOME"]) / "rclverify/spin").glob("*/pan"))  # built in the cache


# -- Promela injection through the model's path -----------------------------------------------

@needs_spin
@pytest.mark.parametrize("directive", ["#define active init { do :: s = s od }", '#include "{secret}"'])
def test_the_model_path_cannot_inject_promela(tmp_path: Path, directive: str) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("SECRET-TOKEN-4711 not promela\n")
    evil = "backends/d*/\n" + directive.replace("{secret}", str(secret)) + "\n/*/agent.gwen"
    target = workspace(tmp_path / "ws", DONE, model=evil, properties={"backends/ajpf/extra.psl": BAD},
                       environment={"percepts": ["x"]})
    [ev] = run(target, extra).values()
    assert ev.status == "failed", ev.explanation
    text = (target.artifacts / "spin/model.pml").read_text()
    assert not any(line.lstrip().startswith("#") for line in text.splitlines())
    assert "active proctype agent()" in text
    assert "SECRET-TOKEN" not in ev.explanation + ev.log + str(ev.details)


def test_comment_text_keeps_workspace_text_inside_its_comment() -> None:
    from rclverify.backends.model_checking.promela import comment_text
    for raw in ("a*/b", "x\n#define active\n/*", "??/\n", "/*/", "\\\n", "é\x00\t"):
        safe = comment_text(raw)
        assert "*/" not in safe and "/*" not in safe and "??" not in safe and "\n" not in safe
        assert all(" " <= ch <= "~" for ch in safe)


# -- a vacuous pass is inconclusive -----------------------------------------------------------

@needs_spin
def test_an_agent_that_does_nothing_passes_guarantee_2_only_vacuously(tmp_path: Path) -> None:
    evs = run(workspace(tmp_path, NOTHING), g2)
    assert len(evs) == 13
    for ev in evs.values():
        assert ev.status == "inconclusive", ev.explanation
        assert ev.details["spin_verdict"] == "holds" and "(vacuous)" in ev.explanation
        assert "holds in no state of the explored graph" in ev.details["vacuous"][0]


@needs_spin
def test_temporal_antecedents_are_checked_by_spin_for_vacuity(tmp_path: Path) -> None:
    props = ("fair: ([] <> B(jackal, never)) -> [] B(jackal, done)\n"
             "seen: (<> B(jackal, done)) -> <> B(jackal, done)\n")
    evs = run(workspace(tmp_path, DONE, properties={"backends/ajpf/extra.psl": props},
                        environment={"percepts": ["x"]}), extra)
    fair, seen = evs["Agent.g0.ajpf.extra_fair"], evs["Agent.g0.ajpf.extra_seen"]
    assert fair.status == "inconclusive" and "holds on no path" in fair.explanation, fair.explanation
    assert seen.status == "discharged", seen.explanation


# -- constant mapping rows are decided after simplification -----------------------------------

@pytest.mark.parametrize("false_row, true_row", [("~T", "~F"), ("F || F", "T & T"),
                                                 ("B(jackal, a) & ~B(jackal, a)", "B(jackal, a) || ~B(jackal, a)")])
def test_constant_rows_are_partial_coverage_whatever_their_form(tmp_path: Path, false_row: str,
                                                                true_row: str) -> None:
    entry = case_entry()
    rows = [dict(r) for r in entry["mapping"]]
    for r in rows:
        if r["ajpf"] == "F":
            r["ajpf"] = false_row
        elif r["ajpf"] == "T":
            r["ajpf"] = true_row
    obligations = AjpfBackend().export(workspace(tmp_path, NOTHING, mapping=rows))
    g1 = [o for o in obligations if o.guarantee == 1]
    assert len(g1) == 13
    for o in g1:
        assert o.data.get("coverage") == "partial", o.id
        assert any("the agent is not checked on it" in n for n in o.data["coverage_notes"])


def test_constant_value_is_decided_after_simplification() -> None:
    for text, value in (("~T", False), ("T & T", True), ("F || F", False), ("[] T", True),
                        ("B(a, x) || ~B(a, x)", True), ("<> B(a, x) & ~<> B(a, x)", False),
                        ("B(a, x)", None), ("B(a, x) || B(a, y)", None)):
        assert psl.constant_value(psl.parse(text)) is value, text


# -- identifiers a program remembers ----------------------------------------------------------

COUNTER = """GWENDOLEN
:name: jackal
:Initial Beliefs:
count(0)
:Initial Goals:
go [perform]
:Plans:
+!go [perform] <- move;
+movebase_result(Id, 3) : { ~B seen(Id), B count(0) } <- +seen(Id), -count(0), +count(1), move;
+movebase_result(Id, 3) : { ~B seen(Id), B count(1) } <- +seen(Id), -count(1), +count(2), move;
+movebase_result(Id, 3) : { ~B seen(Id), B count(2) } <- +seen(Id), -count(2), +count(3), move;
+movebase_result(Id, 3) : { B seen(Id) } <- move;
"""


@needs_spin
def test_a_program_counting_identifiers_reaches_three(tmp_path: Path) -> None:
    props = "never_third: [] ~B(jackal, count(3))\nnamed: <> P(movebase_result(1, 3))\n"
    evs = run(workspace(tmp_path, COUNTER, properties={"backends/ajpf/ids.psl": props},
                        environment={"percepts": ["movebase_result(_, 3)"], "after": ["move"], "at_least": 1}),
              extra)
    third = evs["Agent.g0.ajpf.ids_never_third"]
    assert third.status == "failed", third.explanation
    assert "fresh value per reaction" in third.details["identifiers"]
    assert "variable Id takes an identifier and is used again" in third.details["identifiers"]
    named = evs["Agent.g0.ajpf.ids_named"]
    assert named.status == "inconclusive" and "names an identifier value" in named.explanation


def test_identifier_oblivious_programs_keep_two_alternating_values() -> None:
    env = environment_from_plan({"percepts": ["movebase_result(_, 3)", "movebase_result(_, 2)", "danger_red",
                                              "danger_orange"], "after": ["move"]})
    graph = explore(REPO / "backends/ajpf/jackal.gwen", "backends/ajpf/jackal.gwen", env)
    assert "two alternating values" in graph.identifiers
    assert (len(graph.states), len(graph.transitions)) == (542, 601)


# -- an interrupted tool is not a result -------------------------------------------------------

def test_a_tool_stopped_from_outside_raises_instead_of_giving_a_result(tmp_path: Path) -> None:
    with pytest.raises(ToolInterrupted) as e:
        run_bounded(["sh", "-c", "kill -KILL $$"], tmp_path, 30)
    assert "stopped by SIGKILL from outside rclverify" in str(e.value) and isinstance(e.value, RclError)
    out, code, _ = run_bounded(["sh", "-c", "kill -SEGV $$"], tmp_path, 30)  # a crash is the tool's own
    assert code == -signal.SIGSEGV


@needs_proc
def test_the_time_limit_kills_the_whole_process_group(tmp_path: Path) -> None:
    pidfile = tmp_path / "child.pid"
    out, code, secs = run_bounded(["sh", "-c", f"sleep 60 & echo $! > {pidfile}; wait"], tmp_path, 0.5)
    assert code is None
    child = int(pidfile.read_text())
    for _ in range(100):
        if not _alive(child):
            break
        time.sleep(0.05)
    assert not _alive(child)


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _procs() -> list[tuple[int, str, int, int]]:
    """(pid, command name, parent pid, session id) of every process."""
    out = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                head, rest = (p / "stat").read_text().rsplit(")", 1)
            except OSError:
                continue
            fields = rest.split()
            if fields[0] != "Z":
                out.append((int(p.name), head.split("(", 1)[1], int(fields[1]), int(fields[3])))
    return out


RUN_ONE = """
import sys
from pathlib import Path
from rclverify.app import pipeline
from rclverify.lang.errors import RclError
ws = pipeline.Workspace(Path(sys.argv[1]))
try:
    ev = pipeline.stage_run(ws, "Agent", sys.argv[2])
except RclError as exc:
    print(exc)
    sys.exit(3)
print("recorded", ev.status)
"""


def _start_run(tmp_path: Path) -> tuple[subprocess.Popen[str], Path, Path, str]:
    """A process checking one case-study obligation with SPIN, in an empty verifier cache."""
    from rclverify.app import pipeline
    root = tmp_path / "ws"
    workspace(root)
    ws = pipeline.Workspace(root)
    oid = next(o.id for o in pipeline.stage_export(ws, "Agent") if o.guarantee == 2)
    cache = tmp_path / "cache"
    (tmp_path / "tmp").mkdir()  # the run's $TMPDIR: what a killed compiler would leave there
    env = {**os.environ, "XDG_CACHE_HOME": str(cache), "PYTHONPATH": str(REPO / "src"),
           "TMPDIR": str(tmp_path / "tmp")}
    proc = subprocess.Popen([sys.executable, "-c", RUN_ONE, str(root), oid], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    return proc, root, cache, oid


def _wait_for_compiler(proc: subprocess.Popen[str]) -> tuple[int, int]:
    """The pid and session of the compiler (``gcc ... pan.c``) ``proc`` started, once it runs
    (not ``gcc --version``, which finding the tools runs first)."""
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        for pid, name, ppid, sid in _procs():
            if ppid == proc.pid and name in ("gcc", "cc"):
                try:
                    if b"pan.c" in Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0"):
                        return pid, sid
                except OSError:
                    continue
        time.sleep(0.01)
    raise AssertionError(f"gcc never ran: {proc.communicate()[0] if proc.poll() is not None else 'still running'}")


@needs_spin
@needs_proc
def test_a_compiler_killed_from_outside_records_nothing(tmp_path: Path) -> None:
    proc, root, _, oid = _start_run(tmp_path)
    try:
        os.kill(_wait_for_compiler(proc)[0], signal.SIGKILL)
        out, _ = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 3, out
    assert "gcc was stopped by SIGKILL from outside rclverify" in out and "contracts/plan.yaml:" in out
    assert not (root / "artifacts/evidence" / f"{oid}.json").exists()  # the next run checks it again
    assert not list((tmp_path / "tmp").iterdir())  # the killed compiler's files went with its build


@needs_spin
@needs_proc
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL])
def test_no_tool_and_no_build_directory_outlive_rclverify(tmp_path: Path, signum: int) -> None:
    proc, root, cache, oid = _start_run(tmp_path)
    try:
        compiler, session = _wait_for_compiler(proc)
        # held where it is, so that rclverify is killed while gcc runs even when this test is
        # descheduled on a loaded machine (else the run could finish and record first)
        os.kill(compiler, signal.SIGSTOP)
        os.kill(proc.pid, signum)
        out, _ = proc.communicate(timeout=60)
        assert proc.returncode == (-signum if signum == signal.SIGKILL else 128 + signum), out
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and any(sid == session for _, _, _, sid in _procs()):
            time.sleep(0.05)
        assert not [(pid, name) for pid, name, _, sid in _procs() if sid == session]
        while time.monotonic() < deadline and list(cache.glob("rclverify/spin/.build-*")):
            time.sleep(0.05)
        assert not list(cache.glob("rclverify/spin/.build-*"))
        assert not list((tmp_path / "tmp").iterdir())  # nor gcc's intermediate files
        assert not (root / "artifacts/evidence" / f"{oid}.json").exists()
    finally:
        proc.kill()


SIGNAL_IN_FORK = """
import os, signal, sys, time
from pathlib import Path
from rclverify.backends.bounded import run_bounded
sent = []
def send():  # in os.fork's after_in_parent callbacks, where Python ignores what a handler raises
    if not sent:
        sent.append(1)
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(1000):  # give the handler a bytecode boundary inside this callback
            pass
os.register_at_fork(after_in_parent=send)
t0 = time.monotonic()
try:
    run_bounded(["sleep", "30"], Path(sys.argv[1]), 60)
except SystemExit as exc:
    print("exit", exc.code, round(time.monotonic() - t0, 1))
    raise
print("went on", round(time.monotonic() - t0, 1))
"""


@needs_proc
def test_a_sigterm_while_the_tool_starts_still_stops_rclverify(tmp_path: Path) -> None:
    """A SIGTERM that arrives while ``subprocess.Popen`` forks the tool runs its handler inside a
    fork callback, where Python ignores the ``SystemExit`` it raises (the whole suite once saw it:
    rclverify went on waiting for the tool).  The signal is kept and raised once the tool has started
    (backends/bounded.py): the run exits 143 at once, the tool (``sleep 30``) killed with its group."""
    r = subprocess.run([sys.executable, "-c", SIGNAL_IN_FORK, str(tmp_path)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 143, r.stdout + r.stderr
    word, code, seconds = r.stdout.split()
    assert (word, code) == ("exit", "143") and float(seconds) < 10, r.stdout
    assert "Exception ignored" in r.stderr  # the handler's own SystemExit was lost where Python ignores it


# -- bounds: deep terms, recursion, explosion, time ---------------------------------------------

ENV_X = {"percepts": ["x"]}


def test_deep_terms_in_a_program_are_a_located_error(tmp_path: Path) -> None:
    deep = "a"
    for _ in range(400):
        deep = f"f({deep})"
    (tmp_path / "a.gwen").write_text(f"GWENDOLEN\n:name: jackal\n:Initial Beliefs:\n{deep}\n")
    with pytest.raises(GwendolenError) as e:
        explore(tmp_path / "a.gwen", "a.gwen", environment_from_plan(ENV_X))
    assert str(e.value).startswith("a.gwen:4:") and "nested deeper than 64 levels" in str(e.value)


def test_deep_properties_are_a_located_error(tmp_path: Path) -> None:
    from rclverify.backends.model_checking.ltl import parse_psl_text
    for body in ("(" * 400 + "B(jackal, a)" + ")" * 400, "B(jackal, " + "f(" * 400 + "a" + ")" * 400 + ")",
                 " U ".join(["B(jackal, a)"] * 400)):
        with pytest.raises(PlanError) as e:
            parse_psl_text(f"deep: {body}\n", "p.psl")
        assert str(e.value).startswith("p.psl:1:") and "nested deeper than 64" in str(e.value)


GROWING = """GWENDOLEN
:name: jackal
:Initial Beliefs:
n(z)
:Initial Goals:
g [perform]
:Plans:
+!g [perform] : { B n(X) } <- -n(X), +n(s(X)), +!g [perform];
"""
EXPLODING = ("GWENDOLEN\n:name: jackal\n:Initial Beliefs:\n" + "".join(f"q({k})\n" for k in range(30))
             + ":Reasoning Rules:\np :- q(A), q(B), q(C), q(D), q(E), r;\n"
             ":Initial Goals:\ng [perform]\n:Plans:\n+!g [perform] : { B p } <- +done;\n")


@pytest.mark.parametrize("program, cut", [(GROWING, "term depth > 64"),
                                          (EXPLODING, "resolution steps > 200000 in one state")])
def test_programs_without_bound_are_cut_at_a_bound(tmp_path: Path, program: str, cut: str) -> None:
    (tmp_path / "a.gwen").write_text(program)
    graph = explore(tmp_path / "a.gwen", "a.gwen", environment_from_plan(ENV_X))
    assert not graph.complete and graph.cut == cut


def test_the_exploration_has_a_time_limit(tmp_path: Path) -> None:
    env = environment_from_plan({"percepts": ["movebase_result(_, 3)", "movebase_result(_, 2)", "danger_red",
                                              "danger_orange"], "after": ["move"]})
    graph = explore(REPO / "backends/ajpf/jackal.gwen", "j.gwen", env, time_limit_s=0.0)
    assert not graph.complete and graph.cut == "time > 0 s"


@needs_spin
def test_a_cut_graph_is_inconclusive_and_spin_does_not_run(tmp_path: Path) -> None:
    evs = run(workspace(tmp_path, GROWING, properties={"backends/ajpf/extra.psl": BAD},
                        environment=ENV_X), extra)
    [ev] = evs.values()
    assert ev.status == "inconclusive" and "cut (term depth > 64)" in ev.explanation
    assert ev.details["spin_verdict"] == "not run" and ev.details["bounded"] is True


@needs_spin
def test_a_build_past_its_time_limit_is_inconclusive_and_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                                                 ) -> None:
    from test_spin import RED, obligation, rover, target_at
    from rclverify.backends.model_checking.promela import Claim
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "empty-cache"))  # a build, not a cache hit
    tools, _ = spin.find_tools()
    assert tools is not None
    mc.clear_caches()
    ev = mc.check_graph(obligation("red", RED), target_at(tmp_path), rover(), [Claim("red", psl.parse(RED))], "red",
                        tools=tools, graph_key="time-limit", bounds=(100, 100), timeout_s=0.05)
    assert ev.status == "inconclusive", ev.explanation
    assert "did not finish within the time limit of 0.05 s" in ev.explanation and ev.details["timeout_s"] == 0.05


def test_every_tool_runs_with_a_time_limit_of_minutes() -> None:
    assert spin.DEFAULT_TIMEOUT_S <= 600 and AJPF_TIMEOUT_S <= 600
    assert spin_config.spin_timeout({}) == spin.DEFAULT_TIMEOUT_S and spin_config.spin_timeout({"timeout_s": 20}) == 20


# -- the plan -----------------------------------------------------------------------------------

def test_two_ajpf_entries_on_one_node_are_refused_by_check(tmp_path: Path) -> None:
    with pytest.raises(PlanError) as e:  # the workspace's target loads and checks the plan
        workspace(tmp_path, NOTHING, entries=2)
    text = str(e.value)
    assert text.startswith("contracts/plan.yaml:") and "node Agent has a second ajpf entry" in text


def test_build_products_are_never_bundled(tmp_path: Path) -> None:
    from rclverify.report.bundle.manifest import build_product
    (tmp_path / "artifacts/ajpf/Agent/spin/build/ab").mkdir(parents=True)
    (tmp_path / "artifacts/ajpf/Agent/spin/build/ab/model.pml").write_text("x")
    (tmp_path / "artifacts/ajpf/Agent/spin/model.pml").write_text("x")
    (tmp_path / "artifacts/ajpf/Agent/elf").write_bytes(b"\x7fELF\x02\x01")
    assert build_product(tmp_path, "artifacts/ajpf/Agent/spin/build/ab/model.pml")
    assert build_product(tmp_path, "artifacts/ajpf/Agent/elf")
    assert not build_product(tmp_path, "artifacts/ajpf/Agent/spin/model.pml")
