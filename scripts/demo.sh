#!/usr/bin/env bash
# The main job on the bundled data: installs what is missing, builds, then generates synthetic
# localisation scenes of the bundled hall (the paper's section 4.1) and localises them,
# printing the result table; localises a rendered image and replays a rendered drive
# (scripts/demo_steps.sh). Idempotent. Output in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16
scripts/demo_steps.sh build/app/linetrack out/demo
