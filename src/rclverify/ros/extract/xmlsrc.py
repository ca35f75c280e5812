"""Located XML for launch files and manifests, through lxml (every element
keeps its ``sourceline``).  Entities and network access are off: a launch
file is data, never a fetch."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.ros.extract import safefs
from rclverify.ros.extract.model import Note, Src


def parse_xml(path: Path, shown: str) -> tuple[Any | None, Note | None]:
    """The root element of ``path``, or ``(None, note)`` with a located
    ``ROS-PARSE`` error when the file is not well-formed XML or unreadable."""
    from rclverify.core.extras import require  # deferred: start-up (loads lxml only when called)
    etree = require("lxml.etree", "reading launch files and manifests")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False, remove_comments=True)
    try:
        data = safefs.read_bytes(path)
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line, col = (exc.position if exc.position else (1, 1))
        return None, Note(Src(shown, max(1, line or 1), max(1, (col or 0) + 1)),
                          f"not well-formed XML: {exc.msg}", "ROS-PARSE", "error")
    except safefs.Refused as exc:
        return None, Note(Src(shown), f"not read: {exc}", "ROS-PARSE", "warning")
    except (OSError, ValueError) as exc:
        return None, Note(Src(shown), f"cannot read: {exc}", "ROS-PARSE", "error")
    if root is None:
        return None, Note(Src(shown), "empty XML document", "ROS-PARSE", "error")
    return root, None


def line_of(el: Any) -> int:
    """1-based line of an lxml element (1 when unknown)."""
    return int(getattr(el, "sourceline", None) or 1)
