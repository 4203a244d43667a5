#!/usr/bin/env bash
# Deploy.DebPackage: `cpack -G DEB` makes skyfarm_<version>_<arch>.deb with
# exactly the expected files under /usr, units that run /usr/bin/skyfarm-*,
# and a Depends: line naming the runtime libraries.
#   deb_test.sh BUILD_DIR
# The install step is `cmake --install --strip` into a staging directory that
# cpack then packs, rather than cpack's own install: that one first builds
# every target of the build tree (its preinstall step), which is not this
# test's business and takes minutes on a tree built only in part.
set -euo pipefail
build_dir=$(cd "$1" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "Deploy.DebPackage: $*" >&2; exit 1; }

DESTDIR=$tmp/stage cmake --install "$build_dir" --prefix /usr --strip >/dev/null
cpack -G DEB --config "$build_dir/CPackConfig.cmake" -B "$tmp/out" \
      -D CPACK_INSTALL_CMAKE_PROJECTS= -D "CPACK_INSTALLED_DIRECTORIES=$tmp/stage;." >"$tmp/cpack.log" 2>&1 ||
  { cat "$tmp/cpack.log" >&2; fail "cpack failed"; }
debs=("$tmp"/out/skyfarm_*.deb)
[[ ${#debs[@]} -eq 1 && -f ${debs[0]} ]] || fail "no skyfarm_*.deb in $tmp/out"
deb=${debs[0]}

expected="./usr/bin/skyfarm-server
./usr/bin/skyfarm-worker
./usr/lib/systemd/system/skyfarm-server.service
./usr/lib/systemd/system/skyfarm-worker@.service
./usr/share/doc/skyfarm/DEPLOY.md
./usr/share/doc/skyfarm/README.md
./usr/share/doc/skyfarm/skyfarm.env.example"
actual=$(dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print $6}' | sort)
if [[ $actual != "$expected" ]]; then
  diff <(echo "$expected") <(echo "$actual") >&2 || true
  fail "the package's files differ from the expected list (- expected, + packed)"
fi
dpkg-deb -c "$deb" | awk '$6 ~ /bin\/skyfarm-/ && $1 != "-rwxr-xr-x" {exit 1}' || fail "a program is not mode 0755"
dpkg-deb -c "$deb" | awk '$2 != "root/root" {exit 1}' || fail "a file is not owned by root/root"

[[ $(dpkg-deb -f "$deb" Package) == skyfarm ]] || fail "Package: is not skyfarm"
depends=$(dpkg-deb -f "$deb" Depends)
for lib in libzmq5 libopenexr- libcpp-httplib libsqlite3-0 libpng16-16 libstdc++6; do
  [[ $depends == *"$lib"* ]] || fail "Depends: lacks $lib: $depends"
done

dpkg-deb -x "$deb" "$tmp/x"
grep -qx "ExecStart=/usr/bin/skyfarm-server" "$tmp/x/usr/lib/systemd/system/skyfarm-server.service" ||
  fail "the packed skyfarm-server.service does not run /usr/bin/skyfarm-server"
grep -q "^ExecStart=/usr/bin/skyfarm-worker " "$tmp/x/usr/lib/systemd/system/skyfarm-worker@.service" ||
  fail "the packed skyfarm-worker@.service does not run /usr/bin/skyfarm-worker"
"$tmp/x/usr/bin/skyfarm-worker" --version >/dev/null || fail "the packed skyfarm-worker does not run"
echo "Deploy.DebPackage: $(basename "$deb"), Depends: $depends"
