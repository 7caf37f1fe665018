#!/usr/bin/env bash
# The core figures of docs/algorithm.md ("Both schedules on four meshes"): each reference mesh at 10 % in both schedules, with the
# library's time, the right-sized workspace, Metro error and the per-pass triangle counts.
# Usage: scripts/figures.sh [ratio] [meshes...]
set -euo pipefail
cd "$(dirname "$0")/.."
ratio=${1:-0.1}
shift || true
meshes=${*:-cow fandisk camelhead stanford_bunny}
cargo build -q --release -p tinydecimate-cli
bin=target/release/tinydecimate
out=$(mktemp -d)
echo "| mesh | schedule | triangles in → out | library time (ms) | workspace bytes / triangle | mean error (% diag) | Hausdorff (% diag) | valid | triangles after each pass |"
echo "|---|---|---|---:|---:|---:|---:|---|---|"
for m in $meshes; do
  for s in greedy passes; do
    log="$out/$m-$s.txt"
    "$bin" simplify "tests/fixtures/$m.obj" "$out/$m-$s.obj" --ratio "$ratio" --schedule "$s" >"$log" 2>&1 || true
    tin=$(awk '/triangles in/{print $3}' "$log")
    tout=$(awk '/triangles out/{print $3}' "$log")
    ms=$(awk '/library call/{print $3}' "$log")
    bpt=$(sed -n 's/.*; \([0-9.]*\) bytes per input triangle).*/\1/p' "$log" | tail -1)
    mean=$(awk '/symmetric mean/{print $5}' "$log")
    haus=$(awk '/Hausdorff/{print $5}' "$log")
    valid=$(grep -q "=> VALID" "$log" && echo yes || echo NO)
    passes=$(sed -n 's/.*triangles after pass *//p' "$log")
    echo "| $m | $s | $tin → $tout | $ms | $bpt | $mean | $haus | $valid | $passes |"
  done
done
