"""The runner of bench/robot_generator.py: one generated robot run live and judged three ways.

For one seed: the workspace is written, ``rclverify monitor --live --ros2 --source dds`` (or
``--source rclpy --ros2-python`` the robot's Python) starts with ``--log``, ``--record`` (a ROS 2
bag, MCAP) and ``--verdicts``, then the robot (one process of rclpy nodes, ROS 2's
Python); after its sensing it says ``done`` and both are stopped.  The log and the bag are then
checked offline (``rclverify monitor --json --verdicts``), and the three paths' verdicts are compared
verdict by verdict (bench/_robot_verdicts.py): each message's final verdict live against its verdict
offline on the log and on the bag, identified by node, item (guarantee, call, deadline), topic and
header stamp (else source time); a verdict that differs, or that one path gave and another did not,
is a disagreement, named with both sides' verdicts and reasons (a live verdict still provisional
apart).  On a correct robot any final ``violated`` answer or ``false`` deadline, on any path, is
false (the node is correct by construction); on a robot with one seeded defect the defect's node
must be red live and every other node not.  Per node the live final verdicts are counted:

* ``satisfied`` / ``violated`` / ``undecided`` (inconclusive, incomplete input, open) answers of the
  topic guarantees and of the calls, and ``true`` / ``false`` deadlines; an endpoint the run could
  not judge (the rclpy source without introspection) is ``undecided`` and ``unjudged``;
* ``declaration <verdict>``: the node's declarations (``initially``, ``progress``, ``periodic``;
  bench/_robot_declarations.py), one row each, from the live record (``--evidence``); the log's and the
  bag's rows (``rclverify monitor --json``) are compared with them declaration by declaration, and a
  ``false`` declaration of a correct node on any path is false, as a violated answer is.  A server's
  declarations (its steps are calls) are ``pending`` on the bag, whose reader gives calls to the call
  checks only: counted apart (``bag_pending_calls``), never as a disagreement; any other difference at a
  server is one.

Everything on loopback (Cyclone's loopback configuration for the monitor,
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` for the nodes), a random ``ROS_DOMAIN_ID``, every
process in a session of its own and stopped at the end.
"""
from __future__ import annotations

import functools
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from _live import stop, wait_text  # noqa: E402
from monitor_live_dds import CONFIG  # noqa: E402
from robot_generator import SENSORS, generate, horizon_of, write_workspace  # noqa: E402
from _robot_verdicts import (UNDECIDED, compare_declarations, declaration_verdicts, false_verdicts,  # noqa: E402
                             read_records, tally, tally_declarations, three_way)

SOURCES = ("dds", "rclpy")


@functools.lru_cache(maxsize=None)
def ros2_python() -> tuple[Path | None, str]:
    """The ROS 2 Python (``RCLVERIFY_ROS2_PYTHON`` or ``.venv-ros2``) and ``""``, or None and why not
    (probed once per process: a probe imports rclpy, a second or more on a loaded machine)."""
    named = os.environ.get("RCLVERIFY_ROS2_PYTHON")
    exe = Path(named) if named else ROOT / ".venv-ros2" / "bin" / "python"
    if not exe.exists():
        return None, f"no ROS 2 Python at {exe.name} (scripts/setup.sh --tests installs ROS 2's wheels)"
    probe = subprocess.run([str(exe), "-c", "import rclpy, rmw_fastrtps_cpp, numpy"], capture_output=True,
                           text=True, timeout=60)
    if probe.returncode != 0:
        return None, f"the ROS 2 Python cannot import rclpy: {(probe.stderr.strip().splitlines() or [''])[-1]}"
    return exe, ""


def unjudged(log: Path, links: dict[str, str]) -> Counter[str]:
    """Per node (``links``: each service's and action's RCL name -> its node), the endpoints the live
    run said it could not judge: its log's ``rclverify/call`` lines of part ``unjudged`` (the rclpy
    source without introspection; docs/ros2.md)."""
    out = Counter[str]()
    for line in log.read_text(errors="replace").splitlines():
        if '"unjudged"' not in line:
            continue
        try:
            rec = json.loads(line)
        except ValueError:
            continue
        if rec.get("topic") == "rclverify/call" and rec.get("part") == "unjudged" and str(rec.get("link")) in links:
            out[links[str(rec["link"])]] += 1
    return out


