#!/usr/bin/env bash
# Deploy.SystemdUnits: the installed units pass `systemd-analyze verify` and
# keep their sandbox (`systemd-analyze security --offline` exposure at most
# MAX_EXPOSURE; "OK" is below 4.0 on its 0-10 scale).
#   systemd_test.sh BUILD_DIR
# Exits 77 (skipped) where systemd-analyze is missing.
set -euo pipefail
MAX_EXPOSURE=2.5
build_dir=$(cd "$1" && pwd)
command -v systemd-analyze >/dev/null || { echo "Deploy.SystemdUnits: no systemd-analyze here (package systemd)"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "Deploy.SystemdUnits: $*" >&2; exit 1; }

# Installed, so that ExecStart= names programs that exist.
cmake --install "$build_dir" --prefix "$tmp/prefix" >/dev/null
units=$tmp/prefix/lib/systemd/system
# An instance of the template, as `systemctl start skyfarm-worker@1` makes.
cp "$units/skyfarm-worker@.service" "$units/skyfarm-worker@1.service"
for unit in skyfarm-server.service skyfarm-worker@1.service; do
  out=$(systemd-analyze verify "$units/$unit" 2>&1) || fail "verify $unit: $out"
  # verify prints warnings and still exits 0; none is expected.
  [[ -z $out ]] || fail "verify $unit: $out"
  level=$(systemd-analyze security --offline=yes "$units/$unit" 2>&1 | sed -n 's/.*Overall exposure level for .*: \([0-9.]*\).*/\1/p')
  [[ -n $level ]] || fail "systemd-analyze security gave no exposure level for $unit"
  awk -v l="$level" -v m="$MAX_EXPOSURE" 'BEGIN {exit !(l <= m)}' ||
    fail "$unit: exposure $level > $MAX_EXPOSURE (systemd-analyze security --offline=yes shows why)"
  echo "Deploy.SystemdUnits: $unit verified, exposure $level"
done
