#!/usr/bin/env bash
# Regenerates every figure under docs/ (and docs/thesis.md's tables) from the commands and examples that draw it (about a
# minute and a half on 2 cores; the work-precision example is the long part). Outputs go to
# output/figures/ first, then are copied over docs/.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bins --examples
bin=target/release/nanofold
out=output/figures
rm -rf "$out"
mkdir -p "$out"
$bin unfold patterns/corner_cube.fold --out "$out/corner_cube" > /dev/null
cp "$out/corner_cube/unfold.svg" docs/unfold_corner_cube.svg
$bin constraints patterns/corner_cube.fold --drive 0 --lock 1=0 --range 0:180 --out "$out/constraints" > /dev/null
cp "$out/constraints/constraints.svg" docs/constraints_corner_cube.svg
$bin fold patterns/many/miura_4x4.fold --to 90 --out "$out/miura_4x4" > /dev/null
cp "$out/miura_4x4/fold.svg" docs/fold_miura_4x4.svg
for scene in bridge_step bridge_ramp corner_cube_step1 corner_cube_step1_ramp corner_cube_step2; do
  $bin simulate "patterns/$scene.scene.json" --out "$out/$scene" > /dev/null
  cp "$out/$scene/response.svg" "docs/${scene}_response.svg"
  if [ -f "docs/${scene}_snapshots.svg" ]; then
    cp "$out/$scene/snapshots.svg" "docs/${scene}_snapshots.svg"
  fi
done
$bin fit patterns/bridge_step.scene.json patterns/measurements/bridge_step_measured.csv \
  --free environment.drag_coefficient=0.2:5 --free hinges.*.target_angle_deg=45:135 --out "$out/fit" > /dev/null
cp "$out/fit/fit.svg" docs/fit_bridge_step.svg
$bin nets octahedron --top 11 --unit-um 50 --out "$out/nets" > /dev/null
cp "$out/nets/gallery.svg" docs/nets_octahedron_gallery.svg
for scene in cube_closes cube_lid_first miura_sheet; do
  $bin simulate "patterns/devices/$scene.scene.json" --out "$out/$scene" > /dev/null
done
cp "$out/cube_closes/snapshots.svg" docs/cube_closes_snapshots.svg
cp "$out/cube_lid_first/snapshots.svg" docs/cube_lid_first_snapshots.svg
cp "$out/miura_sheet/response.svg" docs/miura_sheet_response.svg
# The closed chain's timing figure, likewise from a kept report (README's poly-against-exact
# table quotes it).
if [ "${1:-}" != "--keep-timings" ]; then
  target/release/examples/closed_chain_timing > /dev/null
  cp output/closed_chain_timing/report.json docs/closed_chain_timing_report.json
else
  target/release/examples/closed_chain_timing --from docs/closed_chain_timing_report.json > /dev/null
fi
cp output/closed_chain_timing/poly_vs_exact.svg docs/corner_cube_poly_vs_exact.svg
# The work-precision figures are drawn from a measured report, kept as
# docs/work_precision_report.json because README quotes its numbers: by default a new run
# replaces it (then update README's tables from it); `--keep-timings` redraws the kept one.
if [ "${1:-}" != "--keep-timings" ]; then
  target/release/examples/work_precision > /dev/null
  cp output/work_precision/report.json docs/work_precision_report.json
else
  target/release/examples/work_precision --from docs/work_precision_report.json > /dev/null
fi
for figure in output/work_precision/*.svg; do
  cp "$figure" "docs/work_precision_$(basename "$figure")"
done
target/release/examples/thesis --write > /dev/null
echo "regenerated every figure in docs/ and the tables of docs/thesis.md"
