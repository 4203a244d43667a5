#!/usr/bin/env bash
# The house's dependency rules, checked on the sources and on the CMake link
# graph (CTest: House.IncludeRules).
#
#   common  <-  api  <-  server, worker
#
# common (the renderer) includes only common/; api (request types,
# validation, the wire) also common/; server/ and worker/ also api/, never
# each other.  No source includes tests/.  A project include is any
# #include "..." or <...> whose path starts with one of those folders.
#
# Usage: include_rules.sh SOURCE_DIR [TARGET=LINK,LINK,... ...]
#   SOURCE_DIR  the repository root; every .h/.cpp under common/, api/,
#               server/ and worker/ is scanned
#   TARGET=...  a library and its direct link libraries (comma-separated,
#               from $<TARGET_PROPERTY:TARGET,LINK_LIBRARIES>): skyfarm_common
#               may not link skyfarm_api, skyfarm_server or skyfarm_worker,
#               and so on by the same rules
# Prints every offending file:line (or target) and exits 1; 0 when clean.
set -u

src=${1:?usage: include_rules.sh SOURCE_DIR [TARGET=LINKS ...]}
shift
status=0

# What each folder may include besides itself.
declare -A may_use=(
  [common]=""
  [api]="common"
  [server]="api common"
  [worker]="api common"
)

for folder in common api server worker; do
  [[ -d "$src/$folder" ]] || { echo "include_rules: no $src/$folder" >&2; exit 2; }
  allowed="$folder ${may_use[$folder]}"
  offences=$(find "$src/$folder" -type f \( -name '*.h' -o -name '*.cpp' \) -print0 | sort -z |
    xargs -0 -r awk -v folder="$folder" -v allowed="$allowed" -v root="$src/" '
      BEGIN { n = split(allowed, a, " "); for (i = 1; i <= n; ++i) ok[a[i]] = 1 }
      match($0, /^[ \t]*#[ \t]*include[ \t]*["<](common|api|server|worker|tests)\//) {
        line = substr($0, RSTART, RLENGTH)
        sub(/^[ \t]*#[ \t]*include[ \t]*["<]/, "", line)
        sub(/\/$/, "", line)
        if (!(line in ok)) {
          file = FILENAME
          if (index(file, root) == 1) file = substr(file, length(root) + 1)
          printf "%s:%d: %s/ may not include %s/: %s\n", file, FNR, folder, line, $0
        }
      }')
  if [[ -n "$offences" ]]; then
    echo "$offences"
    status=1
  fi
done

# The same rules on the link graph.
declare -A may_link=(
  [skyfarm_common]=""
  [skyfarm_api]="skyfarm_common"
  [skyfarm_server]="skyfarm_api skyfarm_common"
  [skyfarm_worker]="skyfarm_api skyfarm_common"
)
for arg in "$@"; do
  target=${arg%%=*}
  links=${arg#*=}
  [[ -v "may_link[$target]" ]] || { echo "include_rules: no rule for target $target" >&2; exit 2; }
  IFS=',' read -r -a items <<< "$links"
  for item in "${items[@]}"; do
    case "$item" in
      skyfarm_common|skyfarm_api|skyfarm_server|skyfarm_worker)
        if [[ " ${may_link[$target]} " != *" $item "* ]]; then
          echo "CMake: $target may not link $item"
          status=1
        fi ;;
    esac
  done
done

if [[ $status -eq 0 ]]; then echo "include rules: common <- api <- server, worker hold"; fi
exit $status
