#!/usr/bin/env bash
# Runs the fuzz harness of tests/hostile/fuzz.rs (SDF reader and RON spec reader) in release mode.
#
#   scripts/fuzz.sh [--execs N] [--seed S] [--corpus DIR] [--timeout-ms MS] [--out DIR]
#   scripts/fuzz.sh --http [--requests N] [--seed S]   (the preview's HTTP surface:
#                                                        tests/preview/fuzz.rs, 300 000 requests,
#                                                        the test profile: optimized)
#
# Defaults: 10 000 000 executions, seed 1, corpus ../shared/corpus (relative to the
# repository), 2000 ms per input, findings in target/fuzz-findings. Runs at low priority
# (nice 10): the machine is shared. Exit status 0 only for a run with no crash and no hang.
set -euo pipefail
cd "$(dirname "$0")/.."

execs=10000000
seed=1
corpus=../shared/corpus
timeout_ms=2000
out=target/fuzz-findings
http=
requests=300000
while [ $# -gt 0 ]; do
    case "$1" in
        --execs) execs=$2; shift 2 ;;
        --seed) seed=$2; shift 2 ;;
        --corpus) corpus=$2; shift 2 ;;
        --timeout-ms) timeout_ms=$2; shift 2 ;;
        --out) out=$2; shift 2 ;;
        --http) http=1; shift ;;
        --requests) requests=$2; shift 2 ;;
        -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
        *) echo "fuzz.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done

if [ -n "$http" ]; then
    HTTP_FUZZ_REQUESTS=$requests HTTP_FUZZ_SEED=$seed \
        exec nice -n 10 cargo test --test preview -- --ignored --exact fuzz::http_fuzz --nocapture
fi

# Relative paths are taken from the repository root, where cargo runs the test.
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }

FUZZ_EXECS=$execs FUZZ_SEED=$seed FUZZ_CORPUS=$(abs "$corpus") \
FUZZ_TIMEOUT_MS=$timeout_ms FUZZ_OUT=$(abs "$out") \
    nice -n 10 cargo test --release --test hostile -- --ignored --exact fuzz::fuzz --nocapture
