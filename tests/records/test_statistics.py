"""The statistics of counted runs (records/statistics.py, issue 68): the Clopper-Pearson bound, the runs still
needed and Wald's SPRT, each against an independent brute-force computation on small cases."""
from __future__ import annotations

import math
import random

import pytest

from rclverify.records.statistics import count_runs, decide, lower_bound, runs_needed, sprt, upper_bound
from rclverify.model.plan.target_text import parse_target


def binom_cdf(k: int, n: int, p: float) -> float:
    """P(X <= k) for X ~ Binomial(n, p), summed term by term with math.comb."""
    return sum(math.comb(n, i) * p ** i * (1 - p) ** (n - i) for i in range(k + 1))


def oracle_upper(k: int, n: int, level: float) -> float:
    """The p at which P(X <= k) = 1 - level, by bisection (the CDF falls as p grows)."""
    if k >= n:
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(80):
        mid = (lo + hi) / 2
        if binom_cdf(k, n, mid) > 1 - level:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def oracle_lower(k: int, n: int, level: float) -> float:
    """The p at which P(X >= k) = 1 - level, by bisection (P(X >= k) grows with p)."""
    if k <= 0:
        return 0.0
    lo, hi = 0.0, 1.0
    for _ in range(80):
        mid = (lo + hi) / 2
        if 1 - binom_cdf(k - 1, n, mid) < 1 - level:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


def test_upper_and_lower_bounds_equal_brute_force_on_random_small_cases() -> None:
    rng = random.Random(68)
    for _ in range(150):
        n = rng.randint(1, 40)
        k = rng.randint(0, n)
        level = rng.choice([0.8, 0.9, 0.95, 0.99])
        assert upper_bound(k, n, level) == pytest.approx(oracle_upper(k, n, level), abs=1e-9)
        assert lower_bound(k, n, level) == pytest.approx(oracle_lower(k, n, level), abs=1e-9)


def test_the_bounds_are_scipy_stats_beta_quantiles_bit_for_bit() -> None:
    """The bounds take Beta's quantile from scipy.special (a quarter of scipy.stats's import): on random cases
    up to 5,000 trials each is exactly the float scipy.stats.beta.ppf gives."""
    from scipy.stats import beta
    rng = random.Random(67)
    for _ in range(400):
        n = rng.randint(2, 5000)
        k = rng.randint(1, n - 1)
        level = rng.choice([0.8, 0.9, 0.95, 0.99, 0.999, rng.uniform(0.01, 0.99)])
        assert upper_bound(k, n, level) == float(beta.ppf(level, k + 1, n - k))
        assert lower_bound(k, n, level) == float(beta.ppf(1.0 - level, k, n - k + 1))


def test_runs_needed_equals_the_first_n_the_oracle_accepts() -> None:
    rng = random.Random(7)
    for _ in range(40):
        k, n = rng.randint(0, 3), rng.randint(0, 30)
        target = rng.choice([0.05, 0.1, 0.2, 0.3])
        m = 0
        while oracle_upper(k, n + m, 0.95) > target:
            m += 1
        assert runs_needed(k, n, target, 0.95) == m


def sprt_oracle(outcomes: list[bool], target: float, level: float) -> tuple[str, float]:
    """Wald's likelihood ratio as a product over the runs, compared with A = (1-b)/a and B = b/(1-a)."""
    good, bad = target / 2, target
    ratio = 1.0
    for violated in outcomes:
        ratio *= (good / bad) if violated else (1 - good) / (1 - bad)
    a = b = 1 - level
    return ("accept" if ratio >= (1 - b) / a else "reject" if ratio <= b / (1 - a) else "continue"), math.log(ratio)


def test_sprt_equals_the_product_of_likelihood_ratios() -> None:
    rng = random.Random(11)
    for _ in range(60):
        n = rng.randint(0, 300)
        k = rng.randint(0, min(n, 6))
        target = rng.choice([0.01, 0.05, 0.2])
        s = sprt(k, n, target, 0.95)
        decision, llr = sprt_oracle([True] * k + [False] * (n - k), target, 0.95)
        assert s.llr == pytest.approx(llr, abs=1e-9)
        assert s.decision == decision
        after = sprt_oracle([True] * k + [False] * (n - k + s.clean_runs_to_accept), target, 0.95)[0]
        assert after == "accept"
        if s.clean_runs_to_accept:
            assert sprt_oracle([True] * k + [False] * (n - k + s.clean_runs_to_accept - 1), target, 0.95)[0] != "accept"


