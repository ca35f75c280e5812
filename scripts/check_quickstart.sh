#!/usr/bin/env bash
# The README's quick start as a new user types it: its first command, read from the README itself,
# run in a fresh clone of this checkout with the given Python's directory first on PATH (default:
# Debian's own /usr/bin, whose python3 is externally managed, PEP 668).  Passes when the command
# exits 0 and wrote reports/assurance.html.
# Usage: bash scripts/check_quickstart.sh [BINDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bindir=${1:-/usr/bin}
cmd=$(awk '/^## Quick start/ {q=1} q && /^```sh/ {getline; print; exit}' README.md)
[ -n "$cmd" ] || { echo "quickstart: no command found under the README's Quick start" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone --quiet . "$work/rclverify"
cd "$work/rclverify"
# the given directory first, and no pyenv shim or version manager anywhere on PATH
path="$bindir:$(printf '%s' "$PATH" | tr ':' '\n' | grep -v -e pyenv -e '\.venv' | paste -sd: -)"
echo "quickstart: $cmd   (python3 is $(PATH="$path" command -v python3), $(PATH="$path" python3 -V))"
env -u VIRTUAL_ENV -u PYENV_VERSION PATH="$path" bash -c "$cmd" >"$work/quickstart.log" 2>&1 || {
  tail -30 "$work/quickstart.log"; echo "quickstart: the README's first command failed" >&2; exit 1; }
test -s reports/assurance.html || { echo "quickstart: no reports/assurance.html" >&2; exit 1; }
echo "quickstart: exit 0, $(grep -c . "$work/quickstart.log") lines of output, reports/assurance.html written"
