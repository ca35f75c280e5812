"""The keys an evidence entry of each backend may have.

One table for every backend (docs/plan.md, "Evidence entries"), so a
misspelt key -- ``max_example: 50``, ``horizn: 1`` -- is a located error when
the plan is checked instead of an option silently left at its default.
Every entry may also carry ``backend`` and ``expected`` (docs/plan.md,
"Expected verdicts").
"""
from __future__ import annotations

import difflib
from typing import Any, Mapping

#: Keys every entry may have, whatever its backend.
COMMON_KEYS: tuple[str, ...] = ("backend", "expected")

#: Backend name -> the keys of its own configuration.
ENTRY_KEYS: dict[str, tuple[str, ...]] = {
    "hoare": ("program", "binding", "timeout_ms"),
    "dafny": ("implementation", "executable", "time_limit", "timeout", "dafny", "options"),
    "ajpf": ("agent", "model", "domains", "mapping", "environment_class", "mcapl_home", "timeout_s", "results",
             "log_info"),
    "property_tests": ("implementation", "max_examples", "seed", "deadline_ms", "steps", "bounds"),
    "experiment": ("guarantee", "summary", "data", "column", "unit", "better", "constants", "criterion",
                   "timeout_ms"),
    "review": ("record",),
    "monitors": ("traces", "mapping", "horizon"),
}


def allowed_keys(backend: str) -> tuple[str, ...]:
    """Every key an entry of ``backend`` may have (common keys first).
    Raises ``KeyError`` for an unknown backend."""
    return COMMON_KEYS + ENTRY_KEYS[backend]


def unknown_key_messages(backend: str, entry: Mapping[str, Any]) -> list[tuple[str, str]]:
    """``(key, message)`` for each key of ``entry`` its backend does not know,
    in the entry's order, the message naming the closest allowed key if any.
    An unknown backend gives ``[]`` (the plan loader reports it)."""
    if backend not in ENTRY_KEYS:
        return []
    allowed = allowed_keys(backend)
    out = []
    for k in entry:
        if k in allowed:
            continue
        close = difflib.get_close_matches(str(k), allowed, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else f"; its keys are: {', '.join(allowed)}"
        out.append((str(k), f"unknown key {k!r} in a {backend} evidence entry{hint}"))
    return out
