#!/usr/bin/env bash
# The project's one test command: the Rust core's unit tests, then the Python test suite.
# --quick: the quick tier only (pytest -m "not slow", a few minutes; docs/testing.md), no Rust.
# pytest runs one worker per core (pytest-xdist), each test file on one worker so that its
# module fixtures are built once; SPLL_HW_TEST_WORKERS=0 runs it in this process.
set -euo pipefail
cd "$(dirname "$0")/.."
WORKERS=(-n "${SPLL_HW_TEST_WORKERS:-auto}" --dist loadfile)
if [ "${1:-}" = "--quick" ]; then
    shift
    exec python3 -m pytest -q "${WORKERS[@]}" -m "not slow" "$@"
fi
(cd engine && cargo test --quiet)
python3 -m pytest -q "${WORKERS[@]}" "$@"
