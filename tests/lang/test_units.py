"""Units of measure in RCL (docs/rcl-language.md, "Units of measure"): the
unit algebra against an exact brute-force evaluation, the checks of
declarations and formulas, a connection's mismatch located at both ends,
printing, LaTeX, deadlines, and the probable scale mismatch of a side
condition without units."""
from __future__ import annotations

from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.calculus.compose import compose_node
from rclverify.calculus.scale import _range, scale_findings, scale_power
from rclverify.cli.commands import main
from rclverify.stages.contract_texts import node_texts
from rclverify.lang.errors import RclError
from rclverify.lang.latex import to_latex
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.timing import parse_duration, seconds
from rclverify.lang.typecheck import check
from rclverify.lang.units import PREFIXES, SYMBOLS, UnitError, factor_text, parse_unit, power_of_ten
from rclverify.model.system.model import build, unit_diagnostics

# ---------------------------------------------------------------------------
# The algebra, against Python's own evaluator over exact generators
# ---------------------------------------------------------------------------

#: One prime per base dimension and one for pi: distinct from the primes of
#: every scale in the table (2, 3, 5), so equal values mean equal units.
_GEN = [Fraction(p) for p in (7, 11, 13, 17, 19, 23, 29, 31)]
_PI = Fraction(37)
_BASES = ["m", "g", "s", "min", "h", "A", "K", "rad", "deg", "rpm", "Hz", "N", "Pa", "J", "W", "V", "Ohm", "C",
          "T", "percent"]
_PREFIXED = {"mm": ("m", "m"), "km": ("k", "m"), "ms": ("m", "s"), "us": ("u", "s"), "kg": ("k", "g"),
             "kHz": ("k", "Hz"), "mrad": ("m", "rad"), "kPa": ("k", "Pa"), "cm": ("c", "m")}


def _value(name: str) -> Fraction:
    """The brute-force value of one symbol: its table scale times the generators of its dimension."""
    prefix, base = _PREFIXED.get(name, ("", name))
    u = SYMBOLS[base].unit
    v = u.factor * (PREFIXES[prefix] if prefix else 1) * _PI ** u.pi
    for g, e in zip(_GEN, u.dims):
        v *= g ** e
    return v


def _evaluate(text: str) -> Fraction:
    """A unit text evaluated by Python (``^`` as ``**``, left to right), independently of units.py's reader."""
    env = {n: _value(n) for n in [*_BASES, *_PREFIXED]}
    return eval(text.replace("^", "**"), {"__builtins__": {}}, env)  # noqa: S307 - our own generated texts


_SYM = st.sampled_from([*_BASES, *_PREFIXED])
_FACTOR = st.tuples(_SYM, st.integers(-3, 3).filter(lambda k: k != 0))


def _in_range(factors: list[tuple[str, int]], ops: list[str]) -> bool:
    """Whether every base exponent stays within MAX_EXPONENT while the product is read left to
    right (issue 47: the limit holds for repeated multiplication and division too)."""
    from rclverify.lang.units import MAX_EXPONENT
    acc = [0] * len(parse_unit("m").dims)
    for k, ((sym, e), op) in enumerate(zip(factors, ["*", *ops])):
        d = parse_unit(sym).dims
        sign = -1 if op == "/" and k else 1
        acc = [a + sign * e * x for a, x in zip(acc, d)]
        if max(abs(a) for a in acc) > MAX_EXPONENT:
            return False
    return True


def _checked(text: str, ok: bool) -> Any:
    """parse_unit(text), or None after checking it refuses an exponent out of range."""
    if ok:
        return parse_unit(text)
    with pytest.raises(UnitError, match="exponent out of range"):
        parse_unit(text)
    return None


def _text(factors: list[tuple[str, int]], ops: list[str]) -> str:
    out = ""
    for k, ((s, e), op) in enumerate(zip(factors, ["*", *ops])):
        term = s if e == 1 else f"{s}^{e}"
        out += term if k == 0 else f"{op}{term}"
    return out


@settings(max_examples=60, deadline=None)
@given(st.lists(_FACTOR, min_size=1, max_size=4), st.lists(st.sampled_from("*/"), min_size=3, max_size=3),
       st.lists(_FACTOR, min_size=1, max_size=4), st.lists(st.sampled_from("*/"), min_size=3, max_size=3))
