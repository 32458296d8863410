#!/usr/bin/env bash
# The project's one test command: the Rust core's unit tests, then the Python test suite.
# --quick: the quick tier only (pytest -m "not slow", a few minutes; docs/testing.md), no Rust.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--quick" ]; then
    shift
    exec python3 -m pytest -q -m "not slow" "$@"
fi
(cd engine && cargo test --quiet)
python3 -m pytest -q "$@"
