#!/usr/bin/env bash
# The sky look-ups' benchmark (not a test).  One skyfarm-server
# (no local workers), then with skyfarm-sky-load (keep-alive, N threads, D s):
#   1. GET /healthz                        a trivial static route (the yardstick)
#   2. GET /v1/sky?... (warm)              the same query every time: one cached table,
#                                          one look-up, one JSON answer per request
#   3. GET /v1/sky?... --vary-view (warm)  a new direction per request (answers differ,
#                                          the table is shared)
#   4. GET /v1/sky/envmap.exr 2048 x 1024  cold (table + render + encode) and warm (cached bytes)
#   5. a cold 24-position time sweep (one table per hour of a day), through
#      GET /v1/sky on a fresh server, then in process (skyfarm-sky-sweep) with
#      every table built in full (the cache before it reused atmosphere
#      tables) and with LutSky::with_sun after the first
# and prints one key=value line per measurement, then the ratio of 2 to 1.
# Usage: scripts/bench-sky.sh [THREADS] [SECONDS]   (defaults: 2 threads, 5 s)
# Build first: cmake --build "$SKYFARM_BUILD_DIR" --target skyfarm-server skyfarm-sky-load skyfarm-sky-sweep
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${SKYFARM_BUILD_DIR:-$root/build}
threads=${1:-2}
seconds=${2:-5}
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
port=$((20000 + RANDOM % 20000))
load="$build/server/skyfarm-sky-load"

"$build/server/skyfarm-server" --listen "127.0.0.1:$port" --broker "tcp://127.0.0.1:*" --local-workers 0 \
  --data-dir "$work/data" >"$work/server.log" 2>&1 &
for _ in $(seq 100); do curl -sf "http://127.0.0.1:$port/healthz" >/dev/null && break; sleep 0.1; done

place='lat=42.44&lon=-76.48&time=2013-05-27T09:30:00-04:00'
sky="/v1/sky?$place&view_zenith=35&view_azimuth=250"
curl -sf "http://127.0.0.1:$port$sky" >/dev/null  # warm: build the table

healthz=$("$load" --port "$port" --path /healthz --threads "$threads" --seconds "$seconds")
echo "$healthz"
warm=$("$load" --port "$port" --path "$sky" --threads "$threads" --seconds "$seconds")
echo "$warm"
"$load" --port "$port" --path "/v1/sky?$place" --vary-view --threads "$threads" --seconds "$seconds"
rps() { sed -n 's/.* rps=\([0-9.]*\).*/\1/p' <<<"$1"; }
echo "sky_vs_healthz=$(echo "$(rps "$warm") / $(rps "$healthz")" | bc -l | cut -c1-5)"

# A new place/time: the first request builds the table and renders and
# encodes the map; the second is served from the byte cache.
"$load" --port "$port" --path "/v1/sky/envmap.exr?lat=35.68&lon=139.69&time=2021-08-01T17:30:00%2B09:00&width=2048" \
  --requests 2
curl -sf "http://127.0.0.1:$port/metrics" | grep -E '^skyfarm_sky_cache_(hits|misses|builds|bytes|entries)' || true

# A day of sun positions on a fresh server: 24 tables, one atmosphere.
"$build/server/skyfarm-server" --listen "127.0.0.1:$((port + 1))" --broker "tcp://127.0.0.1:*" --local-workers 0 \
  --data-dir "$work/data2" >"$work/server2.log" 2>&1 &
for _ in $(seq 100); do curl -sf "http://127.0.0.1:$((port + 1))/healthz" >/dev/null && break; sleep 0.1; done
start=$(date +%s.%N)
for h in $(seq -w 0 23); do
  curl -sf "http://127.0.0.1:$((port + 1))/v1/sky?lat=42.44&lon=-76.48&time=2013-05-27T$h:30:00-04:00&view_zenith=35&view_azimuth=250" >/dev/null
done
echo "http_sweep_24_cold_ms=$(echo "($(date +%s.%N) - $start) * 1000" | bc -l | cut -d. -f1)"
curl -sf "http://127.0.0.1:$((port + 1))/metrics" | grep -E '^skyfarm_sky_cache_(builds|sun_only_builds)_total' || true
"$build/server/skyfarm-sky-sweep" --repeat 3