def offline_counts(rows: list[dict[str, Any]]) -> dict[str, Counter[str]]:
    """Per node, what ``rclverify monitor --json`` says that no verdict line carries: the deadlines given
    no verdict, with why (``deadline undecided``: an answer within the transport skew before its trigger,
    a call's deadline not yet due), and each declaration's and period's row by its status
    (``declarations <status>``)."""
    out: dict[str, Counter[str]] = {}
    for r in rows:
        c = out.setdefault(str(r["node"]), Counter())
        for key in ("deadlines", "call_deadlines"):
            if key in r:
                c["deadline undecided"] += (r[key].get("unaccepted") or {}).get("undecided", 0)
                first = r[key].get("first_unaccepted") or {}
                if first.get("why") == "undecided":
                    c["deadline undecided why: " + str(first.get("reason"))] += 0
        if "declarations" in r or "periods" in r:
            c[f"declarations {r['status']}"] += 1
    return out


def _offline(ws: Path, traces: dict[str, str], env: dict[str, str],
             horizon: float = 1.0) -> dict[str, tuple[list[dict[str, Any]], str]]:
    """``rclverify monitor --json --verdicts runs/NAME.verdicts.jsonl TRACE`` on each trace of ``traces``
    (name -> path), the checks run side by side with ``horizon`` (s): per name the rows and ``""``, or
    what went wrong."""
    procs = {name: subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(ws),
                                     "--mapping", "mapping.yaml", "--horizon", f"{horizon:g}", "--json", "--verdicts",
                                     f"runs/{name}.verdicts.jsonl", t], cwd=ws, env=env,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for name, t in traces.items()}
    out: dict[str, tuple[list[dict[str, Any]], str]] = {}
    for name, p in procs.items():
        stdout, stderr = p.communicate(timeout=300)
        try:
            rows = json.loads(stdout)
        except ValueError:
            out[name] = ([], f"exit {p.returncode}: {(stdout + stderr)[-1500:]}")
            continue
        out[name] = (rows, f"exit {p.returncode}: {stderr[-1500:]}" if p.returncode not in (0, 1) else "")
    return out


def sent_topics(robot_out: Path, spec: dict[str, Any]) -> dict[str, int]:
    """The messages the robot had published on each of its topics when it said ``done`` (its ``done
    {...}`` line; a server's calls left out: the monitor logs those as call lines), by topic without
    its leading ``/``."""
    topics = {n["topic"] for n in spec["nodes"] if "topic" in n}
    for line in robot_out.read_text(errors="replace").splitlines():
        if line.startswith("done "):
            sent = json.loads(line[5:])
            return {t.lstrip("/"): int(k) for t, k in sent.items() if t in topics}
    return {}


def heard_all(log: Path, sent: dict[str, int], least: float, most: float) -> float:
    """Wait until the live log ``log`` holds at least ``sent[topic]`` lines of each topic (the monitor
    heard, released and judged what the robot had published when it said ``done``), ``least`` s at
    least and ``most`` s at most (a message lost on the way is the comparison's to find, not this
    wait's); returns the seconds waited.  A fixed wait would stop a monitor lagging behind a loaded
    machine before it judged the run's last answers."""
    t0 = time.monotonic()
    while True:
        waited = time.monotonic() - t0
        if waited >= most:
            return waited
        if waited >= least and sent:
            counts = Counter[str]()
            for line in log.read_text(errors="replace").splitlines() if log.exists() else ():
                try:
                    topic = json.loads(line).get("topic")
                except ValueError:
                    continue
                if isinstance(topic, str):
                    counts[topic.lstrip("/")] += 1
            if all(counts[t] >= k for t, k in sent.items()):
                return waited
        time.sleep(0.1)


class RobotFailed(Exception):
    """The generated robot's process exited or hung before it said ``done`` (a fault of the generator)."""


class MonitorFailed(Exception):
    """The monitor did not say ``monitoring`` within 60 s (its output's end says why)."""


def _source_args(source: str, ros2: Path) -> list[str]:
    """The monitor's ``--source`` arguments: the rclpy source runs in the robot's ROS 2 Python."""
    return ["--source", "dds"] if source == "dds" else ["--source", "rclpy", "--ros2-python", str(ros2)]


