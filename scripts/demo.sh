#!/usr/bin/env bash
# The main job on the bundled data: installs what is missing, builds, then generates synthetic
# localisation scenes of the bundled hall (the paper's section 4.1) and localises them,
# printing the result table. Idempotent. Output in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16
mkdir -p out/demo
build/app/linetrack model-info models/hall.cao
build/app/linetrack synth --model models/hall.cao --qi 3 --count 100 --out out/demo/qi3
build/app/linetrack localize --batch out/demo/qi3/cases.jsonl > out/demo/qi3/results.jsonl
build/app/linetrack bench match --count 100 --series qi1 qi3 --no-baseline --out out/demo/table.md
# From an image: a rendered view of the hall, its line segments, and the pose with an overlay.
# One image of this view gives a protection level of about 0.12 m: the alert limit is widened
# from the robot's default 0.10 m, so that the pose is reported (its levels are printed).
build/app/linetrack render --model models/hall.cao --camera tests/data/camera_paper.xml --pose 2.0,2.0,30 --height 1.3 --tilt 5 --clutter 10 --out out/demo/view.png
build/app/linetrack lines out/demo/view.png --camera tests/data/camera_paper.xml --out out/demo/view_lines.csv
build/app/linetrack localize --model models/hall.cao --camera tests/data/camera_paper.xml --image out/demo/view.png --prior 2.4,1.7,40 --delta-t 0.75 --delta-phi 20 --height 1.3 --tilt 5 --focal-error 0.005 --alert-limit 0.15,2 --overlay out/demo/localize_image.png
# Tracking: a rendered drive through the hall (odometry priors that drift), replayed from them:
# the matcher finds the first pose, the moving edges follow, losses are recovered.
build/app/linetrack render --model models/hall.cao --camera tests/data/camera_wide.xml --path hall-loop --nav tests/data/hall.nav.json --frames 120 --clutter 10 --out out/demo/drive
build/app/linetrack replay --input 'out/demo/drive/frame_%05d.png' --model models/hall.cao --camera out/demo/drive/camera.xml --prior-file out/demo/drive/priors.csv --ground-truth out/demo/drive/groundtruth.txt --out out/demo/replay
