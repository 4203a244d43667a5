#!/usr/bin/env bash
# The farm across hosts: a server and three workers, each in its own network
# namespace, joined by veth pairs to a bridge in a fourth (the "switch").  The
# workers authenticate with CURVE keys derived from a shared secret; one
# worker's link is cut in the middle of the job.  The job must finish with an
# EXR byte-identical to `skyfarm-worker render` of the same request, and the
# traffic seen on the switch must not carry the request in clear text.
#
#   multi_host_netns.sh SKYFARM_SERVER SKYFARM_WORKER
#
# Needs root (ip netns) and tcpdump; exits 77 (CTest: skipped) without root.
# Addresses are in 10.201.0.0/24 inside namespaces this script creates and
# removes: nothing leaves the machine.
set -euo pipefail
server_bin=$(realpath "$1")
worker_bin=$(realpath "$2")

if [[ $(id -u) -ne 0 ]]; then
  echo "multi_host_netns: needs root for ip netns; skipped"
  exit 77
fi
for tool in ip tcpdump curl cmp; do
  command -v "$tool" >/dev/null || { echo "multi_host_netns: $tool is missing (scripts/install-deps.sh)"; exit 1; }
done

tag=sf$(($$ % 100000))
hosts=(srv w1 w2 w3)
declare -A addr=([srv]=10.201.0.1 [w1]=10.201.0.11 [w2]=10.201.0.12 [w3]=10.201.0.13)
work=$(mktemp -d)
pids=()

