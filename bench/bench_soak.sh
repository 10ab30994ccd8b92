#!/usr/bin/env bash
# Hours in one place, in minutes (issue 68 item 4): a real dev slice played PASSES times, each pass
# from its first frame again (MODE=jump, the default: the camera is back at the start each pass and
# the run must find itself in its map, as a robot revisiting its room), or forwards then backwards
# in turn (MODE=pingpong: no jump, but a backward pass reads a rolling-shutter image bottom to top,
# which the readout correction does not model: its accuracy is not the camera's), through the
# default configuration (mapping, loop closing and the dense map on their own threads). While it
# runs, the resident memory (/proc/PID/status VmRSS) and the frames done (the journal:
# trajectory_online.txt) are sampled every SAMPLE seconds. Prints one row per pass (fps, peak and
# end memory, each against the first pass), writes samples.csv and soak.svg (memory and frames
# over time, passes marked) and the run's outputs under OUT.
# Usage: bench/bench_soak.sh [PASSES [FOLDER [OUT]]]   (defaults: 4, ../shared/data/bonn_crowd_dev,
#        bench_out/soak); SAMPLE=1 second between samples, MODE=jump|pingpong.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
PASSES="${1:-4}"
SRC="${2:-$ROOT/../shared/data/bonn_crowd_dev}"
OUT="${3:-$ROOT/bench_out/soak}"
SAMPLE="${SAMPLE:-1}"
MODE="${MODE:-jump}"
case "$MODE" in jump | pingpong) ;; *) echo "bench_soak: MODE must be jump or pingpong, not '$MODE'" >&2; exit 1 ;; esac
[ -x "$BIN/yesslam" ] || { echo "bench_soak: build first (./scripts/build.sh)" >&2; exit 1; }
[[ "$PASSES" =~ ^[1-9][0-9]*$ ]] || { echo "bench_soak: PASSES must be a positive whole number, not '$PASSES'" >&2; exit 1; }
for f in rgb.txt depth.txt; do
  [ -f "$SRC/$f" ] || { echo "bench_soak: $SRC: not a TUM-layout folder (no $f)" >&2; exit 1; }
done
SRC="$(cd "$SRC" && pwd)"
name="$(basename "$SRC")"
mkdir -p "$OUT"
# The looped folder keeps the slice's name (its camera and readout are found by it) plus _soak.
SEQ="$OUT/${name}_soak"
rm -rf "$SEQ" "$OUT/run"
mkdir -p "$SEQ"
for d in rgb depth; do ln -s "$SRC/$d" "$SEQ/$d"; done
[ -f "$SRC/calibration.txt" ] && cp "$SRC/calibration.txt" "$SEQ/"

# One time map for colour, depth and ground truth: pass p forwards, t -> t + p * span; backwards
# (pingpong, odd passes), t -> start + p * span + (end - t). Intervals and the colour/depth offsets
# stay the real ones.
read -r T0 T1 < <(awk '!/^#/ && NF >= 2 {if (n++ == 0) a = $1; b = $1} END {printf "%.6f %.6f\n", a, b}' "$SRC/rgb.txt")
SPAN=$(awk -v a="$T0" -v b="$T1" 'BEGIN {printf "%.6f", (b - a) + (b - a) / 200}')  # a frame interval or so between passes
loop_list() {  # loop_list FILE [all]: the file's lines, stamps mapped, every pass, sorted (all: gt lines beyond the frames too)
  awk -v P="$PASSES" -v pp="$([ "$MODE" = pingpong ] && echo 1 || echo 0)" -v t0="$T0" -v t1="$T1" -v span="$SPAN" -v all="${2:-}" '
    /^#/ || NF < 2 { next }
    { if (!all && ($1 < t0 - 0.1 || $1 > t1 + 0.1)) next
      if (all && ($1 < t0 || $1 > t1)) next
      for (p = 0; p < P; p++) {
        t = (!pp || p % 2 == 0) ? $1 + p * span : t0 + p * span + (t1 - $1)
        line = sprintf("%.6f", t); for (i = 2; i <= NF; i++) line = line " " $i; print line } }' "$1" | sort -n -k1,1
}
loop_list "$SRC/rgb.txt" > "$SEQ/rgb.txt"
loop_list "$SRC/depth.txt" > "$SEQ/depth.txt"
GT_ARGS=()
if [ -f "$SRC/groundtruth.txt" ]; then
  loop_list "$SRC/groundtruth.txt" all > "$SEQ/groundtruth.txt"
  GT_ARGS=(--gt "$SEQ/groundtruth.txt")
  case "$name" in *bonn*) GT_ARGS+=(--gt-format bonn) ;; esac
fi
CAM_ARGS=()
case "$name" in *bonn*) "$ROOT/bench/bonn_camera.sh" "$SRC" "$OUT/camera.txt"; CAM_ARGS=(--camera "$OUT/camera.txt") ;; esac
PER_PASS=$(awk '!/^#/ && NF >= 2' "$SRC/rgb.txt" | wc -l)
echo "bench_soak: $name, $PASSES passes of $PER_PASS frames ($MODE), sampled every $SAMPLE s"

