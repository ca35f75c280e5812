"""A poisoned file under ``artifacts/cache/`` is never executed (issue 35).

A workspace is often a clone of someone else's repository.  Its kept files
are pickles, and jinja2's compiled templates used to be kept there too: a
pickle whose ``__reduce__`` names ``open`` or ``os.system`` ran when read.
These tests plant such files (whole files, and after a valid header of the
right kind, and as jinja2 bytecode of every report template), run the
commands that read the cache on a real workspace, and check that no marker
file appears, that every command still succeeds and that the poisoned
entries were treated as misses (rewritten as valid files).
"""
from __future__ import annotations

import io
import os
import pickle
import shutil
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.core.cache import safeload
from rclverify.core.cache.safeload import SafeUnpickler, load, loads

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "tests" / "data" / "requirements" / "stop"
KEPT = ("workspace", "contract-texts", "report-fragments.html", "report-fragments.text", "diagnosis",
        "system-cycles", "ros-scan")


class _Opens:
    """Unpickled, creates ``marker`` (``open(marker, "w")``)."""

    def __init__(self, marker: Path) -> None:
        self.marker = str(marker)

    def __reduce__(self) -> tuple[object, tuple[str, str]]:
        return (open, (self.marker, "w"))


class _Shell:
    """Unpickled, creates ``marker`` through the shell (``os.system``)."""

    def __init__(self, marker: Path) -> None:
        self.marker = str(marker)

    def __reduce__(self) -> tuple[object, tuple[str]]:
        return (os.system, (f"touch '{self.marker}'",))


def _global(module: str, name: str) -> bytes:
    """A protocol-0 pickle that only looks ``module``.``name`` up and returns it."""
    return f"c{module}\n{name}\n.".encode()


def _env(tmp: Path) -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""),
            "XDG_CACHE_HOME": str(tmp / "user-cache")}


