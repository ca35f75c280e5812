"""A class of the program as the linker's index merges it from the files' records: :class:`UnitInfo`.

Each file's record lists its classes under ``units`` (sources_cpp.py,
sources_py.py: ``{"bases", "members", "tparams", "refs"}``);
:meth:`~.link_index.LinkIndex._merge_records` merges them into one
:class:`UnitInfo` per class of the program, and every part of the linker
reads it by attribute through :func:`unit_of`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping


@dataclass
class UnitInfo:
    """A class of the program: its bases as written, its members' types by name, its template parameters
    and the members it holds by reference, each in the order first read."""

    bases: list[str] = field(default_factory=list)
    members: dict[str, str] = field(default_factory=dict)
    tparams: list[str] = field(default_factory=list)
    refs: list[str] = field(default_factory=list)


#: a name that is no class of the program: no bases, members or template parameters (never written to)
NO_UNIT = UnitInfo()


def unit_of(units: Mapping[str, UnitInfo], name: str | None) -> UnitInfo:
    """The class ``name`` of ``units`` (the index's merged classes), :data:`NO_UNIT` when it is none."""
    return units.get(name or "", NO_UNIT)


__all__ = ["NO_UNIT", "UnitInfo", "unit_of"]
