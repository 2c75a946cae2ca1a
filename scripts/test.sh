#!/usr/bin/env bash
# Runs igi's test suite (unit, real-data and end-to-end tests) with ctest. Tests labelled
# "slow" run only when IGI_SLOW=1. Exits non-zero when any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
args=(--test-dir build --output-on-failure -j "$(nproc)")
if [ "${IGI_SLOW:-0}" != "1" ]; then args+=(-LE slow); fi
ctest "${args[@]}" "$@"
