#!/usr/bin/env bash
# Runs every libFuzzer target of the build (tests/fuzz/) for 1 M runs (or RUNS), each over its
# corpus and seed files, with a fixed seed. Usage: scripts/fuzz.sh [BUILD_DIR [RUNS]]
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
runs=${2:-1000000}
fuzz_dir="$build_dir/tests/fuzz"
declare -A seeds=(
  [cao_fuzzer]="tests/data/cao_malformed models"
  [import_fuzzer]="tests/data/import_seeds"
  [camera_fuzzer]="tests/data/camera_seeds"
  [trajectory_fuzzer]="tests/data/trajectory_seeds"
  [pose_file_fuzzer]="tests/data/pose_seeds"
  [angles_fuzzer]="tests/data/angles_seeds"
  [batch_fuzzer]="tests/data/batch_seeds"
  [lines_fuzzer]="tests/data/lines_seeds"
)
for name in "${!seeds[@]}"; do
  fuzzer="$fuzz_dir/$name"
  if [[ ! -x "$fuzzer" ]]; then
    echo "fuzz: $fuzzer is not built (clang++ missing? build the target ${name}_build)" >&2
    exit 2
  fi
  corpus="$fuzz_dir/corpus/${name%_fuzzer}"
  mkdir -p "$corpus"
  echo "fuzz: $name, $runs runs" >&2
  # shellcheck disable=SC2086
  ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=tests/lsan_suppressions.txt "$fuzzer" -seed=1 -runs="$runs" -max_len=2048 -timeout=10 \
    "$corpus" ${seeds[$name]}
done
