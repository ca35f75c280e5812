"""The reading of RCL's literal tokens as the parser reduces them
(:mod:`rclverify.lang.builder`): the limits a numeral is checked against
(``E-number``, docs/rcl-language.md "Robustness limits") and the value of a
string literal.
"""
from __future__ import annotations

import re


#: Most digits a numeral may have (before and after its point) and largest
#: magnitude of its exponent.  A literal within both limits has an exact value
#: of at most 2,001 digits, so every stage (Fraction arithmetic, Z3, printing
#: the value in JSON or text: Python refuses to print integers above 4,300
#: digits) handles it; a longer one is a located ``E-number`` error at parse
#: time (docs/rcl-language.md, "Robustness limits").
NUMERAL_DIGITS_LIMIT = 1000
NUMERAL_EXPONENT_LIMIT = 1000


def numeral_problem(text: str) -> str | None:
    """Why the numeral ``text`` (the ``NUMBER`` terminal of ``rcl.lark``:
    digits, an optional fraction, an optional exponent) is refused, or
    ``None`` when it is within :data:`NUMERAL_DIGITS_LIMIT` digits and its
    exponent within :data:`NUMERAL_EXPONENT_LIMIT` in magnitude."""
    mantissa, _, exponent = text.lower().partition("e")
    digits = len(mantissa) - ("." in mantissa)
    if digits > NUMERAL_DIGITS_LIMIT:
        return f"numeral too long: {digits} digits (limit {NUMERAL_DIGITS_LIMIT})"
    exp_digits = exponent.lstrip("+-").lstrip("0")
    if len(exp_digits) > 4 or (exp_digits and int(exp_digits) > NUMERAL_EXPONENT_LIMIT):
        return f"numeral's exponent too large (limit {NUMERAL_EXPONENT_LIMIT} in magnitude)"
    return None


def unquote(text: str) -> str:
    """The value of a ``STRING_LIT`` token: quotes removed, ``\\x`` -> ``x``."""
    return re.sub(r"\\(.)", r"\1", text[1:-1])
