#!/usr/bin/env bash
# Every timing README quotes, measured again by one command: the self-timing examples
# (each prints error beside time) and the criterion benches, in release mode. Writes
# docs/timings.md, stamped with the date, the commit and the machine, and the reports the
# figures are drawn from (docs/work_precision_report.json, docs/closed_chain_timing_report.json);
# then `bash scripts/figures.sh --keep-timings` redraws the figures from them. About 15
# minutes on 2 cores (the work-precision run with MuJoCo and the benches are most of it).
# `--quick` leaves out the criterion benches.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bins --examples
venv=target/clients-venv
if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import mujoco" 2>/dev/null; then
  export NANOFOLD_PYTHON="$PWD/$venv/bin/python"
fi
out=output/timings
rm -rf "$out"
mkdir -p "$out"
{
  echo "# Timings"
  echo
  echo "Measured by \`bash scripts/timings.sh\` on $(date -u +%Y-%m-%d) at commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
  echo "Machine: $(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2- | sed 's/^ *//' || uname -m), $(nproc) cores, $(free -g 2>/dev/null | awk '/Mem:/{print $2 " GB"}')."
  echo "Each section is the named command's own output (its run counts are stated in it)."
} > "$out/timings.md"
section() {
  local title=$1
  shift
  echo "timings: $title"
  {
    echo
    echo "## $title"
    echo
    echo '```'
    "$@" 2>&1
    echo '```'
  } >> "$out/timings.md"
}
section "unfold_timing (single vertices)" target/release/examples/unfold_timing
section "crease_pattern_speed (patterns of many vertices)" target/release/examples/crease_pattern_speed
section "work_precision (every engine; its report.json)" target/release/examples/work_precision
section "closed_chain_timing (fitted against exact closure)" target/release/examples/closed_chain_timing
section "executor_overhead (argmin's executor against a bare loop, both engines)" target/release/examples/executor_overhead
section "fit_speed (calibration: the bridge and the Miura-ori sheet, estimates beside time)" target/release/examples/fit_speed
section "count_nets (nets of the Platonic solids: counts, overlap, scores, each stage timed)" target/release/examples/count_nets
# The Python layer and Dask sweeps, where the package is installed (scripts/python.sh).
if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c "import nanofold" 2>/dev/null; then
  section "python/examples/overhead.py (the Python layer, Dask sweeps)" "$venv/bin/python" python/examples/overhead.py
fi
if [ "${1:-}" != "--quick" ]; then
  section "cargo bench (criterion)" cargo bench --quiet
fi
cp output/work_precision/report.json docs/work_precision_report.json
cp output/closed_chain_timing/report.json docs/closed_chain_timing_report.json
cp "$out/timings.md" docs/timings.md
echo "wrote docs/timings.md and the reports; run bash scripts/figures.sh --keep-timings to redraw the figures"
