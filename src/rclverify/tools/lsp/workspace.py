"""The workspace the language server serves: its root, the names of its
files, and which RCL files are checked together.

Rules (docs/editor.md):

* The root is the client's workspace folder (``rootUri`` of
  ``initialize``), else the server's working directory.  Every document a
  request names must lie inside it once symbolic links are resolved; any
  other is refused with :class:`Outside` (the server answers the request
  with an error, and publishes nothing for it), as every path a plan names
  must stay inside the workspace (docs/plan.md).
* Files are named in messages by their path relative to the root
  (``contracts/remote_inspection.rcl``), as ``rclverify check`` run at the
  root names them, so the messages are the command line's.
* The files checked together are those of ``rclverify check``
  (:mod:`rclverify.model.plan.scopes`): the plan's ``contracts:`` as one system
  when the edited file is among them, else the file alone.  Open documents
  are read from the editor's unsaved text, the others from disk.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping
from urllib.parse import quote, unquote, urlparse

from rclverify.lang.errors import RclError
from rclverify.lang.source import decode_text
from rclverify.lang.source import read_text

#: The plan, relative to the root (the default of every command).
PLAN = "contracts/plan.yaml"


class Outside(Exception):
    """A document outside the served workspace (or not a ``file:`` URI);
    ``str()`` is the one-line reason the server answers with."""


def _shown(text: str) -> str:
    """``text`` as a message may show it: control characters escaped, at most 200 characters."""
    out = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    return out if len(out) <= 200 else out[:197] + "..."


def _encodable(name: str) -> bool:
    """Whether ``name`` is text a file name can hold (no lone surrogate)."""
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


class LspWorkspace:
    """The workspace rooted at ``root`` (a directory).

    ``plan`` is the plan's path relative to ``root``."""

    def __init__(self, root: Path, plan: str = PLAN) -> None:
        self.root = Path(os.path.realpath(root))
        self.plan = plan
        self._plan_cache: tuple[float, tuple[str, ...]] | None = None

    def rel(self, uri: str) -> str:
        """The root-relative POSIX path of the document ``uri``
        (``file:///.../contracts/a.rcl`` -> ``contracts/a.rcl``).  Raises
        :class:`Outside` for a URI of another scheme, a path with a NUL
        character or a lone surrogate (no file can have that name), or a
        path that is not inside the root (after resolving symbolic links
        and ``..``); the reason shows the URI with its control characters
        escaped."""
        shown = _shown(uri)
        try:
            parsed = urlparse(uri)
        except ValueError:  # e.g. a malformed IPv6 host
            raise Outside(f"{shown}: refused: not a valid URI") from None
        if parsed.scheme != "file":
            raise Outside(f"{shown}: refused: not a file of the workspace {self.root.name}")
        name = unquote(parsed.path)
        if "\x00" in name or not _encodable(name):
            raise Outside(f"{shown}: refused: not a valid file name (it holds a NUL character or a lone surrogate)")
        try:
            path = Path(os.path.realpath(name))
        except (OSError, ValueError) as exc:
            raise Outside(f"{shown}: refused: the path cannot be resolved ({exc.__class__.__name__})") from None
        try:
            return path.relative_to(self.root).as_posix()
        except ValueError:
            raise Outside(f"{_shown(str(path))}: refused: outside the workspace {self.root} (the server reads "
                          "only the files of its workspace)") from None

    def uri(self, rel: str) -> str:
        """The ``file:`` URI of the root-relative path ``rel``."""
        return "file://" + quote((self.root / rel).as_posix())

    def contracts(self) -> tuple[str, ...]:
        """The plan's ``contracts:`` (root-relative), read again when the
        plan file changed; ``()`` without a readable plan."""
        p = self.root / self.plan
        try:
            stamp = p.stat().st_mtime
        except OSError:
            return ()
        if self._plan_cache is None or self._plan_cache[0] != stamp:
            from rclverify.model.plan.load import read_plan_document  # deferred: optional or conditional (inside a block)
            try:
                doc, _ = read_plan_document(self.root, self.plan)
                files = doc.contracts
            except RclError:
                files = ()
            self._plan_cache = (stamp, files)
        return self._plan_cache[1]

    def scope(self, rel: str) -> tuple[str, ...]:
        """The files checked with ``rel`` (see the module docstring)."""
        system = self.contracts()
        return system if rel in system else (rel,)

    def text(self, rel: str, open_docs: Mapping[str, str]) -> str:
        """The text of ``rel``: the editor's, else the file's as
        :func:`rclverify.lang.source.decode_text` reads it.  Raises
        :class:`RclError` (``E-io``, ``E-encoding``) located in ``rel``."""
        if rel in open_docs:
            return open_docs[rel]
        return read_text(self.root / rel, rel)

    def disk_text(self, rel: str) -> str | None:
        """The saved text of ``rel``, ``None`` when it cannot be read."""
        try:
            return decode_text((self.root / rel).read_bytes(), rel)
        except (OSError, RclError):
            return None


    def shown_text(self, rel: str) -> str:
        """The saved text of ``rel`` as far as it reads (bytes that are not
        UTF-8 replaced), for placing a diagnostic in a file that does not
        decode; ``""`` when it cannot be read."""
        try:
            return (self.root / rel).read_bytes().decode("utf-8", "replace")
        except OSError:
            return ""
