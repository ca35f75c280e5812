"""The SPIN keys of an ``ajpf`` plan entry (:mod:`.backend`'s module
docstring), checked (:func:`read_spin_config`), which model checker an
entry uses (:func:`chosen_checker`) and its time limit
(:func:`spin_timeout`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.backends.base import NodeTarget
from rclverify.backends.model_checking import spin

if TYPE_CHECKING:
    from rclverify.backends.model_checking.environment import Environment

#: the model checkers an entry may name
CHECKERS = ("spin", "ajpf")
DEFAULT_MAX_STATES = 100_000
DEFAULT_MAX_DEPTH = 10_000


@dataclass(frozen=True)
class SpinConfig:
    """The SPIN keys of an ``ajpf`` entry, checked (module docstring)."""

    environment: "Environment | None"
    environment_raw: Any
    max_states: int
    max_depth: int
    properties: tuple[str, ...]


def read_spin_config(target: NodeTarget) -> SpinConfig:
    """Check the SPIN keys of ``target.config``.  Raises a located
    :class:`PlanError` for a bad ``model_checker``, ``environment``,
    ``max_states``/``max_depth`` or ``properties`` value, and for
    ``model_checker: spin`` without an ``environment``."""
    cfg = target.config
    checker = cfg.get("model_checker")
    if checker is not None and checker not in CHECKERS:
        raise target.config_error(f"'model_checker' must be one of {', '.join(CHECKERS)}, found {checker!r}",
                                  "model_checker")
    env = None
    if "environment" in cfg:
        try:
            from rclverify.backends.model_checking.environment import environment_from_plan  # stage one; deferred: optional or conditional (inside a block)
        except ImportError:  # an installation without stage one: its evidence says so (run_spin)
            pass
        else:
            env = environment_from_plan(cfg["environment"], lambda *p: target.config_loc("environment", *p))
    elif checker == "spin":
        raise target.config_error("model_checker spin needs an 'environment': the percepts the verification "
                                  "environment may send (docs/plan.md, ajpf)", "model_checker")
    bounds = {}
    for key, default in (("max_states", DEFAULT_MAX_STATES), ("max_depth", DEFAULT_MAX_DEPTH)):
        v = cfg.get(key, default)
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise target.config_error(f"'{key}' must be a positive integer", key)
        bounds[key] = v
    props = cfg.get("properties", [])
    if not isinstance(props, list) or not all(isinstance(p, str) and p for p in props):
        raise target.config_error("'properties' must be a list of property files (workspace-relative)",
                                  "properties")
    for i, p in enumerate(props):
        if not (target.root / p).is_file():
            raise target.config_error(f"property file {p!r} does not exist", "properties", i)
    return SpinConfig(env, cfg.get("environment"), bounds["max_states"], bounds["max_depth"], tuple(props))


def chosen_checker(config: Mapping[str, object], environ: Mapping[str, str] | None = None) -> str:
    """``spin`` or ``ajpf`` for an entry (see the module docstring for the default)."""
    checker = config.get("model_checker")
    if checker in CHECKERS:
        return str(checker)
    env = os.environ if environ is None else environ
    mcapl = config.get("mcapl_home") or env.get("MCAPL_HOME") or env.get("AJPF_HOME")
    return "spin" if "environment" in config and not mcapl else "ajpf"


def spin_timeout(config: Mapping[str, object]) -> float:
    """The entry's ``timeout_s`` (checked by the ajpf backend's read_config), else
    :data:`spin.DEFAULT_TIMEOUT_S`: the limit of each tool run and of the exploration."""
    v = config.get("timeout_s")
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0 else spin.DEFAULT_TIMEOUT_S
