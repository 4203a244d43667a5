#!/usr/bin/env bash
# One command for a fresh Debian machine: installs what is missing, builds in
# Release and runs the service: skyfarm-server on http://127.0.0.1:8080 with
# one local worker per core.  It then renders the demo skies THROUGH THE HTTP
# API with curl (a sunset equirect over Ithaca, a noon all-sky fisheye over
# Paris) into ./skyfarm-demo, and keeps serving until Ctrl-C.
#   SKYFARM_LISTEN, SKYFARM_DATA_DIR, ... (see skyfarm-server --help) apply.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build=${SKYFARM_BUILD_DIR:-$root/build}
listen=${SKYFARM_LISTEN:-127.0.0.1:8080}
out=${SKYFARM_DEMO_DIR:-$PWD/skyfarm-demo}
export SKYFARM_DATA_DIR=${SKYFARM_DATA_DIR:-$PWD/skyfarm-data}
mkdir -p "$out"

"$build/server/skyfarm-server" --listen "$listen" &
server=$!
trap 'kill -TERM $server 2>/dev/null; wait $server 2>/dev/null || true' EXIT
for _ in $(seq 100); do
  curl -sf "http://$listen/healthz" >/dev/null && break
  kill -0 $server 2>/dev/null || { echo "skyfarm-server did not start" >&2; exit 1; }
  sleep 0.1
done

for request in "$root"/api/examples/demo_*.json; do
  name=$(basename "$request" .json)
  name=${name#demo_}
  id=$(curl -sf -X POST -H 'Content-Type: application/json' --data-binary @"$request" \
       "http://$listen/v1/renders" | sed -n 's/.*"id":"\([^"]*\)".*/\1/p')
  echo "$name: job $id (http://$listen/v1/renders/$id)"
  while :; do
    status=$(curl -sf "http://$listen/v1/renders/$id")
    state=$(echo "$status" | sed -n 's/.*"state":"\([a-z]*\)".*/\1/p')
    fraction=$(echo "$status" | sed -n 's/.*"fraction":\([0-9.e-]*\).*/\1/p')
    printf '\r  %-8s %5.1f%%' "$state" "$(echo "${fraction:-0} * 100" | bc -l 2>/dev/null || echo 0)"
    case $state in done) break ;; failed|cancelled) echo; echo "$status" >&2; exit 1 ;; esac
    sleep 0.5
  done
  echo
  curl -sf -o "$out/$name.exr" "http://$listen/v1/renders/$id/image.exr"
  curl -sf -o "$out/$name.png" "http://$listen/v1/renders/$id/image.png"
  echo "  wrote $out/$name.exr and $out/$name.png"
done

echo "skyfarm is serving on http://$listen: the web page at http://$listen/, the API under /v1"
echo "(see /v1/openapi.yaml); Ctrl-C to stop."
wait $server
