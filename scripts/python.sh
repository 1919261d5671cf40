#!/usr/bin/env bash
# Builds the Python package (python/) into target/clients-venv with maturin and installs it
# with its sweep and test dependencies. Used by scripts/test.sh; run alone to rebuild after
# a change to the crate or the package.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/clients-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
if ! "$venv/bin/python" -c "import maturin, dask.distributed, pandas, pyarrow, pytest, hypothesis, mypy, matplotlib" 2>/dev/null; then
  "$venv/bin/pip" install --quiet "maturin>=1.9,<2" "numpy>=1.22" "dask[distributed]>=2024.1" "pandas>=1.5" \
    "pyarrow>=12" "pytest>=7" "hypothesis>=6" "mypy>=1.8" "matplotlib>=3.6"
fi
rm -rf target/wheels
VIRTUAL_ENV="$PWD/$venv" PATH="$PWD/$venv/bin:$PATH" "$venv/bin/maturin" build --quiet --release \
  -m python/Cargo.toml -o target/wheels
"$venv/bin/pip" install --quiet --force-reinstall --no-deps target/wheels/nanofold_origami-*.whl
