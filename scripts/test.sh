#!/usr/bin/env bash
# The test command (README "Run the tests"): every cargo test, the comparison with POV-Ray,
# then the real Slurm run.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --all-targets
cargo build --release --quiet
scripts/compare-pov.sh
scripts/test-slurm.sh
