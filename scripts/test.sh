#!/usr/bin/env bash
# The test command (README "Run the tests"): formatting and lints, every cargo test, the
# comparison with POV-Ray, then the real Slurm run.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
cargo test --workspace --all-targets
cargo build --release --quiet
scripts/compare-pov.sh
scripts/test-slurm.sh
