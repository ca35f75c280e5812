"""The ROS scan against a hostile workspace (docs/ros.md, "Hostile
workspaces"): FIFOs, device links and links leaving the workspace are
skipped with a located warning, never read.  Scans run in a subprocess with
a timeout so a regression (a blocking FIFO read) fails instead of hanging."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

MARK = "OUTSIDE_MARKER_7f3a91"
MANIFEST = ('<?xml version="1.0"?><package format="2"><name>p</name><version>0.0.1</version>'
            '<description>d</description><maintainer email="m@example.com">m</maintainer>'
            '<license>MIT</license></package>\n')
CLI = "import sys; from rclverify.cli.commands import main; sys.exit(main(sys.argv[1:]))"
NODE = "import rospy\nrospy.init_node('n')\nrospy.Publisher('/t', String)\n"


def _scan(ws: Path, *extra: str) -> tuple[subprocess.CompletedProcess[str], dict]:
    out = ws.parent / "graph.json"
    proc = subprocess.run([sys.executable, "-c", CLI, "ros", "scan", ".", "--json", str(out), *extra],
                          cwd=ws, capture_output=True, text=True, timeout=60)
    graph = json.loads(out.read_text()) if out.is_file() else {}
    return proc, graph


def _pkg(ws: Path) -> Path:
    p = ws / "p"
    (p / "scripts").mkdir(parents=True)
    (p / "package.xml").write_text(MANIFEST)
    return p


def _outside(tmp: Path) -> Path:
    o = tmp / "outside"
    o.mkdir()
    (o / "x.py").write_text(f"# {MARK}\nrospy.Publisher('/{MARK}', String)\n")
    (o / "Leak.msg").write_text(f"int32 {MARK.lower()}\n")
    (o / "out.launch").write_text(f'<launch><node pkg="p" type="x.py" name="{MARK}"/></launch>\n')
    return o


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifo_and_device_link_are_skipped_not_read(tmp_path: Path) -> None:
    """Item 8: a FIFO ``package.xml``/script and a link to /dev/zero are skipped, located."""
    ws = tmp_path / "ws"
    p = _pkg(ws)
    (p / "scripts" / "good.py").write_text(NODE)
    os.mkfifo(p / "scripts" / "x.py")
    os.symlink("/dev/zero", p / "scripts" / "z.py")
    q = ws / "q"
    q.mkdir()
    os.mkfifo(q / "package.xml")
    proc, graph = _scan(ws)
    assert "Traceback" not in proc.stderr
    msgs = {(u["file"], u["message"]) for u in graph["unresolved"]}
    assert any(f == "p/scripts/x.py" and "not a regular file" in m for f, m in msgs)
    assert any(f == "p/scripts/z.py" and "skipped" in m for f, m in msgs)
    assert any(f == "q/package.xml" and "not a regular file" in m for f, m in msgs)
    assert [pk["name"] for pk in graph["packages"]] == ["p"]


def test_large_source_is_capped(tmp_path: Path) -> None:
    """Item 8: a source file over the 8 MiB cap is skipped with a warning."""
    from rclverify.ros.extract import safefs
    big = tmp_path / "big.py"
    big.write_bytes(b"#" * (safefs.MAX_FILE_BYTES + 1))
    with pytest.raises(safefs.Refused, match="larger than 8 MiB"):
        safefs.read_bytes(big)


def test_links_and_includes_leaving_the_workspace_are_not_read(tmp_path: Path) -> None:
    """Item 5: a linked workspace dir, a linked script, a linked .msg and an
    absolute include outside the workspace: nothing of them in the output."""
    o = _outside(tmp_path)
    ws = tmp_path / "ws"
    p = _pkg(ws)
    os.symlink(o, ws / "ros_ext")
    os.symlink(o / "x.py", p / "scripts" / "o.py")
    (p / "msg").mkdir()
    os.symlink(o / "Leak.msg", p / "msg" / "Leak.msg")
    (p / "launch").mkdir()
    (p / "launch" / "main.launch").write_text(f'<launch><include file="{o / "out.launch"}"/></launch>\n')
    proc, graph = _scan(ws, "--launch", "p/launch/main.launch")
    assert "Traceback" not in proc.stderr
    text = json.dumps(graph) + proc.stdout + proc.stderr
    assert MARK not in text and MARK.lower() not in text
    warned = {u["file"] for u in graph["unresolved"] if "outside the workspace" in u["message"]}
    assert {"p/scripts/o.py", "p/msg/Leak.msg"} <= warned
    assert graph["nodes"] == []


def test_init_from_ros_copies_no_link_target_and_does_not_loop(tmp_path: Path) -> None:
    """Item 7: ``init --from-ros`` copies neither what a link outside points to
    nor loops on ``a -> .``; an inside link to a regular file is copied."""
    o = _outside(tmp_path)
    ws = tmp_path / "ws"
    p = _pkg(ws)
    (p / "scripts" / "good.py").write_text(NODE)
    os.symlink(o / "x.py", p / "leak.py")
    os.symlink(".", p / "a")
    os.symlink("scripts/good.py", p / "alias.py")
    new = tmp_path / "new"
    proc = subprocess.run([sys.executable, "-c", CLI, "init", str(new), "--from-ros", str(ws)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert "leak.py: warning: link leaving the package: skipped" in proc.stderr
    assert "a: warning: directory link not followed" in proc.stderr
    copied = sorted(q.relative_to(new / "ros" / "p").as_posix() for q in (new / "ros" / "p").rglob("*"))
    assert copied == ["alias.py", "package.xml", "scripts", "scripts/good.py"]
    assert not any((new / "ros" / "p" / c).is_symlink() for c in copied)
    for q in new.rglob("*"):
        if q.is_file():
            assert MARK not in q.read_text(errors="replace")


def test_copy_package_is_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Item 7: the copy stops at its file bound and says so."""
    from rclverify.tools.scaffold import safecopy
    src = tmp_path / "src"
    src.mkdir()
    for i in range(5):
        (src / f"f{i}.txt").write_text("x")
    monkeypatch.setattr(safecopy, "MAX_FILES", 3)
    warns = safecopy.copy_package(src, tmp_path / "dst")
    assert len(list((tmp_path / "dst").iterdir())) == 3
    assert "copy limit reached" in warns[-1]


