#!/usr/bin/env bash
# Speed and memory of the whole pipeline (issue 41), the default configuration as users run it
# (shipped Yolo-Fastest, mapping, loop closing and the dense map on their own threads):
#   - bonn_crowd_dev: the 250 real Xtion frames of ../shared (camera file from bench/bonn_camera.sh);
#   - tum_fr1_rpy_dev: the 300 real Kinect v1 frames of ../shared;
#   - sim_crowd: a 300-frame yesslam-sim crowd sequence with the real-sensor model (seed 1).
# For each: fps, wall time, CPU per frame (user + system over the frames: at 30 Hz, 33 ms is one
# core), peak resident memory (GNU time's maximum RSS), and the
# median and p95 of every stage (stats.json, ms; mapping, dense and loop_detect per keyframe).
# With BIN_B another build runs too, interleaved with this one run by run (A B A B ...: machines
# drift by 20 % from hour to hour), and a last table gives B / A of the medians.
# Usage: bench/bench_speed.sh [RUNS]                       (this build; outputs in bench_out/speed/)
#        BIN_B=/old/build/rawlog_tools bench/bench_speed.sh 5   (two builds side by side)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
BIN_B="${BIN_B:-}"
RUNS="${1:-3}"
SHARED="$ROOT/../shared/data"
[ -x "$BIN/yesslam" ] || { echo "bench_speed: build first (./scripts/build.sh)" >&2; exit 1; }
[ -z "$BIN_B" ] || [ -x "$BIN_B/yesslam" ] || { echo "bench_speed: BIN_B=$BIN_B has no yesslam" >&2; exit 1; }
for d in bonn_crowd_dev tum_fr1_rpy_dev; do
  [ -d "$SHARED/$d" ] || { echo "bench_speed: $SHARED/$d is missing" >&2; exit 1; }
done
[ -x /usr/bin/time ] || { echo "bench_speed: needs GNU time (/usr/bin/time, Debian package 'time') for the peak memory" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench_speed: needs python3 to read stats.json" >&2; exit 1; }
# shellcheck source=bench/sim_sequence.sh
. "$ROOT/bench/sim_sequence.sh"
OUT="$ROOT/bench_out/speed"; mkdir -p "$OUT/runs"
"$ROOT/bench/bonn_camera.sh" "$SHARED/bonn_crowd_dev" "$OUT/bonn_camera.txt"
sim_sequence "$OUT/sim_crowd" --preset crowd --real-sensor --frames 300 --seed 1

STAGES="orb orb_cpu track track_cpu mask detect detect_wait keyframe mapping mapping_cpu dense dense_cpu loop_detect"
builds=(A); [ -n "$BIN_B" ] && builds+=(B)
bin_of() { [ "$1" = A ] && echo "$BIN" || echo "$BIN_B"; }
run() {  # run BUILD SEQUENCE I ARGS...
  local b="$1" s="$2" i="$3"; shift 3
  local dir="$OUT/runs/$s-$b-$i"
  /usr/bin/time -f "%M %e %U %S" -o "$dir.time" "$(bin_of "$b")/yesslam" "$@" --out "$dir" --quiet > "$dir.log" 2> "$dir.err" \
    || { echo "bench_speed: run $dir failed:" >&2; tail -3 "$dir.err" >&2; exit 1; }
}
# Builds from before --gt-format (b67dc07, issue 41's reference) read the Bonn markers' poses as the
# camera's: their ATE column is then not comparable, their speed is.
gt_format() {  # (the help into a variable: grep -q leaving a pipe early fails it under pipefail)
  local help; help="$("$(bin_of "$1")/yesslam" --help 2>&1 || true)"
  [[ "$help" == *--gt-format* ]] && echo "--gt-format bonn" || true
}
for i in $(seq "$RUNS"); do
  for b in "${builds[@]}"; do
    # shellcheck disable=SC2046
    run "$b" bonn_crowd_dev "$i" --input "$SHARED/bonn_crowd_dev" --camera "$OUT/bonn_camera.txt" $(gt_format "$b")
    run "$b" tum_fr1_rpy_dev "$i" --input "$SHARED/tum_fr1_rpy_dev"
    run "$b" sim_crowd "$i" --input "$OUT/sim_crowd"
  done
done

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $RUNS runs each, medians"
echo "A = $BIN${BIN_B:+; B = $BIN_B}"
python3 - "$OUT/runs" "$RUNS" "$STAGES" "${builds[@]}" <<'PY'
import json, statistics, sys
runs, n, stages, builds = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), sys.argv[4:]
def one(seq, b, i):
    d = f"{runs}/{seq}-{b}-{i}"
    st = json.load(open(d + "/stats.json"))
    # The last line: GNU time writes "Command exited with ..." above it when a run fails.
    rss, wall, user, system = open(d + ".time").read().split("\n")[-2].split()[:4]
    log = {k.strip(): v.split()[0] for k, v in (l.split(":", 1) for l in open(d + ".log") if ":" in l) if v.split()}
    frames = float(log.get("frames", "nan"))
    r = {"fps": float(log.get("fps", "nan")), "rss": float(rss) / 1024, "wall": float(wall),
         "cpu": 1000 * (float(user) + float(system)) / frames, "ate": float(log.get("ate_rmse", "nan")) * 1000}
    for s in stages:
        v = st["stages_ms"].get(s)
        r[s] = (v["median"], v["p95"]) if v else (float("nan"), float("nan"))
    return r
med = lambda xs: statistics.median(xs)
table = {}
seqs = ("bonn_crowd_dev", "tum_fr1_rpy_dev", "sim_crowd")
for seq in seqs:
    for b in builds:
        rs = [one(seq, b, i) for i in range(1, n + 1)]
        row = {k: med([r[k] for r in rs]) for k in ("fps", "rss", "wall", "cpu", "ate")}
        for s in stages:
            row[s] = (med([r[s][0] for r in rs]), med([r[s][1] for r in rs]))
        table[(seq, b)] = row
print()
print("| sequence | build | fps | peak RSS | wall | CPU per frame | ATE | " + " | ".join(f"{s} med / p95" for s in stages) + " |")
print("|---" * (7 + len(stages)) + "|")
for (seq, b), r in table.items():
    print(f"| {seq} | {b} | {r['fps']:.1f} | {r['rss']:.0f} MB | {r['wall']:.1f} s | {r['cpu']:.1f} ms | {r['ate']:.1f} mm | "
          + " | ".join(f"{r[s][0]:.1f} / {r[s][1]:.1f}" for s in stages) + " |")
if "B" in builds:
    print()
    print("B / A (medians): | sequence | fps | peak RSS | CPU per frame | " + " | ".join(stages) + " |")
    print("|---" * (4 + len(stages)) + "|")
    for seq in seqs:
        a, b = table[(seq, "A")], table[(seq, "B")]
        # Under 0.05 ms (a stage that no longer waits) a ratio says nothing: "-".
        q = lambda x, y: f"{y / x:.2f}" if x == x and x >= 0.05 else "-"
        print(f"| {seq} | {q(a['fps'], b['fps'])} | {q(a['rss'], b['rss'])} | {q(a['cpu'], b['cpu'])} | "
              + " | ".join(q(a[s][0], b[s][0]) for s in stages) + " |")
PY
echo
echo "Stages in ms: orb, track, mask and keyframe per frame on the tracking thread; detect the detector's own"
echo "time on its thread, detect_wait what the frame waited for it; mapping, dense, loop_detect per keyframe;"
echo "*_cpu the CPU time the stage's thread used (the wall time also counts waiting for one of the shared cores)."
echo "Runs in $OUT/runs."
