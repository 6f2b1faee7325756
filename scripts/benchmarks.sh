#!/usr/bin/env bash
# Every figure of BENCHMARKS.md, from a fresh clone: installs what is missing, builds (Release),
# runs mvog_bench on every shared recording (MVOG, OctoMap and the bare walk on the same rays, in
# one run per file, and Bonxai from MVOG_PEERS_DIR, default ../shared/peers beside the
# repository, when its sources are there), MVOG with 2 threads, with the paper's model and with
# each of its rules changed alone (README's decisions table: the quality each default buys), its synthetic sensors
# (data none of the recordings has), mvog_microbench, and the
# instruction counts of the three insertions (callgrind: the ratios the machine's load cannot
# disturb); writes the outputs (JSON and text) to OUT and prints the report's tables
# (scripts/benchmark_tables.py).
#   scripts/benchmarks.sh [OUT]    (default OUT: the workspace's benchmarks/; ~15 min here
#                                  after the build)
# MVOG_BENCH_REPEAT (default 3): insertions per backend, the fastest reported.
# shellcheck source=scripts/common.sh
source "$(dirname "$0")/common.sh"

OUT=${1:-$WORKSPACE/benchmarks}
REPEAT=${MVOG_BENCH_REPEAT:-3}
export MVOG_PEERS_DIR=${MVOG_PEERS_DIR:-$(cd "$REPO/.." && pwd)/shared/peers}
install_missing_packages
build_workspace
source_workspace
BENCH=$WORKSPACE/devel/lib/mvog/mvog_bench
[ -d "$MVOG_DATA_DIR" ] || { echo "no shared data at $MVOG_DATA_DIR (set MVOG_DATA_DIR)" >&2; exit 1; }
mkdir -p "$OUT"
cut -d' ' -f1-3 /proc/loadavg >"$OUT/load_average_before"

# The 2D laser logs also at 0.1 m, the cell size their users map at.
declare -A RESOLUTIONS=(
  [intel_lab.bag]="0.1 0.05" [people_stationary.bag]="0.1 0.05"
)
FILES=(spherical_scan.graph newcollege_excerpt.bag intel_lab.bag people_stationary.bag
  kurt3d_3scans.bag kurt3d_3scans.graph tum_fr2_pioneer_slam2_10frames.graph
  tum_fr2_pioneer_10frames.bag)
THREADED_FILES=(kurt3d_3scans.graph tum_fr2_pioneer_slam2_10frames.graph
  tum_fr2_pioneer_10frames.bag)

# resolution_options "R1 R2 ...": RESOLUTION_OPTIONS, `--resolution R` for each R.
resolution_options() {
  RESOLUTION_OPTIONS=()
  local r
  for r in $1; do RESOLUTION_OPTIONS+=(--resolution "$r"); done
}

run_bench() {
  local name=$1
  shift
  echo "mvog_bench $* -> $OUT/$name.json"
  "$BENCH" "$@" --repeat "$REPEAT" --json "$OUT/$name.json" >"$OUT/$name.txt" 2>"$OUT/$name.log"
}

for file in "${FILES[@]}"; do
  resolution_options "${RESOLUTIONS[$file]:-0.05}"
  run_bench "all_$file" --input "$MVOG_DATA_DIR/$file" "${RESOLUTION_OPTIONS[@]}" --backend all
  run_bench "paper_$file" --input "$MVOG_DATA_DIR/$file" "${RESOLUTION_OPTIONS[@]}" --backend mvog \
    --model paper
done
# Built without Bonxai, every run of all the backends runs without it: say so once, and why.
grep -h -m 1 "skips Bonxai" "$OUT"/all_*.log | head -n 1 >&2 || true
# One and two threads in turn, a process each, three rounds, before the runs that hold gigabytes
# (OctoMap at 0.02 m, after which two threads ran up to 1.4x slower for a while): a slow spell of
# the machine falls on both alike, and the table compares the fastest of each.
for file in "${THREADED_FILES[@]}"; do
  for round in 1 2 3; do
    for threads in 1 2; do
      run_bench "threads${threads}_round${round}_$file" --input "$MVOG_DATA_DIR/$file" \
        --resolution 0.05 --backend mvog --threads "$threads"
    done
  done
