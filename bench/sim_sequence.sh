# shellcheck shell=bash
# Sourced by the benches (BIN must name the folder of yesslam-sim, ROOT the repository). sim_sequence DIR ARGS...: makes
# the yesslam-sim sequence DIR from ARGS (without --out) once, and reuses it while it is what would
# be made now: the same arguments and the same simulator model (yesslam-sim --model-hash, also in
# meta.json). A sequence made before the simulator changed is made again, not measured as if new.
sim_sequence() {
  local seq="$1"; shift
  local key; key="$("$BIN/yesslam-sim" --model-hash) $*"
  if [ -f "$seq/meta.json" ] && [ -f "$seq/.bench_key" ] && [ "$(cat "$seq/.bench_key")" = "$key" ]; then return 0; fi
  rm -rf "$seq"
  "$BIN/yesslam-sim" "$@" --out "$seq" > /dev/null
  printf '%s' "$key" > "$seq/.bench_key"
}

# SIM_FLAGS (environment, e.g. "--real-sensor"): more yesslam-sim flags for the benches that take
# them (bench_slam, bench_dynamic, bench_dense, bench_loop, bench_scaling), as the array SIMX.
SIM_FLAGS="${SIM_FLAGS:-}"
# shellcheck disable=SC2034  # SIMX is for the benches that source this file
read -r -a SIMX <<< "$SIM_FLAGS"
# bench_out NAME: the bench's output folder, kept apart for each SIM_FLAGS (bench_out/slam--real-sensor).
bench_out() { printf '%s/bench_out/%s%s' "$ROOT" "$1" "$(printf '%s' "$SIM_FLAGS" | tr -c 'a-z0-9.' '-')"; }
