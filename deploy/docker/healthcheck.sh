#!/bin/bash
# The image's HEALTHCHECK: 0 when GET /healthz on the server's HTTP port
# answers 200 within 4 s.  The port is SKYFARM_HEALTH_PORT, else the one of
# SKYFARM_LISTEN, else 8080 (give SKYFARM_HEALTH_PORT when --listen names
# another port).  A container that runs skyfarm-worker and no skyfarm-server
# is healthy while the worker runs: a worker has no HTTP port, and it
# reconnects by itself.  bash's /dev/tcp, so the image needs no HTTP client.
set -u
server=0 worker=0
for comm in /proc/[0-9]*/comm; do
  read -r name 2>/dev/null <"$comm" || continue
  case $name in
    skyfarm-server) server=1 ;;
    skyfarm-worker) worker=1 ;;
  esac
done
if ((!server)); then exit $((worker ? 0 : 1)); fi
listen=${SKYFARM_LISTEN:-}
port=${SKYFARM_HEALTH_PORT:-${listen##*:}}
port=${port:-8080}
# shellcheck disable=SC2016  # expanded by the inner bash
exec timeout 4 bash -c '
  exec 3<>"/dev/tcp/127.0.0.1/$1" || exit 1
  printf "GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n" >&3
  IFS= read -r status <&3 || exit 1
  [[ $status == "HTTP/1."?" 200 "* ]]' healthcheck "$port"
