"""The README is a front page (issue 66): under 150 lines, the two quick-start
commands first, and every page it and the reference pages link to exists."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
PAGES = ["README.md", "docs/commands.md", "docs/case-study.md", "docs/rcl-language.md", "docs/ci.md"]


def test_the_readme_is_short_and_starts_with_the_two_commands() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) < 150
    blocks = re.findall(r"```sh\n(.*?)\n```", text, flags=re.S)
    assert blocks[:2] == ["bash scripts/setup.sh && .venv/bin/doit verify",
                          "bash scripts/setup.sh --tests && .venv/bin/python -m pytest -n 3"]
    assert text.index("```sh") < text.index("\n## ", text.index("## Quick start") + 1)
    assert 'pytest -m "not slow and not live"' in text


def test_the_moved_sections_are_linked_from_the_readme() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for page in ("docs/commands.md", "docs/case-study.md", "docs/rcl-language.md", "docs/ci.md"):
        assert f"]({page})" in text, page
    assert "## RCL in one screen" in (ROOT / "docs/rcl-language.md").read_text(encoding="utf-8")
    assert "## Command line" in (ROOT / "docs/commands.md").read_text(encoding="utf-8")


def test_every_relative_link_resolves() -> None:
    missing = []
    for page in PAGES:
        path = ROOT / page
        for target in LINK.findall(path.read_text(encoding="utf-8")):
            if "://" not in target and not (path.parent / target).exists():
                missing.append(f"{page}: {target}")
    assert missing == []


def test_the_command_reference_lists_every_command() -> None:
    """docs/commands.md's block names every command `rclverify --help` offers."""
    import contextlib
    import io

    from rclverify.cli.commands import main
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
        main(["--help"])
    commands = re.search(r"\{([a-z0-9_,-]+)\}", out.getvalue())
    assert commands is not None, out.getvalue()
    block = (ROOT / "docs/commands.md").read_text(encoding="utf-8").split("## Command line", 1)[1].split("```", 2)[1]
    missing = [c for c in commands.group(1).split(",") if f"rclverify {c}" not in block]
    assert missing == []
