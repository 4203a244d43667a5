#!/bin/sh
# The image's entry point: runs its arguments (skyfarm-server or
# skyfarm-worker and their flags; flags alone go to skyfarm-server) after
# turning secrets given as files into the variables the programs read:
#   SKYFARM_TOKEN_FILE   a file holding the HTTP bearer token, exported as
#                        SKYFARM_TOKEN.  Compose and swarm hand secrets over as
#                        files under /run/secrets; --token would put the token
#                        in argv, which every process of the host can read.
# The workers' secret needs no help: --worker-secret-file / --secret-file read
# the file themselves.
set -eu
if [ -n "${SKYFARM_TOKEN_FILE:-}" ]; then
  if [ ! -r "$SKYFARM_TOKEN_FILE" ]; then
    echo "skyfarm-entrypoint: SKYFARM_TOKEN_FILE: cannot read '$SKYFARM_TOKEN_FILE'" >&2
    exit 2
  fi
  SKYFARM_TOKEN=$(cat "$SKYFARM_TOKEN_FILE")  # $(...) drops the trailing newline
  export SKYFARM_TOKEN
  unset SKYFARM_TOKEN_FILE
fi
case "${1:-}" in
  "") set -- skyfarm-server ;;
  -*) set -- skyfarm-server "$@" ;;
esac
exec "$@"