def _domain() -> tuple[int, int]:
    """A ``ROS_DOMAIN_ID`` (1..230) no other process of this machine holds, by the test suite's lock files
    (tests/dds_ros2.py): the domain and the open lock file, which the caller closes when its run is over."""
    import fcntl
    for d in random.SystemRandom().sample(range(1, 231), 230):
        fd = os.open(os.path.join(tempfile.gettempdir(), f"rclverify-test-dds-domain-{d}.lock"), os.O_CREAT | os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        return d, fd
    raise SystemExit("no free DDS domain: all 230 are held")


def run_one(seed: int, nodes: int, seconds: float, defect: bool, tmp: Path, ros2: Path,
            kinds: tuple[str, ...] = tuple(SENSORS), src: Path = ROOT / "src", source: str = "dds",
            sim_clock: bool = False, actions: bool = False, driver_offset_s: float = 0.0,
            clock_change: bool = False, undeclared_sim_time: bool = False) -> dict[str, Any]:
    """Run generated robot ``seed`` live and offline under ``tmp`` with rclverify's sources ``src``,
    the monitor hearing the robot through ``source`` (:data:`SOURCES`), the robot on a ``/clock`` of its
    own with ``sim_clock`` (its factor changing mid-run with ``clock_change``; the mapping declaring
    ``use_sim_time`` unless ``undeclared_sim_time``), with Fibonacci action servers with ``actions``;
    returns the counts and findings (``other_clocks``: the live record's writers placed at their source
    times; ``figures``: :func:`figures`)."""
    spec = generate(seed, nodes, defect, kinds, sim_clock, actions, driver_offset_s, clock_change,
                    undeclared_sim_time)
    ws = write_workspace(spec, tmp / "ws")
    (ws / "runs").mkdir(exist_ok=True)
    (tmp / "cyclonedds.xml").write_text(CONFIG)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    domain, lock = _domain()
    env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
               ROS_LOG_DIR=str(tmp / "ros_log"), PYTHONUNBUFFERED="1")
    menv = {**env, "PYTHONPATH": str(src)}
    procs: list[subprocess.Popen[bytes]] = []
    try:
        mon = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "monitor", "--live", "--ros2",
                                "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", f"{horizon_of(spec):g}", "--status", "0",
                                "--silence", "0", *_source_args(source, ros2), "--interfaces", "interfaces", "--log", "runs/live.jsonl",
                                "--evidence", str(tmp / "evidence.json"), "--record", "runs/bag", "--record-storage", "mcap",
                                "--verdicts", "runs/live.verdicts.jsonl"],
                               cwd=ws, env=menv, stdout=(tmp / "monitor.out").open("wb"), stderr=subprocess.STDOUT,
                               start_new_session=True)
        procs.append(mon)
        try:
            wait_text(tmp / "monitor.out", "monitoring", 60)
        except SystemExit:
            raise MonitorFailed(f"seed {seed}: the monitor did not start within 60 s (exit {mon.poll()}): "
                                + (tmp / "monitor.out").read_text(errors="replace")[-1500:]) from None
        robot = subprocess.Popen([str(ros2), str(ws / "robot.py"), str(seconds)], cwd=ws, env=env,
                                 stdout=(tmp / "robot.out").open("wb"), stderr=subprocess.STDOUT,
                                 start_new_session=True)
        procs.append(robot)
        until = time.monotonic() + seconds + 120
        while "done" not in (tmp / "robot.out").read_text(errors="replace"):
            if robot.poll() is not None or time.monotonic() > until:
                raise RobotFailed(f"seed {seed}: the robot {'exited' if robot.poll() is not None else 'hung'}:\n"
                                  + (tmp / "robot.out").read_text(errors="replace")[-2000:])
            time.sleep(0.1)
        heard_all(ws / "runs" / "live.jsonl", sent_topics(tmp / "robot.out", spec), 0.2, 5.0)
        stop(mon, signal.SIGINT)
        stop(robot)
    finally:
        for p in procs:
            stop(p)
        os.close(lock)
    res: dict[str, Any] = {"seed": seed, "nodes": nodes, "defect": defect, "spec": spec, "errors": [],
                           "source": source, "clock": spec.get("clock")}
    try:
        evidence = json.loads((tmp / "evidence.json").read_text())
    except (OSError, ValueError):
        evidence = {}
        res["errors"].append("live: the monitor wrote no --evidence record")
    res["other_clocks"] = evidence.get("other_clocks", [])
    decl = {"live": declaration_verdicts(evidence.get("declarations", []))}
    runs = ws / "runs"
    links = {n["rcl_topic"]: n["name"] for n in spec["nodes"] if n["kind"] in ("service", "action")}
    paths = {"live": read_records(runs / "live.verdicts.jsonl")}
    if not (runs / "live.verdicts.jsonl").exists():
        res["errors"].append("live: the monitor wrote no --verdicts file")
    for name, (rows, err) in _offline(ws, {"log": "runs/live.jsonl", "bag": "runs/bag"}, menv,
                                      horizon_of(spec)).items():
        if err:
            res["errors"].append(f"offline {name}: {err}")
        res[name] = offline_counts(rows)
        paths[name] = read_records(runs / f"{name}.verdicts.jsonl")
        decl[name] = declaration_verdicts(rows)
    res["finals"], lines = three_way(paths)
    res["declarations"] = decl
    res["disagreements"] = [x for x in lines if not x.startswith(("provisional: ", "placed apart: "))]
    servers = [n["name"] for n in spec["nodes"] if n["kind"] in ("service", "action")]
    differ, res["bag_pending_calls"] = compare_declarations(decl, servers)
    res["disagreements"] += differ
    res["provisional"] = [x for x in lines if x.startswith("provisional: ")]
    res["placed_apart"] = [x for x in lines if x.startswith("placed apart: ")]
    res["live"] = tally(res["finals"]["live"])
    for node, c in tally_declarations(decl["live"]).items():
        res["live"].setdefault(node, Counter()).update(c)
    for node, n in unjudged(runs / "live.jsonl", links).items():
        res["live"].setdefault(node, Counter()).update({"undecided": n, "unjudged": n})
    res["undecided_why"] = {}
    for (node, _, _, _), rs in res["finals"]["live"].items():
        for r in rs:
            if r["verdict"] in UNDECIDED:
                res["undecided_why"].setdefault(node, set()).add(f"{r['verdict']}: {r['reason'] or '(no reason given)'}")
    res["undecided_why"] = {k: sorted(v) for k, v in res["undecided_why"].items()}
    res["findings"] = findings(res)
    res["figures"] = figures(res)
    res["explained"] = explain(ws, res)
    return res


