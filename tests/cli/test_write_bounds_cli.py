"""Every output of ``verify`` and every ``-o``/``--json``/``--csv`` of the command line, each tried
with a symbolic link out of the workspace, a FIFO no process reads and a character device
(issues 107 and 112; docs/integrity.md, "Where outputs go").

The report files under ``reports/`` are not named by the user: a planted link leading out, a FIFO
or a device there is refused in one line (exit 1) and left as it was, the outside file untouched;
a regular file there (the control) is written.  A path the user names is written wherever it
leads: a link is followed, a device written in place (exit 0), and a FIFO no process reads fails
in one line (exit 1) once no reader
opened it within the wait, never hangs.  The report files are checked in process through
``rclverify report`` (the code the ``report:`` tasks of ``verify`` run), and ``verify`` itself once
end to end on the issue's own cases.
"""
from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
import threading
from pathlib import Path
from typing import Callable, Iterator

import pytest

from rclverify.cli.commands import main
from rclverify.core import atomic
from rclverify.stages.workspace import REPORT_PARTS

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")

REPORT_NAMES = sorted({n for names in REPORT_PARTS.values() for n in names})
KINDS = ("link out", "fifo", "device")


def _bounded(fn: Callable[[], int], seconds: float = 60.0) -> int:
    """``fn()`` in a thread: fail, instead of hanging the suite, when it has not returned in ``seconds``."""
    box: list[object] = []
    t = threading.Thread(target=lambda: box.append(fn()), daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"hung for {seconds} s"
    assert isinstance(box[0], int)
    return box[0]


def _device(path: Path) -> None:
    """A character device equal to /dev/null at ``path`` (root), else a link to the machine's own."""
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        path.symlink_to("/dev/null")


def _plant(path: Path, kind: str, outside: Path) -> None:
    path.unlink(missing_ok=True)
    if kind == "link out":
        path.symlink_to(outside)
    elif kind == "fifo":
        os.mkfifo(path)
    else:
        _device(path)


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    base = tmp_path_factory.mktemp("bounds")
    root = base / "ws"
    assert main(["init", str(root)]) == 0
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify"], cwd=root, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    yield root


def _report(ws: Path) -> int:
    return _bounded(lambda: main(["report", "-w", str(ws)]))


@pytest.mark.parametrize("kind", KINDS)
def test_every_report_file_refuses_what_was_planted_there(ws: Path, tmp_path: Path, kind: str,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    outside = tmp_path / "victim.txt"
    outside.write_text("keep\n")
    for name in REPORT_NAMES:
        path = ws / "reports" / name
        _plant(path, kind, outside)
        capsys.readouterr()
        assert _report(ws) == 1, name
        err = capsys.readouterr().err.strip().splitlines()
        why = "outside the workspace" if kind == "link out" else "not a regular file"
        assert len(err) == 1 and f"reports/{name}" in err[0] and why in err[0], (name, err)
        assert "Traceback" not in err[0]
        assert outside.read_text() == "keep\n"
        mode = os.lstat(path).st_mode
        assert {"link out": stat.S_ISLNK, "fifo": stat.S_ISFIFO, "device": lambda m: not stat.S_ISREG(m)}[kind](mode)
        path.unlink()
    assert _report(ws) == 0  # control: the same places as regular files (here missing) are written
    assert all((ws / "reports" / n).is_file() and (ws / "reports" / n).stat().st_size > 0 for n in REPORT_NAMES)


@pytest.mark.parametrize("name, kind, said", [
    ("assurance.md", "fifo", "reports/assurance.md: is a FIFO, not a regular file"),
    ("assurance.sarif", "link out", "reports/assurance.sarif: leads to "),
])
def test_verify_on_the_issue_cases_ends_in_one_line(ws: Path, tmp_path: Path, name: str, kind: str, said: str) -> None:
    outside = tmp_path / "victim.txt"
    outside.write_text("keep\n")
    _plant(ws / "reports" / name, kind, outside)
    sensor = ws / "contracts" / "sensor.rcl"
    sensor.write_text(sensor.read_text() + "// edited\n")  # the report tasks run again
    try:
        r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify"], cwd=ws, capture_output=True,
                           text=True, timeout=240)
        out = r.stdout + r.stderr
        assert r.returncode != 0 and "Traceback" not in out
        lines = [line for line in out.splitlines() if said in line]
        assert len(lines) == 1, out[-3000:]
        assert kind != "link out" or "outside the workspace" in lines[0]
        assert outside.read_text() == "keep\n"
        assert (stat.S_ISFIFO if kind == "fifo" else stat.S_ISLNK)(os.lstat(ws / "reports" / name).st_mode)
    finally:
        (ws / "reports" / name).unlink()
    assert _report(ws) == 0  # control: the same workspace with plain report files


def _commands(ws: Path) -> dict[str, Callable[[Path], list[str]]]:
    """Every command that writes a FILE the user names, as the argv writing it to ``out``."""
    w = ["-w", str(ws)]
    (ws.parent / "no-ros").mkdir(exist_ok=True)  # a ROS scan of nothing: its --json is still written
    return {
        "fmt": lambda out: ["fmt", str(ws / "contracts" / "sensor.rcl"), "-o", str(out)],
        "latex": lambda out: ["latex", str(ws / "contracts" / "sensor.rcl"), "-o", str(out)],
        "graph": lambda out: ["graph", *w, "-o", str(out)],
        "quotient": lambda out: ["quotient", "Controller", *w, "-o", str(out)],
        "review": lambda out: ["review", "Controller", *w, "-o", str(out)],
        "bundle": lambda out: ["bundle", *w, "-o", str(out)],
        "nodl check --json": lambda out: ["nodl", "check", *w, "--json", str(out)],
        "standards --csv": lambda out: ["standards", *w, "--csv", str(out)],
        "ros scan --json": lambda out: ["ros", "scan", str(ws.parent / "no-ros"), "--json", str(out)],
    }


@pytest.mark.parametrize("command", ["fmt", "latex", "graph", "quotient", "review", "bundle", "nodl check --json",
                                     "standards --csv", "ros scan --json"])
def test_every_named_output_goes_where_the_user_said_and_never_hangs(ws: Path, tmp_path: Path, command: str,
                                                                      capsys: pytest.CaptureFixture[str],
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atomic, "READER_WAIT_S", 0.2)  # the wait for a reader to open the FIFO (2 s)
    argv = _commands(ws)[command]
    # control: a regular file
    plain = tmp_path / "out.bin"
    assert _bounded(lambda: main(argv(plain))) == 0 and plain.stat().st_size > 0
    # a link the user named, leading out of the workspace: followed, the link stays a link
    target = tmp_path / "elsewhere" / "target.bin"
    target.parent.mkdir()
    target.write_text("old\n")
    link = tmp_path / "link.bin"
    link.symlink_to(target)
    assert _bounded(lambda: main(argv(link))) == 0
    assert link.is_symlink() and target.read_bytes() == plain.read_bytes()
    # a device: written in place, still a device, nothing written beside it
    dev = tmp_path / "dev"
    _device(dev)
    capsys.readouterr()
    assert _bounded(lambda: main(argv(dev))) == 0
    assert not stat.S_ISREG(os.stat(dev).st_mode)
    assert not (tmp_path / "dev.svg").exists()  # issue 112: graph drew FILE.svg beside even a device
    # a FIFO no process reads: one line, exit 1, within the wait for a reader
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    capsys.readouterr()
    assert _bounded(lambda: main(argv(fifo)), 30) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "FIFO no process reads" in err[0] and str(fifo) in err[0], err
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_nodl_write_into_a_named_folder_refuses_a_fifo_there(ws: Path, tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "docs"
    out.mkdir()
    os.mkfifo(out / "Sensor.nodl.yaml")
    capsys.readouterr()
    assert _bounded(lambda: main(["nodl", "write", "-w", str(ws), "-o", str(out), "--force", "Sensor"])) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Sensor.nodl.yaml: is a FIFO, not a regular file" in err[0], err
    (out / "Sensor.nodl.yaml").unlink()  # control
    assert main(["nodl", "write", "-w", str(ws), "-o", str(out), "Sensor"]) == 0
    assert (out / "Sensor.nodl.yaml").is_file()


def test_graph_draws_its_svg_beside_a_named_file_only_as_a_regular_file(ws: Path, tmp_path: Path,
                                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """``graph -o FILE`` names FILE, not ``FILE.svg`` beside it: a FIFO there is refused in one line, never
    opened (the command would hang on it), and left as it was; the DOT is written."""
    out, svg = tmp_path / "model.dot", tmp_path / "model.svg"
    os.mkfifo(svg)
    capsys.readouterr()
    assert _bounded(lambda: main(["graph", "-w", str(ws), "-o", str(out)])) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "model.svg: is a FIFO, not a regular file" in err[0] and "Traceback" not in err[0], err
    assert stat.S_ISFIFO(os.lstat(svg).st_mode) and out.read_text().lstrip().startswith(("digraph", "//", "/*"))
    svg.unlink()  # control: nothing there, the SVG is drawn as a regular file (when Graphviz is installed)
    assert _bounded(lambda: main(["graph", "-w", str(ws), "-o", str(out)])) == 0
    assert not shutil.which("dot") or (svg.is_file() and "<svg" in svg.read_text())
