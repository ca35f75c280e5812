"""The NoDL v2 document of each node of a new workspace, written from its contract (docs/nodl.md).

``rclverify init`` writes ``nodl/<Node>.nodl.yaml`` beside ``contracts/``:
the contracts it renders are parsed and type-checked, and each node's
document is :func:`rclverify.model.nodl.contract.document_text` of its
contract, so ``rclverify nodl check`` passes on the new workspace and shows
where a document goes.
"""
from __future__ import annotations

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.nodl.check import FOLDER
from rclverify.model.nodl.contract import document_text

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