def figures(res: dict[str, Any]) -> dict[str, Any]:
    """One run's figures: ``violated_correct``, ``false_deadlines_correct`` and ``false_declarations_correct``
    (final verdicts of correct nodes on any path, each path counted), ``deadlines`` and ``undecided`` (the
    live final deadline verdicts, and those ``undecided``), ``agree`` (live = log = bag: no disagreement, no
    error), and for a seeded robot ``victim``, ``kind`` and ``red`` (its live red verdicts: violated,
    false deadlines and declarations)."""
    victim = _victim(res)
    names = {n["name"] for n in res["spec"]["nodes"]}
    correct = names - {victim} if victim else names
    out: dict[str, Any] = {"violated_correct": 0, "false_deadlines_correct": 0, "false_declarations_correct": 0}
    for f in res["finals"].values():
        for r in false_verdicts(f, correct):
            out["false_deadlines_correct" if r["item"] == "deadline" else "violated_correct"] += 1
    for d in res.get("declarations", {}).values():
        out["false_declarations_correct"] += sum(1 for (node, _, _), row in d.items()
                                                 if node in correct and row["verdict"] == "false")
    tot = Counter[str]()
    for c in res["live"].values():
        tot.update(c)
    out["deadlines"] = sum(v for k, v in tot.items() if k.startswith("deadline "))
    out["undecided"] = sum(tot[f"deadline {v}"] for v in ("undecided",) + UNDECIDED)
    out["agree"] = not res["disagreements"] and not res["errors"]
    out["subset_answers"], out["subset_undecided"], out["subset_open"], out["subset_unjudged"] = _subset(res, correct)
    if victim is not None:
        live = res["live"].get(victim, Counter())
        kind = next(n.get("defect_kind") for n in res["spec"]["nodes"] if n["name"] == victim)
        out.update(victim=victim, kind=kind, red=live.get("violated", 0) + live.get("deadline false", 0)
                   + live.get("declaration false", 0), red_deadlines=live.get("deadline false", 0))
    return out


def in_subset(node: dict[str, Any], nodes: dict[str, dict[str, Any]]) -> bool:
    """Whether generated node ``node`` (its spec; ``nodes`` every node's by name) answers within its input's
    period and copies its stamp or answers one input: an alarm, a relay (a copying one whose delay is at
    most its reading's period) or a server; a fuse reads two inputs."""
    if node.get("kind") == "relay" and node.get("copy"):
        return int(node["delay_ms"]) <= int(nodes[node["source"]]["period_ms"])
    return node.get("kind") in ("alarm", "relay", "service")


