#!/usr/bin/env bash
# Deploy.YamlLint: yamllint, with tests/deploy/yamllint.yaml's rules, on every
# YAML file git knows of plus those not committed yet.
#   yamllint_test.sh SOURCE_DIR
# Exits 77 (skipped) where yamllint is missing (package yamllint).
set -euo pipefail
cd "$1"
command -v yamllint >/dev/null || { echo "Deploy.YamlLint: no yamllint here (package yamllint)"; exit 77; }
mapfile -t files < <(git ls-files --cached --others --exclude-standard -- '*.yaml' '*.yml' 2>/dev/null ||
                     find . -name build -prune -o \( -name '*.yaml' -o -name '*.yml' \) -print)
((${#files[@]})) || { echo "Deploy.YamlLint: no YAML file found" >&2; exit 1; }
yamllint --strict -c tests/deploy/yamllint.yaml "${files[@]}"
echo "Deploy.YamlLint: ${#files[@]} files clean"
