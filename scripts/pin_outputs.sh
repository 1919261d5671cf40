#!/usr/bin/env bash
# Runs every command on every bundled pattern and scene and keeps what it prints (--json) and
# every file it writes, in OUT_DIR, with wall-clock fields masked. Run it before and after a
# change that must not change results, then `diff -r BEFORE AFTER` (or `--compare A B`, which
# also reports numbers that differ by more than 1e-9 relative).
#
#   bash scripts/pin_outputs.sh target/pin/before
#   bash scripts/pin_outputs.sh target/pin/after
#   bash scripts/pin_outputs.sh --compare target/pin/before target/pin/after
set -uo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--compare" ]; then
  exec python3 scripts/pin_compare.py "$2" "$3"
fi
out=${1:?usage: pin_outputs.sh OUT_DIR | --compare A B}
rm -rf "$out" && mkdir -p "$out"
cargo build --release --quiet || exit 1
bin=$PWD/target/release/nanofold
run() { # name, then the command's arguments
  local name=$1
  shift
  "$bin" "$@" >"$out/$name.stdout" 2>"$out/$name.stderr"
  echo "$?" >"$out/$name.status"
}
for f in $(find patterns -name '*.fold' -o -name '*.json' | grep -v scene.json | sort); do
  key=$(echo "$f" | tr '/' '_')
  run "check_$key" check "$f" --json
  run "unfold_$key" unfold "$f" --json --out "$out/files/unfold_$key"
  case "$f" in
    patterns/many/*.fold | patterns/devices/*.fold)
      run "fold_$key" fold "$f" --json --frames 5 --out "$out/files/fold_$key" ;;
  esac
  run "view_$key" view "$f" --out "$out/files/view_$key"
done
run constraints_corner_cube constraints patterns/corner_cube.fold --drive 0 --lock 1=0 --range 0:180 --format mujoco --json --out "$out/files/constraints_cc"
run constraints_waterbomb constraints patterns/waterbomb.fold --drive 0 --json --out "$out/files/constraints_wb"
for f in $(find patterns -name '*.scene.json' | sort); do
  key=$(echo "$f" | tr '/' '_')
  run "simulate_$key" simulate "$f" --json --out "$out/files/simulate_$key"
  run "modes_$key" modes "$f" --json --out "$out/files/modes_$key"
  run "export_$key" export mujoco "$f" --out "$out/files/export_$key.xml"
done
run generate_miura generate miura --rows 3 --cols 4 --angle 60 --out "$out/files/gen_miura.fold"
run generate_twist generate square-twist --out "$out/files/gen_twist.fold"
# Paths printed into outputs name OUT_DIR: make them relative so two runs compare.
grep -rl --null "$out" "$out" 2>/dev/null | xargs -0 -r sed -i "s#$out#OUT#g"
echo "pinned $(find "$out" -type f | wc -l) files in $out"