def test_unit_equality_matches_brute_force(fa, oa, fb, ob):
    a, b = _text(fa, oa), _text(fb, ob)
    ua, ub = _checked(a, _in_range(fa, oa)), _checked(b, _in_range(fb, ob))
    if ua is not None and ub is not None:
        assert (ua == ub) == (_evaluate(a) == _evaluate(b)), (a, b)


@settings(max_examples=40, deadline=None)
@given(st.lists(_FACTOR, min_size=1, max_size=4), st.randoms(use_true_random=False))
def test_a_rearranged_unit_is_the_same_unit(factors, rnd):
    """The same factors in another order, negative exponents written as
    divisions: always the same unit (and the oracle agrees)."""
    a = _text(factors, ["*"] * len(factors))
    shuffled = list(factors)
    rnd.shuffle(shuffled)
    b = "1" + "".join(f"/{s}^{-e}" if e < 0 else f"*{s}^{e}" for s, e in shuffled)
    ua = _checked(a, _in_range(factors, ["*"] * len(factors)))
    ub = _checked(b, _in_range([("1", 1), *[(s, abs(e)) for s, e in shuffled]],
                               ["/" if e < 0 else "*" for _, e in shuffled]))
    if ua is not None and ub is not None:
        assert ua == ub
    assert _evaluate(a) == _evaluate(b)


@pytest.mark.parametrize("a, b", [("N", "kg*m/s^2"), ("Pa", "N/m^2"), ("J", "N*m"), ("W", "J/s"), ("V", "W/A"),
                                  ("Ohm", "V/A"), ("C", "A*s"), ("T", "kg/(A*s^2)"), ("Hz", "1/s"), ("%", "percent"),
                                  ("mm/m*m", "mm"), ("rad/s*s", "rad"), ("kPa", "kN/m^2"), ("m/s/s", "m/s^2")])
def test_derived_units(a, b):
    assert parse_unit(a) == parse_unit(b), (a, b)


@pytest.mark.parametrize("a, b", [("rad", "1"), ("rad/s", "Hz"), ("h", "min"), ("ms", "s"), ("degC", "K"),
                                  ("deg", "rad"), ("m/s/s", "m/(s/s)")])
def test_different_units(a, b):
    assert parse_unit(a) != parse_unit(b), (a, b)


def test_scale_factors_and_words():
    assert factor_text(parse_unit("m"), parse_unit("mm")) == "a factor of 1000 (1 m = 1000 mm)"
    assert factor_text(parse_unit("mm"), parse_unit("m")) == "a factor of 1000 (1 m = 1000 mm)"
    assert factor_text(parse_unit("rad"), parse_unit("deg")) == "a factor of 180/pi (1 rad = 180/pi deg)"
    assert "offset of 273.15 K" in factor_text(parse_unit("degC"), parse_unit("K"))
    assert parse_unit("km/h").factor == Fraction(5, 18)
    assert power_of_ten(parse_unit("m"), parse_unit("mm")) == 3
    assert power_of_ten(parse_unit("us"), parse_unit("s")) == -6
    assert power_of_ten(parse_unit("rad"), parse_unit("deg")) is None
    assert parse_unit("µs") == parse_unit("us")


@pytest.mark.parametrize("text, offset, words", [
    ("", 0, "empty unit"), ("sec", 0, "did you mean 's'"), ("m/", 2, "expected a unit symbol"),
    ("degC*m", 0, "affine"), ("m^99", 2, "exponent"), ("(m", 2, "missing ')'"), ("m)", 1, "unexpected ')'"),
    ("s^x", 2, "integer"), ("kmin", 0, "unknown unit"),
])
def test_bad_unit_texts(text, offset, words):
    with pytest.raises(UnitError) as e:
        parse_unit(text)
    assert e.value.offset == offset and words in e.value.message


# ---------------------------------------------------------------------------
# Declarations and formulas
# ---------------------------------------------------------------------------

def _errors(src: str) -> list[tuple[int, int, str, str]]:
    try:
        check([parse_text(src, "u.rcl")])
    except RclError as e:
        return [(d.loc.line, d.loc.col, d.code, d.message) for d in e.diagnostics]
    return []


_NODE = """node A {{
  inputs( r : REAL [m], t : REAL [ms], x : REAL, c : REAL [degC], k : REAL [K] )
  outputs( d : REAL [mm], v : REAL [m/s] )
  guarantee( {formula} )
}}
"""


