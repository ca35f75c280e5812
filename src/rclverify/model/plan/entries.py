"""The evidence-entry schemas: what each backend's plan entries hold.

Each backend declares, in its ``declaration.yaml`` (read by :mod:`.declarations`,
the one registry of backends), the schema of its plan entry
(``nodes.<Node>.evidence[k]``, docs/plan.md "Evidence entries"):

``keys``        every key of the backend's own configuration (besides the
                :data:`COMMON_KEYS` every entry may have);
``path_keys``   keys whose value names a file or directory of the workspace
                (a string or a list of strings); ``implementation`` values of
                the form ``<file>:<callable>`` name the file before the last
                ``:``;
``tool_keys``   keys whose value names an installed tool or a tool's options
                (``dafny: PATH``, ``mcapl_home: DIR``, ``options``): never a
                workspace file, so never refused for lying outside the
                workspace and never a doit file dependency.

The declarations are read as data, below both the plan and the backends: the
plan validates an entry against them without importing any backend's code.
"""
from __future__ import annotations

from typing import Any, Iterator, Mapping

from rclverify.model.plan.declarations import BACKEND_NAMES as BACKEND_NAMES, DECLARATIONS, PlanEntry

#: Keys every entry may have, whatever its backend.
COMMON_KEYS: tuple[str, ...] = ("backend", "expected")


#: Backend name -> schema, in registry order (each backend's ``declaration.yaml``, :mod:`.declarations`).
SCHEMAS: dict[str, PlanEntry] = {d.name: d.plan for d in DECLARATIONS.values()}

#: Every key, of any backend, that names a tool rather than a workspace file.
TOOL_KEYS: frozenset[str] = frozenset(k for s in SCHEMAS.values() for k in s.tool_keys)

#: Tool keys whose value, when written as a path (with a ``/``), must name an existing
#: ``executable`` file or ``directory`` (relative paths from the workspace root).  A bare
#: command name (``dafny: dafny``) is looked up on ``PATH`` when the backend runs, and a
#: missing one leaves the evidence ``pending`` with the command to run.
TOOL_PATH_KINDS: dict[str, str] = {k: v for d in DECLARATIONS.values() for k, v in d.plan.tool_paths.items()}


def allowed_keys(backend: str) -> tuple[str, ...]:
    """Every key an entry of ``backend`` may have (common keys first).
    Raises ``KeyError`` for an unknown backend."""
    return COMMON_KEYS + SCHEMAS[backend].keys


def unknown_key_messages(backend: str, entry: Mapping[str, Any]) -> list[tuple[str, str]]:
    """``(key, message)`` for each key of ``entry`` its backend does not know,
    in the entry's order, the message naming the closest allowed key if any.
    An unknown backend gives ``[]`` (the plan loader reports it)."""
    if backend not in SCHEMAS:
        return []
    allowed = allowed_keys(backend)
    out = []
    for k in entry:
        if k in allowed:
            continue
        import difflib  # deferred: start-up (a close spelling is only looked for in an error)
        close = difflib.get_close_matches(str(k), allowed, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else f"; its keys are: {', '.join(allowed)}"
        out.append((str(k), f"unknown key {k!r} in a {backend} evidence entry{hint}"))
    return out


def declared_paths(entry: Mapping[str, Any]) -> Iterator[tuple[tuple[Any, ...], str]]:
    """``(value path within the entry, workspace path)`` for every declared
    path value of ``entry`` (its backend's ``path_keys``; a ``<file>:<name>``
    value gives its file part).  Non-string values are left to the backend's
    own checks; an unknown backend declares nothing."""
    schema = SCHEMAS.get(str(entry.get("backend")))
    if schema is None:
        return
    for key in sorted(schema.path_keys):
        value = entry.get(key)
        values = [((key,), value)] if isinstance(value, str) else \
            [((key, i), v) for i, v in enumerate(value) if isinstance(v, str)] if isinstance(value, list) else []
        for path, v in values:
            if key in schema.qualified_keys and ":" in v:
                v = v.rpartition(":")[0]
            yield path, v


def is_tool_key(backend: str, key: str) -> bool:
    """``key`` names a tool (or tool options) in an entry of ``backend``."""
    schema = SCHEMAS.get(backend)
    return key in (schema.tool_keys if schema is not None else TOOL_KEYS)
