"""The SARIF log's rules (``reportingDescriptor``, SARIF 2.1.0 section 3.49):
one stable rule id per kind of finding the assurance report lists, with its
name, default level and one-paragraph text (:data:`RULES`), the rule of a
lint code (:func:`lint_rule_id`), and which rule a requirement's verdict, a
health check or an obligation's status gives (:data:`REQUIREMENT_RULE`,
:data:`HEALTH_RULE`, :data:`OBLIGATION_RULE`).  :mod:`.sarif` lays the
results out; the ids never change once published (code scanning views track
results by them; docs/ci.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping


@dataclass(frozen=True)
class Rule:
    """One kind of finding: a stable SARIF ``reportingDescriptor``."""

    id: str
    name: str
    level: str
    text: str


#: The fixed rules, keyed by id.  Lint rules are derived from the lint codes
#: (:func:`lint_rule_id`).
RULES: Mapping[str, Rule] = {r.id: r for r in (
    Rule("RCL-ACK-STALE", "AcknowledgementStale", "warning",
         "A plan acknowledgement answers no warning of this run, or the text it acknowledged changed (the "
         "warning is raised again), or it names an item that is not a warning."),
    Rule("RCL-OBL-FAILED", "ObligationFailed", "error",
         "A backend refuted a proof obligation of a node's guarantee (the evidence is failed)."),
    Rule("RCL-OBL-ERROR", "ObligationError", "error",
         "A backend could not check a proof obligation (the evidence is error)."),
    Rule("RCL-OBL-STALE", "ObligationStale", "warning",
         "An input of the obligation changed after its evidence was produced; the evidence no longer vouches for it."),
    Rule("RCL-OBL-INCONCLUSIVE", "ObligationInconclusive", "warning",
         "The backend could not decide the obligation (unknown, timeout or bounded search)."),
    Rule("RCL-OBL-PENDING", "ObligationPending", "warning",
         "The obligation has no evidence yet (the backend cannot run here or is not implemented): the guarantee "
         "is not established, and --strict fails on it."),
    Rule("RCL-GUARANTEE-UNVERIFIED", "GuaranteeUnverified", "warning",
         "No obligation covers the guarantee: no evidence entry of the plan exports one for it, so nothing "
         "establishes it."),
    Rule("RCL-SC-REFUTED", "SideConditionRefuted", "error",
         "Z3 refuted a side condition of the composition calculus: the producers' guarantees do not entail "
         "this conjunct of the consumer's assumption."),
    Rule("RCL-SC-INCONCLUSIVE", "SideConditionInconclusive", "warning",
         "Z3 could not decide a side condition of the composition calculus."),
    Rule("RCL-SC-IN-CONTEXT", "SideConditionDischargedInContext", "note",
         "A side condition the producers' guarantees alone do not entail (the premise of rules R1-R3 as printed) "
         "is discharged in context: Z3 proved it from the upstream cone, each guarantee under its own node's "
         "assumption; the upstream premises it rests on are named (docs/calculus.md)."),
    Rule("RCL-HEALTH-UNSATISFIABLE-ASSUMPTION", "AssumptionUnsatisfiable", "error",
         "The node's assumption can never hold: its contract promises nothing."),
    Rule("RCL-HEALTH-INCONSISTENT", "ContractInconsistent", "error",
         "The node's guarantees contradict each other (or the environment facts) under its assumption."),
    Rule("RCL-HEALTH-VACUOUS", "GuaranteeVacuous", "error",
         "The premise of a guarantee can never hold together with the other guarantees and the facts: "
         "it promises nothing."),
    Rule("RCL-HEALTH-UNREALIZABLE", "ContractUnrealizable", "error",
         "Some input the node's assumption (and the environment facts) admit has no output satisfying its "
         "guarantees: no implementation can meet the contract (the input is in the message)."),
    Rule("RCL-HEALTH-REPLACEMENT", "ReplacementDoesNotRefine", "error",
         "The replacement contract offered for the node does not refine the node's contract."),
    Rule("RCL-HEALTH-TAUTOLOGY", "GuaranteeTautology", "error",
         "A conjunct of a guarantee holds whatever the inputs and outputs: it promises nothing."),
    Rule("RCL-HEALTH-NO-OUTPUT", "GuaranteeConstrainsNoOutput", "error",
         "A guarantee mentions no output of its node: an implementation meets it whatever it outputs."),
    Rule("RCL-HEALTH-REDUNDANT", "ConjunctRedundant", "warning",
         "A conjunct of a guarantee follows from the assumption and the other conjuncts: it adds nothing (often a "
         "copy-paste slip)."),
    Rule("RCL-HEALTH-SCALE", "ProbableScaleMismatch", "warning",
         "A side condition fails and the producer's range and the consumer's differ by a power of ten: probably one "
         "end is in other units (mm against m); declare the units (docs/rcl-language.md)."),
    Rule("RCL-HEALTH-OTHER", "HealthProblem", "error", "A contract health check found a problem."),
    Rule("RCL-HEALTH-INCONCLUSIVE", "HealthInconclusive", "warning",
         "Z3 could not decide a contract health check."),
    Rule("RCL-SC-STALE", "SideConditionStale", "warning",
         "The side condition was decided for another text of the contracts or plan than the current one."),
    Rule("RCL-HEALTH-STALE", "HealthStale", "warning",
         "The contract health check was made for another text of the contract or plan than the current one."),
    Rule("RCL-REQ-REFUTED", "RequirementRefuted", "error",
         "Z3 found a counterexample to a formal requirement that the guarantees of its cone allow: the composed "
         "contracts do not meet it."),
    Rule("RCL-REQ-INCONSISTENT", "RequirementProvedFromInconsistency", "error",
         "A formal requirement is proved only because the premises its proof used contradict each other: it holds "
         "vacuously, not because the system meets it."),
    Rule("RCL-REQ-VACUOUS", "RequirementProvedVacuously", "error",
         "A formal requirement of the form P -> Q is proved only because P can never hold with the premises of its "
         "cone: it never applies."),
    Rule("RCL-REQ-INCONCLUSIVE", "RequirementInconclusive", "warning",
         "Z3 could not decide a formal requirement (or whether the premises of its proof are consistent)."),
    Rule("RCL-REQ-EVIDENCE", "RequirementEvidenceOutstanding", "warning",
         "A formal requirement is proved from the guarantees, but the evidence of the guarantees its proof used "
         "is not all discharged."),
    Rule("RCL-REQ-STALE", "RequirementStale", "warning",
         "A requirement's check was made from another text of the contracts, plan or model than the current one."),
    Rule("RCL-REQ-ERROR", "RequirementRecordAltered", "error",
         "A requirement's check record was altered outside rclverify (its seal does not hold): its verdict is not shown."),
    Rule("RCL-REQ-INFORMAL", "RequirementInformal", "note",
         "A requirement has no formal statement: it is traced to guarantees, never checked, never met."),
)}
#: A requirement's verdict -> its rule id (a met requirement has none).
REQUIREMENT_RULE = {"refuted": "RCL-REQ-REFUTED", "proved from an inconsistency": "RCL-REQ-INCONSISTENT",
                     "proved vacuously": "RCL-REQ-VACUOUS",
                     "inconclusive": "RCL-REQ-INCONCLUSIVE", "proved, evidence outstanding": "RCL-REQ-EVIDENCE",
                     "informal": "RCL-REQ-INFORMAL", "stale": "RCL-REQ-STALE", "error": "RCL-REQ-ERROR"}

#: A health check -> the rule id of its problem (``RCL-HEALTH-OTHER`` for a check not named).
HEALTH_RULE = {"assumption-satisfiable": "RCL-HEALTH-UNSATISFIABLE-ASSUMPTION",
                "contract-consistent": "RCL-HEALTH-INCONSISTENT",
                "non-vacuous": "RCL-HEALTH-VACUOUS",
                "realizable": "RCL-HEALTH-UNREALIZABLE",
                "replacement-refines": "RCL-HEALTH-REPLACEMENT",
                "tautology": "RCL-HEALTH-TAUTOLOGY",
                "constrains-no-output": "RCL-HEALTH-NO-OUTPUT",
                "redundant": "RCL-HEALTH-REDUNDANT",
                "probable-scale-mismatch": "RCL-HEALTH-SCALE"}
#: An obligation's status -> its rule id (a discharged one has none).
OBLIGATION_RULE = {"failed": "RCL-OBL-FAILED", "error": "RCL-OBL-ERROR", "stale": "RCL-OBL-STALE",
                    "inconclusive": "RCL-OBL-INCONCLUSIVE", "pending": "RCL-OBL-PENDING"}


def lint_rule_id(code: str) -> str:
    """Rule id of a lint code: ``W-unused-bound`` -> ``RCL-LINT-UNUSED-BOUND``
    (``RCL-LINT`` when the code is empty)."""
    tail = code.split("-", 1)[1] if code[:2] in ("W-", "E-") else code
    return f"RCL-LINT-{tail.upper()}" if tail else "RCL-LINT"


__all__ = ["HEALTH_RULE", "OBLIGATION_RULE", "REQUIREMENT_RULE", "RULES", "Rule", "lint_rule_id"]