@pytest.mark.parametrize("formula, code, col, words", [
    ("out.d == 1000 * in.r", "E-unit-scale", 23,
     "out.d is [mm] (length) but 1000 * in.r is [m] (length): one dimension (length) at two scales, a factor of "
     "1000 (1 m = 1000 mm); RCL does not convert units: write the factor with its unit, 1000 [mm/m] * in.r"),
    ("in.r + in.t > 0", "E-unit-dimension", 21, "different dimensions (length against time)"),
    ("in.x + in.r > in.t", "E-unit-dimension", 28, "in.x + in.r is [m] (length) but in.t is [ms] (time)"),
    ("out.d == 1000 [mm/m] * in.t", "E-unit-dimension", 23, "1000 [mm/m] * in.t is [us] (time)"),
    ("in.t < 2 [s]", "E-unit-scale", 21, "write 2000 [ms] for 2 [s]"),
    ("out.v == in.r / in.t", "E-unit-scale", 23, "a factor of 1000"),
    ("in.c * 2 > 0", "E-unit-affine", 14, "affine scale"),
    ("in.c < in.k", "E-unit-offset", 21, "an offset of 273.15 K"),
    ("in.r in {1 [m], 2 [s]}", "E-unit-dimension", 30, "a collection's items"),
    ("out.d == 3 [furlong]", "E-unit-unknown", 26, "unknown unit 'furlong'"),
])
def test_unit_errors_in_formulas_are_located(formula, code, col, words):
    [(line, c, got, msg)] = _errors(_NODE.format(formula=formula))
    assert (line, c, got) == (4, col, code), msg
    assert words in msg


_WHEEL = """node Wheel {{
  inputs( w : REAL [rad/s], r : REAL [m], rr : REAL [m/rad] )
  outputs( v : REAL [m/s] )
  guarantee( {formula} )
}}
"""


def test_dimensions_differing_only_by_angle_say_how_to_write_the_radian():
    [(line, col, code, msg)] = _errors(_WHEEL.format(formula="out.v == in.w * in.r"))
    assert (line, col, code) == (4, 23, "E-unit-dimension"), msg
    assert "different dimensions (velocity against length*time^-1*angle)" in msg
    assert "differ only by angle (the second side has rad more)" in msg
    assert "angle is a base dimension" in msg and "[m/rad]" in msg and "1 [1/rad]" in msg
    # both ways the message proposes are accepted
    assert _errors(_WHEEL.format(formula="out.v == in.w * in.rr and out.v == in.w * in.r * 1 [1/rad]")) == []
    # control: dimensions that differ by more than angle get no angle advice
    [(_, _, _, other)] = _errors(_WHEEL.format(formula="out.v == in.r"))
    assert "different dimensions (velocity against length)" in other and "angle" not in other


@pytest.mark.parametrize("formula", [
    "out.d == 1000 [mm/m] * in.r", "in.r <= 30 and in.t < 2000", "out.v == in.r / (in.t / 1000 [ms/s])",
    "out.v * 2 [s] <= in.r", "in.x * in.r > in.t", "in.c < 40 and in.c + 2 < in.c", "in.r in {1 [m], 2}",
    "forall(y in REAL | y <= in.r -> y < 31 [m])", "out.d == in.r * 1000 [mm/m]",
])
def test_consistent_formulas_check(formula):
    assert _errors(_NODE.format(formula=formula)) == []


def test_units_on_declarations_and_constants():
    errs = _errors("context { MaxR : REAL [m] = 30 ; Bad : REAL [m] = 3 [s] ; Lim = 30 [km] ; }\n"
                   "node A {\n  inputs( r : REAL [m], q : BOOL [m] )\n  outputs( d : REAL [mm] )\n"
                   "  guarantee( out.d <= Lim and in.r <= MaxR )\n}\n")
    assert [(l, c, code) for l, c, code, _ in errs] == [(1, 51, "E-unit-dimension"), (3, 34, "E-unit-type"),
                                                       (5, 23, "E-unit-scale")]
    assert "a factor of 1000000 (1 km = 1000000 mm)" in errs[2][3]


def test_contracts_without_units_are_unchanged():
    src = "node A { inputs( r : REAL ) outputs( d : REAL ) guarantee( out.d == 1000 * in.r and out.d <= 5 ) }"
    checked = check([parse_text(src)])
    assert checked.nodes["A"].units == {}


# ---------------------------------------------------------------------------
# Connections: a mismatch located at both ends
# ---------------------------------------------------------------------------

