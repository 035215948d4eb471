#!/usr/bin/env bash
# Sharp points on the same N-point cloud (`crease synth two-cylinders`, default 1M), crease
# against PCL, in random (sampling) order and in Morton-sorted order, THREADS threads, measured
# side by side in one run. Every figure is a whole process, best of 3 (wall clock), with its peak
# memory and its CPU time, user + system (`/usr/bin/time -f "%e s %M KB %U %S"`; a second view
# when other jobs share the cores, though contention inflates it too), and the load average read
# just before its three runs:
#   - crease:  `crease sharp IN -o OUT.ply` (the default: multi-scale projected distance, Otsu,
#              the surface stage); for reference also `--no-surfaces` (tran's method alone) and
#              `--method surface-variation --scales 20 --no-surfaces` (PCL's measure, one scale);
#   - PCL:     scripts/pcl_sharp.cpp (compiled here with g++ -O3): loadPLYFile, then
#              NormalEstimationOMP + KdTreeFLANN at k = 20 (normals and `curvature`, the surface
#              variation), a point is sharp when its curvature is above a threshold, savePLYFile;
#              its own read / compute / write times are printed too. The threshold labels as
#              many points as the default `crease sharp` did on the same file (`top:N`), so both
#              outputs have the same number of sharp points; how many points PCL has above the
#              fixed 0.02 is printed beside it;
#   - crease network IN -o OUT.obj and crease run IN -o DIR (no PCL analogue; times only).
# Both clouds, clean and with noise of NOISE spacings along the normal (default 0.5), are
# rewritten as binary little-endian PLY of float x y z only (what PCL's PointXYZ reads), the same
# file for both tools; the Morton order (11 bits per axis, stable) is computed here with numpy,
# crease having no option to sort a file. The labels of both tools are scored against the
# synthetic ground truth with `crease eval` (MCC of the sharp class), as a check.
# PCL comes from Debian (libpcl-dev) and numpy from python3-numpy; the script installs them with
# apt-get when it can, and otherwise says why and skips PCL (numpy is required). The temporary
# folder is removed on exit; nothing is committed.
#   usage: scripts/compare-sharp.sh [N_POINTS] [THREADS] [NOISE]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
threads=${2:-2}
noise=${3:-0.5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
loadavg() { cut -d' ' -f1-3 /proc/loadavg; }
echo "$(date -u +%F), load average: $(loadavg), $(nproc) CPUs, $threads threads, $n points"

can_apt() { command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; }

# --- numpy (required: the float32 and Morton-sorted files) ------------------------------------
# The first python3 on PATH if it has numpy, else Debian's (where python3-numpy installs it).
py=python3
if ! "$py" -c 'import numpy' 2>/dev/null; then
  py=/usr/bin/python3
  if ! "$py" -c 'import numpy' 2>/dev/null; then
    if can_apt && (apt-get update -qq && apt-get install -y -qq python3-numpy) >"$work/apt-numpy.log" 2>&1; then
      echo "installed python3-numpy with apt-get"
    else
      echo "numpy is needed to write the float32 and Morton-sorted files: install python3-numpy" >&2
      exit 1
    fi
  fi
fi

# --- PCL (optional) ---------------------------------------------------------------------------
pcl_bin=""
if ! pkg-config --exists pcl_features 2>/dev/null; then
  if can_apt; then
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
  if g++ -O3 -march=native -fopenmp -std=c++17 scripts/pcl_sharp.cpp -o "$work/pcl_sharp" \
    $(pkg-config --cflags --libs pcl_features pcl_io pcl_search pcl_kdtree pcl_common) \
    2>"$work/pcl_build.log"; then
    pcl_bin="$work/pcl_sharp"
    echo "PCL $(pkg-config --modversion pcl_features), g++ $(g++ -dumpversion)"
  else
    echo "PCL skipped: scripts/pcl_sharp.cpp did not compile:"; tail -5 "$work/pcl_build.log"
  fi
fi

cargo build -q --release -p crease-cli
crease=./target/release/crease
"$crease" synth two-cylinders -n "$n" -q -o "$work/clean.src.ply"
"$crease" synth two-cylinders -n "$n" --noise "$noise" -q -o "$work/noisy.src.ply"
# For each cloud and order: ORDER.ply (float x y z) and ORDER.gt.ply (the same + uchar gt_sharp).
"$py" - "$work" <<'PY'
import sys, numpy as np
work = sys.argv[1]
types = {"double": "<f8", "float": "<f4", "uchar": "u1", "int": "<i4", "uint": "<u4"}
for cloud in ("clean", "noisy"):
    with open(f"{work}/{cloud}.src.ply", "rb") as f:
        props = []
        while (line := f.readline().decode().split()) != ["end_header"]:
            if line[0] == "element":
                n = int(line[2])
            elif line[0] == "property":
                props.append((line[2], types[line[1]]))
        v = np.fromfile(f, dtype=np.dtype(props), count=n)
    pts = np.stack([v["x"], v["y"], v["z"]], axis=1)
    q = np.clip(((pts - pts.min(0)) / np.ptp(pts, 0).max() * 2047).astype(np.uint64), 0, 2047)
    code = np.zeros(len(pts), dtype=np.uint64)
    for b in range(11):
        for a in range(3):
            code |= ((q[:, a] >> np.uint64(b)) & np.uint64(1)) << np.uint64(3 * b + a)
    for order, idx in (("random", np.arange(n)), ("sorted", np.argsort(code, kind="stable"))):
        head = f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n" \
               "property float x\nproperty float y\nproperty float z\n"
        xyz = np.ascontiguousarray(pts[idx], dtype="<f4")
        with open(f"{work}/{cloud}-{order}.ply", "wb") as f:
            f.write((head + "end_header\n").encode())
            f.write(xyz.tobytes())
        gt = np.zeros(n, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("g", "u1")])
        gt["x"], gt["y"], gt["z"], gt["g"] = xyz[:, 0], xyz[:, 1], xyz[:, 2], v["gt_sharp"][idx]
        with open(f"{work}/{cloud}-{order}.gt.ply", "wb") as f:
            f.write((head + "property uchar gt_sharp\nend_header\n").encode())
            f.write(gt.tobytes())
