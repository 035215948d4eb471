#!/usr/bin/env bash
# The segmentation of every real scan in ../shared/data/scans, one line each: surfaces (and per
# type), assigned share of the points, seed regions, the six largest regions' point counts.
# For comparing two builds of crease on the scans (`docs/experiments/noisy-segmentation.md`).
# Usage: scripts/scan-segments.sh [CREASE_BINARY] (default: target/release/crease)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$here/target/release/crease}"
data="$here/../shared/data/scans"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for f in "$data"/*/*; do
  name="$(basename "$f")"
  if ! "$bin" segment "$f" -o "$tmp/s.ply" -q --json > "$tmp/s.json"; then
    echo "$name: crease segment failed"
    continue
  fi
  python3 - "$name" "$tmp/s.json" <<'PY'
import json, sys
name, path = sys.argv[1], sys.argv[2]
d = json.load(open(path))
big = sorted((s["vertices"] for s in d["surface_list"]), reverse=True)[:6]
print("%-12s %3d %-58s assigned %.4f seeds %4d largest %s" % (
    name, d["surfaces"], d["by_type"], d["assigned_points"] / d["points"], d["seeds"], big))
PY
done
