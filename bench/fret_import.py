"""FRET exports imported and decided (issue 113): the figures of docs/requirements.md, "Requirements from FRET".

Reads every ``*.json`` FRET export under DIR (FRET's ``caseStudies/``, for
instance), imports each with rclverify's importer
(:mod:`rclverify.model.plan.fret.requirements`) and prints, per export and
in total: the requirements read, those translated to a decided temporal
statement, those refused by reason.

With ``--decide`` each export is then decided as a workspace of its own,
written under a temporary folder (nothing of the export is kept): one
contract per FRET component whose inputs and outputs are the component's
FRET ``Input`` and ``Output`` variables (``boolean`` as ``BOOL``, an
integer type as ``INTEGER``, another number as ``REAL``), ``assume(
TRUE )``, ``guarantee( TRUE )`` and ``progress( within 0 steps )``, the
plan reading a copy of the export through ``requirements_from: {fret:
...}``.  A translated statement that does not type-check with these
contracts is counted as refused (``type error``) and left out of the copy.
Then ``rclverify requirements`` (``stage_requirements``) decides each
one; a contract that guarantees nothing refutes almost every requirement,
so the figure measures that the statement is decided (a verdict other than
``inconclusive``), not that it holds.

With ``--plan FILE`` (a YAML file with a plan's ``fret:`` section; only
its ``variables`` and ``functions`` are read, e.g.
``bench/data/fret_case_studies.yaml``) the declarations a FRET export does
not carry are added; the totals then say how many requirements are
translated only with them.  With ``--decide`` the generated contract gives
a variable the plan declares an ``input``/``output`` a port (REAL unless
FRET says boolean or an integer type).

Usage::

    python bench/fret_import.py DIR            # import figures only
    python bench/fret_import.py DIR --decide   # and the verdicts (a minute or two)
    python bench/fret_import.py --smoke        # CI: the example's own export, decided
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import collections
import json
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from rclverify.model.plan.errors import PlanError  # noqa: E402
from rclverify.model.plan.fret.declared import ID_TYPES  # noqa: E402
from rclverify.model.plan.fret.export import FretExport, read_export  # noqa: E402
from rclverify.model.plan.fret.requirements import Options, import_export, options_of  # noqa: E402

#: Words RCL's grammar keeps for itself: a FRET variable so named gets no port in the generated contract.
RESERVED = {"and", "or", "not", "in", "forall", "exists", "exists_unique", "TRUE", "FALSE", "REAL", "INTEGER",
            "NATURAL", "BOOL", "STRING"}
INTEGERS = ("integer", "int", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64")


def reason_kind(reason: str) -> str:
    """A refusal's reason without its names: the row it is counted in."""
    for pat, kind in ((r"calls the FRET function (\w+)", r"FRET function \1"),
                      (r"it calls (\w+) with \d+ arguments", r"\1 called with another count of arguments than the plan's"),
                      (r"is an Internal variable defined in Lustre", "Internal variable defined in Lustre"),
                      (r"is not declared in the export", "identifier not declared in the export"),
                      (r"declared without an idType", "variable without an idType"),
                      (r"the timing finally", "timing finally"),
                      (r"with the scope (\w+), FRET(?:'s timing| reads the timing) (\w+)", r"timing \2 in scope \1"),
                      (r"has no past-time formalisation", "no ptExpanded in the export"),
                      (r"looks back (\d+) steps", "a window longer than the look-back bound"),
                      (r"is in \[[^]]*\] in FRET", "unit differs from the port's"),
                      (r"does not parse", "FRETish expression rclverify does not parse"),
                      (r"has no (input|output) named", "variable not a port of the node"),
                      (r"has not formalised it", "not formalised by FRET"),
                      (r"pre function's initial value", "a pre function whose initial value reads variables")):
        m = re.search(pat, reason)
        if m:
            return m.expand(kind)
    return reason


