"""The ``dafny`` backend's plan entry, checked (keys in :mod:`.backend`'s
module docstring): :class:`DafnyConfig`, or an :class:`RclError` located
in the plan (code ``E-plan-dafny``).
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.lang.errors import RclError
from rclverify.backends.base import NodeTarget
from rclverify.backends.dafny.stubgen import snake

#: Dafny's time limit per verification condition and the whole process's, seconds
DEFAULT_TIME_LIMIT_S = 60
DEFAULT_TIMEOUT_S = 600


class DafnyConfig:
    """The validated plan entry (see the module docstring)."""

    def __init__(self, target: NodeTarget) -> None:
        cfg: Mapping[str, Any] = target.config
        where = f"nodes.{target.node.name}.evidence[{target.index}]"

        def bad(key: str, what: str) -> RclError:
            return target.config_error(f"{where}.{key} must be {what}, found {cfg.get(key)!r}", key,
                                       code="E-plan-dafny")

        impl = cfg.get("implementation", f"backends/dafny/{snake(target.node.name)}.dfy")
        if not isinstance(impl, str) or not impl.endswith(".dfy"):
            raise bad("implementation", "a workspace-relative path of a .dfy file")
        self.implementation = impl.replace("\\", "/")
        executable = cfg.get("executable", False)
        if not isinstance(executable, bool):
            raise bad("executable", "true or false")
        self.ghost = not executable
        self.time_limit = cfg.get("time_limit", DEFAULT_TIME_LIMIT_S)
        if isinstance(self.time_limit, bool) or not isinstance(self.time_limit, int) or self.time_limit <= 0:
            raise bad("time_limit", "a positive whole number of seconds")
        self.timeout = cfg.get("timeout", DEFAULT_TIMEOUT_S)
        if isinstance(self.timeout, bool) or not isinstance(self.timeout, (int, float)) or self.timeout <= 0:
            raise bad("timeout", "a positive number of seconds")
        self.dafny = cfg.get("dafny", "dafny")
        if not isinstance(self.dafny, str) or not self.dafny:
            raise bad("dafny", "a command name or path")
        options = cfg.get("options", [])
        if not isinstance(options, list) or not all(isinstance(o, str) and o[:1] in "/-" and o for o in options):
            raise bad("options", "a list of Dafny command-line options (each starting with '/' or '-')")
        self.options: tuple[str, ...] = tuple(options)