def _subset(res: dict[str, Any], correct: set[str]) -> tuple[int, int, int, int]:
    """``(answers, undecided, open, unjudged)`` of the run's correct nodes :func:`in_subset`: their live final
    verdicts on answers and deadlines, those undecided, and of those the answers ``open`` (their question
    raised less than the horizon before the monitor stopped, unanswered: the trace ended before the answer
    was owed) and the endpoints the source could not hear (``unjudged``: a server without introspection
    heard through the rclpy source, one per endpoint, its calls never counted as answers)."""
    nodes = {n["name"]: n for n in res["spec"]["nodes"]}
    answers = undecided = still_open = unjudged_ends = 0
    for name, c in res["live"].items():
        if name not in correct or name not in nodes or not in_subset(nodes[name], nodes):
            continue
        u = c["undecided"] + sum(c[f"deadline {v}"] for v in ("undecided",) + UNDECIDED)
        answers += c["satisfied"] + c["violated"] + c["deadline true"] + c["deadline false"] + u
        undecided += u
        still_open += c["undecided open"] + c["deadline open"]
        unjudged_ends += c["unjudged"]
    return answers, undecided, still_open, unjudged_ends


def _pct(part: int, whole: int) -> str:
    """``"PART of WHOLE (P %)"``."""
    return f"{part} of {whole}" + (f" ({100 * part / whole:.2f} %)" if whole else "")


def late_unsaid(res: dict[str, Any]) -> bool:
    """Whether the seeded node answers late (``"late"``) on a ``/clock`` whose mapping leaves ``use_sim_time``
    unsaid, and is never red but has deadlines ``undecided``: a deadline is then decided only where the wall
    clock and ``/clock`` time agree, and at a factor above 1.3 its answer is in time by the wall clock (its
    wall-clock delay 1.3 d over the factor), so undecided is its verdict, which the run says apart."""
    victim = _victim(res)
    spec = res["spec"]
    node = next((n for n in spec["nodes"] if n["name"] == victim), None)
    if node is None or node.get("defect_kind") != "late" or spec.get("use_sim_time"):
        return False
    live = res["live"].get(victim or "", Counter())
    red = live.get("violated", 0) + live.get("deadline false", 0) + live.get("declaration false", 0)
    return bool(red == 0 and live.get("deadline undecided", 0) > 0)


def _victim(res: dict[str, Any]) -> str | None:
    """The name of the node of ``res``'s spec that carries the seeded defect (``None``: no defect)."""
    return next((n["name"] for n in res["spec"]["nodes"] if n.get("defect")), None)


def explain(ws: Path, res: dict[str, Any]) -> list[str]:
    """For each live ``violated`` answer of a correct node: when the answer left the robot
    (``published.json``, the robot's own wall clock) against the stamp of the reading it was judged
    against, and the answer's stamp in the log (its receipt).  An answer that left before that reading
    was taken is judged against a reading it could not know."""
    victim = _victim(res)
    try:
        sent = json.loads((ws / "published.json").read_text())
    except (OSError, ValueError):
        return []
    lines = [json.loads(x) for x in (ws / "runs" / "live.jsonl").read_text(errors="replace").splitlines() if x.strip()]
    by_topic = {n["name"]: n for n in res["spec"]["nodes"]}
    out: list[str] = []
    for rec in lines:
        v = rec.get("verdict") if rec.get("topic") == "rclverify/verdict" else None
        if not isinstance(v, dict) or v.get("verdict") != "violated" or v.get("node") == victim:
            continue
        node = by_topic.get(str(v.get("node")))
        if node is None or "topic" not in node:
            continue
        heard = float(v["time"])
        left = max((t for topic, t in sent if topic == node["topic"] and t <= heard + 0.001), default=None)
        inputs = [by_topic[node[k]]["rcl_topic"] for k in ("source", "a_source", "b_source") if node.get(k)]
        stamps = [_stamp(r) for r in lines if r.get("topic") in inputs and _stamp(r) <= heard]
        question = max(stamps, default=None)
        if left is not None and question is not None:
            out.append(f"{node['name']}: the answer heard at {heard:.4f} left the robot at {left:.4f}, "
                       f"{(heard - left) * 1e3:.1f} ms before; the latest reading before it is stamped {question:.4f}"
                       + (" (taken after the answer left)" if question > left else ""))
    return out