def _ident(name: str) -> str:
    out = re.sub(r"[^A-Za-z0-9_]", "_", name) or "Component"
    return out if out[0].isalpha() else f"C_{out}"


def _contracts(exp: FretExport, declared: dict[str, str] | None = None) -> tuple[str, dict[str, str]]:
    """One contract per component with its FRET Input and Output variables (and those without an idType
    that ``declared``, the plan's ``fret: variables``, places); the component -> node names."""
    comps = sorted({c for c, _ in exp.variables} | {r.component for r in exp.requirements if r.component})
    nodes = {c: _ident(c) for c in comps}
    text = []
    for c in comps:
        ports: dict[str, list[str]] = {"Input": [], "Output": []}
        for (vc, name), v in sorted(exp.variables.items()):
            kind = v.id_type or ID_TYPES.get((declared or {}).get(name, ""), "")
            if vc == c and kind in ports and name not in RESERVED and re.fullmatch(r"[A-Za-z_]\w*", name):
                t = "BOOL" if v.data_type == "boolean" else "INTEGER" if v.data_type in INTEGERS else "REAL"
                ports[kind].append(f"{name} : {t}")
        text.append(f"node {nodes[c]} {{\n  inputs( {', '.join(ports['Input'])} )\n"
                    f"  outputs( {', '.join(ports['Output'])} )\n  assume( TRUE )\n  guarantee( TRUE )\n"
                    f"  progress( within 0 steps )\n}}\n")
    return "\n".join(text), nodes


def exp_refused(exp: FretExport, options: Options) -> set[str]:
    """The reqids the import refuses without the contracts."""
    return {i.fret.reqid for i in import_export(exp, options) if i.refusal is not None}


