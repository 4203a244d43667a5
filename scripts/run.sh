#!/usr/bin/env bash
# One command for a fresh Debian machine: installs what is missing, builds in
# Release and runs the service: skyfarm-server on http://127.0.0.1:8080 with
# one local worker per core.  It then renders the demo skies THROUGH THE HTTP
# API with the Python client (clients/python, `python3 -m skyfarm render`: a
# sunset equirect over Ithaca, a noon all-sky fisheye over Paris) into
# ./skyfarm-demo, and keeps serving until Ctrl-C.
#   SKYFARM_LISTEN, SKYFARM_DATA_DIR, SKYFARM_TOKEN, ... (see skyfarm-server
#   --help) apply; the client reads SKYFARM_TOKEN too.
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

skyfarm() { PYTHONPATH="$root/clients/python${PYTHONPATH:+:$PYTHONPATH}" python3 -m skyfarm --server "http://$listen" "$@"; }
for request in "$root"/api/examples/demo_*.json; do
  name=$(basename "$request" .json)
  name=${name#demo_}
  echo "$name:"
  skyfarm render "$request" -o "$out/$name.exr" --png "$out/$name.png"
done

echo "skyfarm is serving on http://$listen: the web page at http://$listen/, the API under /v1"
echo "(see /v1/openapi.yaml); Ctrl-C to stop."
wait $server
