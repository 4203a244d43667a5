#!/usr/bin/env bash
# Configures and builds skyfarm in Release into ./build (or $SKYFARM_BUILD_DIR).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${SKYFARM_BUILD_DIR:-$root/build}
jobs=${SKYFARM_JOBS:-$(nproc)}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$jobs"
