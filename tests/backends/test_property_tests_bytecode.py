"""An implementation edited within the second of its last import, to a text of the same length, runs
its new code: Python's bytecode cache, which trusts a whole-second modification time and the size,
must not hand the property tests the old code (their evidence hashes the new file)."""
from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

from rclverify.backends.property_tests.config import Config, load_implementation

HELPER = "def delta():\n    return 1\n"


def _write(path: Path, text: str, stamp: int) -> None:
    path.write_text(text)
    os.utime(path, (stamp, stamp))  # the same second every time: what a quick edit gives


def test_an_edit_in_the_same_second_and_of_the_same_size_is_what_runs(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    ws.mkdir()
    stamp = 1_700_000_000
    _write(ws / "helper.py", HELPER, stamp)
    impl = ws / "impl.py"
    cfg = Config("impl.py:step", "impl.py", "step")
    sys.path.insert(0, str(ws))
    dont_write = sys.dont_write_bytecode
    sys.dont_write_bytecode = False  # as on a machine that writes bytecode (CI): the cache would be trusted
    try:
        _write(impl, "from helper import delta\n\ndef step(x):\n    return x - delta()\n", stamp)
        assert load_implementation(ws, cfg)(5) == 4
        # a cache written by an ordinary import of the same files (a pytest run, another tool)
        import py_compile
        py_compile.compile(str(impl), cfile=importlib.util.cache_from_source(str(impl)))
        py_compile.compile(str(ws / "helper.py"), cfile=importlib.util.cache_from_source(str(ws / "helper.py")))
        _write(impl, "from helper import delta\n\ndef step(x):\n    return x + delta()\n", stamp)
        _write(ws / "helper.py", HELPER.replace("1", "2"), stamp)
        assert load_implementation(ws, cfg)(5) == 7  # both files' new code
    finally:
        sys.dont_write_bytecode = dont_write
        sys.path.remove(str(ws))
        sys.modules.pop("helper", None)
