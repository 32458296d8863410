#!/usr/bin/env bash
# The project's one test command: the Rust core's unit tests, then the Python test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
(cd engine && cargo test --quiet)
python3 -m pytest -q "$@"