"$BIN/yesslam" --input "$SEQ" "${CAM_ARGS[@]}" "${GT_ARGS[@]}" --out "$OUT/run" --quiet > "$OUT/run.log" 2> "$OUT/run.err" &
pid=$!
start=$(date +%s.%N)
echo "seconds,rss_mb,frames,peak_mb" > "$OUT/samples.csv"
sample() {
  local rss hwm frames now
  rss=$(awk '/^VmRSS:/ {printf "%.1f", $2 / 1024}' "/proc/$pid/status" 2>/dev/null || true)
  hwm=$(awk '/^VmHWM:/ {printf "%.1f", $2 / 1024}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && [ -n "$hwm" ] || return 1
  frames=$(grep -vc '^#' "$OUT/run/trajectory_online.txt" 2>/dev/null || true)
  now=$(date +%s.%N)
  echo "$(awk -v a="$start" -v b="$now" 'BEGIN {printf "%.2f", b - a}'),$rss,${frames:-0},$hwm" >> "$OUT/samples.csv"
}
while kill -0 "$pid" 2>/dev/null; do
  sample || break
  sleep "$SAMPLE"
done
wait "$pid" || { echo "bench_soak: the run failed:" >&2; tail -3 "$OUT/run.err" >&2; exit 1; }
# The whole run's peak (the kernel's high-water mark at the last sample: the end of the run's
# outputs may add to it after that).
echo "peak resident memory of the run (VmHWM at the last sample): $(tail -1 "$OUT/samples.csv" | cut -d, -f4) MB"

# Per pass: the samples whose frames lie in it (the journal counts frames with a pose).
awk -F, -v n="$PER_PASS" -v P="$PASSES" '
  NR == 1 { next }
  { t[NR] = $1; r[NR] = $2; f[NR] = $3; last = NR }
  END {
    printf "| pass | fps | peak MB | end MB | peak / pass 1 | fps / pass 1 |\n|---|---|---|---|---|---|\n"
    for (p = 1; p <= P; p++) {
      lo = (p - 1) * n; hi = p * n; peak = 0; ta = -1; tb = -1; fa = 0; fb = 0; endr = 0
      for (i = 2; i <= last; i++) {
        if (f[i] >= lo && f[i] <= hi) { if (r[i] > peak) peak = r[i]; endr = r[i]
          if (ta < 0) { ta = t[i]; fa = f[i] } else if (f[i] > f[i - 1]) { tb = t[i]; fb = f[i] } } }
      fps = (tb > ta) ? (fb - fa) / (tb - ta) : 0
      if (p == 1) { peak1 = peak; fps1 = fps }
      printf "| %d | %.1f | %.0f | %.0f | %.2f | %.2f |\n", p, fps, peak, endr, (peak1 > 0 ? peak / peak1 : 0), (fps1 > 0 ? fps / fps1 : 0) } }' \
  "$OUT/samples.csv" | tee "$OUT/passes.md"
grep -E "^(ate_rmse|online_ate_rmse|loops|keyframes|frames|lost)" "$OUT/run.log" || true

# soak.svg: memory (MB, left axis) and frames (right axis) over seconds, a line at each pass's end.
awk -F, -v n="$PER_PASS" -v P="$PASSES" -v title="bench_soak: $name, $PASSES passes" '
  NR == 1 { next }
  { t[NR] = $1; r[NR] = $2; f[NR] = $3; if ($1 > tm) tm = $1; if ($2 > rm) rm = $2; last = NR }
  END {
    W = 800; H = 400; L = 60; B = 40; Tp = 30; R = 60; w = W - L - R; h = H - B - Tp
    if (tm <= 0) tm = 1; rm = rm * 1.1; fm = n * P
    printf "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H
    printf "<rect width=\"%d\" height=\"%d\" fill=\"white\"/><text x=\"%d\" y=\"18\">%s</text>\n", W, H, L, title
    printf "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>\n", L, Tp, w, h
    for (k = 0; k <= 4; k++) {
      y = Tp + h - k * h / 4
      printf "<text x=\"%d\" y=\"%.0f\" text-anchor=\"end\" fill=\"#c00\">%.0f MB</text>", L - 4, y + 4, rm * k / 4
      printf "<text x=\"%d\" y=\"%.0f\" fill=\"#00c\">%.0f</text>\n", L + w + 4, y + 4, fm * k / 4 }
    printf "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">seconds (0 - %.0f)</text>\n", L + w / 2, H - 10, tm
    for (i = 2; i <= last; i++) if (i > 2 && int(f[i] / n) > int(f[i - 1] / n) && f[i] < fm) {
      x = L + w * t[i] / tm; printf "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#999\" stroke-dasharray=\"4\"/>\n", x, Tp, x, Tp + h }
    printf "<polyline fill=\"none\" stroke=\"#c00\" stroke-width=\"2\" points=\""
    for (i = 2; i <= last; i++) printf "%.1f,%.1f ", L + w * t[i] / tm, Tp + h - h * r[i] / rm
    printf "\"/>\n<polyline fill=\"none\" stroke=\"#00c\" points=\""
    for (i = 2; i <= last; i++) printf "%.1f,%.1f ", L + w * t[i] / tm, Tp + h - h * f[i] / fm
    printf "\"/>\n</svg>\n" }' "$OUT/samples.csv" > "$OUT/soak.svg"
echo "bench_soak: $OUT/passes.md, $OUT/samples.csv, $OUT/soak.svg, the run in $OUT/run"
