"""Bounds on the YAML the tool reads (the plan and the files it names).

PyYAML's composer keeps an alias as a second reference to the anchored node,
so a small file can describe an exponentially large document (the "billion
laughs" alias bomb), and an anchor may even refer to itself (a cycle).  The
plan loader turns the node graph into plain data, which would expand every
alias.  This module refuses such input before that happens:

``check_size(path, file)``      the file is at most :data:`MAX_YAML_BYTES`
                                bytes (checked with ``stat``, before reading);
``compose_guarded(text, file)`` ``yaml.compose`` with the safe loader, then an
                                iterative walk of the node graph that counts
                                the nodes the expansion would produce
                                (memoised per node, so the walk itself is
                                linear in the file) and refuses an expansion
                                that aliases make more than
                                :data:`MAX_YAML_NODES` larger than the nodes
                                written (a document without aliases is bounded
                                by its size alone, however many entries it
                                has), an alias cycle, or nesting deeper than
                                :data:`MAX_YAML_DEPTH`.

``to_data(node, file, ...)``     the plain data of a composed node, with a
                                location for every value path (the plan
                                loader's form);
``safe_load_guarded(text, file)`` the same for every other YAML file the plan
                                names (review records, summary statistics,
                                trace mappings), keys constructed as
                                ``yaml.safe_load`` would;
``read_yaml_text(path, file)``  a YAML file's text (a regular file only: a FIFO,
                                device or socket is refused without waiting on
                                it, :func:`rclverify.core.within.read_regular`;
                                size bound, UTF-8 rules of
                                :mod:`rclverify.lang.source`: a UTF-8
                                byte-order mark accepted, UTF-16/32 and
                                invalid UTF-8 refused naming the encoding).

Every YAML file the tool reads goes through this one guarded loader, which
also refuses (docs/plan.md, "YAML rules"):

* a duplicate key in a mapping (YAML 1.2 section 3.2.1.1: keys are unique;
  PyYAML keeps the last silently), located at the second key, naming the
  line of the first;
* a tag on a list or a mapping other than the standard ``!!seq``/``!!map``
  (``!!python/tuple``, ``!!set``, ``!custom``...), as the safe constructor
  refuses a non-standard tag on a scalar;
* a merge key ``<<`` (YAML 1.1 only; the plan never read it, and reading it
  in the other files would make the same text mean two things).

Every refusal is a :class:`~rclverify.model.plan.errors.PlanError` located in the
file (``E-yaml-limit`` for the bounds, ``E-yaml`` for the rules above);
memory stays bounded by the file size.  The limits are far above any real
plan (the case study's plan has a few hundred nodes); docs/rcl-language.md
records them.
"""
from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rclverify.core.within import read_regular
from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.lang.source import decode_text

if TYPE_CHECKING:
    import yaml

Path_ = tuple[Any, ...]
#: Marker in a location path: ``path + (key, KEY)`` is where the key itself is written.
KEY = "\0key"
#: Block scalars (``|``/``>``) by value path: (first content line, the content's source lines).
Blocks = dict[Path_, tuple[int, str]]
#: The only tags a list or a mapping may carry (the YAML 1.2 core schema's).
COLLECTION_TAGS = frozenset({"tag:yaml.org,2002:seq", "tag:yaml.org,2002:map"})


@lru_cache(maxsize=1)
def _composer() -> Any:
    """The safe loader that composes the node graph: libyaml's where PyYAML was built with it (the
    same nodes and marks, eight times faster: 1.7 of the 1000-node plan's 1.9 s were PyYAML's
    pure-Python scanner), else PyYAML's own.  Malformed YAML is composed again by PyYAML's own
    loader, whose messages name what it found, so the error a user sees does not depend on libyaml."""
    import yaml  # deferred: start-up (a warm start reads its YAML files from the start-up cache, core/cache/startup.py)
    return getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def __getattr__(name: str) -> Any:
    """``_COMPOSER``: :func:`_composer`'s loader (PyYAML imported when it is first asked for)."""
    if name == "_COMPOSER":
        return _composer()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def yaml_error() -> type[Exception]:
    """``yaml.YAMLError`` (PyYAML imported when it is first asked for): an ``except yaml_error():`` clause
    imports PyYAML only when an exception reaches it."""
    import yaml  # deferred: start-up (as above)
    return yaml.YAMLError