_SYSTEM = """node Lidar {
  inputs( r : REAL [m] )
  outputs( d : REAL [mm], w : REAL )
  assume( 0 <= in.r and in.r <= 30 )
  guarantee( out.d == 1000 [mm/m] * in.r and out.w >= 0 )
}

node Controller {
  inputs( d : REAL [m], w : REAL [m/s] )
  outputs( v : REAL [m/s] )
  assume( in.d <= 30 )
  guarantee( out.v >= 0 )
}
"""


def test_unit_mismatch_located_at_both_ends():
    checked = check([parse_text(_SYSTEM, "robot.rcl")])
    build(checked)  # a unit mismatch does not stop the build (issue 48): the diagnostics say it
    diags = [d for d in unit_diagnostics(checked) if d.code == "E-unit-scale"]
    ends = {(d.loc.file, d.loc.line, d.loc.col) for d in diags}
    # the producer's output declaration `d : REAL [mm]` and the consumer's input declaration `d : REAL [m]`
    assert ends == {("robot.rcl", 3, 12), ("robot.rcl", 9, 11)}
    for d in diags:
        assert "Lidar.out.d is [mm] (length), Controller.in.d is [m] (length)" in d.message
        assert "a factor of 1000 (1 m = 1000 mm)" in d.message
    assert "the reader's declaration: robot.rcl:9:11" in str(diags[0]) and str(diags[0]).startswith("robot.rcl:3:12:")
    assert "the writer's declaration: robot.rcl:3:12" in str(diags[1]) and str(diags[1]).startswith("robot.rcl:9:11:")


def test_check_command_reports_both_ends(tmp_path, capsys):
    f = tmp_path / "robot.rcl"
    f.write_text(_SYSTEM, encoding="utf-8")
    assert main(["check", str(f), "-w", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert f"{f}:3:12: error: unit mismatch on the connection Lidar.out.d -> Controller.in.d" in err
    assert f"{f}:9:11: error: unit mismatch on the connection Lidar.out.d -> Controller.in.d" in err


def test_dimension_mismatch_and_missing_unit_on_connections():
    src = _SYSTEM.replace("d : REAL [m], w", "d : REAL [mm], w")
    diags = unit_diagnostics(check([parse_text(src, "robot.rcl")]))
    assert [(d.severity, d.code, d.loc.line) for d in diags] == [("warning", "W-unit-missing", 3)]
    assert "Lidar.out.w declares no unit but feeds Controller.in.w, which is [m/s] (velocity)" in diags[0].message
    src = _SYSTEM.replace("d : REAL [m], w", "d : REAL [rad], w")
    codes = {(d.code, d.loc.line) for d in unit_diagnostics(check([parse_text(src, "robot.rcl")]))}
    assert {("E-unit-dimension", 3), ("E-unit-dimension", 9)} <= codes


# ---------------------------------------------------------------------------
# Printing, LaTeX, snapshots, deadlines
# ---------------------------------------------------------------------------

_UNITS = ["m", "mm", "m/s^2", "kg*m/s^2", "rad/s", "%", "1", "degC", "km/h", "us", "(m/s)/s"]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.sampled_from(_UNITS), min_size=3, max_size=3), st.booleans(), st.sampled_from(["", " "]))
def test_units_survive_fmt(units, literal, blank):
    a, b, c = units
    lit = f"2 [{b}]" if literal else "2"
    src = (f"context {{ C : REAL [{blank}{a}{blank}] = 1 ; }}\n"
           f"node N {{ inputs( x : REAL [{a}] ) outputs( y : REAL [{c}] ) guarantee( out.y >= {lit} ) }}\n")
    spec = parse_text(src)
    printed = to_rcl(spec)
    assert parse_text(printed) == spec
    assert f"x : REAL [{a}]" in printed and f"y : REAL [{c}]" in printed
    assert f"C : REAL [{a}] = 1 ;" in printed


def test_latex_and_snapshot_texts_show_units():
    spec = parse_text(_SYSTEM, "robot.rcl")
    tex = to_latex(spec, document=False)
    assert r"d : \mathbb{R}\,[\mathrm{mm}]" in tex
    assert r"1000\,\mathrm{mm}/\mathrm{m} \cdot \mathit{in.r}" in tex
    texts = node_texts(spec.nodes[0])
    assert texts["outputs"][0] == ["d", "REAL [mm]"] and "d : REAL [mm]" in texts["rcl"]
    other = parse_text(_SYSTEM.replace("d : REAL [mm]", "d : REAL [m]"), "robot.rcl")
    assert node_texts(other.nodes[0])["rcl"] != texts["rcl"]  # a changed unit changes the snapshot


