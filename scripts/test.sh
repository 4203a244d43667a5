#!/usr/bin/env bash
# One command for a fresh Debian machine: installs what is missing, builds in
# Release and runs every test (CTest, all registered via gtest_discover_tests).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# --browser: the web page's test drives headless Chromium; --dcc: Blender
# renders a sky as its World (tests/dcc).
"$root/scripts/install-deps.sh" --browser --dcc
"$root/scripts/build.sh"
build=${SKYFARM_BUILD_DIR:-$root/build}
cd "$build"
ctest --output-on-failure -j "${SKYFARM_JOBS:-$(nproc)}" --timeout 600
