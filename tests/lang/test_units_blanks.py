"""Units (issue 47, runtime hardening): a blank inside a unit is a product or
an error, never glued into another symbol (``[m s]`` was read as ``[ms]``,
``[c d]`` as candela); the exponent limit holds for repeated division and
multiplication too."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.lang.typecheck import load
from rclverify.lang.errors import RclError
from rclverify.lang.units import MAX_EXPONENT, UnitError, parse_unit


def test_a_blank_between_two_symbols_is_a_product() -> None:
    assert parse_unit("m s") == parse_unit("m*s") != parse_unit("ms")
    assert parse_unit("kg m / s^2") == parse_unit("N")
    assert parse_unit("(m s)^2") == parse_unit("m^2*s^2")


def test_a_blank_never_makes_a_symbol_of_its_pieces() -> None:
    with pytest.raises(UnitError, match="unknown unit 'c'"):
        parse_unit("c d")


@pytest.mark.parametrize("text", ["m" + "/s" * (MAX_EXPONENT + 1), "m" + "*m" * MAX_EXPONENT, "m^12 m"])
def test_the_exponent_limit_holds_for_repeated_operators(text: str) -> None:
    with pytest.raises(UnitError, match="exponent out of range"):
        parse_unit(text)


def test_a_declared_blank_unit_reads_as_the_product_in_a_contract(tmp_path: Path) -> None:
    p = tmp_path / "u.rcl"
    p.write_text("node N {\n  inputs( d : REAL [N m] )\n  outputs( e : REAL [N*m] )\n  guarantee( out.e == in.d )\n}\n")
    checked = load([p])  # the same unit at both ends of the equation: no unit error
    assert str(checked.nodes["N"].node.inputs[0].unit.text) == "N*m"
    p.write_text("node N {\n  inputs( d : REAL [c d] )\n  outputs( e : REAL )\n  guarantee( out.e == 0 )\n}\n")
    with pytest.raises(RclError) as e:
        load([p])
    assert "u.rcl:2:" in str(e.value.diagnostics[0]) and "unknown unit 'c'" in str(e.value.diagnostics[0])