def _stamp(rec: dict[str, Any]) -> float:
    h = rec.get("header")
    if isinstance(h, dict) and isinstance(h.get("stamp"), dict):
        return float(h["stamp"]["sec"]) + float(h["stamp"]["nanosec"]) / 1e9
    return float(rec.get("time", 0.0))


def findings(res: dict[str, Any]) -> list[str]:
    """What is wrong in one run: each verdict live and offline disagree on (final verdicts), each final
    false verdict of a correct node on any path, a node judged nothing live, a defect not red at its node."""
    out = list(res["disagreements"])
    names = [n["name"] for n in res["spec"]["nodes"]]
    victim = _victim(res)
    correct = {n for n in names if n != victim}
    for path, f in res["finals"].items():
        wrong = Counter(f"{r['node']}: {'deadline false' if r['item'] == 'deadline' else r['item'] + ' violated'}"
                        for r in false_verdicts(f, correct))
        out += [f"{k} x{n} {path} (false: the node is correct)" for k, n in sorted(wrong.items())]
    for path, d in res.get("declarations", {}).items():
        out += [f"{node}: {what} ({src}) false on the {path} (false: the node is correct): {row.get('reason', '')}"
                for (node, what, src), row in sorted(d.items()) if node in correct and row["verdict"] == "false"]
    for node in names:
        live = res["live"].get(node, Counter())
        judged = live.get("satisfied", 0) + live.get("violated", 0)
        if judged == 0 and not live.get("unjudged"):  # an unjudged endpoint is said, as docs/ros2.md promises
            out.append(f"{node}: nothing judged live")
        red = live.get("violated", 0) + live.get("deadline false", 0) + live.get("declaration false", 0)
        if node == victim and red == 0 and not victim_unjudged(res) and not late_unsaid(res):
            out.append(f"{node}: seeded defect not red live")
    return out


def victim_unjudged(res: dict[str, Any]) -> bool:
    """Whether the seeded node is a server none of whose calls the monitor could judge (the rclpy source hears
    calls through introspection events only, docs/ros2.md): its defect cannot show, and the node is judged
    nothing (never green), which the run's line says apart rather than as a finding (generated seed 1029)."""
    live = res["live"].get(_victim(res) or "", Counter())
    return bool(live.get("unjudged")) and live.get("satisfied", 0) + live.get("violated", 0) == 0


def _declarations(res: dict[str, Any]) -> str:
    """The declarations' verdicts on each path (``live 12 true, 1 false; log ...``; ``0``: none)."""
    parts = []
    for path, d in res.get("declarations", {}).items():
        c = Counter(str(row["verdict"]) for row in d.values())
        parts.append(f"{path} " + (", ".join(f"{n} {k}" for k, n in sorted(c.items())) or "0"))
    return "; ".join(parts) or "0"