def test_cache_in_copied_workspace_scans_the_copy(tmp_path: Path) -> None:
    """Item 6: a scan cache made in ``ws`` and carried by ``cp -a ws ws2``
    does not make ``ws2``'s scan read ``ws``: an edit in the copy is seen,
    and the cached scan equals a clean one."""
    import shutil

    from rclverify.ros.graph.scan import scan
    ws = tmp_path / "ws"
    p = _pkg(ws)
    (p / "scripts" / "good.py").write_text(NODE)
    cache = ws / "artifacts" / "cache" / "ros-scan.pickle"
    scan([ws], cache_path=cache, base=ws).graph
    ws2 = tmp_path / "ws2"
    shutil.copytree(ws, ws2, symlinks=True)
    (ws2 / "p" / "scripts" / "good.py").write_text(NODE.replace("'/t'", "'/edited'"))
    cached = scan([ws2], cache_path=ws2 / "artifacts" / "cache" / "ros-scan.pickle", base=ws2).graph
    clean = scan([ws2], base=ws2).graph
    assert {e[2] for e in cached.edges()} == {"/edited"}
    assert cached.to_json() == clean.to_json()


def test_launch_fanout_deep_args_yaml_bomb_and_many_depends_are_bounded(tmp_path: Path) -> None:
    """Item 9: 20 files each including the next 4 times, ``$(arg)`` defaults
    nested 40 levels (4^40 characters), a YAML alias bomb and 5,000
    ``<depend>``s each end quickly with a located warning saying what was cut."""
    ws = tmp_path / "ws"
    p = _pkg(ws)
    (p / "launch").mkdir()
    for i in range(20):
        inc = "".join(f'<include file="$(dirname)/f{i + 1}.launch"/>' for _ in range(4)) if i < 19 else ""
        (p / "launch" / f"f{i}.launch").write_text(f'<launch><node pkg="p" type="x" name="n{i}"/>{inc}</launch>\n')
    args = '<arg name="a0" default="xxxx"/>' + "".join(
        f'<arg name="a{i}" default="$(arg a{i - 1})$(arg a{i - 1})$(arg a{i - 1})$(arg a{i - 1})"/>'
        for i in range(1, 41))
    (p / "launch" / "deep.launch").write_text(f'<launch>{args}<node pkg="p" type="x" name="$(arg a40)"/></launch>\n')
    bomb = 'a: &a ["x","x","x","x","x","x","x","x","x","x"]\n' + "".join(
        f'{c}: &{c} [*{b},*{b},*{b},*{b},*{b},*{b},*{b},*{b},*{b},*{b}]\n' for b, c in zip("abcdefgh", "bcdefghi"))
    (p / "launch" / "bomb.launch.yaml").write_text(bomb + "launch: [*i]\n")
    q = ws / "q"
    q.mkdir()
    (q / "package.xml").write_text(MANIFEST.replace("<name>p</name>", "<name>q</name>").replace(
        "<license>MIT</license>", "<license>MIT</license>" + "<depend>d</depend>" * 5000))
    proc, graph = _scan(ws, "--launch", "p/launch/deep.launch", "--launch", "p/launch/bomb.launch.yaml",
                        "--launch", "p/launch/f0.launch")
    assert "Traceback" not in proc.stderr
    notes = [(u["file"], u["message"]) for u in graph["unresolved"]]
    assert any("more than 256 launch files" in m for _, m in notes)
    assert any(f == "p/launch/deep.launch" and "expands beyond 65536 characters" in m for f, m in notes)
    assert any(f == "p/launch/bomb.launch.yaml" and "refused" in m for f, m in notes)
    assert any(f == "q/package.xml" and "5000 dependency elements" in m for f, m in notes)
    # deep.launch's node is kept without the name that expands too far (named by its executable)
    assert {n["name"] for n in graph["nodes"]} == {f"/n{i}" for i in range(20)} | {"/x"}