def test_deadlines_use_the_unit_table():
    assert parse_duration("1 h") == 3600 and parse_duration("200000 us") == parse_duration("0.2 s")
    errs = _errors("node A { inputs( x : BOOL ) outputs( y : BOOL )\n"
                   "  guarantee( out.y ) triggered by in.x within 200 m }")
    assert [(c, code) for _, c, code, _ in errs] == [(40, "E-deadline")]
    assert "'m' is a unit of length, not of time" in errs[0][3]
    spec = parse_text("node A { inputs( x : BOOL ) outputs( y : BOOL ) guarantee( out.y ) triggered by in.x within 2 h }")
    assert seconds(spec.nodes[0].guarantees[0].deadline) == 7200


# ---------------------------------------------------------------------------
# Probable scale mismatch without units
# ---------------------------------------------------------------------------

def _pair(producer: str, consumer: str, out_unit: str = "", in_unit: str = "") -> list:
    src = (f"node Lidar {{ inputs( r : REAL ) outputs( d : REAL{out_unit} ) assume( 0 <= in.r and in.r <= 30 ) "
           f"guarantee( {producer} ) }}\n"
           f"node Controller {{ inputs( d : REAL{in_unit} ) outputs( v : REAL ) assume( {consumer} ) "
           f"guarantee( out.v >= 0 ) }}\n")
    checked = check([parse_text(src, "w.rcl")])
    return list(compose_node(checked, build(checked), "Controller").side_conditions)


def test_probable_scale_mismatch_on_a_side_condition():
    [sc] = _pair("out.d == 1000 * in.r", "0 <= in.d and in.d <= 30")[1:]
    assert sc.status == "failed"
    [m] = sc.scale
    assert m["producer_range"] == ["0", "30000"] and m["consumer_range"] == ["0", "30"] and m["factor"] == "1000"
    assert m["message"].startswith("probable scale mismatch: Lidar.out.d ranges over [0, 30000]")
    assert "they differ by a factor of 1000, as a value in [mm] read as [m] would" in m["message"]
    assert "rather than widen Controller's assumption" in m["message"]
    assert "Probable scale mismatch" in sc.explanation
    [f] = scale_findings([sc.to_json("x.smt2")])
    assert (f.check, f.status, f.node, f.id) == ("probable-scale-mismatch", "warning", "Controller",
                                                            "Controller.sc2.scale")
    assert "probable scale mismatch" in f.message
    # a stale record, or a discharged side condition, gives no finding
    assert scale_findings([{**sc.to_json("x.smt2"), "status": "stale"}]) == []


@pytest.mark.parametrize("producer, consumer", [
    ("out.d == 10 * in.r", "0 <= in.d and in.d <= 30"),          # a factor of 10: an ordinary margin
    ("0 <= out.d and out.d <= 31000", "in.d <= 25"),            # 1240: not a power of ten
    ("out.d >= 0", "in.d <= 30"),                               # unbounded producer
    ("out.d == in.r", "in.d <= 30"),                            # discharged
])
def test_no_scale_mismatch(producer, consumer):
    assert all(sc.scale == () for sc in _pair(producer, consumer))


def test_declared_units_leave_it_to_the_unit_check():
    scs = _pair("out.d == 1000 * in.r", "in.d <= 30", " [mm]", " [mm]")
    assert scs[0].status == "failed" and scs[0].scale == ()


@settings(max_examples=40, deadline=None)
@given(st.integers(-50, 50), st.integers(1, 60), st.sampled_from([-6, -3, -2, 2, 3, 6, 9]))
def test_scale_power_against_its_definition(lo, width, k):
    consumer = (Fraction(lo), Fraction(lo + width))
    f = Fraction(10) ** k
    producer = (consumer[0] * f, consumer[1] * f)
    assert scale_power(producer, consumer) == k
    assert scale_power(consumer, consumer) is None  # one scale: nothing to say
    s = width + Fraction(abs(lo) + width, 10) + 1  # past the 2 % slack whatever the bounds' magnitude
    shifted = (producer[0] + f * s, producer[1] + f * s)  # right scale, wrong place: that scale does not fit
    assert scale_power(shifted, consumer) != k  # (another power of ten may fit what is left: not this one)