def _line(res: dict[str, Any]) -> str:
    tot = Counter[str]()
    for c in res["live"].values():
        tot.update(c)
    undecided = {n: c["deadline undecided"] for n, c in res.get("log", {}).items() if c.get("deadline undecided")}
    why = sorted({k.split(": ", 1)[1] for c in res.get("log", {}).values() for k in c
                  if k.startswith("deadline undecided why: ")})
    clock = res.get("clock")
    fig = res.get("figures") or figures(res)
    sim = ("" if not clock else ", use_sim_time declared" if res["spec"].get("use_sim_time")
           else ", use_sim_time unsaid")
    seeded = ("" if "victim" not in fig else
              f"; seeded {fig['kind']} at {fig['victim']}: " + (f"red live ({fig['red']}, {fig['red_deadlines']} false "
                                                                 "deadline(s))" if fig["red"] else "NOT red live"))
    return (f"seed {res['seed']}{' defect' if res['defect'] else ''}: {res['nodes']} nodes, source "
            f"{res.get('source', 'dds')}, " + (f"/clock x{clock['rate']:g} from {clock['start_s']:g} s" if clock
                                               else "wall clock")
            + "".join(f", {'paused' if r == 0 else f'x{r:g}'} at {at:g} s" for at, r in (clock or {}).get("segments") or [])
            + sim + f": at correct nodes violated {fig['violated_correct']}, false deadlines "
            f"{fig['false_deadlines_correct']}, false declarations {fig['false_declarations_correct']} (every path); "
            f"deadlines undecided live {fig['undecided']} of {fig['deadlines']}"
            + (f" ({100 * fig['undecided'] / fig['deadlines']:.0f} %)" if fig["deadlines"] else "")
            + f"; live {'=' if fig['agree'] else '!='} log = bag" + seeded + "; live satisfied "
            f"{tot['satisfied']}, violated {tot['violated']}, undecided {tot['undecided']}, deadlines true "
            f"{tot['deadline true']} false {tot['deadline false']}"
            + (f", undecided {sum(undecided.values())} (log: " + ", ".join(f"{n} {k}" for n, k in undecided.items())
               + ")" if undecided else "")
            + f", declarations ({_declarations(res)}); verdicts compared: " + ", ".join(
                f"{k} {sum(len(x) for x in f.values())}" for k, f in res["finals"].items())
            + f", {len(res['disagreements'])} disagreement(s)"
            + (f", {len(res['provisional'])} on a provisional verdict" if res["provisional"] else "")
            + (f", {len(res['placed_apart'])} message(s) placed apart" if res["placed_apart"] else "")
            + (f", {len(res.get('bag_pending_calls', []))} server declaration(s) pending on the bag (calls)"
               if res.get("bag_pending_calls") else "")
            + (f", {tot['provisional']} live verdict(s) left provisional" if tot["provisional"] else "") + "; "
            f"{'agree' if not res['findings'] else 'FINDINGS: ' + '; '.join(res['findings'])}"
            + ("; " + "; ".join(res["errors"]) if res["errors"] else "")
            + "".join(f"\n  {x}" for x in res["provisional"] + res["placed_apart"] + res.get("bag_pending_calls", []))
            + (f"\n  seeded defect at {_victim(res)} not judged: its calls are unjudged (no introspection, heard "
               "through the rclpy source), the node judged nothing, never green" if victim_unjudged(res) else "")
            + (f"\n  seeded late answers at {_victim(res)} undecided, never red: use_sim_time unsaid, the wall clock "
               "and /clock time disagree on them" if late_unsaid(res) else "")
            + "".join(f"\n  other clock: {c}" for c in res.get("other_clocks", []))
            + "".join(f"\n  undecided at {k}: {' | '.join(v)}" for k, v in res.get("undecided_why", {}).items())
            + "".join(f"\n  deadline undecided (first, log): {w}" for w in why)
            + "".join(f"\n  violated: {e}" for e in res.get("explained", [])))