@pytest.mark.skipif(sys.platform == "darwin", reason="needs a filesystem that takes any bytes in names")
def test_non_utf8_names_are_skipped_with_an_escaped_warning(tmp_path: Path) -> None:
    """Item 10: a directory or file whose name is not UTF-8 is skipped, named with escapes, no traceback."""
    ws = tmp_path / "ws"
    p = _pkg(ws)
    (p / "scripts" / "good.py").write_text(NODE)
    bad_dir = os.fsencode(p / "scripts") + b"/\xff\xfe"
    os.mkdir(bad_dir)
    with open(bad_dir + b"/n.py", "w") as f:
        f.write(NODE)
    with open(os.fsencode(p / "scripts") + b"/b\xffad.py", "w") as f:
        f.write(NODE)
    proc, graph = _scan(ws)
    assert "Traceback" not in proc.stderr
    warned = {u["file"] for u in graph["unresolved"] if "not valid UTF-8" in u["message"]}
    assert warned == {"p/scripts/\\xff\\xfe", "p/scripts/b\\xffad.py"}
    assert "p/scripts/\\xff\\xfe:1:1: warning: name is not valid UTF-8: skipped" in proc.stderr


def _hostile_workspace(tmp: Path, seed: int) -> tuple[Path, Path]:
    import random
    rnd = random.Random(seed)
    o = _outside(tmp)
    (o / "secret.launch").write_text(f'<launch><node pkg="p" type="x" name="{MARK}"/></launch>\n')
    ws = tmp / "ws"
    p = _pkg(ws)
    (p / "scripts" / "good.py").write_text(NODE)
    (p / "launch").mkdir()
    entry = p / "launch" / "main.launch"
    makers = [
        lambda d: os.mkfifo(d / "package.xml") if not (d / "package.xml").exists() else None,
        lambda d: os.mkfifo(d / f"f{rnd.randrange(99)}.py"),
        lambda d: os.symlink(".", d / f"loop{rnd.randrange(99)}"),
        lambda d: os.symlink(o, d / f"ext{rnd.randrange(99)}"),
        lambda d: os.symlink(o / "x.py", d / f"o{rnd.randrange(99)}.py"),
        lambda d: os.symlink("/dev/zero", d / f"z{rnd.randrange(99)}.py"),
        lambda d: os.truncate(_touch(d / f"huge{rnd.randrange(99)}.py"), 9 * 1024 * 1024),
        lambda d: (d / f"bin{rnd.randrange(99)}.cpp").write_bytes(bytes(rnd.randrange(256) for _ in range(4096))),
        lambda d: os.mkdir(os.fsencode(d) + bytes([0x80 + rnd.randrange(64)]) + b"dir"),
    ]
    for _ in range(12):
        d = rnd.choice([ws, p, p / "scripts", p / "launch"])
        try:
            rnd.choice(makers)(d)
        except FileExistsError:
            pass
    kind = rnd.randrange(3)
    if kind == 0:  # fan-out
        for i in range(12):
            inc = "".join(f'<include file="$(dirname)/g{i + 1}.launch"/>' for _ in range(4)) if i < 11 else ""
            (p / "launch" / f"g{i}.launch").write_text(f"<launch>{inc}</launch>\n")
        entry.write_text(f'<launch><include file="$(dirname)/g0.launch"/>'
                         f'<include file="{o / "secret.launch"}"/></launch>\n')
    elif kind == 1:  # deep args
        args = '<arg name="a0" default="yy"/>' + "".join(
            f'<arg name="a{i}" default="$(arg a{i - 1})$(arg a{i - 1})$(arg a{i - 1})"/>' for i in range(1, 35))
        entry.write_text(f'<launch>{args}<node pkg="p" type="x" name="$(arg a34)"/></launch>\n')
    else:  # include through a link leaving the workspace
        os.symlink(o / "secret.launch", p / "launch" / "s.launch")
        entry.write_text('<launch><include file="$(dirname)/s.launch"/></launch>\n')
    return ws, entry


