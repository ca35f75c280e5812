"""Where a piece of RCL text is: :class:`Loc`, the source location every
node of the abstract syntax carries (:mod:`rclverify.lang.ast`,
:mod:`rclverify.lang.typeexpr`), and the diagnostics, plan values and
reports that point into a file.

Locations are excluded from the nodes' equality (:func:`loc_field`:
``compare=False``) so that a printed-and-reparsed file compares equal to
the original (the round-trip property of the printer).
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class Loc:
    """A source location: 1-based line and column of the first character.

    ``end_line``/``end_col`` point one past the last character (0 when
    unknown).  ``file`` is the path as given by the user.
    """

    file: str = "<string>"
    line: int = 0
    col: int = 0
    end_line: int = 0
    end_col: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"

    def __reduce__(self) -> tuple[type["Loc"], tuple[str, int, int, int, int]]:
        """Pickle as a constructor call: the dataclass default for a frozen
        class with slots looks its fields up on every object, which made
        Locs (one per AST node and plan value) most of the cost of the
        workspace cache (:mod:`rclverify.core.cache.workspace`): 4x faster to write, 1.7x to read."""
        return (Loc, (self.file, self.line, self.col, self.end_line, self.end_col))


NOLOC = Loc()


def loc_field() -> Loc:
    """The ``loc`` field of a syntax node: :data:`NOLOC` by default, left out of equality and ``repr``."""
    return field(default=NOLOC, compare=False, repr=False)


__all__ = ["Loc", "NOLOC", "loc_field"]