def run_many(seeds: list[int], sizes: tuple[int, int], seconds: float, defect: bool, burn: bool,
             keep: Path | None, kinds: tuple[str, ...] = tuple(SENSORS), src: Path = ROOT / "src",
             source: str = "dds", sim_clock: bool = False, actions: bool = False,
             driver_offset_s: float = 0.0, clock_change: bool = False, undeclared_sim_time: bool = False) -> int:
    """Run every seed (a node count drawn per seed in ``sizes``) through ``source``, on a ``/clock`` with
    ``sim_clock``; print one line per seed and the totals.  Returns 0 (the figures are the output; a
    finding is printed, not raised)."""
    ros2, why = ros2_python()
    if ros2 is None:
        print(f"robot generator: skipped: {why}")
        return 0
    burner = None
    if burn:
        burner = subprocess.Popen([sys.executable, "-c", "while True: pass"], start_new_session=True)
    total = Counter[str]()
    undecided = 0  # deadlines given no verdict, counted offline on the logs
    failing: list[int] = []
    agree, compared, disagreements, provisional, apart = 0, Counter[str](), 0, 0, 0
    declarations = Counter[str]()
    per_run = Counter[str]()
    loads: list[float] = []
    try:
        for seed in seeds:
            n = random.Random(seed).randint(*sizes)
            with tempfile.TemporaryDirectory() as d:
                try:
                    res = run_one(seed, n, seconds, defect, Path(d), ros2, kinds, src, source, sim_clock,
                                  actions, driver_offset_s, clock_change, undeclared_sim_time)
                except (RobotFailed, MonitorFailed) as exc:
                    what = "GENERATOR FAULT" if isinstance(exc, RobotFailed) else "MONITOR DID NOT START"
                    print(f"seed {seed}: {what}: {exc}", flush=True)
                    failing.append(seed)
                    if keep is not None:
                        shutil.copytree(d, keep / f"seed-{seed}{'-defect' if defect else ''}", dirs_exist_ok=True)
                    continue
                if keep is not None and (res["findings"] or res["errors"]):
                    shutil.copytree(d, keep / f"seed-{seed}{'-defect' if defect else ''}", dirs_exist_ok=True)
            print(_line(res), flush=True)
            for c in res["live"].values():
                total.update(c)
            undecided += sum(c["deadline undecided"] for c in res["log"].values())
            for k in ("violated_correct", "false_deadlines_correct", "false_declarations_correct", "deadlines",
                      "undecided", "subset_answers", "subset_undecided", "subset_open",
                      "subset_unjudged"):
                per_run[k] += res["figures"][k]
            if "victim" in res["figures"]:
                per_run["seeded red"] += bool(res["figures"]["red"])
                per_run["seeded late unsaid"] += late_unsaid(res)
                per_run["seeded"] += 1
            victim = _victim(res)
            declarations["bag pending at a server"] += len(res.get("bag_pending_calls", []))
            for path, d in res["declarations"].items():
                declarations.update(f"{path} {row['verdict']}" for row in d.values())
                declarations.update(f"{path} false at a correct node" for (node, _, _), row in d.items()
                                    if row["verdict"] == "false" and node != victim)
            compared.update({k: sum(len(x) for x in f.values()) for k, f in res["finals"].items()})
            disagreements += len(res["disagreements"])
            provisional += len(res["provisional"])
            apart += len(res["placed_apart"])
            loads.append(os.getloadavg()[0])
            if res["findings"] or res["errors"]:
                failing.append(seed)
            agree += not res["disagreements"] and not res["errors"]
    finally:
        if burner is not None:
            stop(burner, signal.SIGKILL)
    print(f"robot generator: {len(seeds)} system(s){' with a seeded defect' if defect else ''}, "
          f"{'one CPU burner beside, ' if burn else ''}load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} "
          f"core(s): live satisfied {total['satisfied']}, violated {total['violated']}, undecided "
          f"{total['undecided']} (" + ", ".join(f"{total['undecided ' + v]} {v}" for v in UNDECIDED)
          + f", {total['unjudged']} unjudged endpoints), deadlines true {total['deadline true']} false {total['deadline false']} "
          f"(undecided on the logs: {undecided}); declarations: " + "; ".join(
              f"{path} " + ", ".join(f"{declarations[k]} {k.split(' ', 1)[1]}" for k in sorted(declarations)
                                     if k.startswith(path + " ") and "correct" not in k and "server" not in k)
              for path in ("live", "log", "bag")) + ", false declarations (at a correct node): " + ", ".join(
              f"{path} {declarations[path + ' false at a correct node']}" for path in ("live", "log", "bag"))
          + f" ({declarations['bag pending at a server']} server declaration(s) pending on the bag alone, its calls "
          "given to the call checks only)"
          + f"; verdicts compared: live {compared['live']}, log {compared['log']}, bag "
          f"{compared['bag']}; disagreements {disagreements} (and {provisional} on a verdict still provisional, {apart} "
          f"message(s) given one verdict but placed apart); "
          f"at correct nodes (every path): violated {per_run['violated_correct']}, false deadlines "
          f"{per_run['false_deadlines_correct']}, false declarations {per_run['false_declarations_correct']}; "
          f"deadlines undecided live {per_run['undecided']} of {per_run['deadlines']}"
          + (f" ({100 * per_run['undecided'] / per_run['deadlines']:.0f} %)" if per_run["deadlines"] else "")
          + f"; undecided at correct nodes answering one input within its period (alarms, relays, servers: "
          f"answers and deadlines) {per_run['subset_undecided']} of {per_run['subset_answers']}"
          + (f" ({100 * per_run['subset_undecided'] / per_run['subset_answers']:.2f} %)"
             if per_run["subset_answers"] else "")
          + (f", of them {per_run['subset_open']} open when the run ended (raised less than the horizon before "
             f"the monitor stopped, unanswered) and {per_run['subset_unjudged']} endpoint(s) the source cannot hear "
             f"(servers without introspection through the rclpy source); without those "
             + _pct(per_run['subset_undecided'] - apart, per_run['subset_answers'] - apart)
             if (apart := per_run["subset_open"] + per_run["subset_unjudged"]) else "")
          + (f"; seeded defects red at their node {per_run['seeded red']} of {per_run['seeded']}"
             + (f" ({per_run['seeded late unsaid']} late, undecided with use_sim_time unsaid)"
                if per_run["seeded late unsaid"] else "") if per_run["seeded"] else "") + "; "
          f"load average after each run {min(loads, default=0):.1f}-{max(loads, default=0):.1f}; seeds with "
          f"findings: {failing or 'none'}; live = log = bag verdict by verdict on {agree} of {len(seeds)}")
    return 0
