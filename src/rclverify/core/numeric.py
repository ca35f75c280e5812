"""numpy and scipy, loaded with one OpenBLAS thread.

numpy's wheel and scipy's each bundle OpenBLAS, which starts one thread
per CPU when the library loads; the extra threads busy-wait for work
before they sleep.  rclverify's arrays are elementwise (monitor columns,
trace blocks, the statistics of recorded runs) and make no BLAS call, so
those threads only spend CPU.  Measured on a 2-core machine (CPU seconds
of a process that only imports): ``import numpy`` 0.33 -> 0.24, ``from
scipy.special import betaincinv`` 0.70 -> 0.51 (docs/scale.md,
"Start-up").

OpenBLAS reads ``OPENBLAS_NUM_THREADS`` once, when it loads (OpenBLAS's
documentation, "Setting the number of threads using environment
variables").  The variable is set to ``1`` only while :func:`import_numpy`
or :func:`scipy_special` imports, and removed afterwards, so every process
rclverify starts (the user's nodes, property-test processes) inherits the
environment the user gave it.  A value the user set is kept, and a numpy
loaded before rclverify's first import keeps its threads.  rclverify
imports numpy and scipy through this module only
(``tests/core/test_numeric.py``).
"""
from __future__ import annotations

import importlib
import sys
from contextlib import AbstractContextManager
from types import ModuleType
from typing import TYPE_CHECKING

from rclverify.core.environ import variable_during

#: The variable OpenBLAS reads when it loads.
VARIABLE = "OPENBLAS_NUM_THREADS"


def one_blas_thread() -> AbstractContextManager[None]:
    """While the block runs, ``OPENBLAS_NUM_THREADS=1`` unless the user set
    it; afterwards the environment is as before (:mod:`.environ`)."""
    return variable_during(VARIABLE, "1", override=False)


def import_numpy() -> ModuleType:
    """The ``numpy`` module, its OpenBLAS loaded with one thread (see the
    module's docstring).  Raises ``ImportError`` when numpy is missing."""
    return _loaded("numpy")


def scipy_special() -> ModuleType:
    """The ``scipy.special`` module, numpy's and scipy's OpenBLAS loaded
    with one thread (numpy is loaded with this module).  Raises
    :class:`~rclverify.core.extras.MissingExtra` (an ``ImportError``) when
    scipy, the ``stats`` extra, is missing."""
    try:
        return _loaded("scipy.special")  # 0.3 s, only where a statistic is computed
    except ImportError as exc:
        from rclverify.core.extras import MissingExtra, installed  # deferred: only when scipy is missing
        if installed("scipy"):
            raise
        raise MissingExtra("scipy", "the exact Clopper-Pearson bound") from exc


def _loaded(name: str) -> ModuleType:
    """The module ``name``, imported inside :func:`one_blas_thread` the first
    time only: once loaded, the environment is not touched again (it is the
    whole process's)."""
    module = sys.modules.get(name)
    if module is None:
        with one_blas_thread():
            module = importlib.import_module(name)
    return module


if TYPE_CHECKING:  # the type checker reads numpy's own annotations (np.ndarray, dtypes)
    import numpy

    np = numpy  # a module alias, exported to the modules that import ``np`` from here
else:
    np = import_numpy()