@settings(max_examples=30, deadline=None)
@given(st.integers(-5, 5), st.integers(0, 6), st.integers(-4, 4), st.integers(-3, 3))
def test_optimised_range_against_enumeration(lo, width, c, shift):
    """The producer's range Z3's optimiser gives equals the enumerated
    range of ``c * r + shift`` over the integers ``lo..lo+width``."""
    import z3
    r, d = z3.Int("r"), z3.Int("d")
    facts = [lo <= r, r <= lo + width, d == c * r + shift]
    values = [c * x + shift for x in range(lo, lo + width + 1)]
    assert _range(d, facts) == (Fraction(min(values)), Fraction(max(values)))


def test_snapshots_follow_units_incremental_equals_clean(tmp_path):
    """A changed unit changes the node's snapshot (so every stage made from
    it is made again), and the snapshot after the edit in a workspace that
    kept its texts equals the one a clean workspace makes; the check stage
    lists a unit declared at one end only among its warnings."""
    import shutil
    from rclverify.app.pipeline import Workspace, stage_check

    def ws(root, text):
        (root / "contracts").mkdir(parents=True, exist_ok=True)
        (root / "contracts" / "robot.rcl").write_text(text, encoding="utf-8")
        (root / "contracts" / "plan.yaml").write_text("contracts: [contracts/robot.rcl]\n", encoding="utf-8")
        return Workspace(root)

    same = _SYSTEM.replace("d : REAL [m], w", "d : REAL [mm], w")
    inc = tmp_path / "inc"
    out = stage_check(ws(inc, same))
    assert [w["code"] for w in out["warnings"] if w["code"].startswith("W-unit")] == ["W-unit-missing"]
    before = (inc / "artifacts/contracts/Controller.json").read_text(encoding="utf-8")
    edited = same.replace("d : REAL [mm], w : REAL [m/s]", "d : REAL [um], w : REAL [m/s]").replace(
        "d : REAL [mm], w : REAL )", "d : REAL [um], w : REAL )").replace("1000 [mm/m]", "1000000 [um/m]")
    stage_check(ws(inc, edited))
    after = (inc / "artifacts/contracts/Controller.json").read_text(encoding="utf-8")
    assert after != before and "d : REAL [um]" in after
    clean = tmp_path / "clean"
    stage_check(ws(clean, edited))
    for node in ("Lidar", "Controller"):
        assert (clean / f"artifacts/contracts/{node}.json").read_text(encoding="utf-8") == \
            (inc / f"artifacts/contracts/{node}.json").read_text(encoding="utf-8")
    shutil.rmtree(clean)


def test_fmt_command_round_trip_and_literal_units_alone(tmp_path, capsys):
    f = tmp_path / "robot.rcl"
    f.write_text(_SYSTEM, encoding="utf-8")
    assert main(["fmt", str(f)]) == 0
    printed = capsys.readouterr().out
    assert "outputs( d : REAL [mm], w : REAL )" in printed and "1000 [mm/m] * in.r" in printed
    assert parse_text(printed) == parse_text(_SYSTEM)
    # a file without any unit is parsed as such, and skips the unit pass; a unit on a number alone is checked
    assert parse_text("node A { inputs( r : REAL ) outputs( d : REAL ) guarantee( out.d > 2 ) }").has_units is False
    [(line, col, code, _)] = _errors("node A { inputs( r : REAL ) outputs( d : REAL )\n"
                                     "  guarantee( out.d > 0 and 2 [m] < 3 [s] ) }")
    assert (line, col, code) == (2, 36, "E-unit-dimension")


@pytest.mark.parametrize("producer, consumer, factor, units", [
    ("out.d == 180 / 3.141592653589793 * in.r / 5", "0 <= in.d and in.d <= 6.2832 / 5 * 30 / 6.2832", "180/pi",
     ("[deg] read as [rad]")),
    ("out.d == 3.6 * in.r", "0 <= in.d and in.d <= 30", "3.6", "[km/h] read as [m/s]"),
    ("out.d == in.r / 0.3048", "0 <= in.d and in.d <= 30", "1/0.3048", "[ft] read as [m]"),
])
def test_the_usual_conversions_are_named(producer, consumer, factor, units):
    """Issue 48: the scale hint knew powers of ten only (not 180/pi, 3.6, 0.3048)."""
    [sc] = _pair(producer, consumer)[1:]
    assert sc.status == "failed"
    [m] = sc.scale
    assert m["factor"] == factor and f"as a value in {units} would" in m["message"], m["message"]
    [f] = scale_findings([sc.to_json("x.smt2")])
    assert f"differ by a factor of {factor}" in f.explanation
