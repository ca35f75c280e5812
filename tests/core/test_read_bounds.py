"""What a read of a file a document or the plan names refuses (docs/integrity.md, "Where outputs go").

A FIFO or device is never waited on; a NoDL include leading out of the
workspace is a located error; the YAML alias guard counts aliases, not size.
Each refusal has its control: a regular file, an include inside, a file
named on the command line, a document without aliases.
"""
from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import Callable

import pytest

from rclverify.core.within import Refused, read_regular
from rclverify.lang.errors import RclError
from rclverify.model.nodl.check import read_all, shown
from rclverify.model.nodl.document import Resolver, read_document
from rclverify.model.plan import yamlguard
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.yamlguard import MAX_YAML_NODES, compose_guarded, read_yaml_text

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")


def _bounded(fn: Callable[[], object], seconds: float = 20.0) -> object:
    """Run ``fn`` in a thread; fail (instead of hanging the suite) when it has not returned in ``seconds``."""
    box: list[object] = []

    def run() -> None:
        try:
            box.append(fn())
        except BaseException as exc:  # handed to the test
            box.append(exc)

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"{fn} did not return within {seconds} s"
    if isinstance(box[0], BaseException):
        raise box[0]
    return box[0]


def test_read_regular_refuses_a_fifo_without_waiting(tmp_path: Path) -> None:
    fifo = tmp_path / "doc.yaml"
    os.mkfifo(fifo)
    with pytest.raises(Refused, match="is a FIFO, not a regular file"):
        _bounded(lambda: read_regular(fifo))
    with pytest.raises(PlanError, match="cannot read file: is a FIFO, not a regular file"):
        _bounded(lambda: read_yaml_text(fifo, "doc.yaml"))
    plain = tmp_path / "plain.yaml"
    plain.write_bytes(b"a: 1\n")
    assert read_regular(plain) == b"a: 1\n" and read_yaml_text(plain, "plain.yaml") == "a: 1\n"
    with pytest.raises(Refused, match="above the limit of 3 bytes"):
        read_regular(plain, limit=3)


PART = "nodl_version: 2\nservice_servers:\n  - {name: /reset, type: std_srvs/srv/Trigger}\n"


def _including(ws: Path, ref: str) -> Path:
    (ws / "nodl").mkdir(parents=True, exist_ok=True)
    doc = ws / "nodl" / "Base.nodl.yaml"
    doc.write_text(f"nodl_version: 2\ninclude:\n  - ref: {ref}\n")
    return doc


def _read(ws: Path, doc: Path, within: bool = True) -> object:
    return _bounded(lambda: read_all([doc], Resolver((), shown(ws), (ws,) if within else ())))


def test_an_include_outside_the_workspace_is_refused(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "elsewhere" / "Part.nodl.yaml").write_text(PART)
    doc = _including(ws, "local://../../elsewhere/Part.nodl.yaml")
    with pytest.raises(RclError, match=r"nodl/Base.nodl.yaml:3:10: error: include 'local://.*': resolves to "
                                       r".*elsewhere/Part.nodl.yaml, outside the workspace"):
        _read(ws, doc)
    docs = _read(ws, doc, within=False)  # control: nodl validate, every file named on the command line
    assert [e.name for d in docs for e in d.endpoints] == ["/reset"]  # type: ignore[attr-defined]
    (ws / "nodl" / "Part.nodl.yaml").write_text(PART)  # control: the same include inside the workspace
    inside = _including(ws, "local://Part.nodl.yaml")
    assert [e.name for e in read_document(inside, resolver=Resolver((), shown(ws), (ws,))).endpoints] == ["/reset"]


def test_a_document_linked_out_of_the_nodl_folder_is_refused(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "nodl").mkdir(parents=True)
    (tmp_path / "Secret.nodl.yaml").write_text(PART)
    (ws / "nodl" / "Sensor.nodl.yaml").symlink_to(tmp_path / "Secret.nodl.yaml")
    with pytest.raises(RclError, match=r"nodl/Sensor.nodl.yaml:1:1: error: resolves to .*Secret.nodl.yaml, outside"):
        _read(ws, ws / "nodl" / "Sensor.nodl.yaml")
    assert len(_read(ws, ws / "nodl" / "Sensor.nodl.yaml", within=False)) == 1  # type: ignore[arg-type]


def test_a_fifo_include_is_named_as_one_not_waited_on(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    doc = _including(ws, "local://Part.nodl.yaml")
    with pytest.raises(RclError, match=r"include 'local://Part.nodl.yaml': no file nodl/Part.nodl.yaml"):
        _read(ws, doc)  # control: missing is "no file"
    os.mkfifo(ws / "nodl" / "Part.nodl.yaml")
    with pytest.raises(RclError, match=r"include 'local://Part.nodl.yaml': nodl/Part.nodl.yaml is a FIFO, not a "
                                       r"regular file"):
        _read(ws, doc)
    with pytest.raises(RclError, match=r"Part.nodl.yaml:1:1: error: cannot read file: is a FIFO, not a regular file"):
        _read(ws, ws / "nodl" / "Part.nodl.yaml")  # named itself: refused by the read, never opened for a wait


def _servers_yaml(n: int) -> str:
    return "nodl_version: 2\nservice_servers:\n" + "".join(f"  - {{name: /s{i}, type: a/srv/B}}\n" for i in range(n))


def _bomb(levels: int) -> str:
    lines = ["a: &a [x, x, x, x, x, x, x, x, x, x]"]
    for i in range(1, levels):
        lines.append(f"{chr(97 + i)}: &{chr(97 + i)} [" + ", ".join([f"*{chr(96 + i)}"] * 10) + "]")
    return "\n".join(lines) + "\n"


def test_the_alias_guard_counts_aliases_not_size(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # the document: 20,000 endpoints, 100,004 nodes, no alias (it was refused as an "alias bomb?")
    assert compose_guarded(_servers_yaml(20_000), "big.nodl.yaml") is not None
    with pytest.raises(PlanError, match=f"aliases expand to more than {MAX_YAML_NODES} nodes beyond those written"):
        compose_guarded(_bomb(7), "bomb.yaml")  # control: 70 nodes written, 10**7 through aliases
    # the NoDL reader end to end, under a limit made small: more nodes than the limit, read; aliases past it, refused
    monkeypatch.setattr(yamlguard, "MAX_YAML_NODES", 1000)
    big = tmp_path / "Big.nodl.yaml"
    big.write_text(_servers_yaml(400))  # 2,004 nodes
    assert len(read_document(big).endpoints) == 400
    bomb = tmp_path / "Bomb.nodl.yaml"
    bomb.write_text("nodl_version: 2\ndescription: x\n" + _bomb(4).replace("a:", "x_a:", 1))
    with pytest.raises(RclError, match="aliases expand to more than 1000 nodes"):
        read_document(bomb)
