"""Incremental equals clean: a workspace, the edits a user makes to it, and
the comparison of an incremental ``doit verify`` with a from-scratch one.

Used by ``tests/app/test_incremental_equivalence.py`` (a few sequences, driven by
Hypothesis) and by ``bench/incremental_equivalence.py`` (hundreds).  The
workspace is the case study cut down to what runs in a few seconds: the
four-node rover contracts, its requirements and environment facts, and one
entry of each cheap backend (review, experiment, Hoare, property tests,
monitors).  Each edit is a change a user makes between two runs: a
requirement's text or tracing, the plan's name, a fact, a connection, a
contract's formula or comment, a backend input, a recorded run (also one
rewritten in place with its size and modification time kept), a file
deleted or added, every edit so far undone.

After every edit ``doit verify`` runs in the workspace (incrementally, as a
user's second run would), and a copy of its inputs alone is verified from
scratch; every report file of the two must be equal once evidence times and
durations are masked (:func:`normalise`), and both runs must end the same
way.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Callable

REPO = Path(__file__).resolve().parents[1]

#: The case study's files the cut-down workspace copies (workspace-relative).
FILES = (
    "dodo.py",
    "contracts/remote_inspection.rcl",
    "backends/hoare/radiation_sensor.imp",
    "backends/review/localisation.yaml",
    "backends/experiment/navigation.yaml",
    "backends/monitors/mapping.yaml",
    "backends/monitors/msg/gazebo_radiation_plugin/msg/Snapshot.msg",
    "backends/monitors/traces/nominal.jsonl",
    "backends/monitors/traces/env_fault.jsonl",
    "backends/property_tests/radiation_sensor.py",
)

PLAN = """\
name: rover, cut down
contracts:
  - contracts/remote_inspection.rcl
requirements:
  - id: REQ1
    text: The robot should inspect each waypoint unless the radiation there is red.
    supported_by:
      - {node: Agent, guarantees: [1, 2]}
      - {node: RadiationSensor, guarantees: [1]}
  - id: REQ2
    text: Each waypoint only needs to be inspected at least once.
    supported_by:
      - {node: Agent, guarantees: [2]}
  - id: REQ3
    text: The position is known.
    supported_by:
      - {node: Localisation, guarantees: [1]}
connections: []
environment:
  Agent:
    facts:
      - "forall(x, y in REAL | in.wayP(x, y) <= 12)"
nodes:
  Localisation:
    evidence:
      - backend: review
        record: backends/review/localisation.yaml
  Navigation:
    evidence:
      - backend: experiment
        guarantee: 1
        summary: backends/experiment/navigation.yaml
        constants: {tolerance: 25 cm}
        criterion: "worst <= tolerance"
  RadiationSensor:
    evidence:
      - backend: hoare
        program: backends/hoare/radiation_sensor.imp
        binding:
          in.r: radiation_at(i)
          out.radiationStatus: output
      - backend: property_tests
        implementation: backends/property_tests/radiation_sensor.py:radiation_sensor
        max_examples: 5
      - backend: monitors
        mapping: backends/monitors/mapping.yaml
        horizon: 2.0
        traces:
          - backends/monitors/traces/nominal.jsonl
