#!/usr/bin/env bash
# Two builds of a Google Benchmark binary compared on a noisy machine (not a
# test).  On the shared VMs this project runs on, the same binary's time
# varies by 10 % from run to run and the machine's speed drifts by up to
# 1.4x within minutes, so "before" and "after" are run alternately, ROUNDS
# times each, and the best (what a quiet machine gives) and the median of
# every benchmark are printed side by side (the figures in
# docs/experiments/2026-12-02-lut-build-time.md were made this way).
# Usage: scripts/bench-compare.sh BEFORE AFTER [ROUNDS] [FILTER]
#   BEFORE, AFTER  two skyfarm_bench binaries (copy the first aside before rebuilding)
#   ROUNDS         alternations (default 10)
#   FILTER         --benchmark_filter (default: the LUT build, all tables and by stage at 32 bins)
set -euo pipefail
if [ $# -lt 2 ]; then
  awk 'NR > 1 && !/^#/ {exit} NR > 1 {sub(/^# ?/, ""); print}' "$0"
  exit 2
fi
before=$1 after=$2 rounds=${3:-10}
filter=${4:-'BM_LutBuildAll/bins:(8|32)/bands:2$|BM_LutBuildPerSun/32$|BM_LutBuildStage/stage:./bins:32'}
for binary in "$before" "$after"; do
  [ -x "$binary" ] || { echo "not an executable: $binary" >&2; exit 2; }
done
runs=$(mktemp)
trap 'rm -f "$runs"' EXIT
for _ in $(seq "$rounds"); do
  for side in before after; do
    binary=$before
    [ "$side" = after ] && binary=$after
    # Console lines: NAME  TIME UNIT  CPU UNIT  ITERATIONS.
    "$binary" --benchmark_filter="$filter" --benchmark_min_time=0.2 2>/dev/null |
      awk -v side="$side" '/^BM_/ && NF >= 5 {print side, $1, $2, $3}' >>"$runs"
  done
done
# Per benchmark and side: the best and the median of its rounds.
sort -k2,2 -k1,1 -k3,3g "$runs" | awk '
  function flush() {
    if (n == 0) return
    m = (n % 2) ? t[(n + 1) / 2] : (t[n / 2] + t[n / 2 + 1]) / 2
    best[key] = t[1]; median[key] = m; unit[name] = u
    n = 0
  }
  { k = $2 " " $1
    if (k != key) { flush(); key = k; name = $2; if (!(name in seen)) { seen[name] = 1; order[++names] = name } }
    t[++n] = $3; u = $4 }
  END {
    flush()
    printf "%-44s %12s %12s %12s %12s\n", "benchmark (" unit[order[1]] ")", "best before", "best after", "median before", "median after"
    for (i = 1; i <= names; ++i) {
      b = order[i]
      printf "%-44s %12.3g %12.3g %12.3g %12.3g\n", b, best[b " before"], best[b " after"], median[b " before"], median[b " after"]
    }
  }'
