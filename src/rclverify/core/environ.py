"""One environment variable set while a block runs, and given back after.

Used where a library reads a variable once, when it is imported (Hypothesis's
``HYPOTHESIS_NO_PLUGINS``, OpenBLAS's ``OPENBLAS_NUM_THREADS``): the
variable is set for the import only, so every process rclverify starts
afterwards inherits the environment the user gave it.  ``os.environ`` is
the process's, so a process started by another thread during the block
would see the variable too.
"""
from __future__ import annotations

import contextlib
import os
from typing import Iterator


@contextlib.contextmanager
def variable_during(name: str, value: str, *, override: bool) -> Iterator[None]:
    """While the block runs, ``os.environ[name] == value``; with
    ``override=False`` a value the user set is kept instead.  Afterwards the
    variable is as before the block (removed, or its old value), whether the
    block returned or raised.  Never raises by itself."""
    before = os.environ.get(name)
    if before is not None and not override:
        yield
        return
    os.environ[name] = value
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = before
