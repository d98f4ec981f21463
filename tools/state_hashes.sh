#!/usr/bin/env bash
# Prints the state hash of every example scene and a digest of every experiment's
# deterministic outputs (timings left out), one line each: compare two commits' outputs
# with diff to see whether a change moved any trajectory.
# Usage: tools/state_hashes.sh [FLEXFIT] > hashes.txt
set -euo pipefail
cd "$(dirname "$0")/.."
flexfit=${1:-build/release/apps/flexfit/flexfit}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for scene in examples/*.toml; do
  name=$(basename "$scene" .toml)
  "$flexfit" run "$scene" --no-progress --out "$out/$name" >/dev/null
  echo "scene $name $(sed -n 's/.*"state_hash": "\(.*\)".*/\1/p' "$out/$name/summary.json")"
done
for experiment in restoration zones contact ball-torus; do
  "$flexfit" experiment "$experiment" --out "$out/x_$experiment" >/dev/null 2>&1
done
for run in "$out"/x_ball-torus/runs/*/; do
  echo "ball-torus $(basename "$run") $(sed -n 's/.*"state_hash": "\(.*\)".*/\1/p' "$run/summary.json")"
done
digest() { md5sum | cut -c1-16; }
echo "restoration table_4_2 $(digest < "$out/x_restoration/table_4_2.csv")"
echo "restoration active_springs $(digest < "$out/x_restoration/active_springs.csv")"
echo "zones counts $(cut -d, -f1-5 "$out/x_zones/zones.csv" | digest)"
echo "contact series $(digest < "$out/x_contact/contact.csv")"
echo "contact frames $(cat "$out"/x_contact/frame_*.obj | digest)"
