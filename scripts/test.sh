#!/usr/bin/env bash
# The test command (README): installs the real third-party client the tests run against —
# MuJoCo's Python wheel, in target/clients-venv — then runs the test suite. Extra arguments
# go to `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/clients-venv
if ! "$venv/bin/python" -c "import mujoco" 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet "mujoco==4.0.0"
fi
export NANOFOLD_PYTHON="$PWD/$venv/bin/python"
export NANOFOLD_REQUIRE_CLIENTS=1
cargo test --release "$@"