cleanup() {
  local rc=$?
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  sleep 0.3
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  # A pid above is the subshell of in_ns, not always the program it runs:
  # whatever still runs in a namespace goes with it.
  for h in "${hosts[@]}" hub; do
    ip netns pids "$tag$h" 2>/dev/null | xargs -r kill -9 2>/dev/null || true
    ip netns del "$tag$h" 2>/dev/null || true
  done
  if [[ $rc -ne 0 ]]; then
    for f in "$work"/*.log; do [[ -f $f ]] && { echo "--- $f"; tail -n 30 "$f"; }; done
  fi
  rm -rf "$work"
  exit $rc
}
trap cleanup EXIT

in_ns() { local ns=$1; shift; ip netns exec "$tag$ns" "$@"; }

# --- The network: a bridge in the hub namespace, one veth pair per host.
ip netns add "${tag}hub"
in_ns hub ip link set lo up
in_ns hub ip link add br0 type bridge
in_ns hub ip link set br0 up
for h in "${hosts[@]}"; do
  ip netns add "$tag$h"
  in_ns "$h" ip link set lo up
  ip link add "v$tag$h" type veth peer name "p$tag$h"
  ip link set "v$tag$h" netns "$tag$h"
  ip link set "p$tag$h" netns "${tag}hub"
  in_ns "$h" ip link set "v$tag$h" name eth0
  in_ns "$h" ip addr add "${addr[$h]}/24" dev eth0
  in_ns "$h" ip link set eth0 up
  in_ns hub ip link set "p$tag$h" master br0
  in_ns hub ip link set "p$tag$h" up
done

# --- The request, and its local reference render (in the root namespace).
cat >"$work/request.json" <<'EOF'
{
  "sun": {"zenith_deg": 62, "azimuth_deg": 140},
  "camera": {"projection": "equirectangular", "width": 96, "height": 48},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 128},
  "output": {"half": false},
  "seed": 23
}
EOF
"$worker_bin" render "$work/request.json" -o "$work/local.exr" --threads 2 >"$work/local.log" 2>&1

# --- Secrets: the worker credential and the HTTP token are separate.
head -c 32 /dev/urandom | base64 >"$work/worker.secret"
chmod 600 "$work/worker.secret"
token=$(head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n')

# Everything the switch sees on the broker's port.
in_ns hub tcpdump -i br0 -U -w "$work/broker.pcap" tcp port 5555 >"$work/tcpdump.log" 2>&1 &
pids+=($!)

in_ns srv "$server_bin" --listen "${addr[srv]}:8080" --broker "tcp://${addr[srv]}:5555" --token "$token" \
  --worker-secret-file "$work/worker.secret" --local-workers 0 --data-dir "$work/data" --unit-timeout 10 \
  >"$work/server.log" 2>&1 &
pids+=($!)
api() { in_ns srv curl -sS --max-time 10 -H "Authorization: Bearer $token" "$@"; }
for _ in $(seq 100); do
  in_ns srv curl -sf "http://${addr[srv]}:8080/healthz" >/dev/null 2>&1 && break
  sleep 0.1
done
for h in w1 w2 w3; do
  in_ns "$h" "$worker_bin" --connect "tcp://${addr[srv]}:5555" --secret-file "$work/worker.secret" \
    --threads 1 --slots 1 --id "$h" >"$work/$h.log" 2>&1 &
  pids+=($!)
done
for _ in $(seq 100); do
  [[ $(api "http://${addr[srv]}:8080/v1/workers" | grep -o '"id"' | wc -l) -ge 3 ]] && break
  sleep 0.1
done
workers=$(api "http://${addr[srv]}:8080/v1/workers" | grep -o '"id"' | wc -l)
[[ $workers -eq 3 ]] || { echo "multi_host_netns: $workers of 3 workers joined"; exit 1; }

id=$(api -X POST -H 'Content-Type: application/json' --data @"$work/request.json" \
  "http://${addr[srv]}:8080/v1/renders" | sed -n 's/.*"id": *"\([^"]*\)".*/\1/p')
[[ -n $id ]] || { echo "multi_host_netns: the render was not accepted"; exit 1; }

status() { api "http://${addr[srv]}:8080/v1/renders/$id"; }
state() { status | sed -n 's/.*"state": *"\([^"]*\)".*/\1/p' | head -n 1; }
fraction() { status | sed -n 's/.*"fraction": *\([0-9.e+-]*\).*/\1/p' | head -n 1; }

# Cut w2's link once the job is under way (and w2 has units).
cut=no
for _ in $(seq 600); do
  f=$(fraction)
  if [[ -n $f ]] && awk "BEGIN{exit !($f >= 0.2)}"; then
    in_ns hub ip link set "p${tag}w2" down
    cut=yes
    break
  fi
  [[ $(state) == done ]] && break
  sleep 0.05
done
[[ $cut == yes ]] || { echo "multi_host_netns: the job ended before the link could be cut"; exit 1; }
echo "multi_host_netns: cut w2's link at fraction $f"

for _ in $(seq 1200); do
  s=$(state)
  [[ $s == done || $s == failed || $s == cancelled ]] && break
  sleep 0.1
done
[[ $s == done ]] || { echo "multi_host_netns: the job ended '$s'"; status; exit 1; }

api -o "$work/farm.exr" "http://${addr[srv]}:8080/v1/renders/$id/image.exr"
cmp "$work/local.exr" "$work/farm.exr" || { echo "multi_host_netns: the farm's EXR differs from the local render"; exit 1; }
grep -q "w2" <<<"$(status)" || { echo "multi_host_netns: w2 never rendered a unit before its link was cut"; exit 1; }

# Encrypted: the unit messages carried the request (its projection's name), so
# it must not appear in clear text in what the switch saw.
kill "${pids[0]}" 2>/dev/null || true
wait "${pids[0]}" 2>/dev/null || true
bytes=$(stat -c %s "$work/broker.pcap")
[[ $bytes -gt 20000 ]] || { echo "multi_host_netns: only $bytes bytes captured on the broker port"; exit 1; }
if grep -a -q equirectangular "$work/broker.pcap"; then
  echo "multi_host_netns: the request travelled in clear text"
  exit 1
fi
echo "multi_host_netns: 3 hosts, one cut mid-job: identical bytes, $bytes bytes captured, none in clear"