#: Largest plan file read, in bytes (1 MiB).
MAX_YAML_BYTES = 1 << 20
#: Largest number of YAML nodes aliases may add to those written, when expanded.
MAX_YAML_NODES = 100_000
#: Deepest nesting of YAML collections.
MAX_YAML_DEPTH = 100


def check_size(path: Path, file: str) -> None:
    """Raise ``PlanError`` when ``path`` is larger than :data:`MAX_YAML_BYTES`
    (a missing file is left to the caller's read)."""
    try:
        size = os.stat(path).st_size
    except OSError:
        return
    if size > MAX_YAML_BYTES:
        raise plan_error(file, 1, 1, f"file is {size} bytes, above the limit of {MAX_YAML_BYTES} bytes for YAML input",
                         "E-yaml-limit")


def _children(node: yaml.Node) -> list[yaml.Node]:
    import yaml  # deferred: start-up (as _composer)
    if isinstance(node, yaml.MappingNode):
        return [x for kv in node.value for x in kv]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _refuse(file: str, node: yaml.Node, message: str) -> PlanError:
    mark = node.start_mark
    return plan_error(file, mark.line + 1, mark.column + 1, message, "E-yaml-limit")


def compose_guarded(text: str, file: str) -> yaml.Node | None:
    """``yaml.compose(text)`` with the limits of the module docstring.

    Returns the root node (``None`` for an empty document).  Raises
    ``yaml.YAMLError`` for malformed YAML (the caller locates it) and
    ``PlanError`` for input over a limit."""
    if len(text.encode("utf-8", "surrogatepass")) > MAX_YAML_BYTES:
        raise plan_error(file, 1, 1, f"YAML text above the limit of {MAX_YAML_BYTES} bytes", "E-yaml-limit")
    import yaml  # deferred: start-up (as _composer)
    composer = _composer()
    try:
        try:
            root = yaml.compose(text, Loader=composer)
        except yaml.YAMLError:
            if composer is yaml.SafeLoader:
                raise
            # PyYAML's own scanner says more (it names the character found); the error is its
            root = yaml.compose(text, Loader=yaml.SafeLoader)
    except RecursionError:
        raise plan_error(file, 1, 1, f"YAML nested too deeply (limit {MAX_YAML_DEPTH})", "E-yaml-limit") from None
    if root is None:
        return None
    size: dict[int, int] = {}
    on_path: set[int] = set()
    # Post-order walk with an explicit stack: (node, depth, children done?).
    stack: list[tuple[yaml.Node, int, bool]] = [(root, 1, False)]
    while stack:
        node, depth, done = stack.pop()
        key = id(node)
        if done:
            on_path.discard(key)
            total = 1 + sum(size[id(c)] for c in _children(node))
            # the node's subtree holds at most the len(size) + 1 distinct nodes done so far: what it
            # expands to beyond them comes from aliases
            if total - len(size) - 1 > MAX_YAML_NODES:
                raise _refuse(file, node, f"YAML aliases expand to more than {MAX_YAML_NODES} nodes beyond those "
                                          "written (alias bomb?); refused")
            size[key] = total
            continue
        if key in size:
            continue
        if key in on_path:
            raise _refuse(file, node, "YAML alias refers to a node that contains it (a cycle); refused")
        if depth > MAX_YAML_DEPTH:
            raise _refuse(file, node, f"YAML nested too deeply (limit {MAX_YAML_DEPTH})")
        on_path.add(key)
        stack.append((node, depth, True))
        for c in reversed(_children(node)):
            if id(c) in on_path:
                raise _refuse(file, c, "YAML alias refers to a node that contains it (a cycle); refused")
            if id(c) not in size:
                stack.append((c, depth + 1, False))
    return root


def _short_tag(tag: str) -> str:
    return "!!" + tag[len("tag:yaml.org,2002:"):] if tag.startswith("tag:yaml.org,2002:") else tag


