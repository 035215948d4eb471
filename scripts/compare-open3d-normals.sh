#!/usr/bin/env bash
# PCA normals at k = 20 on the same N-point cloud (faces of the synthetic cube, default 1M), in
# random (sampling) order and Morton-sorted order: Open3D's estimate_normals(KDTreeSearchParamKNN(20))
# against `crease normals` (kNN + PCA, reported separately), best of 3 each, in one run.
# Open3D is installed with pip into a throw-away virtual environment removed on exit (set
# OPEN3D_VENV to reuse an existing one). Nothing is committed.
#   usage: scripts/compare-open3d-normals.sh [N_POINTS]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
venv=${OPEN3D_VENV:-$work/venv}
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q open3d
fi
cargo build -q --release -p crease-cli
./target/release/crease synth cube -n "$n" -q -o "$work/src.ply"
# Both files hold float x y z only, written by Open3D, so both tools read the same bytes.
"$venv/bin/python" - "$work" <<'PY'
import sys, time, numpy as np, open3d as o3d
work = sys.argv[1]
pts = np.asarray(o3d.io.read_point_cloud(f"{work}/src.ply").points)
q = np.clip(((pts - pts.min(0)) / np.ptp(pts, 0).max() * 2047).astype(np.uint64), 0, 2047)
code = np.zeros(len(pts), dtype=np.uint64)
for b in range(11):
    for a in range(3):
        code |= ((q[:, a] >> np.uint64(b)) & np.uint64(1)) << np.uint64(3 * b + a)
for name, p in (("random", pts), ("sorted", pts[np.argsort(code, kind="stable")])):
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
    o3d.io.write_point_cloud(f"{work}/{name}.ply", pc, write_ascii=False)
    best = 1e9
    for _ in range(3):
        pc = o3d.io.read_point_cloud(f"{work}/{name}.ply")
        t = time.perf_counter()
        pc.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(20))
        best = min(best, time.perf_counter() - t)
    print(f"open3d {o3d.__version__} estimate_normals KNN(20), {name}, {len(p)} points: {best:.3f} s (best of 3)")
PY
for order in random sorted; do
  best=""
  for _ in 1 2 3; do
    line=$(./target/release/crease normals "$work/$order.ply" -o "$work/out.ply" -k 20 --json -q |
      python3 -c 'import json,sys; t=json.load(sys.stdin)["timings"]; print(t["knn"]+t["normals"], t["knn"], t["normals"])')
    best=$(printf '%s\n%s\n' "$best" "$line" | sed '/^$/d' | sort -g | head -1)
  done
  read -r total knn pca <<<"$best"
  printf 'crease normals -k 20, %s, %s points: %.3f s (kNN %.3f s + PCA %.3f s; best of 3)\n' "$order" "$n" "$total" "$knn" "$pca"
done
