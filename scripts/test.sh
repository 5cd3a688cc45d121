#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite twice: a Release build, then a
# build under AddressSanitizer + UndefinedBehaviorSanitizer. Idempotent. Used by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

# OpenCV's calibration sample images (from Debian's opencv-doc) for the calibration tests; when
# the fetch fails, those tests fail and name the script.
data="$PWD/.cache/test-data"
scripts/fetch_test_data.sh "$data" || echo "test: could not fetch the test data into $data" >&2

# Unity builds (DEVELOPERS.md, "The CI run must stay under 50 minutes").
unity=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16)
scripts/setup.sh build "${unity[@]}" -DLINETRACK_TEST_DATA="$data"
(cd build && ctest --output-on-failure -j "$jobs")

# -O1 with line tables (-g1): what the sanitizers' documentation recommends, with file:line in every
# report's stack trace, at half the compile time of RelWithDebInfo's -O2 -g.
# The fuzzers are left out: they are built with clang's ASan+UBSan in either build, and the Release
# suite has run them.
scripts/setup.sh build-asan "${unity[@]}" -DLINETRACK_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DLINETRACK_BUILD_FUZZERS=OFF \
  -DLINETRACK_TEST_DATA="$data"
# Leaks inside Debian's libraries (ROS, OpenCV, ViSP) are suppressed by library in
# tests/lsan_suppressions.txt (also set per gtest binary by linetrack_add_test).
(cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  LSAN_OPTIONS="suppressions=$PWD/../tests/lsan_suppressions.txt" \
  ctest --output-on-failure -j "$jobs")
echo "test: all suites passed"
