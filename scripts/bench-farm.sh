#!/usr/bin/env bash
# The farm's benchmarks (not tests): prints one JSON line each.
#   1. the same render through skyfarm-server with N local workers vs
#      skyfarm-worker render with N threads: wall times and their ratio (median of 3)
#   2. scheduler throughput with tiny units (a 1x1 image, 4096 units of 16 paths)
#   3. the server's peak memory (VmHWM) for a 4096x2048 job
#   4. the scheduler at scale: 1000 simulated workers, 100000 tiny units
#      (skyfarm-farm-bench, server/tools/farm_sim.h; median of 3 runs)
# Usage: scripts/bench-farm.sh [N]   (N defaults to the number of cores)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${SKYFARM_BUILD_DIR:-$root/build}
n=${1:-$(nproc)}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
port=$((20000 + RANDOM % 20000))

now() { date +%s.%N; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
request() {  # request WIDTH HEIGHT SPP BATCHES SEED
  printf '{"sun":{"zenith_deg":40,"azimuth_deg":120},"camera":{"projection":"equirectangular","width":%d,"height":%d},"spectral":{"batches":%d},"quality":{"samples_per_pixel":%d},"output":{"half":false},"seed":%d}' "$1" "$2" "$4" "$3" "$5"
}
submit_and_wait() {  # submit_and_wait BODY -> seconds from POST to done
  local t0 id state
  t0=$(now)
  id=$(curl -sf -X POST -H 'Content-Type: application/json' --data-binary "$1" "http://127.0.0.1:$port/v1/renders" |
       sed -n 's/.*"id":"\([^"]*\)".*/\1/p')
  while :; do
    state=$(curl -sf "http://127.0.0.1:$port/v1/renders/$id" | sed -n 's/.*"state":"\([a-z]*\)".*/\1/p')
    [[ $state == done ]] && break
    [[ $state == failed || $state == cancelled ]] && { echo "job $id $state" >&2; exit 1; }
    sleep 0.02
  done
  echo "$(now) - $t0" | bc -l
}

"$build/server/skyfarm-server" --listen "127.0.0.1:$port" --broker "tcp://127.0.0.1:*" --local-workers "$n" \
  --data-dir "$work/data" >"$work/server.log" 2>&1 &
server=$!
for _ in $(seq 100); do curl -sf "http://127.0.0.1:$port/healthz" >/dev/null && break; sleep 0.1; done
sleep 1  # let the local workers join

# 1. farm vs local
farm=(); local_t=()
for seed in 1 2 3; do
  body=$(request 256 128 64 2 "$seed")
  farm+=("$(submit_and_wait "$body")")
  echo "$body" >"$work/r$seed.json"
  t0=$(now)
  "$build/worker/skyfarm-worker" render "$work/r$seed.json" -o "$work/r$seed.exr" --threads "$n" >/dev/null 2>&1
  local_t+=("$(echo "$(now) - $t0" | bc -l)")
done
fm=$(printf '%s\n' "${farm[@]}" | median); lm=$(printf '%s\n' "${local_t[@]}" | median)
printf '{"bench":"farm_vs_local","workers":%d,"farm_s":%.3f,"local_s":%.3f,"ratio":%.3f}\n' "$n" "$fm" "$lm" "$(echo "$fm / $lm" | bc -l)"

# 2. scheduler throughput: 1x1 pixel, 64 batches x 64 passes of 16 samples = 4096 tiny units
t=$(submit_and_wait "$(request 1 1 1024 64 9)")
printf '{"bench":"scheduler_tiny_units","units":4096,"seconds":%.3f,"units_per_second":%.0f}\n' "$t" "$(echo "4096 / $t" | bc -l)"

# 3. server memory for a 4096x2048 job (1 sample per pixel, 1 batch: 8192 units)
t=$(submit_and_wait "$(request 4096 2048 1 1 5)")
hwm=$(awk '/VmHWM/ {print $2}' "/proc/$server/status")
printf '{"bench":"server_memory_4096x2048","seconds":%.1f,"server_peak_rss_mb":%.1f}\n' "$t" "$(echo "$hwm / 1024" | bc -l)"

# 4. scale by simulation: the real broker and job service, 1000 simulated workers
"$build/server/skyfarm-farm-bench" --workers 1000 --units 100000 --runs 3 --json | tail -1 |
  sed 's/^{/{"bench":"farm_scale_simulated",/'
