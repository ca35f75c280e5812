"""`rclverify lsp` in a real editor (issue 52): Debian's Neovim, headless,
starts the server with its own LSP client (``vim.lsp.start_client``, the
Neovim 0.7 API docs/editor.md uses), opens an RCL file with a type error and
reads the diagnostic back from ``vim.diagnostic``.  Skipped, with the
reason, when ``nvim`` is not installed (scripts/setup.sh installs it)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
NVIM = shutil.which("nvim")

BAD = """context {
  Speed : REAL ;
}

node Planner {
  inputs( goal : REAL )
  outputs( speed : Speed )
  guarantee( out.speed <= limit )
}
"""

LUA = """
local root, file, out, python, src = unpack(_G.args)
local id = vim.lsp.start_client({
  name = "rclverify",
  cmd = { python, "-m", "rclverify.cli.commands", "lsp" },
  cmd_env = { PYTHONPATH = src },
  root_dir = root,
})
vim.cmd("edit " .. file)
vim.lsp.buf_attach_client(0, id)
local got = {}
vim.wait(20000, function()
  got = vim.diagnostic.get(0)
  return #got > 0
end, 50)
local rows = {}
for _, d in ipairs(got) do
  table.insert(rows, { lnum = d.lnum, col = d.col, message = d.message, code = d.code, severity = d.severity })
end
vim.fn.writefile({ vim.fn.json_encode(rows) }, out)
vim.lsp.stop_client(id)
vim.cmd("qall!")
"""


@pytest.mark.skipif(NVIM is None, reason="nvim (Debian's neovim package) is not installed: scripts/setup.sh installs it")
def test_neovim_reads_the_located_diagnostic(tmp_path: Path) -> None:
    root = tmp_path / "ws"
    (root / "contracts").mkdir(parents=True)
    rcl = root / "contracts" / "planner.rcl"
    rcl.write_text(BAD, encoding="utf-8")
    out = tmp_path / "diagnostics.json"
    script = tmp_path / "attach.lua"
    args = [str(root), str(rcl), str(out), sys.executable, str(REPO / "src")]
    script.write_text("_G.args = " + "{" + ", ".join(json.dumps(a) for a in args) + "}\n" + LUA, encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NVIM", "VIM", "MYVIMRC"))}
    env.update(HOME=str(tmp_path), XDG_CONFIG_HOME=str(tmp_path / "config"), XDG_DATA_HOME=str(tmp_path / "data"),
               XDG_STATE_HOME=str(tmp_path / "state"), XDG_CACHE_HOME=str(tmp_path / "cache"))
    p = subprocess.run([NVIM, "--headless", "--clean", "-n", "-u", "NONE", "-S", str(script)], cwd=root, env=env,
                       capture_output=True, text=True, timeout=60)
    assert out.is_file(), f"nvim wrote no diagnostics (exit {p.returncode}): {p.stdout[-2000:]} {p.stderr[-2000:]}"
    rows = json.loads(out.read_text(encoding="utf-8"))
    from rclverify.lang.errors import RclError
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    with pytest.raises(RclError) as exc:
        check([parse_text(BAD, "contracts/planner.rcl")])
    want = [(d.loc.line - 1, d.loc.col - 1, d.message, d.code) for d in exc.value.diagnostics]
    assert [(r["lnum"], r["col"], r["message"], r["code"]) for r in rows] == want
    assert all(r["severity"] == 1 for r in rows)  # vim.diagnostic.severity.ERROR


def test_the_textmate_grammar_reads_rcl_lark_s_words() -> None:
    """editors/rcl.tmLanguage.json: every pattern compiles, and each reserved word of rcl.lark (the words
    its NAME terminal excludes) and each clause keyword is coloured as a keyword, not as a variable."""
    import re
    grammar = json.loads((REPO / "editors" / "rcl.tmLanguage.json").read_text(encoding="utf-8"))
    patterns: list[tuple[str, str]] = []

    def walk(x: object) -> None:
        if isinstance(x, dict):
            if "match" in x:
                caps = x.get("captures") or {}
                patterns.append((str(x.get("name") or (caps.get("1") or {}).get("name", "")), str(x["match"])))
            for k, v in x.items():
                if k in ("match", "begin", "end"):
                    re.compile(str(v))
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
    walk(grammar)
    lark = (REPO / "src" / "rclverify" / "lang" / "rcl.lark").read_text(encoding="utf-8")
    reserved = re.search(r"NAME: /\(\?!\(([^)]*)\)", lark).group(1).split("|")
    assert "forall" in reserved and "TRUE" in reserved
    for word in reserved + ["context", "assume(", "guarantee(", "matches"]:
        name = next(n for n, p in patterns if re.match(p, word))
        assert not name.startswith("variable"), (word, name)
