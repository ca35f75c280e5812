"""Statistical guarantees from counted runs (docs/statistics.md).

What a set of monitored runs or experiment trials says about the
probability that a run (or a judged answer) violates a guarantee:

* :func:`upper_bound` - the exact one-sided Clopper-Pearson upper
  confidence bound on a binomial proportion (Clopper and Pearson,
  Biometrika 26(4), 1934), from scipy's inverse of the regularized
  incomplete beta function (``scipy.special.betaincinv``, the quantile
  ``scipy.stats.beta.ppf`` computes, bit for bit; the import is a quarter
  of ``scipy.stats``'s, 0.3 s instead of 1.2 s): with ``k``
  violations in ``n`` trials, the ``level`` quantile of Beta(k+1, n-k);
  with ``k = 0`` it is ``1 - (1 - level) ** (1 / n)``, about ``3 / n`` at
  95 % (the "rule of three");
* :func:`runs_needed` - the fewest further violation-free runs after which
  the bound, with the violations seen so far, meets a target;
* :func:`sprt` - Wald's sequential probability ratio test (Wald, Annals of
  Mathematical Statistics 16(2), 1945) of "the rate is at most half the
  target" against "the rate is at least the target", which says when a
  campaign may stop because it has already failed (or passed with margin);
* :func:`count_runs` and :func:`decide` - run rows counted once per digest,
  and the target's verdict on them.

The rules assume the runs are independent and representative of the
operating conditions they are tagged with; nothing here can check that
(docs/statistics.md says what the plan must state).  Standard library and
scipy only: this sits with the evidence records, below every stage.
scipy is the ``stats`` extra (docs/install.md): without it a bound with
``k > 0`` cannot be computed, :func:`trivial_or_exact` gives the trivial
bound 1 with the reason, and :func:`decide` says ``inconclusive``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, NotRequired, Protocol, TypedDict

#: What a target counts: a whole run with any violation, or one judged answer.
PER = ("run", "answer")


def upper_bound(k: int, n: int, level: float) -> float:
    """The exact one-sided upper confidence bound, at ``level`` (0 < level <
    1), on the probability of a violation, from ``k`` violations in ``n``
    independent trials (Clopper-Pearson; module docstring).  ``1.0`` when
    ``n <= 0`` or ``k >= n`` (nothing bounds it).  Raises ``ValueError`` for
    ``k < 0`` or a level outside (0, 1)."""
    if not 0.0 < level < 1.0:
        raise ValueError(f"a confidence level is between 0 and 1 (exclusive), not {level}")
    if k < 0:
        raise ValueError(f"a count of violations is at least 0, not {k}")
    if n <= 0 or k >= n:
        return 1.0
    if k == 0:  # closed form, exact in floating point where beta.ppf rounds
        return 1.0 - math.pow(1.0 - level, 1.0 / n)
    from rclverify.core.numeric import scipy_special  # here, not at import: scipy costs every plan load 0.3 s
    return float(scipy_special().betaincinv(k + 1, n - k, level))  # Beta(k+1, n-k)'s quantile at level


def trivial_or_exact(k: int, n: int, level: float) -> tuple[float, str]:
    """``(upper_bound(k, n, level), "")``, or ``(1.0, why)`` when the exact
    bound needs scipy and the ``stats`` extra is not installed: 1 bounds
    every probability, so the figure stays true, and ``why`` is the one
    line naming the extra (:mod:`rclverify.core.extras`)."""
    from rclverify.core.extras import MissingExtra  # deferred: start-up (the module is small; only where a bound is computed)
    try:
        return upper_bound(k, n, level), ""
    except MissingExtra as exc:
        return 1.0, str(exc)


def lower_bound(k: int, n: int, level: float) -> float:
    """The exact one-sided lower Clopper-Pearson bound at ``level``: the
    ``1 - level`` quantile of Beta(k, n-k+1); ``0.0`` when ``k <= 0``."""
    if k <= 0 or n <= 0:
        return 0.0
    if k >= n:
        return math.pow(1.0 - level, 1.0 / n)
    from rclverify.core.numeric import scipy_special  # deferred: start-up (loads numpy and scipy only when called)
    return float(scipy_special().betaincinv(k, n - k + 1, 1.0 - level))  # Beta(k, n-k+1)'s quantile at 1 - level


def runs_needed(k: int, n: int, target: float, level: float) -> int | None:
    """The fewest further violation-free runs ``m >= 0`` such that
    ``upper_bound(k, n + m, level) <= target``; ``None`` when no number
    does (``target <= 0``).  The bound falls as ``n`` grows with ``k`` fixed,
    so an exponential then a binary search finds ``m``."""
    if upper_bound(k, n, level) <= target:
        return 0
    if target <= 0.0:
        return None
    hi = 1
    while upper_bound(k, n + hi, level) > target:
        hi *= 2
        if hi > 1 << 62:
            return None
    lo = hi // 2  # the bound at n + lo misses the target (or lo == 0, checked above)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if upper_bound(k, n + mid, level) <= target:
            hi = mid
        else:
            lo = mid
    return hi


class SprtJson(TypedDict):
    """:class:`Sprt` as JSON (``llr`` and the thresholds rounded to 6 places)."""
    llr: float
    accept_at: float
    reject_at: float
    p_good: float
    p_bad: float
    decision: str
    clean_runs_to_accept: int


class TargetJson(TypedDict):
    """A statistical target as JSON (model/plan/target_text.py ``TargetText.to_json``)."""
    bound: float
    level: float
    per: str
    text: str
    guarantee: int
    #: a margin target (docs/statistics.md, "Margin targets"): the least margin a trial must keep
    margin: NotRequired[float]


class TargetDecision(TypedDict):
    """What :func:`decide` gives: the trials, the bounds, the target, the runs still needed, the SPRT
    and the verdict (``status`` and ``explanation``)."""
    n: int
    k: int
    undecided: int
    bound: float
    bound_without_undecided: float
    level: float
    target: TargetJson
    runs_needed: int | None
    sprt: SprtJson
    status: str
    explanation: str


@dataclass(frozen=True)
class Sprt:
    """Wald's SPRT state: ``llr`` the log likelihood ratio of the good rate
    ``p_good`` over the bad rate ``p_bad``; ``accept_at`` / ``reject_at`` its
    thresholds ``ln((1-b)/a)`` and ``ln(b/(1-a))``; ``decision`` one of
    ``"accept"`` (the rate is at most ``p_good``), ``"reject"`` (at least
    ``p_bad``) or ``"continue"``; ``clean_runs_to_accept`` how many further
    violation-free runs would reach ``accept`` from here."""

    llr: float
    accept_at: float
    reject_at: float
    p_good: float
    p_bad: float
    decision: str
    clean_runs_to_accept: int

    def to_json(self) -> SprtJson:
        return {"llr": round(self.llr, 6), "accept_at": round(self.accept_at, 6), "reject_at": round(self.reject_at, 6),
                "p_good": self.p_good, "p_bad": self.p_bad, "decision": self.decision,
                "clean_runs_to_accept": self.clean_runs_to_accept}


def sprt(k: int, n: int, target: float, level: float) -> Sprt:
    """Wald's SPRT after ``k`` violations in ``n`` runs, of ``H0: p =
    target / 2`` (good) against ``H1: p = target`` (bad), both error rates
    ``1 - level``.  Each clean run adds ``ln((1-p_good)/(1-p_bad))`` to the
    log likelihood ratio, each violation ``ln(p_good/p_bad)`` (Wald 1945).
    Raises ``ValueError`` unless ``0 < target < 1``."""
    if not 0.0 < target < 1.0:
        raise ValueError(f"an SPRT needs a target rate between 0 and 1, not {target}")
    good, bad = target / 2.0, target
    a = b = 1.0 - level
    step_clean = math.log((1.0 - good) / (1.0 - bad))
    llr = k * math.log(good / bad) + (n - k) * step_clean
    accept_at, reject_at = math.log((1.0 - b) / a), math.log(b / (1.0 - a))
    decision = "accept" if llr >= accept_at else "reject" if llr <= reject_at else "continue"
    more = 0 if llr >= accept_at else math.ceil((accept_at - llr) / step_clean - 1e-12)
    return Sprt(llr, accept_at, reject_at, good, bad, decision, int(more))


class TargetLike(Protocol):
    """What :func:`decide` reads of a target (the plan's
    :class:`rclverify.model.plan.targets.Target`): the violation probability
    ``bound``, the confidence ``level``, ``per`` run or answer, and its
    words and JSON form."""

    @property
    def bound(self) -> float: ...

    @property
    def level(self) -> float: ...

    @property
    def per(self) -> str: ...

    def words(self) -> str: ...

    def to_json(self) -> TargetJson: ...


#: The fields of one run row that :func:`count_runs` adds up.
COUNTED = ("answers", "violations", "inconclusive", "seconds")


def count_runs(rows: Iterable[Mapping[str, Any]]) -> dict[str, Any]:
    """The counts of run ``rows`` (each ``{"sha256", "status", "answers",
    "violations", "inconclusive", "seconds"}``), each distinct ``sha256``
    counted once (the first row of a digest; the later ones are
    ``duplicates``).  A run is *judged* when its status is ``discharged``
    or ``failed``, *violating* when it has a violation, *undecided* when it
    is judged nowhere else but has an inconclusive answer, and *unjudged*
    (pending, error: nothing checked) otherwise; only judged and undecided
    runs count.  Returns ``{"runs", "violating_runs", "undecided_runs",
    "unjudged_runs", "duplicates", "answers", "violations", "inconclusive",
    "seconds", "digests"}``."""
    seen: set[str] = set()
    out: dict[str, Any] = {"runs": 0, "violating_runs": 0, "undecided_runs": 0, "unjudged_runs": 0,
                           "duplicates": 0, "answers": 0, "violations": 0, "inconclusive": 0, "seconds": 0.0}
    for r in rows:
        sha = str(r.get("sha256") or "")
        if sha in seen:
            out["duplicates"] += 1
            continue
        seen.add(sha)
        violations, unsure = int(r.get("violations") or 0), int(r.get("inconclusive") or 0)
        if violations == 0 and unsure == 0 and r.get("status") not in ("discharged", "failed"):
            out["unjudged_runs"] += 1
            continue
        out["runs"] += 1
        out["violating_runs"] += violations > 0
        out["undecided_runs"] += violations == 0 and unsure > 0
        out["answers"] += int(r.get("answers") or 0)
        out["violations"] += violations
        out["inconclusive"] += unsure
        out["seconds"] += float(r.get("seconds") or 0.0)
    out["seconds"] = round(out["seconds"], 6)
    out["digests"] = sorted(seen)
    return out


def trials(counts: Mapping[str, Any], per: str) -> tuple[int, int, int]:
    """``(n, violations, undecided)`` of ``counts`` counted ``per`` run or
    answer: per run, the runs, the violating runs and the undecided runs;
    per answer, the judged answers plus the inconclusive ones, the
    violations and the inconclusive answers."""
    if per == "answer":
        return (int(counts["answers"]) + int(counts["inconclusive"]), int(counts["violations"]),
                int(counts["inconclusive"]))
    return int(counts["runs"]), int(counts["violating_runs"]), int(counts["undecided_runs"])


def decide(counts: Mapping[str, Any], target: TargetLike) -> TargetDecision:
    """The target's verdict on ``counts`` (:func:`count_runs`).  Undecided
    runs or answers count as violations for the bound (never a guess in the
    target's favour).  Returns ``{"status", "explanation", "n", "k",
    "undecided", "bound", "bound_without_undecided", "level", "target",
    "runs_needed", "sprt"}`` where ``status`` is ``discharged`` (the bound
    meets the target), ``failed`` (the SPRT says the rate is at least the
    target from the decided violations alone, the undecided ones counted
    clean), ``inconclusive`` (it would meet it were the undecided ones
    clean, or it is missed only if they are violations: undecided is never
    failed), or ``pending`` (``runs_needed`` further clean runs would)."""
    n, k, unsure = trials(counts, target.per)
    worst = k + unsure
    from rclverify.core.extras import MissingExtra  # deferred: start-up (only where a target is decided)
    try:
        bound = upper_bound(worst, n, target.level)
    except MissingExtra as exc:  # no bound without scipy: nothing decided, said so
        unit = "run" if target.per == "run" else "answer"
        return {"n": n, "k": k, "undecided": unsure, "bound": 1.0, "bound_without_undecided": 1.0,
                "level": target.level, "target": target.to_json(), "runs_needed": None,
                "sprt": sprt(worst, n, target.bound, target.level).to_json(), "status": "inconclusive",
                "explanation": f"{k} violating {unit}(s) in {n}: the bound is not computed ({exc})"}
    best = upper_bound(k, n, target.level)
    test = sprt(worst, n, target.bound, target.level)
    needed = runs_needed(worst, n, target.bound, target.level)
    unit = "run" if target.per == "run" else "answer"
    seen = f"{k} violating {unit}(s) in {n}" + (f" and {unsure} undecided" if unsure else "")
    pct = f"{target.level * 100:g} %"
    if n == 0:
        status, explanation = "pending", f"no judged {unit} yet: {needed} clean {unit}(s) would meet {target.words()}"
    elif bound <= target.bound:
        status, explanation = "discharged", f"{seen}: the {pct} upper bound {bound:.3g} meets {target.words()}"
    elif test.decision == "reject" and sprt(k, n, target.bound, target.level).decision == "reject":
        status, explanation = "failed", (f"{seen}: the SPRT says the rate is at least {target.bound:g} "
                                         f"(upper bound {bound:.3g}): stop, the target is missed")
    elif test.decision == "reject":  # missed only if the undecided ones are violations: nothing decided it
        status, explanation = "inconclusive", (f"{seen}: the target is missed only if the {unsure} "
                                               f"undecided {unit}(s) are violations (the SPRT rejects with "
                                               f"them, not with the {k} decided violation(s) alone)")
    elif unsure and best <= target.bound:
        status, explanation = "inconclusive", (f"{seen}: the target is met only if the {unsure} undecided "
                                               f"{unit}(s) are clean (upper bound {best:.3g} without them, "
                                               f"{bound:.3g} with them)")
    else:
        status, explanation = "pending", (f"{seen}: the {pct} upper bound {bound:.3g} misses "
                                          f"{target.words()}; {needed} further clean {unit}(s) would meet it "
                                          f"(SPRT: {test.decision})")
    return {"n": n, "k": k, "undecided": unsure, "bound": bound, "bound_without_undecided": best,
            "level": target.level, "target": target.to_json(), "runs_needed": needed, "sprt": test.to_json(),
            "status": status, "explanation": explanation}


__all__ = ["PER", "Sprt", "TargetLike", "count_runs", "decide", "lower_bound", "runs_needed", "sprt", "trials",
           "upper_bound"]