def to_data(node: yaml.Node, file: str, *, locs: dict[Path_, ast.Loc] | None = None, lines: list[str] | None = None,
            blocks: Blocks | None = None, raw_keys: bool = True) -> Any:
    """The plain value of the composed ``node`` of ``file``.

    ``locs`` (when given) receives ``file:line:col`` of every value path (a
    quoted scalar's column is that of its first character) and, at
    ``path + (key, KEY)``, of every mapping key; ``blocks`` (with ``lines``,
    the file's lines) receives each block scalar's first content line and
    source.  ``raw_keys=True`` keeps a key as written (``1:`` is ``"1"``, the
    plan's convention); ``False`` constructs it as ``yaml.safe_load`` does.

    Raises ``PlanError`` (``E-yaml``) for a key that is a list or a mapping, a
    duplicate key, or a tag on a collection (module docstring), and
    ``yaml.YAMLError`` (with the node's mark) for a scalar tag the safe
    constructor does not know."""
    import yaml  # deferred: start-up (as _composer)
    loader = yaml.SafeLoader("")
    out_locs: dict[Path_, ast.Loc] = {} if locs is None else locs
    out_blocks: Blocks = {} if blocks is None else blocks
    src = lines or []

    def construct(n: yaml.Node) -> Any:
        return loader.construct_object(n, deep=True)

    def err(mark: Any, message: str) -> PlanError:
        return plan_error(file, mark.line + 1, mark.column + 1, message, "E-yaml")

    def walk(n: yaml.Node, path: Path_) -> Any:
        mark = n.start_mark
        quoted = isinstance(n, yaml.ScalarNode) and n.style in ("'", '"')
        out_locs[path] = ast.Loc(file, mark.line + 1, mark.column + 1 + (1 if quoted else 0))
        if isinstance(n, yaml.ScalarNode):
            if n.style in ("|", ">") and lines is not None:
                first, last = mark.line + 1, n.end_mark.line
                raw = src[first:last + 1] if n.end_mark.column else src[first:last]
                out_blocks[path] = (first + 1, "\n".join(raw))
            return construct(n)
        if n.tag not in COLLECTION_TAGS:
            kind = "a mapping" if isinstance(n, yaml.MappingNode) else "a list"
            raise err(mark, f"tag {_short_tag(n.tag)!r} on {kind} is not allowed: rclverify reads plain YAML "
                            "data (mappings, lists, strings, numbers, booleans), without tags")
        if isinstance(n, yaml.SequenceNode):
            return [walk(v, path + (i,)) for i, v in enumerate(n.value)]
        out: dict[Any, Any] = {}
        first_at: dict[Any, int] = {}
        for k, v in n.value:
            if not isinstance(k, yaml.ScalarNode):
                raise err(k.start_mark, "a mapping key must be a plain value, not a list or a mapping")
            if k.tag == "tag:yaml.org,2002:merge":
                raise err(k.start_mark, "merge keys ('<<') are a YAML 1.1 extension rclverify does not read; "
                                        "write the keys out")
            key = k.value if raw_keys else construct(k)
            try:
                seen = key in first_at
            except TypeError:  # an unhashable key constructed from a scalar cannot happen; be safe
                raise err(k.start_mark, "a mapping key must be a plain value") from None
            if seen:
                raise err(k.start_mark, f"duplicate key {k.value!r} in a mapping (first written at line "
                                        f"{first_at[key]}); each key may appear once")
            first_at[key] = k.start_mark.line + 1
            out[key] = walk(v, path + (key,))
            out_locs[path + (key, KEY)] = ast.Loc(file, k.start_mark.line + 1, k.start_mark.column + 1)
        return out

    try:
        return walk(node, ())
    finally:
        loader.dispose()


def safe_load_guarded(text: str, file: str) -> object:
    """The data of the YAML ``text`` of ``file``, as ``yaml.safe_load`` would
    give it, once :func:`compose_guarded` has accepted it, through
    :func:`to_data` (duplicate keys and tags on collections refused).

    Raises ``yaml.YAMLError`` for malformed YAML and ``PlanError`` (located in
    ``file``) for input over a limit, before any alias is expanded, or
    refused by :func:`to_data`."""
    return load_located(text, file)[0]


def load_located(text: str, file: str) -> tuple[object, dict[Path_, ast.Loc]]:
    """``(data, locations)`` of the YAML ``text`` of ``file``: as
    :func:`safe_load_guarded`, with the location of every value path (and
    of every key at ``path + (key, KEY)``)."""
    node = compose_guarded(text, file)
    locs: dict[Path_, ast.Loc] = {}
    if node is None:
        return None, locs
    return to_data(node, file, locs=locs, raw_keys=False), locs


