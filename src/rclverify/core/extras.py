"""The optional parts of rclverify, and the one line said when one is missing.

The default install is the core (docs/install.md); what serves one part
only is an extra of the ``rclverify`` distribution (``pyproject.toml``,
``[project.optional-dependencies]``).  :func:`require` imports a module of
an extra or raises :class:`MissingExtra`, whose message names the extra
and the command that installs it; the CLI prints it as one line with exit
code 1, and evidence that needed the module says so in its explanation.
"""
from __future__ import annotations

import importlib
import importlib.util
from functools import lru_cache
from types import ModuleType

#: The extra that installs each optional top-level module (pyproject.toml).
EXTRA_OF: dict[str, str] = {
    "numpy": "fast", "rosbags": "ros", "catkin_pkg": "ros", "lxml": "ros", "tree_sitter": "ros", "tree_sitter_cpp": "ros",
    "tree_sitter_python": "ros", "cyclonedds": "ros2", "matplotlib": "plots", "scipy": "stats",
    "dask": "cluster", "distributed": "cluster", "doorstop": "doorstop", "cryptography": "sign",
    "pygls": "lsp", "lsprotocol": "lsp", "openpyxl": "xlsx",
}


class MissingExtra(ImportError):
    """An optional module is not installed.  ``str(exc)`` is one line:
    ``<purpose> needs rclverify's [<extra>] extra: pip install 'rclverify[<extra>]'``.

    A subclass of ``ImportError``, so code that already degrades on a
    missing import keeps doing so."""

    def __init__(self, module: str, purpose: str) -> None:
        self.module = module
        self.extra = EXTRA_OF.get(module.split(".")[0], "all")
        self.purpose = purpose
        super().__init__(missing_message(module, purpose), name=module)


def missing_message(module: str, purpose: str) -> str:
    """The one line for ``module`` missing while doing ``purpose`` (a noun
    phrase: "reading a ROS 2 bag")."""
    extra = EXTRA_OF.get(module.split(".")[0], "all")
    return (f"{purpose} needs rclverify's [{extra}] extra ({module.split('.')[0]} is not installed): "
            f"pip install 'rclverify[{extra}]'")


def require(module: str, purpose: str) -> ModuleType:
    """``importlib.import_module(module)``; raises :class:`MissingExtra`
    when the module's top-level package is not installed (an ``ImportError``
    raised from inside an installed package is not hidden)."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        top = module.split(".")[0]
        if exc.name is not None and (exc.name == top or exc.name.startswith(top + ".") or exc.name == module):
            raise MissingExtra(module, purpose) from None
        if importlib.util.find_spec(top) is None:
            raise MissingExtra(module, purpose) from None
        raise


@lru_cache(maxsize=None)
def installed(module: str) -> bool:
    """Whether the top-level package of ``module`` can be imported (nothing is
    imported); asked once per process (every trace read asks it)."""
    try:
        return importlib.util.find_spec(module.split(".")[0]) is not None
    except (ImportError, ValueError):
        return False


__all__ = ["EXTRA_OF", "MissingExtra", "installed", "missing_message", "require"]
