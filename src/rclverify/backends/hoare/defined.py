"""The definedness verification conditions of a Hoare triple.

A triple is discharged only when everything it reads is defined
(docs/semantics.md, "Definedness"; the conditions Why3, Dafny and SPARK
generate): Z3 reads ``n / 0`` as an unspecified number, so without them
``{0 <= d <= 10} r := n / d {r == n / d}`` would be proved.  Three kinds:

``defined.pre<k>``
    the precondition's ``k``-th condition (left to right, under the
    conjuncts before it) holds wherever the guarantee's bound variables
    range (Dafny checks a ``requires`` clause's well-formedness so);
``defined@<line>:<col>`` (and ``...loop@<l>.<part>``)
    the program's division at that place divides by a non-zero number on
    every run from the precondition (:func:`.wp.wp` with ``target``);
``defined.post<k>``
    the postcondition's ``k``-th condition holds in every final state of a
    run from the precondition (Dafny checks an ``ensures`` clause under
    the ``requires``).

Each VC's label names the condition and where the division is written
(``file:line:col``); a refuted one's counterexample shows the zero divisor.
"""
from __future__ import annotations

import dataclasses

import z3

from rclverify.lang.ast import Loc
from rclverify.semantics.operators import OPERATORS
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.obligations import EncodedTriple
from rclverify.backends.hoare.program_model import ProgramModel
from rclverify.backends.hoare.wp import VC, main_vc, partial_applications, requirement_text, wp


def _prefixed(prefix: str, label: str, vcs: tuple[VC, ...]) -> list[VC]:
    return [dataclasses.replace(v, id=f"{prefix}.{v.id}", label=f"{label} ({v.label})") for v in vcs]


def definedness_vcs(program: lang.Program, m: ProgramModel, triple: EncodedTriple, loc: Loc) -> list[VC]:
    """The definedness VCs of ``triple`` over ``program`` (module docstring),
    in the order pre, program (program order), post.  ``loc`` locates the
    conjunct.  Empty when neither the triple nor the program applies a
    partial operator.  Pure: no solver call."""
    vcs: list[VC] = []
    for k, (cond, formula) in enumerate(triple.pre_defined, 1):
        vcs.append(VC(f"defined.pre{k}", f"the precondition is defined: {cond.describe()}", triple.pre_guards,
                      formula, cond.loc, "initial"))
    for target in partial_applications(program.body):
        where = target.loc
        vid = f"defined@{where.line}:{where.col}"
        label = (f"{requirement_text(target)} for the {OPERATORS[target.op].name} at "
                 f"{where.file}:{where.line}:{where.col}")
        run = wp(program.body, z3.BoolVal(True), m, target=target)
        if not z3.is_true(run.pre):
            vcs.append(dataclasses.replace(main_vc(triple.pre, run, m, where), id=vid, label=label))
        vcs.extend(_prefixed(vid, label, run.vcs))
    for k, (cond, formula) in enumerate(triple.post_defined, 1):
        run = wp(program.body, formula, m)
        label = f"the postcondition is defined after the program: {cond.describe()}"
        vcs.append(dataclasses.replace(main_vc(triple.pre, run, m, loc), id=f"defined.post{k}", label=label))
        vcs.extend(_prefixed(f"defined.post{k}", label, run.vcs))
    return vcs


__all__ = ["definedness_vcs"]
