"""The blank review record ``rclverify review NODE`` writes (jinja2 template)."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import jinja2

from rclverify.lang.types import CheckedNode
from rclverify.backends.review.record import assumption_text, checklist, sha256_of


def blank_record(node: CheckedNode, root: Path, files: Sequence[str] = ()) -> str:
    """YAML text of a record to fill in for ``node``: the generated checklist
    (one question per guarantee conjunct, with its RCL location) and ``files``
    (workspace-relative) with their current sha256.

    Raises ``FileNotFoundError`` naming a file that cannot be read.
    """
    listed = []
    for f in files:
        digest = sha256_of(root / f)
        if digest is None:
            raise FileNotFoundError(f)
        listed.append({"path": f, "sha256": digest})
    env = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.review", "templates"),
                             undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True)
    return env.get_template("record.yaml.j2").render(node=node.name, files=listed, questions=checklist(node),
                                                     assumption=assumption_text(node))