def _touch(p: Path) -> Path:
    p.write_bytes(b"")
    return p


@pytest.mark.parametrize("seed", range(6))
def test_fuzz_hostile_workspaces(tmp_path: Path, seed: int) -> None:
    """Generated hostile workspaces: every scan and ``init --from-ros`` ends
    within its bound, without a traceback, and nothing from the outside
    directory (its marker) appears in stdout, stderr, graph.json or the new workspace."""
    ws, entry = _hostile_workspace(tmp_path, seed)
    proc, graph = _scan(ws, "--launch", entry.relative_to(ws).as_posix())
    assert proc.returncode in (0, 1)
    assert "Traceback" not in proc.stderr
    text = proc.stdout + proc.stderr + json.dumps(graph)
    assert MARK not in text and MARK.lower() not in text
    new = tmp_path / "new"
    init = subprocess.run([sys.executable, "-c", CLI, "init", str(new), "--from-ros", str(ws)],
                          cwd=ws, capture_output=True, text=True, timeout=60)
    assert init.returncode == 0, init.stderr  # package p (good.py) is always found: the copy is exercised
    assert "Traceback" not in init.stderr
    assert MARK not in init.stdout + init.stderr
    for q in new.rglob("*"):
        assert not q.is_symlink()
        if q.is_file():
            assert MARK.encode() not in q.read_bytes()
