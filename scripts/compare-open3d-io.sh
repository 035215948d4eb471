#!/usr/bin/env bash
# Reads the same 1M-point binary PLY (float x y z nx ny nz, uchar rgb: the layout most tools
# write) with crease and with Open3D's read_point_cloud, best of 5 each, on this machine.
# Open3D is installed with pip into a throw-away virtual environment (nothing is committed).
#   usage: scripts/compare-open3d-io.sh [N_POINTS]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
venv=${OPEN3D_VENV:-/tmp/crease-open3d-venv}
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q open3d
fi
cargo build -q --release -p crease-cli
./target/release/crease synth sphere -n "$n" -q -o "$work/src.ply"
# Re-encode as float32 xyz + normals + uchar rgb with Open3D itself, so both read one file.
"$venv/bin/python" - "$work" <<'PY'
import sys, time, numpy as np, open3d as o3d
work = sys.argv[1]
pc = o3d.io.read_point_cloud(f"{work}/src.ply")
pc.colors = o3d.utility.Vector3dVector(np.tile([0.2, 0.5, 0.8], (len(pc.points), 1)))
if not pc.has_normals():
    pc.estimate_normals()
o3d.io.write_point_cloud(f"{work}/cloud.ply", pc, write_ascii=False)
best = min((lambda t: (o3d.io.read_point_cloud(f"{work}/cloud.ply"), time.perf_counter() - t)[1])(time.perf_counter()) for _ in range(5))
print(f"open3d {o3d.__version__} read_point_cloud: {best:.4f} s (best of 5)")
PY
best=999
for _ in 1 2 3 4 5; do
  t=$(./target/release/crease convert "$work/cloud.ply" "$work/out.xyz" --json -v 2>&1 >/dev/null | sed -n 's/.*reading .*: \([0-9.]*\) s/\1/p' | head -1)
  best=$(python3 -c "print(min($best, $t))")
done
echo "crease io::read: ${best} s (best of 5)"
