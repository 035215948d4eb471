#!/usr/bin/env bash
# PCA normals at k = 20 on the same N-point cloud (faces of the synthetic cube, default 1M), in
# random (sampling) order and Morton-sorted order, measured side by side in one run, best of 3:
#   - crease:  `crease normals -k 20` (fused kNN + PCA; the time of the estimate, I/O excluded),
#              best of 3 processes, and the same estimate best of 3 runs in one process
#              (examples/normals_timing.rs on the file), which is how the PCL and Open3D
#              figures are taken,
#   - Open3D:  estimate_normals(KDTreeSearchParamKNN(20)),
#   - PCL:     NormalEstimationOMP + KdTreeFLANN, setKSearch(20), THREADS threads
#              (scripts/pcl_normals.cpp, compiled here with g++ -O3).
# Open3D is installed with pip into a throw-away virtual environment removed on exit (set
# OPEN3D_VENV to reuse one). PCL comes from Debian (libpcl-dev); the script installs it with
# apt-get when it can, and otherwise says why and skips PCL. Nothing is committed.
#   usage: scripts/compare-normals.sh [N_POINTS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
threads=${2:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) CPUs, $threads threads"

# --- PCL (optional) ---------------------------------------------------------------------------
pcl_bin=""
if ! pkg-config --exists pcl_features 2>/dev/null; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "installing libpcl-dev with apt-get..."
    if ! (apt-get update -qq && apt-get install -y -qq --no-install-recommends \
      libpcl-dev libeigen3-dev libflann-dev libboost-dev g++ pkg-config) >"$work/apt.log" 2>&1; then
      echo "PCL skipped: apt-get install libpcl-dev failed; the end of its log:"
      tail -5 "$work/apt.log"
    fi
  else
    echo "PCL skipped: libpcl-dev is not installed and apt-get is unavailable or needs root"
  fi
fi
if pkg-config --exists pcl_features 2>/dev/null; then
  # shellcheck disable=SC2046
  if g++ -O3 -march=native -fopenmp -std=c++17 scripts/pcl_normals.cpp -o "$work/pcl_normals" \
    $(pkg-config --cflags --libs pcl_features pcl_io pcl_search pcl_kdtree pcl_common) \
    2>"$work/pcl_build.log"; then
    pcl_bin="$work/pcl_normals"
  else
    echo "PCL skipped: scripts/pcl_normals.cpp did not compile:"; tail -5 "$work/pcl_build.log"
  fi
fi

# --- Open3D -------------------------------------------------------------------------------------
venv=${OPEN3D_VENV:-$work/venv}
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q open3d
fi

cargo build -q --release -p crease-cli
cargo build -q --release -p crease --example normals_timing
./target/release/crease synth cube -n "$n" -q -o "$work/src.ply"
# Both files hold float x y z only, so every tool reads the same bytes.
"$venv/bin/python" - "$work" "$threads" <<'PY'
import os, sys, time, numpy as np
work, threads = sys.argv[1], sys.argv[2]
import open3d as o3d
pts = np.asarray(o3d.io.read_point_cloud(f"{work}/src.ply").points)
q = np.clip(((pts - pts.min(0)) / np.ptp(pts, 0).max() * 2047).astype(np.uint64), 0, 2047)
code = np.zeros(len(pts), dtype=np.uint64)
for b in range(11):
    for a in range(3):
        code |= ((q[:, a] >> np.uint64(b)) & np.uint64(1)) << np.uint64(3 * b + a)
for name, p in (("random", pts), ("sorted", pts[np.argsort(code, kind="stable")])):
    # Binary little-endian PLY of float x y z (what PCL's PointXYZ reads), same file for all.
    xyz = np.ascontiguousarray(p, dtype="<f4")
    with open(f"{work}/{name}.ply", "wb") as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(xyz)}\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n").encode())
        f.write(xyz.tobytes())
    best = 1e9
    for _ in range(3):
        pc = o3d.io.read_point_cloud(f"{work}/{name}.ply")
        t = time.perf_counter()
        pc.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(20))
        best = min(best, time.perf_counter() - t)
    print(f"open3d {o3d.__version__} estimate_normals KNN(20), {name}, {len(p)} points: {best:.3f} s (best of 3)")
PY

for order in random sorted; do
  if [ -n "$pcl_bin" ]; then
    read -r t cnt < <(OMP_NUM_THREADS=$threads "$pcl_bin" "$work/$order.ply" 20 "$threads" 3)
    printf 'pcl %s NormalEstimationOMP k=20 (%s threads), %s, %s points: %.3f s (best of 3)\n' \
      "$(pkg-config --modversion pcl_features)" "$threads" "$order" "$cnt" "$t"
  fi
  best=""
  for _ in 1 2 3; do
    line=$(RAYON_NUM_THREADS=$threads ./target/release/crease normals "$work/$order.ply" \
      -o "$work/out.ply" -k 20 --json -q |
      python3 -c 'import json,sys; t=json.load(sys.stdin)["timings"]; print(t["knn"]+t["normals"])')
    best=$(printf '%s\n%s\n' "$best" "$line" | sed '/^$/d' | sort -g | head -1)
  done
  printf 'crease normals -k 20 (fused kNN + PCA, %s threads), %s, %s points: %.3f s (best of 3 processes)\n' \
    "$threads" "$order" "$n" "$best"
  # Timed as PCL and Open3D are: best of 3 runs in one process (a warm heap after the first).
  RAYON_NUM_THREADS=$threads ./target/release/examples/normals_timing "$work/$order.ply" 3 |
    sed 's/^/crease in-process: /'
  /usr/bin/time -f "crease peak RSS (whole command incl. reading and writing): %M KB" \
    ./target/release/crease normals "$work/$order.ply" -o "$work/out.ply" -k 20 -q 2>&1 |
    tail -1 || true
done
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
