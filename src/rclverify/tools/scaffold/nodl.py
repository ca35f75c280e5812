"""The NoDL v2 document of each node of a new workspace, written from its contract (docs/nodl.md).

``rclverify init`` writes ``nodl/<Node>.nodl.yaml`` beside ``contracts/``:
the contracts it renders are parsed and type-checked, and each node's
document is :func:`rclverify.model.nodl.contract.document_text` of its
contract, so ``rclverify nodl check`` passes on the new workspace and shows
where a document goes.  ``rclverify init --from-ros`` writes, for each node
whose scanned package registers a document for its executable, one that
includes it (:func:`from_ros_documents`).
"""
from __future__ import annotations

import re
from pathlib import Path

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.nodl.check import FOLDER
from rclverify.model.nodl.contract import document_text, yaml_text
from rclverify.model.nodl.document import SUFFIXES

#: The comment line each document starts with.
HEADER = ("the interface of this node as its contract names it, written by rclverify init: "
          "yours to edit (docs/nodl.md)")


def nodl_documents(contracts: dict[str, str]) -> dict[str, str]:
    """Workspace-relative path -> text of the NoDL document of every node of ``contracts``
    (workspace-relative contract file -> its RCL text).  Raises
    :class:`~rclverify.lang.errors.RclError` (located) when the contracts do not check or a
    topic entry has no direction (:func:`~rclverify.model.nodl.contract.document_data`)."""
    checked = check([parse_text(text, rel) for rel, text in contracts.items()])
    return {f"{FOLDER}/{name}.nodl.yaml": document_text(cn, cn.node.loc.file, HEADER)
            for name, cn in checked.nodes.items()}


#: ``ament_nodl_register(<executable> FILE <path> ...)`` in a package's CMakeLists.txt (ament_nodl's macro).
_REGISTER = re.compile(r"ament_nodl_register\s*\(\s*\"?([A-Za-z0-9_.-]+)\"?\s+FILE\s+\"?([^\s\")]+)\"?", re.I)


def registered_document(package_root: Path, executable: str) -> Path | None:
    """The NoDL document package ``package_root`` gives its executable ``executable``: the ``FILE``
    of its ``ament_nodl_register(<executable> FILE ...)`` call (a path relative to the package,
    without CMake variables), else ``nodl/<executable>.nodl.yaml`` (``.yml``, ``.json``), where
    ``rclverify generate ros2`` puts it; ``None`` when there is none."""
    cmake = package_root / "CMakeLists.txt"
    if cmake.is_file():
        for m in _REGISTER.finditer(cmake.read_text(encoding="utf-8", errors="replace")):
            path = package_root / m.group(2)
            if m.group(1) == executable and "${" not in m.group(2) and path.is_file():
                return path
    for suffix in SUFFIXES:
        path = package_root / FOLDER / f"{executable}{suffix}"
        if path.is_file():
            return path
    return None


def from_ros_documents(nodes: list[tuple[str, str | None, str | None]], packages: dict[str, Path],
                       copied: str = "ros") -> dict[str, str]:
    """For ``init --from-ros``: workspace-relative path -> text of ``nodl/<Node>.nodl.yaml`` for each
    node ``(contract name, package, executable)`` whose package (by name in ``packages``: its
    scanned directory) registers a document for its executable (:func:`registered_document`).
    The node's document includes the package's own, in the copy of the package the new
    workspace holds (``<copied>/<package>/...``), so its local includes keep working."""
    out: dict[str, str] = {}
    for name, pkg, exe in nodes:
        root = packages.get(pkg or "")
        found = registered_document(root, exe) if root is not None and exe else None
        if root is None or found is None:
            continue
        rel = found.relative_to(root).as_posix()
        data: dict[str, object] = {"nodl_version": 2,
                                   "description": f"Node {name}: the document its package {pkg} registers for "
                                                  f"its executable {exe}",
                                   "include": [{"ref": f"local://../{copied}/{pkg}/{rel}"}]}
        out[f"{FOLDER}/{name}.nodl.yaml"] = yaml_text(data, "written by rclverify init --from-ros (docs/nodl.md)")
    return out
