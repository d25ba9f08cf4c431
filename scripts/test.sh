#!/usr/bin/env bash
# The test command (README "Run the tests"): every cargo test, then the real Slurm run.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --all-targets
cargo build --release --quiet
scripts/test-slurm.sh