done
# Every file also at the resolutions the runs above leave out (0.1 and 0.02 m; 0.02 m for the 2D
# logs), the three backends on the same rays: how the ratios move with the cell size a user
# chooses. After the two-thread runs: OctoMap's trees at 0.02 m hold up to gigabytes.
declare -A OTHER_RESOLUTIONS=(
  [intel_lab.bag]="0.02" [people_stationary.bag]="0.02"
)
for file in "${FILES[@]}"; do
  resolution_options "${OTHER_RESOLUTIONS[$file]:-0.1 0.02}"
  run_bench "resolutions_$file" --input "$MVOG_DATA_DIR/$file" "${RESOLUTION_OPTIONS[@]}" \
    --backend all
done
# The rules one at a time, MVOG alone at 0.05 m on every file (the quality only: one insertion).
declare -A RULE_OPTIONS=(
  [clip_off]="--clip-free-space-at-hits off" [per_reading]="--mass-counting per-reading"
  [split_off]="--split-free-space-at-obstacles off" [threshold_0.5]="--occupancy-threshold 0.5"
)
# The free length of out-of-range readings, on the recordings that have them (by default both
# backends disregard them, as the paper's Table I; the server frees 2 m of each).
OUT_OF_RANGE_FILES=(newcollege_excerpt.bag intel_lab.bag people_stationary.bag)
for file in "${FILES[@]}"; do
  for rule in "${!RULE_OPTIONS[@]}"; do
    read -r -a options <<<"${RULE_OPTIONS[$rule]}"
    REPEAT=1 run_bench "rule_${rule}_$file" --input "$MVOG_DATA_DIR/$file" --resolution 0.05 \
      --backend mvog "${options[@]}"
  done
done
for file in "${OUT_OF_RANGE_FILES[@]}"; do
  for length in 1 2 4 inf; do
    REPEAT=1 run_bench "rule_out_of_range_${length}_$file" --input "$MVOG_DATA_DIR/$file" \
      --resolution 0.05 --backend mvog --out-of-range-free-length "$length"
  done
done
# The paper's Table I: its New College resolutions, and its office room's on the TUM frames (a
# Kinect indoors) and on Kurt3D (one insertion: only the sizes are read).
REPEAT=1 run_bench table_one_newcollege_excerpt.bag --input "$MVOG_DATA_DIR/newcollege_excerpt.bag" \
  --resolution 1.0 --resolution 0.5 --resolution 0.1 --backend both
for file in tum_fr2_pioneer_slam2_10frames.graph kurt3d_3scans.graph; do
  REPEAT=1 run_bench "table_one_$file" --input "$MVOG_DATA_DIR/$file" --resolution 0.1 \
    --resolution 0.05 --resolution 0.02 --backend both
done
# Sensors none of the recordings has, cast into scenes built in code (mvog_bench's synthetic
# inputs): the quality of the defaults on data they were not tuned on. One insertion each (OctoMap
# takes about a minute for a drive of the 100 m lidar at 0.05 m).
for sensor in rotating-lidar-16 rotating-lidar-16-firing-order rotating-lidar-32 tilting-laser; do
  REPEAT=1 run_bench "synthetic_$sensor" --input "synthetic:$sensor" --resolution 0.1 \
    --resolution 0.05 --backend all
done
echo "mvog_microbench -> $OUT/microbench.json"
"$WORKSPACE/devel/lib/mvog/mvog_microbench" --benchmark_out="$OUT/microbench.json" \
  --benchmark_out_format=json >"$OUT/microbench.txt" 2>&1
# count_instructions FILE BACKEND FUNCTION: the instructions retired inside FUNCTION (callgrind's
# --toggle-collect) while mvog_bench inserts FILE at 0.05 m with BACKEND alone.
count_instructions() {
  local name=$2_$1
  echo "callgrind: $2 on $1 -> $OUT/instructions_$name"
  valgrind --tool=callgrind --callgrind-out-file="$OUT/callgrind_$name.out" \
    --toggle-collect="$3" "$BENCH" --input "$MVOG_DATA_DIR/$1" --resolution 0.05 --backend "$2" \
    >"$OUT/callgrind_$name.log" 2>&1
  callgrind_annotate "$OUT/callgrind_$name.out" |
    awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1; exit }' >"$OUT/instructions_$name"
}
for file in kurt3d_3scans.graph tum_fr2_pioneer_slam2_10frames.graph; do
  count_instructions "$file" mvog 'mvog::Map::insertScan*'
  count_instructions "$file" walk 'mvog_bench::runWalk*'
  count_instructions "$file" octomap 'octomap::OccupancyOcTreeBase*::insertPointCloud*'
done
cut -d' ' -f1-3 /proc/loadavg >"$OUT/load_average_after"
python3 "$REPO/scripts/benchmark_tables.py" "$OUT" | tee "$OUT/tables.md"
