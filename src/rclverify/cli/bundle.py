"""``rclverify bundle``: the assessor's bundle written, checked against its manifest, signed, or its
stored queries re-decided from the bundle alone (docs/argument.md, docs/second-solver.md)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from rclverify.cli.common import AddCommand, no_wait_option, run_lock, workspace_of


def cmd_bundle(args: argparse.Namespace) -> int:
    """Write the assessor's bundle, or (``--verify FILE``) check one against its manifest."""
    from rclverify.report.bundle.archive import verify_bundle, write_bundle  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.report.bundle.manifest import BundleError  # deferred: start-up (loads yaml, z3 and more only when called)
    if args.recheck:
        return _bundle_recheck(args.recheck)
    from rclverify.report.bundle import signature  # deferred: start-up (loads cryptography, yaml and more only when called)
    if args.keygen:
        try:
            public = signature.write_key_pair(Path(args.keygen))
        except BundleError as exc:
            print(f"rclverify bundle: error: {exc.problems[0]}", file=sys.stderr)
            return 1
        print(f"{args.keygen}: private key (keep it); {public}: public key, fingerprint "
              f"{signature.fingerprint(signature.load_public_key(public))} (give it to the assessor to pin)")
        return 0
    if args.verify:
        try:
            key = signature.load_public_key(Path(args.key)) if args.key else None
            manifest = verify_bundle(Path(args.verify), key=key)
        except BundleError as exc:
            for problem in exc.problems:
                print(f"{args.verify}: error: {problem}", file=sys.stderr)
            return 1
        signed = (f"; signed by the pinned key {manifest['signed']}" if manifest["signed"] else
                  "; no key pinned (--key AUTHOR.pub): the seals prove the records unchanged since sealing, not "
                  "who sealed them")
        print(f"{args.verify}: {len(manifest['files'])} file(s) match MANIFEST.json; every record's seal holds; "
              "every kept query and proof is tied to what it decides" + signed)
        return 0
    ws = workspace_of(args)
    with run_lock(args):  # the report and the evidence it is checked against, as one run left them
        problems = _report_out_of_date(ws)
        if problems:
            for problem in problems:
                print(f"{args.workspace}: error: {problem}", file=sys.stderr)
            return 1
        name = "".join(c if c.isalnum() or c in "-_." else "-"
                       for c in (ws.plan.name or ws.root.resolve().name)).strip("-")
        out = Path(args.output) if args.output else Path(f"{name or 'workspace'}-bundle.tar.gz")
        try:
            private = signature.load_private_key(Path(args.sign)) if args.sign else None
            manifest = write_bundle(ws.root, ws.plan, out, key=private, named=args.output is not None)
        except BundleError as exc:
            for problem in exc.problems:
                print(f"{args.workspace}: error: {problem}", file=sys.stderr)
            return 1
    for m in manifest["missing"]:
        print(f"warning: {m}: named by the plan but does not exist; not in the bundle", file=sys.stderr)
    print(f"{out}: {len(manifest['files'])} file(s) and MANIFEST.json; check with: rclverify bundle --verify {out}")
    return 0


def _report_out_of_date(ws: Any) -> list[str]:
    """Why the written report no longer says what the recorded artifacts say
    (:func:`rclverify.report.bundle.fresh.report_out_of_date`)."""
    from rclverify.report.bundle.fresh import report_out_of_date  # deferred: start-up (imported where it is used)
    return report_out_of_date(ws)


def _bundle_recheck(archive: str) -> int:
    """``bundle --recheck``: re-decide every stored query of ``archive`` with both solvers (docs/second-solver.md)."""
    from rclverify.report.bundle.archive import scan_members  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.report.bundle.manifest import BundleError  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.stages.crosscheck.recheck import recheck_members  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    records: dict[str, bytes] = {}
    try:  # streamed under --verify's limits and member-name rules; only the records kept
        scan_members(Path(archive), None, records)
        out = recheck_members(records)
    except BundleError as exc:
        for problem in exc.problems:
            print(f"{archive}: error: {problem}", file=sys.stderr)
        return 1
    for n in out.notes:
        print(f"{archive}: note: {n}", file=sys.stderr)
    for p in out.problems:
        print(f"{archive}: error: {p}", file=sys.stderr)
    if out.problems:
        return 1
    print(f"{archive}: {out.checked} discharging quer{'y' if out.checked == 1 else 'ies'} re-decided from the "
          "bundle alone; every answer agrees with its record")
    return 0


def add_bundle(add: AddCommand) -> None:
    """The ``bundle`` parser."""
    bnd = add("bundle", cmd_bundle, "write the assessor's bundle (reports, artifacts, plan, contracts, manifest)", True)
    bnd.add_argument("-o", "--output", help="archive to write (.tar.gz or .zip; default: <workspace name>-bundle.tar.gz)")
    bnd.add_argument("--verify", metavar="FILE", help="check the archive FILE against its manifest instead")
    bnd.add_argument("--sign", metavar="KEY",
                     help="sign the manifest with the Ed25519 private key KEY (PEM; MANIFEST.sig in the archive)")
    bnd.add_argument("--key", metavar="PUB",
                     help="with --verify: the author's pinned Ed25519 public key (PEM); the signature must hold")
    bnd.add_argument("--keygen", metavar="KEY",
                     help="write a new Ed25519 key pair KEY and KEY.pub instead, for --sign and --key")
    bnd.add_argument("--recheck", metavar="FILE",
                     help="re-decide every stored query of the archive FILE with Z3 and cvc5 from the bundle "
                          "alone and compare with the recorded verdicts instead")
    no_wait_option(bnd)
