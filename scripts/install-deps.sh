#!/usr/bin/env bash
# Installs the Debian packages skyfarm builds and runs with, when missing.
# Safe to run again: it only calls apt-get when something is not installed.
#   --browser   also headless Chromium and its WebDriver (chromium,
#               chromium-driver) for the web page's test (scripts/test.sh)
#   --dcc       also Blender, for the test that loads a sky as Blender's World
#               and renders with Cycles (tests/dcc, scripts/blender)
set -euo pipefail

packages=(
  build-essential cmake pkg-config curl bc
  libopenexr-dev libimath-dev libglm-dev nlohmann-json3-dev libpng-dev
  libcpp-httplib-dev libzmq3-dev cppzmq-dev libsodium-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libembree-dev               # the BVH over the scene's triangles (common/accel)
  libassimp-dev               # mesh assets' import (common/assets/mesh_import.h)
  libopencolorio-dev          # colour spaces and filmic views of the images (common/image/color_management.h)
  libopenvdb-dev              # cloud volumes' import (common/assets/vdb_import.h); its headers
  libboost-dev libboost-iostreams-dev  # and CMake module need Boost, which it does not pull in
  ffmpeg
  file                        # cpack -G DEB finds the programs' libraries with it
  yamllint python3-yaml       # the deployment files' tests (tests/deploy)
  python3                     # the Python client (clients/python): scripts/run.sh, its test Client.Python
  libjson-validator-perl      # the OpenAPI document's lint (tests/api/openapi_lint.pl)
  tcpdump iproute2            # the multi-host test (tests/farm/multi_host_netns.sh)
)
for arg in "$@"; do
  case $arg in
    --browser) packages+=(chromium chromium-driver) ;;
    --dcc) packages+=(blender) ;;
    *) echo "install-deps.sh: unknown option $arg (known: --browser, --dcc)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "skyfarm: installing ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
