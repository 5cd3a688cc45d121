#!/usr/bin/env bash
# The main job on the bundled data: installs what is missing, builds, then generates synthetic
# localisation scenes of the bundled hall (the paper's section 4.1) and localises them,
# printing the result table. Idempotent. Output in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build
mkdir -p out/demo
build/app/linetrack model-info models/hall.cao
build/app/linetrack synth --model models/hall.cao --qi 3 --count 100 --out out/demo/qi3
build/app/linetrack localize --batch out/demo/qi3/cases.jsonl > out/demo/qi3/results.jsonl
build/app/linetrack bench match --count 100 --series qi1 qi3 --no-baseline --out out/demo/table.md
