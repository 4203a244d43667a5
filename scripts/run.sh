#!/usr/bin/env bash
# One command for a fresh Debian machine: installs what is missing, builds in
# Release and runs skyfarm's main job: the demo skies rendered to EXR and PNG
# (a sunset over Ithaca as an equirectangular map, a noon all-sky fisheye over
# Paris) in ./skyfarm-demo, after a report of the sunset's sun and optical depths.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build=${SKYFARM_BUILD_DIR:-$root/build}
out=${SKYFARM_DEMO_DIR:-$PWD/skyfarm-demo}
"$build/worker/skyfarm-worker" info "$root/api/examples/sunset_equirect.json"
echo
"$build/worker/skyfarm-worker" demo "$out"
echo
echo "demo skies in $out:"
ls -l "$out"
