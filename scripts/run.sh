#!/usr/bin/env bash
# One command for a fresh Debian machine: installs what is missing, builds in
# Release and runs skyfarm's main job on the demo request.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build=${SKYFARM_BUILD_DIR:-$root/build}
# Until the path tracer lands (issue 3) the main job is the physical model of
# the demo sky: sun position and optical depths.
"$build/worker/skyfarm-worker" info "$root/api/examples/sunset_equirect.json"
