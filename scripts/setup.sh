#!/usr/bin/env bash
# Installs everything rclverify needs on a fresh Debian/Ubuntu machine:
#   - Debian packages: dafny (the Dafny backend's verifier) and graphviz
#     (the system model diagram); both optional, their evidence is pending
#     or the diagram replaced by DOT source when they are missing;
#   - the rclverify package itself with its Python dependencies and pytest.
# Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null 2>&1; then sudo "$@"; else return 1; fi
}

if command -v apt-get >/dev/null 2>&1; then
  need=()
  command -v dafny >/dev/null 2>&1 || need+=(dafny)
  command -v dot >/dev/null 2>&1 || need+=(graphviz)
  if [ ${#need[@]} -gt 0 ]; then
    echo "setup: installing Debian packages: ${need[*]}"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq \
      && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null \
      || echo "setup: could not install ${need[*]}; the Dafny evidence will be pending and the diagram shown as DOT"
  fi
else
  echo "setup: apt-get not found; install dafny and graphviz yourself for the Dafny backend and the diagram"
fi

PY=${PYTHON:-python3}
echo "setup: installing rclverify and its Python dependencies"
"$PY" -m pip install --quiet --disable-pip-version-check -e '.[test]'
# The package's bytecode, compiled once here: an editable install compiles nothing, and a shell
# with PYTHONDONTWRITEBYTECODE set would otherwise compile every module in every doit process.
"$PY" -m compileall -q src/rclverify >/dev/null || true
