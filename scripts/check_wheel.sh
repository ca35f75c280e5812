#!/usr/bin/env bash
# The package as a user installs it, outside the repository: the standard build frontend makes the
# sdist and, from the sdist, the wheel (so both carry every module, template, grammar and schema);
# the wheel goes into a fresh virtual environment with the default dependencies only (no extra);
# there `rclverify init` writes a workspace and `rclverify verify` verifies it, and an optional part
# that is not installed (the language server) is refused in one line naming its extra.
# Usage: bash scripts/check_wheel.sh  (after scripts/setup.sh --tests, which installs `build`).
set -euo pipefail
cd "$(dirname "$0")/.."
VPY=${VPY:-.venv/bin/python}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$VPY" -m build --sdist --wheel --outdir "$out/dist" . >"$out/build.log" 2>&1 \
  || { cat "$out/build.log"; exit 1; }
# --wheel after --sdist builds the wheel from the unpacked sdist
sdist=$(ls "$out"/dist/*.tar.gz) && wheel=$(ls "$out"/dist/*.whl)
echo "wheel: built $(basename "$sdist") and $(basename "$wheel")"
"${PYTHON:-python3}" -m venv "$out/venv"
"$out/venv/bin/python" -m pip install --quiet --disable-pip-version-check -c constraints.txt "$wheel"
cd "$out"
"$out/venv/bin/rclverify" init ws --nodes Sensor,Controller,Actuator >/dev/null
(cd ws && "$out/venv/bin/rclverify" verify >"$out/verify.log" 2>&1) || { cat "$out/verify.log"; exit 1; }
test -s ws/reports/assurance.html || { echo "wheel: no report written" >&2; exit 1; }
"$out/venv/bin/python" -c 'import json, sys; json.load(open(sys.argv[1]))["summary"]' ws/reports/assurance.json
set +e
msg=$("$out/venv/bin/rclverify" lsp </dev/null 2>&1); rc=$?
set -e
if [ "$rc" != 1 ] || [ "$(printf '%s\n' "$msg" | wc -l)" != 1 ] || ! grep -q "rclverify\[lsp\]" <<<"$msg"; then
  echo "wheel: a missing extra should be one line naming it, exit 1; got exit $rc: $msg" >&2; exit 1
fi
size=$("$out/venv/bin/python" - <<'PY'
from importlib import metadata
from pathlib import Path
total = n = 0
for d in metadata.distributions():
    n += 1
    for f in d.files or []:
        p = Path(str(d.locate_file(f)))
        if p.is_file():
            total += p.stat().st_size
print(f"{total / 1e6:.0f} MB in {n} distributions")
PY
)
echo "wheel: installed outside the repository ($size), init and verify ran, a missing extra said in one line"
