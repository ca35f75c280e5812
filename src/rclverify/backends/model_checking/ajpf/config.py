"""The ``ajpf`` backend's plan entry (``nodes.<Node>.evidence[k]``, keys
in :mod:`.backend`'s module docstring), checked: :func:`read_config` gives
an :class:`AjpfConfig` or raises :class:`PlanError` located in the plan
file.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Mapping

from rclverify.model.plan.errors import PlanError
from rclverify.lang.errors import RclError
from rclverify.backends.base import NodeTarget
from rclverify.backends.model_checking.ajpf.mapping import Row, RowError, build_row

DEFAULT_ENV = "ail.mas.DefaultEnvironment"
DEFAULT_RESULTS = "backends/ajpf/results"
#: AJPF's time limit per run, seconds: minutes, not hours (a run that hits it is inconclusive and says so).
DEFAULT_TIMEOUT_S = 600.0
#: Loggers at info level: the property echo, the environment's actions and the
#: product automaton's path (used to give counterexamples their actions).
DEFAULT_LOG_INFO = ("ail.util.AJPF_w_AIL", "ail.mas.DefaultEnvironment", "ajpf.product.Product")
#: Upper bound on the number of instances of one guarantee.
MAX_INSTANCES = 10000
_JAVA_CLASS = re.compile(r"^[A-Za-z_$][\w$]*(\.[A-Za-z_$][\w$]*)*$")
_AGENT = re.compile(r"^[a-z][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class AjpfConfig:
    """A checked ``ajpf`` plan entry (see the module docstring for the keys)."""

    agent: str
    model: str
    domains: Mapping[str, tuple[int, int]]
    rows: tuple[Row, ...]
    environment_class: str = DEFAULT_ENV
    mcapl_home: str | None = None
    timeout_s: float = DEFAULT_TIMEOUT_S
    results: str = DEFAULT_RESULTS
    log_info: tuple[str, ...] = DEFAULT_LOG_INFO
    spin: Any = None  # model_checking.spin_config.SpinConfig: the SPIN keys, checked


def read_config(target: NodeTarget) -> AjpfConfig:
    """Check the plan entry ``target.config`` and the mapping rows in it.

    Raises :class:`PlanError` (located in the plan file) for
    a missing or ill-typed value, a model file that does not exist, an
    invalid domain, or a mapping row that does not parse or check.
    """
    cfg = target.config  # its keys were checked when the plan was resolved (backends/keys.py)
    agent = cfg.get("agent")
    if not isinstance(agent, str) or not _AGENT.match(agent):
        raise target.config_error("'agent' must name the Gwendolen agent (a lower-case name, e.g. jackal)", "agent")
    model = cfg.get("model")
    if not isinstance(model, str) or not model:
        raise target.config_error("'model' must be the workspace-relative path of the Gwendolen program", "model")
    if not (target.root / model).is_file():
        raise target.config_error(f"model file {model!r} does not exist", "model")
    domains = _domains(cfg.get("domains", {}), target)
    env_class = cfg.get("environment_class", DEFAULT_ENV)
    if not isinstance(env_class, str) or not _JAVA_CLASS.match(env_class):
        raise target.config_error("'environment_class' must be a Java class name", "environment_class")
    home = cfg.get("mcapl_home")
    if home is not None and not isinstance(home, str):
        raise target.config_error("'mcapl_home' must be a directory path", "mcapl_home")
    timeout = cfg.get("timeout_s", DEFAULT_TIMEOUT_S)
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or timeout <= 0:
        raise target.config_error("'timeout_s' must be a positive number of seconds", "timeout_s")
    results = cfg.get("results", DEFAULT_RESULTS)
    if not isinstance(results, str) or not results:
        raise target.config_error("'results' must be a workspace-relative directory", "results")
    log_info = cfg.get("log_info", list(DEFAULT_LOG_INFO))
    if not isinstance(log_info, list) or not all(isinstance(x, str) and _JAVA_CLASS.match(x) for x in log_info):
        raise target.config_error("'log_info' must be a list of logger (class) names", "log_info")
    rows = _rows(cfg.get("mapping", []), target, agent, domains)
    from rclverify.backends.model_checking.spin_config import read_spin_config  # lazily: model_checking imports ajpf.psl; deferred: start-up (loads rclverify.backends.model_checking, rclverify.lang.source and more only when called)
    return AjpfConfig(agent, model, domains, rows, env_class, home, float(timeout), results.rstrip("/"),
                      tuple(log_info), read_spin_config(target))


def _domains(raw: Any, target: NodeTarget) -> dict[str, tuple[int, int]]:
    if not isinstance(raw, Mapping):
        raise target.config_error("'domains' must map variable names to [low, high] (inclusive)", "domains")
    out: dict[str, tuple[int, int]] = {}
    size = 1
    for name, bounds in raw.items():
        ok = (isinstance(bounds, (list, tuple)) and len(bounds) == 2
              and all(isinstance(b, int) and not isinstance(b, bool) for b in bounds))
        if not isinstance(name, str) or not ok:
            raise target.config_error(f"domain of {name!r} must be [low, high] with integer bounds", "domains", name)
        lo, hi = bounds
        if lo > hi:
            raise target.config_error(f"domain of {name!r} is empty: {lo} > {hi}", "domains", name)
        size *= hi - lo + 1
        out[name] = (lo, hi)
    if size > MAX_INSTANCES:
        raise target.config_error(f"the domains give {size} instances per guarantee (limit {MAX_INSTANCES})", "domains")
    return out


def fixed_names(target: NodeTarget) -> set[str]:
    """The names of ``target``'s contract a mapping row reads as fixed values: enumeration values,
    constants and constructors without arguments."""
    env = target.checked.env
    names = set(env.enum_values) | set(env.constants)
    names |= {c for c, dt in env.ctors.items() if dt.ctor(c) == ()}
    return names


def io_sides(target: NodeTarget) -> dict[str, str]:
    """Each port of ``target``'s node -> ``"in"`` or ``"out"`` (an input wins a name both have)."""
    io = {n: "out" for n in target.node.outputs}
    io.update({n: "in" for n in target.node.inputs})
    return io


def _rows(raw: Any, target: NodeTarget, agent: str, domains: Mapping[str, tuple[int, int]],
          ) -> tuple[Row, ...]:
    if not isinstance(raw, list):
        raise target.config_error("'mapping' must be a list of rows {rcl: ..., ajpf: ...}", "mapping")
    rows = []
    fixed = fixed_names(target)
    io = io_sides(target)
    for k, item in enumerate(raw):
        try:
            rows.append(build_row(k, item, dom_names=domains, fixed=fixed, io=io, agent=agent,
                                  loc=target.config_loc("mapping", k, "rcl")))
        except RowError as exc:
            text = item.get(exc.key) if isinstance(item, Mapping) and isinstance(item.get(exc.key), str) else None
            raise target.config_error(f"mapping row {k + 1}: {exc}", "mapping", k, *((exc.key,) if text else ()),
                                      col_offset=max(exc.col - 1, 0) if text else 0) from None
        except RclError as exc:
            raise PlanError(exc.diagnostics) from None
    return tuple(rows)
