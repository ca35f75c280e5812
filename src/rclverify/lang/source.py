"""Reading input text files (RCL contracts, the plan, the YAML files it names) as UTF-8.

Every input the tool reads is UTF-8 text (RCL: docs/rcl-language.md; YAML
1.2 section 5.2 allows UTF-8, UTF-16 and UTF-32, of which rclverify reads
UTF-8 only, so that every file of a workspace and of its bundle has one
encoding).  Rules:

* a UTF-8 byte-order mark (``EF BB BF``) at the start is accepted and
  dropped (editors on Windows write one); line and column numbers count
  from the character after it;
* a UTF-32 or UTF-16 byte-order mark (``FF FE 00 00``, ``00 00 FE FF``,
  ``FF FE``, ``FE FF``; UTF-32 tested first, as its little-endian mark
  begins with UTF-16's) is one located error at ``file:1:1`` naming the
  encoding and the command that converts it;
* a NUL byte in a file without a byte-order mark (UTF-16/32 written without
  one) is an error at the NUL's line and column;
* bytes that are not UTF-8 are an error at their line and column, naming the
  byte offset.

Each error is an :class:`~rclverify.lang.errors.RclError` with code
``E-encoding``.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error

UTF8_BOM = b"\xef\xbb\xbf"

#: (byte-order mark, encoding name), longest marks first.
_OTHER_BOMS: tuple[tuple[bytes, str], ...] = (
    (b"\xff\xfe\x00\x00", "UTF-32 (little-endian)"),
    (b"\x00\x00\xfe\xff", "UTF-32 (big-endian)"),
    (b"\xff\xfe", "UTF-16 (little-endian)"),
    (b"\xfe\xff", "UTF-16 (big-endian)"),
)


def _where(data: bytes, offset: int) -> tuple[int, int]:
    """1-based (line, column in characters) of byte ``offset`` of ``data``."""
    head = data[:offset]
    line_start = head.rfind(b"\n") + 1
    return head.count(b"\n") + 1, len(head[line_start:].decode("utf-8", "replace")) + 1


def decode_text(data: bytes, file: str) -> str:
    """The text of the file ``file`` whose bytes are ``data`` (rules of the
    module docstring).  Raises :class:`RclError` (``E-encoding``), located
    in ``file``."""
    if data.startswith(UTF8_BOM):
        data = data[len(UTF8_BOM):]
    else:
        for bom, name in _OTHER_BOMS:
            if data.startswith(bom):
                raise RclError([error(ast.Loc(file, 1, 1), f"file is encoded as {name} (byte-order mark "
                                      f"{bom.hex(' ')}); rclverify reads UTF-8 only: convert it, e.g. "
                                      f"`iconv -f {name.split()[0]} -t UTF-8`", "E-encoding")])
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line, col = _where(data, exc.start)
        raise RclError([error(ast.Loc(file, line, col), f"invalid UTF-8 (byte 0x{data[exc.start]:02x} at offset "
                              f"{exc.start}); rclverify reads UTF-8 only", "E-encoding")]) from None
    nul = text.find("\0")
    if nul >= 0:
        line, col = _where(data, len(text[:nul].encode("utf-8")))
        raise RclError([error(ast.Loc(file, line, col), "NUL character in a text file: is it UTF-16 or UTF-32 "
                              "without a byte-order mark? rclverify reads UTF-8 only", "E-encoding")])
    return text


def read_text(path: str | Path, file: str | None = None) -> str:
    """:func:`decode_text` of the file at ``path`` (``file``: the name used in
    messages, default ``path``).  Raises :class:`RclError`: ``E-io`` when the
    file cannot be read, ``E-encoding`` as above."""
    name = str(path) if file is None else file
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise RclError([error(ast.Loc(name, 1, 1), f"cannot read file: {exc.strerror or exc}", "E-io")]) from None
    return decode_text(data, name)