def decide(export: Path, exp: FretExport, out: collections.Counter[str], step: str | None = None,
           extra: dict[str, Any] | None = None) -> None:
    """Decide the translated requirements of ``export`` in a workspace of their own (module docstring)."""
    from rclverify.app.pipeline import stage_check, stage_requirements
    from rclverify.stages.workspace import Workspace
    from rclverify.lang.errors import RclError
    raw = json.loads(export.read_text(encoding="utf-8-sig"))
    reqs = raw if isinstance(raw, list) else raw["requirements"]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        extra = extra or {}
        contracts, nodes = _contracts(exp, extra.get("variables"))
        (root / "contracts").mkdir()
        (root / "fret").mkdir()
        (root / "contracts" / "sys.rcl").write_text(contracts, encoding="utf-8")
        (root / "contracts" / "plan.yaml").write_text(
            "name: bench\ncontracts: [contracts/sys.rcl]\nrequirements_from: {fret: fret/export.json}\n"
            f"fret:\n  components: {json.dumps(nodes)}\n" + (f"  step: {step}\n" if step else "")
            + "".join(f"  {k}: {json.dumps(v)}\n" for k, v in sorted(extra.items())), encoding="utf-8")
        dropped: set[str] = set()
        for _ in range(len(reqs) + 1):
            kept = [r for r in reqs if r.get("reqid") not in dropped]
            body = kept if isinstance(raw, list) else {**raw, "requirements": kept}
            (root / "fret" / "export.json").write_text(json.dumps(body, indent=1), encoding="utf-8")
            try:
                Workspace(root, "contracts/plan.yaml").checked
                break
            except RclError as exc:
                lines = {r.loc.line: r.reqid for r in read_export(root / "fret" / "export.json", "x").requirements}
                bad = {lines[max(k for k in lines if k <= d.loc.line)] for d in exc.diagnostics
                       if d.loc.file == "fret/export.json" and any(k <= d.loc.line for k in lines)}
                if not bad:
                    print(f"  {export.name}: the generated workspace does not check: {exc.diagnostics[0]}")
                    return
                for rid in sorted(bad - dropped):
                    print(f"  {export.name}:{rid}: refused: type error with the generated contracts")
                out["refused: type error"] += len(bad - dropped)
                dropped |= bad
        ws = Workspace(root, "contracts/plan.yaml")
        from rclverify.model.plan.fret.requirements import options_of, read_fret
        plan_data: dict[str, Any] = {"fret": {"components": nodes, **({"step": step} if step else {}), **extra}}
        options = options_of(plan_data)
        for i in read_fret(root, "fret/export.json", options, ("contracts/sys.rcl",)):
            if i.refusal is not None and i.fret.reqid not in exp_refused(exp, options):
                print(f"  {export.name}:{i.fret.reqid}: refused with the contracts: {i.refusal.reason}")
                out[f"refused: {reason_kind(i.refusal.reason)}"] += 1
        stage_check(ws)
        for rec, _ in stage_requirements(ws):
            if rec.get("verdict") != "informal":
                out[f"verdict {rec['verdict']}"] += 1
            if rec.get("verdict") == "inconclusive":
                detail = str((rec.get("temporal") or {}).get("detail") or rec.get("reason") or "")
                print(f"  {export.name}:{rec['id']}: inconclusive: {detail[:160]}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path, nargs="?", help="a folder of FRET exports (*.json)")
    ap.add_argument("--decide", action="store_true", help="also decide each translated requirement")
    ap.add_argument("--step", help="the plan's fret: step: (the seconds of one step, '1 s'), for durations in secs")
    ap.add_argument("--plan", type=Path, help="a YAML file whose fret: variables and functions are added")
    ap.add_argument("--smoke", action="store_true",
                    help="CI: the project's own example export (examples/fret_rover/fret), decided")
    args = ap.parse_args(argv)
    if args.smoke:
        args.dir, args.decide = Path(__file__).resolve().parents[1] / "examples" / "fret_rover" / "fret", True
    if args.dir is None:
        ap.error("a folder of FRET exports is needed (or --smoke)")
    extra: dict[str, Any] = {}
    if args.plan is not None:
        import yaml
        section = (yaml.safe_load(args.plan.read_text(encoding="utf-8")) or {}).get("fret") or {}
        extra = {k: section[k] for k in ("variables", "functions") if k in section}
    base = {"step": args.step} if args.step else {}
    total: collections.Counter[str] = collections.Counter()
    reasons: collections.Counter[str] = collections.Counter()
    start = time.perf_counter()
    for export in sorted(args.dir.rglob("*.json")):
        try:
            exp = read_export(export, export.name)
        except PlanError as exc:
            print(f"{exc.diagnostics[0]}")
            total["malformed exports"] += 1
            continue
        got = import_export(exp, options_of({"fret": {**base, **extra}}))
        refused = [i for i in got if i.refusal is not None]
        if extra:  # those translated only with the plan's declarations
            without = {i.fret.reqid for i in import_export(exp, options_of({"fret": base})) if i.refusal is not None}
            total["translated with the plan's declarations only"] += len(without - {i.fret.reqid for i in refused})
        for i in refused:
            assert i.refusal is not None
            reasons[reason_kind(i.refusal.reason)] += 1
        total["requirements"] += len(got)
        total["translated"] += len(got) - len(refused)
        print(f"{export.name}: {len(got)} requirements, {len(got) - len(refused)} translated, {len(refused)} refused")
        if args.decide:
            verdicts: collections.Counter[str] = collections.Counter()
            decide(export, exp, verdicts, args.step, extra)
            print("  " + ", ".join(f"{k}: {v}" for k, v in sorted(verdicts.items())))
            total.update(verdicts)
    print(f"\ntotal: {total['requirements']} requirements, {total['translated']} translated to a decided "
          f"temporal statement, {total['requirements'] - total['translated']} refused")
    for k, v in reasons.most_common():
        print(f"  refused, {k}: {v}")
    for k, v in sorted(total.items()):
        if k.startswith(("verdict", "refused:", "malformed", "translated with")):
            print(f"  {k}: {v}")
    print(f"({time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