PY

# best3 NAME CMD...: runs CMD three times under /usr/bin/time; sets t (best wall seconds), mb
# (its peak memory in MB), cpu (its user + system seconds), f ("T s / CPU s CPU, MB MB") and la
# (load average before the runs); the best run's stdout goes to $work/NAME.out.
best3() {
  local name=$1 s kb us sy
  shift
  la=$(loadavg)
  t=""
  for _ in 1 2 3; do
    /usr/bin/time -o "$work/time" -f "%e s %M KB %U %S" "$@" >"$work/last.stdout"
    read -r s _ kb _ us sy <"$work/time"
    if [ -z "$t" ] || awk -v a="$s" -v b="$t" 'BEGIN { exit !(a < b) }'; then
      t=$s mb=$((kb / 1024)) cpu=$(awk -v u="$us" -v s="$sy" 'BEGIN { printf "%.2f", u + s }')
      cp "$work/last.stdout" "$work/$name.out"
    fi
  done
  f="$t s / $cpu s CPU, $mb MB"
}
mcc() { # PRED GT LABEL SCORE
  "$crease" --threads "$threads" eval "$1" --gt "$2" --label "$3" --score "$4" --json -q |
    "$py" -c 'import json,sys; print("%.3f" % json.load(sys.stdin)["metrics"]["mcc"])'
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

table="| cloud, order | crease sharp | PCL whole process (compute) | crease / PCL | sharp points: crease, PCL > 0.02 | MCC crease, PCL | crease sharp --no-surfaces | crease surface variation k 20 (/ PCL) | crease network | crease run | load average |
|---|---|---|---|---|---|---|---|---|---|---|"
c=(--threads "$threads")
for cloud in clean noisy; do
  for order in random sorted; do
    in="$work/$cloud-$order.ply"
    best3 sharp "$crease" "${c[@]}" --json -q sharp "$in" -o "$work/crease.ply"
    c_t=$t c_f=$f c_la=$la
    count=$("$py" -c 'import json,sys; print(json.load(sys.stdin)["sharp"])' <"$work/sharp.out")
    c_mcc=$(mcc "$work/crease.ply" "$work/$cloud-$order.gt.ply" sharp sharpness)
    echo "crease sharp, $cloud, $order: $c_f, $count sharp, MCC $c_mcc (best of 3; load $c_la)"
    p_cell="skipped" r_cell="" p_count="" p_mcc=""
    if [ -n "$pcl_bin" ]; then
      best3 pcl env OMP_NUM_THREADS="$threads" "$pcl_bin" "$in" "$work/pcl.ply" 20 "$threads" "top:$count"
      read -r p_read p_comp p_write _ p_sharp p_thr p_002 <"$work/pcl.out"
      p_mcc=$(mcc "$work/pcl.ply" "$work/$cloud-$order.gt.ply" label curvature)
      echo "pcl_sharp k=20, $cloud, $order: $f (read $p_read s, normals + threshold $p_comp s, write $p_write s); $p_sharp sharp at curvature > $p_thr, $p_002 above 0.02, MCC $p_mcc (best of 3; load $la)"
      p_t=$t p_cell="$f (compute $p_comp s)" r_cell=$(ratio "$c_t" "$t") p_count=", $p_002"
      c_la="$c_la / $la"
    fi
    best3 nosurf "$crease" "${c[@]}" -q sharp "$in" -o "$work/crease.ply" --no-surfaces
    ns=$f
    echo "crease sharp --no-surfaces, $cloud, $order: $ns (best of 3; load $la)"
    best3 sv "$crease" "${c[@]}" -q sharp "$in" -o "$work/crease.ply" --no-surfaces \
      --method surface-variation --scales 20
    sv=$f
    if [ -n "$r_cell" ]; then sv+=" ($(ratio "$t" "$p_t")x PCL)"; fi
    echo "crease sharp --method surface-variation --scales 20 --no-surfaces, $cloud, $order: $sv (best of 3; load $la)"
    best3 network "$crease" "${c[@]}" -q network "$in" -o "$work/net.obj"
    nw=$f
    echo "crease network, $cloud, $order: $nw (best of 3; load $la)"
    best3 run "$crease" "${c[@]}" -q run "$in" -o "$work/run"
    rn=$f
    echo "crease run, $cloud, $order: $rn (best of 3; load $la)"
    table+="
| $cloud, $order | $c_f | $p_cell | $r_cell | $count$p_count | $c_mcc, $p_mcc | $ns | $sv | $nw | $rn | $c_la |"
  done
done
echo
echo "$table"
echo "load average: $(loadavg)"