"""


def make_workspace(dest: Path) -> Path:
    """Write the cut-down workspace at ``dest`` (created) and return it."""
    for rel in FILES:
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(REPO / rel, dest / rel)
    (dest / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    return dest


#: What a clean copy leaves out: everything a run writes.
GENERATED = ("artifacts", "reports", ".doit.sqlite", ".doit.db")


def clean_copy(src: Path, dest: Path) -> Path:
    """Copy the inputs of the workspace ``src`` (not what a run wrote) to ``dest``."""
    def ignore(d: str, names: list[str]) -> set[str]:
        return {n for n in names if Path(d) == src and (n in GENERATED or n.startswith(".doit"))}
    shutil.copytree(src, dest, ignore=ignore)
    return dest


def verify(root: Path, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """``doit verify`` in ``root``, as a user runs it (a process of its own)."""
    env = {**os.environ, "PYTHONHASHSEED": "0"}
    env.pop("RCLVERIFY_CLUSTER", None)
    return subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=root, capture_output=True, text=True,
                          timeout=timeout, env=env)


_MASKS = (
    # JSON: evidence and side-condition timing fields
    (re.compile(r'"started": "[^"]*"'), '"started": "T"'),
    (re.compile(r'"duration_s": [0-9.e+-]+'), '"duration_s": 0'),
    # JUnit: test case and suite times
    (re.compile(r'\btime="[0-9.]+"'), 'time="0"'),
    # HTML and Markdown: an evidence record's start and duration, a side condition's solver time
    (re.compile(r"(Started</th><td>|- Started: )[0-9T:+.-]+"), r"\1T"),
    (re.compile(r"(Duration</th><td>|- Duration: )[0-9.]+ s"), r"\1D s"),
    (re.compile(r"(\.smt2</a><br>|\.smt2\) \()[0-9.]+ s"), r"\1D s"),
)


def normalise(text: str) -> str:
    """``text`` with evidence start times and durations masked: the only
    parts of a report that may differ between two runs of the same inputs."""
    for pattern, repl in _MASKS:
        text = pattern.sub(repl, text)
    return text


def report_files(root: Path) -> dict[str, str]:
    """Every file under ``root/reports`` (relative name -> normalised text;
    binary files by their bytes' repr)."""
    out = {}
    base = root / "reports"
    for p in sorted(base.rglob("*")) if base.is_dir() else ():
        if p.is_file():
            try:
                out[str(p.relative_to(base))] = normalise(p.read_text(encoding="utf-8"))
            except UnicodeDecodeError:
                out[str(p.relative_to(base))] = repr(p.read_bytes())
    return out


def _outcome(proc: subprocess.CompletedProcess[str]) -> str:
    """How a run ended, without what depends on the run's history: its exit
    code and, for a failed run, its error lines."""
    if proc.returncode == 0:
        return "rc 0"
    lines = [l for l in (proc.stdout + proc.stderr).splitlines() if ": error: " in l]
    return f"rc {proc.returncode}: " + " | ".join(sorted(set(lines)))


def compare(inc: Path, scratch: Path) -> list[str]:
    """Run a from-scratch ``doit verify`` on a clean copy of ``inc`` in
    ``scratch`` (its name must equal ``inc``'s: the report names the
    workspace), and an incremental one in ``inc``; return the differences
    (empty when the two agree)."""
    a = verify(inc)
    shutil.rmtree(scratch, ignore_errors=True)
    b = verify(clean_copy(inc, scratch))
    out = []
    if _outcome(a) != _outcome(b):
        out.append(f"outcome: incremental {_outcome(a)!r} vs clean {_outcome(b)!r}\n{a.stdout[-2000:]}{a.stderr[-2000:]}")
        return out
    if a.returncode != 0:
        return out
    ra, rb = report_files(inc), report_files(scratch)
    for name in sorted(set(ra) | set(rb)):
        if ra.get(name) != rb.get(name):
            out.append(f"reports/{name} differs" + _first_difference(ra.get(name, ""), rb.get(name, "")))
    return out


def _first_difference(a: str, b: str) -> str:
    la, lb = a.splitlines(), b.splitlines()
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            return f" at line {i + 1}:\n  incremental: {x[:300]}\n  clean:       {y[:300]}"
    return f": {len(la)} vs {len(lb)} lines"


# -- the edits -------------------------------------------------------------------------------------

Edit = Callable[[Path, int], str]


def _sub(path: Path, old: str, new: str) -> bool:
    text = path.read_text(encoding="utf-8")
    if old not in text:
        return False
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return True


def _plan(root: Path) -> Path:
    return root / "contracts/plan.yaml"


def edit_requirement_text(root: Path, k: int) -> str:
    text = _plan(root).read_text(encoding="utf-8")
    new = re.sub(r"(- id: REQ2\n    text: ).*", lambda m: m.group(1) + f"Each waypoint is inspected (wording {k}).", text)
    _plan(root).write_text(new, encoding="utf-8")
    return f"REQ2's text, wording {k}"


_SUPPORTS = ("{node: Agent, guarantees: [2]}", "{node: Agent, guarantees: [1, 3]}",
             "{node: Localisation, guarantees: [1]}", "{node: RadiationSensor, guarantees: [1]}",
             "{node: Navigation, guarantees: [1]}")


def edit_requirement_tracing(root: Path, k: int) -> str:
    text = _plan(root).read_text(encoding="utf-8")
    new = re.sub(r"(- id: REQ2\n    text: .*\n    supported_by:\n      - ).*", lambda m: m.group(1) + _SUPPORTS[k % 5],
                 text)
    _plan(root).write_text(new, encoding="utf-8")
    return f"REQ2 traced to {_SUPPORTS[k % 5]}"


def edit_plan_name(root: Path, k: int) -> str:
    text = _plan(root).read_text(encoding="utf-8")
    _plan(root).write_text(re.sub(r"^name: .*", f"name: rover {k}", text, count=1, flags=re.M), encoding="utf-8")
    return f"plan name 'rover {k}'"


def edit_fact(root: Path, k: int) -> str:
    text = _plan(root).read_text(encoding="utf-8")
    bound = (12, 11, 20)[k % 3]
    _plan(root).write_text(re.sub(r"in\.wayP\(x, y\) <= \d+", f"in.wayP(x, y) <= {bound}", text), encoding="utf-8")
    return f"Agent's fact: waypoints <= {bound}"


def edit_connection(root: Path, k: int) -> str:
    text = _plan(root).read_text(encoding="utf-8")
    if k % 2:
        new = text.replace("connections: []",
                           "connections:\n  - {from: RadiationSensor.radiationStatus, to: Agent.radiationStatus}")
        what = "explicit connection RadiationSensor.radiationStatus -> Agent.radiationStatus"
    else:
        new = re.sub(r"connections:\n(  - .*\n)+", "connections: []\n", text)
        what = "no explicit connection"
    _plan(root).write_text(new, encoding="utf-8")
    return what


def edit_contract_formula(root: Path, k: int) -> str:
    rcl = root / "contracts/remote_inspection.rcl"
    text = rcl.read_text(encoding="utf-8")
    level = (250, 240, 300)[k % 3]
    rcl.write_text(re.sub(r"\(\d+ <= in\.r -> out\.radiationStatus == red\)",
                          f"({level} <= in.r -> out.radiationStatus == red)", text), encoding="utf-8")
    return f"RadiationSensor's red threshold {level}"


def edit_contract_comment(root: Path, k: int) -> str:
    rcl = root / "contracts/remote_inspection.rcl"
    lines = rcl.read_text(encoding="utf-8").splitlines(keepends=True)
    at = k % (len(lines) + 1)
    lines.insert(at, f"// a comment ({k})\n")
    rcl.write_text("".join(lines), encoding="utf-8")
    return f"a comment line at line {at + 1} of the contracts"


def edit_hoare_program(root: Path, k: int) -> str:
    prog = root / "backends/hoare/radiation_sensor.imp"
    text = prog.read_text(encoding="utf-8")
    level = (120, 110, 130)[k % 3]
    prog.write_text(re.sub(r"IF \(input < \d+\) THEN\n   output := green", f"IF (input < {level}) THEN\n   output := green",
                           text), encoding="utf-8")
    return f"Hoare program's green threshold {level}"


def edit_experiment_data(root: Path, k: int) -> str:
    data = root / "backends/experiment/navigation.yaml"
    text = data.read_text(encoding="utf-8")
    worst = (43, 24, 30)[k % 3]
    data.write_text(re.sub(r"^worst: .*", f"worst: {worst} cm", text, flags=re.M), encoding="utf-8")
    return f"experiment's worst run {worst} cm"


def edit_review_record(root: Path, k: int) -> str:
    rec = root / "backends/review/localisation.yaml"
    text = rec.read_text(encoding="utf-8")
    verdict = ("pass", "fail")[k % 2]
    rec.write_text(re.sub(r"^verdict: .*", f"verdict: {verdict}", text, flags=re.M), encoding="utf-8")
    return f"review verdict {verdict}"


def edit_trace(root: Path, k: int) -> str:
    trace = root / "backends/monitors/traces/nominal.jsonl"
    lines = trace.read_text(encoding="utf-8").splitlines(keepends=True)
    if len(lines) > 2:
        del lines[k % len(lines)]
    trace.write_text("".join(lines), encoding="utf-8")
    return f"line {k % max(len(lines), 1) + 1} of the nominal run dropped"


#: Readings of the nominal run, each as wide as the others: one rewritten as another keeps the file's size.
_IN_PLACE = (b'"value": 245.0', b'"value": 265.0', b'"value": 255.0')


def edit_trace_in_place(root: Path, k: int) -> str:
    """Rewrite one reading of the nominal run in place, the file's size and
    modification time kept (``os.utime``: an editor or a copy tool that
    keeps times; issue 107): only its content says that it changed."""
    trace = root / "backends/monitors/traces/nominal.jsonl"
    st = trace.stat()
    data = trace.read_bytes()
    now = next((v for v in _IN_PLACE if v in data), None)
    if now is not None:
        old, new = now, _IN_PLACE[(_IN_PLACE.index(now) + 1 + k % 2) % len(_IN_PLACE)]
    else:  # that reading's line was dropped (edit_trace): the first time stamp's first digit instead
        m = re.search(rb'"time": (\d)', data)
        assert m is not None, "the nominal run has no time stamp left to rewrite"
        old, new = m.group(0), m.group(0)[:-1] + str((int(m.group(1)) + 1) % 10).encode()
    with trace.open("r+b") as fh:  # the same file, rewritten where it is
        fh.write(data.replace(old, new, 1))
    os.utime(trace, ns=(st.st_atime_ns, st.st_mtime_ns))
    return f"the nominal run's {old.decode()} rewritten in place as {new.decode()}, its size and mtime kept"


def edit_trace_file(root: Path, k: int) -> str:
    """Add a second recorded run to the monitors entry, or take it away and delete its file."""
    extra = root / "backends/monitors/traces/env_fault.jsonl"
    listed = "          - backends/monitors/traces/env_fault.jsonl\n"
    text = _plan(root).read_text(encoding="utf-8")
    if k % 2 and extra.exists() and listed not in text:
        _plan(root).write_text(text.replace("          - backends/monitors/traces/nominal.jsonl\n",
                                            "          - backends/monitors/traces/nominal.jsonl\n" + listed),
                               encoding="utf-8")
        return "env_fault.jsonl added to the monitors entry"
    if listed in text:
        _plan(root).write_text(text.replace(listed, ""), encoding="utf-8")
    if extra.exists():
        extra.unlink()
        return "env_fault.jsonl taken out of the plan and deleted"
    shutil.copyfile(REPO / "backends/monitors/traces/env_fault.jsonl", extra)
    return "env_fault.jsonl restored (not in the plan)"


def edit_contract_file(root: Path, k: int) -> str:
    """Add a second contract file with a node of its own to the plan, or remove it."""
    extra = root / "contracts/logger.rcl"
    text = _plan(root).read_text(encoding="utf-8")
    if extra.exists():
        extra.unlink()
        _plan(root).write_text(text.replace("  - contracts/logger.rcl\n", ""), encoding="utf-8")
        return "contracts/logger.rcl removed"
    extra.write_text("node Logger {\n  inputs( radiationStatus : RadStat )\n  outputs( logged : BOOL )\n"
                     "  topics( std_msgs/String radiationStatus matches(in.radiationStatus),\n"
                     "          std_msgs/Bool logged matches(out.logged) )\n"
                     f"  guarantee( out.logged == TRUE or {k} < 0 )\n}}\n", encoding="utf-8")
    _plan(root).write_text(text.replace("  - contracts/remote_inspection.rcl\n",
                                        "  - contracts/remote_inspection.rcl\n  - contracts/logger.rcl\n"),
                           encoding="utf-8")
    return "contracts/logger.rcl added"


def edit_revert(root: Path, k: int) -> str:
    """Undo every edit so far (a user's ``git checkout .``): the inputs as
    :func:`make_workspace` wrote them, files added since deleted; what the
    runs wrote is kept.  The one edit that may change nothing (on a
    workspace not edited yet): then the run after it is a no-op run."""
    for rel in FILES:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        if not (root / rel).exists() or (root / rel).read_bytes() != (REPO / rel).read_bytes():
            shutil.copyfile(REPO / rel, root / rel)
    if _plan(root).read_text(encoding="utf-8") != PLAN:
        _plan(root).write_text(PLAN, encoding="utf-8")
    (root / "contracts/logger.rcl").unlink(missing_ok=True)
    return f"every edit undone ({k})"


EDITS: tuple[Edit, ...] = (
    edit_requirement_text, edit_requirement_tracing, edit_plan_name, edit_fact, edit_connection,
    edit_contract_formula, edit_contract_comment, edit_hoare_program, edit_experiment_data, edit_review_record,
    edit_trace, edit_trace_in_place, edit_trace_file, edit_contract_file, edit_revert,
)
