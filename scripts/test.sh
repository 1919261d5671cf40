#!/usr/bin/env bash
# The test command (README): installs the real third-party client the tests run against —
# MuJoCo's Python wheel, in target/clients-venv — then runs the Rust test suite, then builds
# the Python package into the same environment and runs its checks (type stubs against the
# module, mypy, pytest with the docstrings' examples and README's Python), then loads the 3D
# pages in headless Chromium (scripts/browser_test.sh). Extra arguments go to `cargo test`.
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
bash scripts/python.sh
root=$PWD
export NANOFOLD_BIN="$root/target/release/nanofold" MYPY_CACHE_DIR="$root/target/mypy-cache"
# stubtest imports the installed package: run it away from the source folder.
(cd "$root/target" && "$root/$venv/bin/python" -m mypy.stubtest nanofold)
(cd python && "$root/$venv/bin/python" -m mypy nanofold)
"$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests --doctest-modules --pyargs nanofold
# The 3D pages in a real browser (installs Debian's chromium when missing).
bash scripts/browser_test.sh
