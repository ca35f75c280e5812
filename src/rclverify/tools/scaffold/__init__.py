"""``rclverify init``: write a new workspace that verifies at once.

The workspace has the layout of docs/architecture.md: ``dodo.py``,
``contracts/`` with one documented example contract per node (a chain: each
node's output feeds the next node's input, so the calculus has a side
condition to prove per link, paper rule R1), each node's NoDL document in
``nodl/`` written from its contract (:mod:`.nodl`), a commented
``contracts/plan.yaml``, and empty ``backends/``, ``artifacts/`` and
``reports/``.  Every file comes from the jinja2 templates in
``scaffold/templates``.  Decisions are written down in docs/ci.md.
"""
from __future__ import annotations

import keyword
import re
from dataclasses import dataclass
from pathlib import Path

import jinja2

from rclverify.records.store import atomic_write_text

#: Node names used when ``--nodes`` is not given.
DEFAULT_NODES: tuple[str, ...] = ("Sensor", "Controller", "Actuator")

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: Words RCL reserves (they cannot name a node).
_RCL_WORDS = frozenset({"node", "context", "inputs", "outputs", "topics", "assume", "guarantee", "forall",
                        "exists", "exists_unique", "and", "or", "not", "in", "out", "TRUE", "FALSE", "REAL",
                        "INTEGER", "NATURAL", "BOOL", "matches"})


class InitError(Exception):
    """A mistake of the user of ``rclverify init`` (printed as ``DIR: error: ...``).

    ``exit_code`` is 2 for a usage error (bad ``--nodes``), 1 otherwise.
    """

    def __init__(self, message: str, exit_code: int = 2) -> None:
        super().__init__(message)
        self.exit_code = exit_code


@dataclass(frozen=True)
class NodeSpec:
    """One node of the example chain, as the templates see it."""

    name: str
    stem: str
    input: str
    output: str
    producer: str | None
    consumer: str | None
    position: str

    @property
    def file(self) -> str:
        """Workspace-relative path of the node's contract file."""
        return f"contracts/{self.stem}.rcl"


def _stem(name: str) -> str:
    """``RadiationSensor`` -> ``radiation_sensor`` (file and variable stem)."""
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name).lower()


def plan_nodes(names: list[str]) -> list[NodeSpec]:
    """The chain ``names[0] -> names[1] -> ...`` as :class:`NodeSpec` values.

    The first node reads the environment input ``reading``; node ``k`` outputs
    ``<stem>_value``, which is node ``k+1``'s input.  Raises
    :class:`InitError` for an empty list, a name that is not an RCL
    identifier (or is an RCL word) and a repeated name or file stem.
    """
    if not names:
        raise InitError("--nodes needs at least one node name")
    seen: dict[str, str] = {}
    for n in names:
        if not _IDENT.match(n) or n in _RCL_WORDS or keyword.iskeyword(n):
            raise InitError(f"node name {n!r} is not an RCL identifier (letters, digits, _; not a keyword)")
        if _stem(n) in seen:
            raise InitError(f"node names {seen[_stem(n)]!r} and {n!r} repeat (contract file {_stem(n)}.rcl)")
        seen[_stem(n)] = n
    out = []
    for k, n in enumerate(names):
        prev = names[k - 1] if k else None
        nxt = names[k + 1] if k + 1 < len(names) else None
        pos = (f"node {k + 1} of {len(names)}" + (f", fed by {prev}" if prev else ", fed by the environment")
               + (f", feeding {nxt}" if nxt else ""))
        out.append(NodeSpec(n, _stem(n), f"{_stem(prev)}_value" if prev else "reading", f"{_stem(n)}_value",
                            prev, nxt, pos))
    return out


def _env() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.tools.scaffold", "templates"), autoescape=False,
                              undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                              keep_trailing_newline=True)


def render_workspace(name: str, names: list[str]) -> dict[str, str]:
    """Workspace-relative path -> text of every file of a new workspace.

    ``name``: the system's name (the report's title); ``names``: node names in
    chain order.  Raises :class:`InitError` like :func:`plan_nodes`.
    """
    nodes = plan_nodes(names)
    env = _env()
    files = {"dodo.py": env.get_template("dodo.py.j2").render(name=name),
             "contracts/plan.yaml": env.get_template("plan.yaml.j2").render(name=name, nodes=nodes)}
    for node in nodes:
        files[node.file] = env.get_template("contract.rcl.j2").render(name=name, node=node)
    from rclverify.tools.scaffold.nodl import nodl_documents  # deferred: start-up (loads lark, yaml and more only when called)
    files.update(nodl_documents({n.file: files[n.file] for n in nodes}))
    return files


#: Directories created empty.
EMPTY_DIRS: tuple[str, ...] = ("backends", "artifacts", "reports")


def init_workspace(root: Path, names: list[str] | None = None) -> list[Path]:
    """Write a new workspace at ``root`` (created when missing).

    ``names``: node names in chain order (default :data:`DEFAULT_NODES`).
    Returns the written files and created directories.  Raises
    :class:`InitError` when ``root`` exists and is not an empty directory
    (nothing is overwritten) or a node name is unusable, ``OSError`` when
    ``root`` cannot be written.
    """
    if root.exists() and (not root.is_dir() or any(root.iterdir())):
        raise InitError("exists and is not an empty directory; rclverify init writes only into a new or empty one",
                        exit_code=1)
    files = render_workspace(root.resolve().name or "workspace", list(names or DEFAULT_NODES))
    written: list[Path] = []
    for rel, text in files.items():
        atomic_write_text(root / rel, text)
        written.append(root / rel)
    for d in EMPTY_DIRS:
        (root / d).mkdir(parents=True, exist_ok=True)
        written.append(root / d)
    return written