def read_yaml_text(path: Path, file: str) -> str:
    """The text of the YAML file at ``path`` (named ``file`` in messages).

    Raises ``PlanError``: over :data:`MAX_YAML_BYTES` (``E-yaml-limit``), not
    readable or not a regular file (``E-io``: a FIFO is refused, never waited
    on), not UTF-8 (``E-encoding``, naming the encoding a byte-order mark
    shows; :mod:`rclverify.lang.source`)."""
    check_size(path, file)
    try:
        data = read_regular(path)
    except OSError as exc:
        raise plan_error(file, 1, 1, f"cannot read file: {exc.strerror or exc}", "E-io") from None
    try:
        return decode_text(data, file)
    except RclError as exc:
        raise PlanError(exc.diagnostics) from None


def schema_error_loc(error: Any, locs: dict[Path_, ast.Loc] | Any, file: str) -> ast.Loc:
    """Where a ``jsonschema`` validation ``error`` of YAML data read by
    :func:`load_located` is written: the unexpected key itself for an
    ``additionalProperties`` error, else the value's path, or its nearest
    written ancestor (``file:1:1`` when none is)."""
    path: Path_ = tuple(error.absolute_path)
    if error.validator == "additionalProperties" and isinstance(error.instance, dict):
        extra = _unknown_keys(error)
        if extra and path + (extra[0], KEY) in locs:
            path = path + (extra[0], KEY)
    while path and path not in locs:
        path = path[:-1]
    loc: ast.Loc = locs.get(path, ast.Loc(file, 1, 1))
    return loc


def _unknown_keys(error: Any) -> list[Any]:
    """The keys an ``additionalProperties`` ``error`` refuses, in written order."""
    allowed = set(error.schema.get("properties", {})) if isinstance(error.schema, dict) else set()
    return [k for k in error.instance if k not in allowed] if isinstance(error.instance, dict) else []


def _named_missing(error: Any) -> str | None:
    """The one required key an ``additionalProperties`` ``error``'s object
    lacks while it has exactly one unknown key (that key may mean it), else ``None``."""
    schema = error.schema if isinstance(error.schema, dict) else {}
    if error.validator != "additionalProperties" or len(_unknown_keys(error)) != 1:
        return None
    missing = [str(r) for r in schema.get("required", []) if r not in error.instance]
    return missing[0] if len(missing) == 1 else None


def schema_messages(errors: list[Any], where_of: Any) -> list[tuple[Any, str]]:
    """``(error, message)`` for each ``jsonschema`` error of ``errors`` worth
    a line (:func:`schema_message`; ``where_of(error)`` is its place).  A
    missing required key is left out when an unknown key beside it is
    already said to perhaps mean it, so one slip gives one line."""
    hinted = {(tuple(e.absolute_path), m) for e in errors if (m := _named_missing(e)) is not None}
    out: list[tuple[Any, str]] = []
    for e in errors:
        if e.validator == "required" and isinstance(e.validator_value, list):
            missing = [r for r in e.validator_value if isinstance(e.instance, dict) and r not in e.instance]
            if missing and all((tuple(e.absolute_path), str(r)) in hinted for r in missing):
                continue
        out.append((e, schema_message(e, where_of(e))))
    return out


def schema_message(error: Any, where: str) -> str:
    """The one-line message of a ``jsonschema`` validation ``error`` at
    ``where`` (``"plan"``, ``"nodes.Base"``): an unknown key is named as
    one, with the known key it may mean (a close spelling, or the one
    required key missing beside it) and the keys that are known; a missing
    key is named as one; every other error keeps jsonschema's text."""
    schema = error.schema if isinstance(error.schema, dict) else {}
    known = sorted(map(str, schema.get("properties", {})))
    if error.validator == "additionalProperties" and known and (unknown := _unknown_keys(error)):
        key = str(unknown[0])
        import difflib  # deferred: start-up (a close spelling is only looked for in an error)
        close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
        missing = _named_missing(error)
        if close:
            hint = f" (did you mean {close[0]!r}?)"
        elif missing is not None:
            hint = f" (did you mean {missing!r}? it is required and missing)"
        else:
            hint = ""
        more = f" (and {', '.join(repr(str(k)) for k in unknown[1:])})" if len(unknown) > 1 else ""
        return f"{where}: unknown key {key!r}{more}{hint}; the known keys are: {', '.join(known)}"
    if error.validator == "required":
        return f"{where}: {error.message.replace(' is a required property', '')} is a required key and is missing"
    return f"{where}: {error.message}"

