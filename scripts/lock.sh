#!/usr/bin/env bash
# Refreshes constraints.txt: every distribution rclverify and its extras (all, test, dev) resolve to
# today, for each Python from 3.10 on (uv's universal resolution writes one pin per range of Pythons
# where they differ, as environment markers pip understands).  setup.sh and CI install with
# `pip install -c constraints.txt`, so a run resolves what was tested, not what was released that day.
# Run it, run the suite, commit both files together (docs/install.md).
set -euo pipefail
cd "$(dirname "$0")/.."
tool=$(mktemp -d)
trap 'rm -rf "$tool"' EXIT
"${PYTHON:-python3}" -m venv "$tool"
"$tool/bin/python" -m pip install --quiet --disable-pip-version-check uv
"$tool/bin/uv" pip compile pyproject.toml --extra all --extra test --extra dev --universal \
  --python-version 3.10 --no-header --no-annotate --quiet -o "$tool/pins.txt"
{ echo "# Pins for CI and scripts/setup.sh, made by scripts/lock.sh (docs/install.md); do not edit by hand."
  cat "$tool/pins.txt"; } > constraints.txt.tmp
mv constraints.txt.tmp constraints.txt
echo "lock: constraints.txt has $(grep -c '==' constraints.txt) pins"
