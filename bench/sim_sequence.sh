# Sourced by the benches (BIN must name the folder of yesslam-sim). sim_sequence DIR ARGS...: makes
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
