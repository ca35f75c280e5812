"""An in-process `rclverify verify` writes to the standard output of the moment
it runs: doit's default output stream is the `sys.stdout` of the moment doit
was first imported, which in a long-lived process (a test runner, an editor)
may have been closed since ("ValueError: I/O operation on closed file", no
report written: two test modules failed when one worker ran both)."""
from __future__ import annotations

import io
from pathlib import Path

import pytest

from rclverify.cli.commands import main


def test_verify_in_process_after_doit_was_imported_under_a_closed_stream(tmp_path: Path,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    import doit.cmd_run as cmd_run
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--nodes", "A,B"]) == 0
    closed = io.StringIO()
    closed.close()
    before = cmd_run.opt_outfile["default"]
    cmd_run.opt_outfile["default"] = closed  # as if doit had been imported while that stream was sys.stdout
    try:
        assert main(["verify", "-w", str(ws)]) == 0
    finally:
        cmd_run.opt_outfile["default"] = before
    assert (ws / "reports" / "assurance.json").is_file()
