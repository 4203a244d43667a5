#!/usr/bin/env bash
# Runs a test's Python script with Debian's python3 and its yaml module
# (python3-yaml), or the first python3 on PATH that has it; exits 77 (skipped)
# if none has.
#   run_python.sh SCRIPT ARGS...
for py in /usr/bin/python3 python3; do
  if command -v "$py" >/dev/null && "$py" -c 'import yaml' 2>/dev/null; then
    exec "$py" "$@"
  fi
done
echo "no python3 with the yaml module here (package python3-yaml)"
exit 77