def test_the_rule_of_three_and_the_issue_figures() -> None:
    assert upper_bound(0, 299, 0.95) <= 0.01 < upper_bound(0, 298, 0.95)  # 299 clean runs meet 1 % at 95 %
    assert 3 / 300 == pytest.approx(upper_bound(0, 300, 0.95), rel=0.01)
    assert runs_needed(0, 100, 0.01, 0.95) == 199  # 100 clean runs fall short: 199 more
    assert upper_bound(1, 1000, 0.95) == pytest.approx(0.004735, abs=1e-6)  # one violation among 1000


def test_targets_parse_and_bad_ones_say_why() -> None:
    t = parse_target("violation probability <= 1e-3 at 95 % per answer")
    assert (t.bound, t.level, t.per) == (0.001, 0.95, "answer")
    t = parse_target("violation probability <= 1% at 0.99")
    assert (t.bound, t.level, t.per, t.guarantee) == (0.01, 0.99, "run", 0)
    t = parse_target("violation probability <= 2e-3 at 99 % per answer of guarantee 2")
    assert (t.per, t.guarantee) == ("answer", 2) and t.words().endswith("per answer of guarantee 2")
    for bad, why in [("violation probability < 1e-3 at 95 %", "a target reads"),
                     ("violation probability <= 1e-3 at 95 % per hour", "per run or per answer"),
                     ("violation probability <= 0 at 95 %", "between 0 and 1"),
                     ("violation probability <= 0.1 at 100 %", "below 100 %"),
                     ("violation probability <= 0.1 at 95 % per run of guarantee 0", "1-based")]:
        with pytest.raises(ValueError, match=why):
            parse_target(bad)


def _rows(n: int, violating: int = 0, unsure: int = 0, prefix: str = "r") -> list[dict[str, object]]:
    return [{"sha256": f"{prefix}{i}", "status": "failed" if i < violating else "inconclusive"
             if i < violating + unsure else "discharged", "answers": 3, "violations": int(i < violating),
             "inconclusive": int(violating <= i < violating + unsure), "seconds": 1.5} for i in range(n)]


def test_decide_meets_misses_and_refutes() -> None:
    per_run = parse_target("violation probability <= 1e-2 at 95 % per run")
    d = decide(count_runs(_rows(299)), per_run)
    assert d["status"] == "discharged" and d["bound"] <= 0.01
    d = decide(count_runs(_rows(100)), per_run)
    assert d["status"] == "pending" and d["runs_needed"] == 199 and "199 further clean run(s)" in d["explanation"]
    d = decide(count_runs(_rows(1000, violating=1)), per_run)
    assert d["status"] == "discharged" and d["k"] == 1
    d = decide(count_runs(_rows(40, violating=8)), per_run)
    assert d["status"] == "failed" and d["sprt"]["decision"] == "reject"
    d = decide(count_runs(_rows(400, unsure=2)), per_run)  # met only if the two undecided runs were clean
    assert d["status"] == "inconclusive" and d["undecided"] == 2
    assert decide(count_runs([]), per_run)["status"] == "pending"


def test_the_same_run_twice_is_counted_once() -> None:
    rows = _rows(5) + _rows(2)
    c = count_runs(rows)
    assert (c["runs"], c["duplicates"], c["answers"], c["seconds"]) == (5, 2, 15, 7.5)
    c = count_runs([{"sha256": "x", "status": "pending"}])
    assert (c["runs"], c["unjudged_runs"]) == (0, 1)


def test_decide_agrees_with_the_oracle_on_random_run_sets() -> None:
    """A target is discharged exactly when the brute-force bound, undecided runs counted as violations, meets it."""
    rng = random.Random(3)
    target = parse_target("violation probability <= 0.2 at 90 % per run")
    for _ in range(60):
        n = rng.randint(0, 30)
        k = rng.randint(0, min(n, 3))
        u = rng.randint(0, min(n - k, 2))
        d = decide(count_runs(_rows(n, violating=k, unsure=u)), target)
        assert (d["status"] == "discharged") == (n > 0 and oracle_upper(k + u, n, 0.9) <= 0.2)
        if d["status"] == "pending":
            m = d["runs_needed"]
            assert m > 0 and oracle_upper(k + u, n + m, 0.9) <= 0.2 < oracle_upper(k + u, n + m - 1, 0.9)
