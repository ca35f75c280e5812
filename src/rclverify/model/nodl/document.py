"""A NoDL v2 document read, validated against the schema, its ``include``s followed and merged.

A document is JSON (a file named ``*.json``, read strictly by
:mod:`.jsonpos`) or YAML (any other name, read by the plan's guarded YAML
loader, :mod:`rclverify.model.plan.yamlguard`); both give the same data
and a location for every value.  The data is validated with ``jsonschema``
against ``nodl.schema.json`` beside this module (docs/nodl.md: written for
rclverify from the format ros-tooling/nodl publishes).  Each ``include``
reference is resolved (:class:`Resolver`: ``local://<path>`` relative to
the including document, ``nodl://<package>/<name>`` in the ament index of
the prefixes given), read the same way, and its endpoints and parameters
merged into the including document, as NoDL's ``include`` says: a document
included twice on one chain (a cycle) or twice in one tree, and a name
declared twice in one category (two publishers ``/status``), are located
errors.  Every user error is an :class:`~rclverify.lang.errors.RclError`
located at ``file:line:col`` (codes ``E-nodl-*``).
"""
from __future__ import annotations

import json
import os
import stat
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Callable, Sequence

import yaml

from rclverify.core.within import kind_of, outside
from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.model.nodl.jsonpos import load_json_located
from rclverify.model.plan.yamlguard import KEY, load_located, read_yaml_text, schema_error_loc

#: The endpoint lists of a document, in the schema's order, with the kind of interface each one's type is.
ENDPOINT_LISTS: dict[str, str] = {"publishers": "msg", "subscriptions": "msg", "service_servers": "srv",
                                  "service_clients": "srv", "action_servers": "action", "action_clients": "action"}
#: The QoS fields of the schema's ``qos`` object, in its order.
QOS_FIELDS = ("history", "depth", "reliability", "durability", "deadline_ns", "lifespan_ns", "liveliness",
              "liveliness_lease_duration_ns")
#: The endings of a NoDL document's file name, longest first (the node is the name before them).
SUFFIXES = (".nodl.yaml", ".nodl.yml", ".nodl.json")
#: The longest jsonschema message kept in a diagnostic, in characters (a message quotes the whole value).
MESSAGE_MAX = 160

Path_ = tuple[Any, ...]


def _fail(loc: ast.Loc, message: str, code: str) -> RclError:
    return RclError([error(loc, message, code)])


@dataclass(frozen=True)
class QoS:
    """A ``qos`` object as written: each field ``None`` when the document leaves it out.
    Durations are integers of nanoseconds (0: none, the schema's meaning)."""

    history: str
    reliability: str
    depth: int | None = None
    durability: str | None = None
    deadline_ns: int | None = None
    lifespan_ns: int | None = None
    liveliness: str | None = None
    liveliness_lease_duration_ns: int | None = None
    loc: ast.Loc = field(default_factory=ast.Loc, compare=False)
    #: where each written field's value is: (field, location)
    field_locs: tuple[tuple[str, ast.Loc], ...] = field(default=(), compare=False)

    def where(self, name: str) -> ast.Loc:
        """Where field ``name`` is written; the ``qos`` object's place when it is left out."""
        return dict(self.field_locs).get(name, self.loc)


@dataclass(frozen=True)
class Endpoint:
    """One entry of an endpoint list: ``kind`` is the list (``publishers``, ..., ``action_clients``),
    ``name`` and ``type`` as written; ``loc`` where the entry's name is written, ``type_loc`` its type."""

    kind: str
    name: str
    type: str
    qos: QoS | None = None
    loc: ast.Loc = field(default_factory=ast.Loc, compare=False)
    type_loc: ast.Loc = field(default_factory=ast.Loc, compare=False)


@dataclass(frozen=True)
class Parameter:
    """One entry of ``parameters``: ``type`` (``double``, ``int_array``, ...), ``default``
    (``has_default`` says whether one is written), ``read_only``, ``validation`` as written
    (validator name -> argument); ``loc`` where its name is written, ``default_loc`` its default."""

    name: str
    type: str
    default: Any = None
    has_default: bool = False
    read_only: bool = False
    validation: tuple[tuple[str, Any], ...] = ()
    loc: ast.Loc = field(default_factory=ast.Loc, compare=False)
    default_loc: ast.Loc = field(default_factory=ast.Loc, compare=False)


@dataclass(frozen=True)
class Document:
    """A document with its includes merged.  ``file`` as given, ``node`` the name its file name
    gives (:func:`node_of`), ``files`` the file and every file it includes, in reading order."""

    file: str
    node: str
    description: str = ""
    endpoints: tuple[Endpoint, ...] = ()
    parameters: tuple[Parameter, ...] = ()
    files: tuple[str, ...] = ()

    def of(self, *kinds: str) -> list[Endpoint]:
        """The endpoints of the lists ``kinds`` (:data:`ENDPOINT_LISTS`' keys)."""
        return [e for e in self.endpoints if e.kind in kinds]