def _run(ws: Path, tmp: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    r = subprocess.run(list(argv), cwd=ws, env=_env(tmp), capture_output=True, text=True, timeout=300)
    assert "Traceback" not in r.stderr, r.stderr
    return r


def _header_length(path: Path) -> int | None:
    """The length of the file's valid header, or ``None`` (no valid header)."""
    with open(path, "rb") as fh:
        try:
            load(fh)
        except Exception:  # noqa: BLE001
            return None
        return fh.tell()


def _poison_templates(cache: Path, payload: bytes) -> int:
    """jinja2 bytecode files for every report template, under the names
    jinja2's ``FileSystemBytecodeCache`` looks for, whose checksum pickle is
    ``payload``.  Returns how many were written."""
    import jinja2
    from jinja2.bccache import bc_magic

    from rclverify.report.render import environment
    env = environment()
    bcc = jinja2.FileSystemBytecodeCache(str(cache / "templates"))
    (cache / "templates").mkdir(parents=True, exist_ok=True)
    names = env.list_templates()
    for name in names:
        _, filename, _ = env.loader.get_source(env, name)  # type: ignore[union-attr]
        key = bcc.get_cache_key(name, filename)
        (cache / "templates" / (bcc.pattern % key)).write_bytes(bc_magic + payload)
    return len(names)


def test_the_loader_refuses_every_callable_that_is_not_a_kept_value_class() -> None:
    for module, name in [("os", "system"), ("posix", "system"), ("builtins", "eval"), ("builtins", "open"),
                         ("io", "open"), ("subprocess", "Popen"), ("rclverify.cli.commands", "os.system"),
                         ("rclverify.cli.commands", "main"), ("rclverify.__main__", "main"),
                         ("rclverify.core.cache.store", "Shelf"), ("rclverify.runtime.oracle", "serve"),
                         ("rclverify.lang.errors", "RclError"), ("rclverify.nonexistent", "Thing"),
                         ("copyreg", "_reconstructor"), ("pathlib", "Path.touch")]:
        with pytest.raises(pickle.UnpicklingError):
            loads(_global(module, name))
    with pytest.raises(pickle.UnpicklingError):
        loads(pickle.dumps(_Opens(Path("/nonexistent/never"))))
    # the values rclverify keeps still load, as themselves
    from rclverify.lang.ast import Loc
    from rclverify.lang.parser import parse_text
    spec = parse_text("node N { inputs( x : REAL ) outputs( y : REAL )\n  guarantee( out.y >= in.x + 1/2 ) }\n",
                      "n.rcl")
    value = {"spec": spec, "loc": Loc("f", 1, 2, 3, 4), "path": Path("a/b"), "half": Fraction(1, 2),
             "set": {1, 2}, "frozen": frozenset({"a"}), "z": complex(1, 2)}
    assert loads(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)) == value
    assert loads(pickle.dumps(value, protocol=2)) == value
    # a forged Fraction that would take hours to build is refused
    forged = b"\x80\x04cfractions\nFraction\n\x8c\x0b1e999999999\x85R."
    with pytest.raises(pickle.UnpicklingError):
        SafeUnpickler(io.BytesIO(forged)).load()
    assert safeload.allowed("rclverify.lang.loc", "Loc") is Loc  # the class by the module that defines it
    # a name a module only re-exports is none of its classes (a file kept before Loc moved is computed again)
    assert safeload.allowed("rclverify.lang.ast", "Loc") is None


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    tmp = tmp_path_factory.mktemp("poison")
    ws = tmp / "ws"
    shutil.copytree(DATA, ws)
    rcl = ws / "contracts/stop.rcl"  # a failed side condition: a problem with a diagnosis and repairs (Z3)
    text = rcl.read_text()
    assert "  assume( 0 <= in.speed_cmd )" in text
    rcl.write_text(text.replace("  assume( 0 <= in.speed_cmd )", "  assume( 0.5 <= in.speed_cmd )"))
    r = _run(ws, tmp, sys.executable, "-m", "doit", "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    assert (ws / "artifacts/cache/diagnosis.pickle").is_file()
    return ws, tmp


@pytest.mark.parametrize("where", ["whole file", "after a valid header"])
def test_a_poisoned_cache_is_never_executed_by_any_command(verified: tuple[Path, Path], where: str) -> None:
    pristine, tmp = verified
    ws = tmp / where.replace(" ", "-")
    shutil.copytree(pristine, ws)
    cache = ws / "artifacts/cache"
    marker = tmp / f"marker-{where.replace(' ', '-')}"
    payloads = [pickle.dumps(_Opens(marker), protocol=p) for p in (0, 2, pickle.HIGHEST_PROTOCOL)]
    payloads.append(pickle.dumps(_Shell(marker)))
    planted = []
    for k, kind in enumerate(KEPT):
        path = cache / f"{kind}.pickle"
        payload = payloads[k % len(payloads)]
        if where == "whole file":
            path.write_bytes(payload)
        elif path.is_file() and _header_length(path):  # the valid header of this kind and code, then the poison
            path.write_bytes(path.read_bytes()[:_header_length(path)] + payload)
        else:
            continue
        planted.append(path)
    assert len(planted) >= 5
    assert _poison_templates(cache, payloads[0]) >= 5
    before = (ws / "reports/assurance.json").read_text()

    r = _run(ws, tmp, sys.executable, "-m", "rclverify.cli.commands", "report")
    assert r.returncode == 0 and "reports/assurance.html" in r.stdout, r.stdout + r.stderr
    assert not marker.exists()
    r = _run(ws, tmp, sys.executable, "-m", "rclverify.cli.commands", "status")
    assert r.returncode == 0 and "MotorDriver assumes `0.5 <= in.speed_cmd`" in r.stdout, r.stdout + r.stderr
    r = _run(ws, tmp, sys.executable, "-m", "rclverify.cli.commands", "explain", "MotorDriver.sc1")
    assert r.returncode == 0 and "counterexample" in r.stdout.lower() and "repair" in r.stdout.lower(), r.stdout
    assert not marker.exists()
    workspace = cache / "workspace.pickle"  # poisoned again: `report` above may have rewritten it
    n = _header_length(workspace) if where != "whole file" else 0
    workspace.write_bytes(workspace.read_bytes()[:n] + payloads[1] if n else payloads[1])
    r = _run(ws, tmp, sys.executable, "-m", "doit", "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    assert not marker.exists()

    # the poisoned entries were misses: the run's results are those of the clean run,
    # and the kept files it wrote are valid again
    def outcome(text: str) -> dict[str, object]:
        import json
        d = json.loads(text)
        return {**{k: sorted((x["id"], x["status"]) for x in d[k]) for k in ("obligations", "side_conditions",
                                                                              "findings")},
                "diagnoses": sorted(json.dumps(x, sort_keys=True) for x in d["diagnoses"]),
                "requirements": [(x["id"], x["verdict"]) for x in d["requirements"]]}
    assert outcome((ws / "reports/assurance.json").read_text()) == outcome(before)
    with open(cache / "workspace.pickle", "rb") as fh:
        assert load(fh)["kind"] == "workspace"
