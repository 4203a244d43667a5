#!/usr/bin/env bash
# Deploy.Install: `cmake --install` into a fresh prefix gives programs that run
# from there, without the source or build tree.
#   install_test.sh SOURCE_DIR BUILD_DIR
# Checks: the installed files (programs, units with ExecStart= in the prefix,
# docs); both programs' --help; with the source and build trees hidden (a
# private mount namespace where unshare(1) may make one, else only a foreign
# working directory): skyfarm-worker renders a 16x16 sky to EXR and PNG, and
# skyfarm-server, started from the prefix, runs the installed worker as its
# local worker and renders the same request through its HTTP API.
set -euo pipefail
source_dir=$(cd "$1" && pwd)
build_dir=$(cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix

cmake --install "$build_dir" --prefix "$prefix" >/dev/null

fail() { echo "Deploy.Install: $*" >&2; exit 1; }
for f in bin/skyfarm-server bin/skyfarm-worker; do
  [[ -x $prefix/$f ]] || fail "$f is not installed (or not executable)"
done
for f in lib/systemd/system/skyfarm-server.service lib/systemd/system/skyfarm-worker@.service \
         share/doc/skyfarm/skyfarm.env.example share/doc/skyfarm/DEPLOY.md share/doc/skyfarm/README.md; do
  [[ -f $prefix/$f ]] || fail "$f is not installed"
done
grep -qx "ExecStart=$prefix/bin/skyfarm-server" "$prefix/lib/systemd/system/skyfarm-server.service" ||
  fail "skyfarm-server.service: ExecStart= does not name $prefix/bin/skyfarm-server"
grep -q "^ExecStart=$prefix/bin/skyfarm-worker " "$prefix/lib/systemd/system/skyfarm-worker@.service" ||
  fail "skyfarm-worker@.service: ExecStart= does not name $prefix/bin/skyfarm-worker"

"$prefix/bin/skyfarm-server" --help | grep -q "usage: skyfarm-server" || fail "skyfarm-server --help"
"$prefix/bin/skyfarm-worker" --help | grep -q "usage: skyfarm-worker" || fail "skyfarm-worker --help"

mkdir -p "$tmp/run"
cp "$here/installed_run.py" "$tmp/run/"
python=python3
[[ -x /usr/bin/python3 ]] && python=/usr/bin/python3
run=("$python" "$tmp/run/installed_run.py" "$prefix" "$tmp/run")
cd "$tmp/run"
# Hide the trees under empty tmpfs mounts if a user namespace is allowed here.
hide="mount -t tmpfs none '$build_dir' && mount -t tmpfs none '$source_dir' && cd '$tmp/run'"
if unshare --map-root-user --mount true 2>/dev/null; then
  echo "Deploy.Install: running from $prefix with $source_dir and $build_dir hidden"
  unshare --map-root-user --mount bash -c "$hide && exec \"\$@\"" hide "${run[@]}" "$source_dir" "$build_dir"
else
  echo "Deploy.Install: unshare not permitted here; running from $prefix without hiding the trees"
  "${run[@]}"
fi