def node_of(path: Path) -> str:
    """The node a document's file name names: the name before ``.nodl.yaml``, ``.nodl.yml`` or
    ``.nodl.json`` (:data:`SUFFIXES`), else the name before its last suffix."""
    name = path.name
    for suffix in SUFFIXES:
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return path.stem


@lru_cache(maxsize=1)
def schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a NoDL v2 document, ``nodl.schema.json``."""
    text = resources.files("rclverify.model.nodl").joinpath("nodl.schema.json").read_text(encoding="utf-8")
    out: dict[str, Any] = json.loads(text)
    return out


def parse_text(text: str, file: str, as_json: bool) -> tuple[Any, dict[Path_, ast.Loc]]:
    """``(data, locations)`` of a document's text: strict JSON when ``as_json``, else YAML.
    Raises :class:`RclError` located at the syntax error (``E-nodl-json``, ``E-nodl-yaml``)."""
    if as_json:
        return load_json_located(text, file)
    try:
        return load_located(text, file)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark is not None else (1, 1)
        what = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise _fail(ast.Loc(file, line, col), f"not YAML: {what}", "E-nodl-yaml") from None


def validate(data: Any, locs: dict[Path_, ast.Loc], file: str) -> None:
    """Check ``data`` against :func:`schema`; raises :class:`RclError` with one located
    ``E-nodl-schema`` error per violation (jsonschema's, sorted by place)."""
    import jsonschema  # deferred: start-up (loads jsonschema only when a document is read)
    validator = jsonschema.Draft202012Validator(schema())
    diags: list[Diagnostic] = []
    for e in sorted(validator.iter_errors(data), key=lambda e: [str(p) for p in e.absolute_path]):
        where = "/".join(str(p) for p in e.absolute_path) or "the document"
        message = e.message if len(e.message) <= MESSAGE_MAX else e.message[:MESSAGE_MAX] + "..."
        diags.append(error(schema_error_loc(e, locs, file), f"NoDL v2 schema: {where}: {message}",
                           "E-nodl-schema"))
    if diags:
        diags.sort(key=lambda d: (d.loc.line, d.loc.col))
        raise RclError(diags)


class Resolver:
    """Where an ``include`` reference leads: ``local://<path>`` is ``path`` relative to the
    including document's folder; ``nodl://<package>/<name>`` is the ament index resource
    ``share/ament_index/resource_index/nodl/<package>__<name>`` under the first of ``prefixes``
    that has it (what ``ament_nodl_register`` installs).  ``display`` turns a path into the file
    name diagnostics show.  ``within`` (the workspace, and a folder of documents named on the
    command line): when given, every document read -- a ``local://`` include, and a document
    found in a folder -- must resolve inside one of them (:func:`rclverify.core.within.outside`;
    the ament prefixes are named on the command line, so ``nodl://`` reaches them); with none
    (``nodl validate``, whose files are all named) no place is refused.  A document is a regular
    file: a FIFO, device or socket is refused without being opened for a wait."""

    def __init__(self, prefixes: Sequence[Path] = (), display: Callable[[Path], str] = str,
                 within: Sequence[Path] = ()) -> None:
        self.prefixes = tuple(prefixes)
        self.display = display
        self.within = tuple(within)

    def outside(self, path: Path) -> Path | None:
        """Where ``path`` leads when ``within`` is given and that is outside all of its folders and
        the ament prefixes (``None``: allowed)."""
        if not self.within:
            return None
        reals = [outside(w, path) for w in self.within + self.prefixes]
        return reals[0] if all(r is not None for r in reals) else None

    def resolve(self, ref: str, origin: Path, at: ast.Loc) -> Path:
        """The file ``ref`` names, read from document ``origin``; raises :class:`RclError`
        (``E-nodl-include``, at ``at``) for a scheme without a resolver or a file not found."""
        scheme, _, body = ref.partition("://")
        if scheme == "local":
            target = (origin.parent / body).resolve()
            real = self.outside(target)
            if real is not None:
                raise _fail(at, f"include {ref!r}: resolves to {real}, outside the workspace; an include must lie "
                                "inside it (only a document named on the command line may lie outside)",
                            "E-nodl-include")
            try:
                mode = os.stat(target).st_mode
            except OSError:
                raise _fail(at, f"include {ref!r}: no file {self.display(target)}", "E-nodl-include") from None
            if not stat.S_ISREG(mode):
                raise _fail(at, f"include {ref!r}: {self.display(target)} is {kind_of(mode)}, not a regular file",
                            "E-nodl-include")
            return target
        if scheme == "nodl":
            pkg, _, name = body.partition("/")
            key = f"{pkg}__{name}"
            for prefix in self.prefixes:
                target = prefix / "share" / "ament_index" / "resource_index" / "nodl" / key
                if target.is_file():
                    return target.resolve()
            where = ", ".join(str(p) for p in self.prefixes) or "no prefix given (--ament-prefix)"
            raise _fail(at, f"include {ref!r}: no NoDL resource {key} in the ament index of {where}",
                        "E-nodl-include")
        raise _fail(at, f"include {ref!r}: no resolver for the scheme {scheme!r} (rclverify resolves local:// "
                        "and nodl://)", "E-nodl-include")


def _qos(raw: Any, path: Path_, locs: dict[Path_, ast.Loc], here: ast.Loc) -> QoS | None:
    if not isinstance(raw, dict):
        return None
    where = tuple((k, locs.get(path + (k,), here)) for k in QOS_FIELDS if k in raw)
    return QoS(loc=locs.get(path, here), field_locs=where, **{k: raw[k] for k in QOS_FIELDS if k in raw})


def _own(data: dict[str, Any], locs: dict[Path_, ast.Loc], file: str) -> tuple[list[Endpoint], list[Parameter]]:
    """The endpoints and parameters ``data`` (schema-valid) declares itself."""
    here = ast.Loc(file, 1, 1)
    ends: list[Endpoint] = []
    for kind in ENDPOINT_LISTS:
        for i, raw in enumerate(data.get(kind) or []):
            p = (kind, i)
            ends.append(Endpoint(kind, raw["name"], raw["type"], _qos(raw.get("qos"), p + ("qos",), locs, here),
                                 locs.get(p + ("name",), here), locs.get(p + ("type",), here)))
    params: list[Parameter] = []
    for name, raw in (data.get("parameters") or {}).items():
        p = ("parameters", name)
        params.append(Parameter(name, raw["type"], raw.get("default_value"), "default_value" in raw,
                                bool(raw.get("read_only", False)), tuple((raw.get("validation") or {}).items()),
                                locs.get(p + (KEY,), here), locs.get(p + ("default_value",), here)))
    return ends, params


class _Reader:
    """One document tree read: the files on the current include chain and every file read."""

    def __init__(self, resolver: Resolver) -> None:
        self.resolver = resolver
        self.chain: list[Path] = []
        self.read: dict[Path, str] = {}
        self.ends: dict[tuple[str, str], Endpoint] = {}
        self.params: dict[str, Parameter] = {}
        self.files: list[str] = []

    def load(self, path: Path, file: str) -> dict[str, Any]:
        real = self.resolver.outside(path)
        if real is not None:
            raise _fail(ast.Loc(file, 1, 1), f"resolves to {real}, outside the workspace (through a symbolic link); "
                                             "a NoDL document is read there only when the command line names it",
                        "E-nodl-include")
        text = read_yaml_text(path, file)
        data, locs = parse_text(text, file, path.suffix == ".json")
        if not isinstance(data, dict):
            raise _fail(ast.Loc(file, 1, 1), "a NoDL document is a mapping (an object) at its top", "E-nodl-schema")
        validate(data, locs, file)
        self.read[path] = file
        self.files.append(file)
        ends, params = _own(data, locs, file)
        for e in ends:
            first = self.ends.setdefault((e.kind, e.name), e)
            if first is not e:
                raise _fail(e.loc, f"{e.kind[:-1].replace('_', ' ')} {e.name!r} is declared twice: first at "
                                   f"{first.loc} (an include merges documents; NoDL refuses a repeated name)",
                            "E-nodl-include")
        for prm in params:
            was = self.params.setdefault(prm.name, prm)
            if was is not prm:
                raise _fail(prm.loc, f"parameter {prm.name!r} is declared twice: first at {was.loc}", "E-nodl-include")
        self.chain.append(path)
        for i, inc in enumerate(data.get("include") or []):
            at = locs.get(("include", i, "ref"), ast.Loc(file, 1, 1))
            target = self.resolver.resolve(inc["ref"], path, at)
            if target in self.chain:
                cycle = " -> ".join([self.read[p] for p in self.chain[self.chain.index(target):]] + [self.read[target]])
                raise _fail(at, f"include {inc['ref']!r} closes a cycle: {cycle}", "E-nodl-include")
            if target in self.read:
                raise _fail(at, f"include {inc['ref']!r}: {self.read[target]} is already included in this document "
                                "tree (NoDL refuses a document included twice)", "E-nodl-include")
            self.load(target, self.resolver.display(target))
        self.chain.pop()
        return data


def read_document(path: Path, file: str | None = None, resolver: Resolver | None = None) -> Document:
    """The document at ``path`` with its includes merged (module docstring); ``file`` is the
    name diagnostics give it (default ``str(path)``).  Raises :class:`RclError` (located) for a
    file that cannot be read, is not JSON or YAML, breaks the schema, or whose includes cannot
    be resolved, cycle, or repeat a name."""
    r = _Reader(resolver or Resolver())
    shown = file or str(path)
    data = r.load(path.resolve(), shown)
    return Document(shown, node_of(path), str(data.get("description", "")), tuple(r.ends.values()),
                    tuple(r.params.values()), tuple(r.files))


__all__ = ["Document", "ENDPOINT_LISTS", "Endpoint", "Parameter", "QOS_FIELDS", "QoS", "Resolver", "SUFFIXES",
           "node_of", "parse_text", "read_document", "schema", "validate"]
