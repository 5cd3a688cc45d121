#!/usr/bin/env python3
"""Why observable frames of a drive replay are not `tracking` (docs/tracking.md).

Usage: availability_breakdown.py WORK [DRIVE ...] [--alt LABEL=WORK2 ...]

WORK is a `linetrack bench drive --work` folder (WORK/DRIVE/frames/frame_truth.csv and
WORK/DRIVE/replay/frames.csv). Each observable frame that is not `tracking` is put in one class,
read from frames.csv (status, source, note):
- no pose: `lost` (the tracker, the matcher and the global mode have nothing);
- coasted: the odometry carries the last pose (source `odometry`), `degraded` because the image
  does not show that pose, or because the grown levels exceed the alert limit;
- an image pose `degraded`: a re-localisation under confirmation, an exclusion's levels, a
  critical edge (no other edge checks it: infinite level), the position level set by one edge's
  fault or by the fault-free bound, the rotation level alone, other.
With --alt, each image pose degraded by its protection levels in WORK is also looked up in the
same drive replayed with one allowance changed (e.g. casing=W-casing0, calibration=W-camera0): the
count of those that are `tracking` there is the share of frames that allowance keeps out.
"""
import csv
import os
import sys
from collections import Counter, OrderedDict

CLASSES = OrderedDict([
    ("lost", "no pose (`lost`)"),
    ("coast_image", "coasted, levels within the limit, the image does not confirm the pose"),
    ("coast_levels", "coasted, levels beyond the alert limit"),
    ("confirming", "image pose, re-localisation under confirmation"),
    ("exclusion", "image pose, levels after an exclusion"),
    ("critical", "image pose, a critical edge (infinite level)"),
    ("edge_fault", "image pose, position level set by one edge's fault"),
    ("fault_free", "image pose, position level fault-free"),
    ("rotation", "image pose, rotation level only"),
    ("other", "image pose, other"),
])
LEVEL_CLASSES = ("critical", "edge_fault", "fault_free", "rotation")
ALERT_M, ALERT_DEG = 0.10, 2.0  # the default alert limit (`--alert-limit 0.10,2`)


def classify(row):
    note, status, source = row["note"], row["status"], row["source"]
    if status == "lost":
        return "lost"
    if source == "odometry":
        level_m = float(row["protection_level_m"] or "inf")
        level_deg = float(row["protection_level_deg"] or "inf")
        if "does not show the pose" in note or (level_m <= ALERT_M and level_deg <= ALERT_DEG):
            return "coast_image"
        return "coast_levels"
    if "being confirmed" in note or "beyond both levels" in note:
        return "confirming"
    if "excluded" in note:
        return "exclusion"
    if "a fault of one edge would go unnoticed" in note:
        return "critical"
    if "position protection" in note:
        return "edge_fault" if "(an edge fault" in note else "fault_free"
    if "rotation protection" in note:
        return "rotation"
    return "other"


def read_drive(work, drive):
    truth = {}
    with open(os.path.join(work, drive, "frames", "frame_truth.csv")) as f:
        for r in csv.DictReader(f):
            truth[int(r["frame"])] = r["observable"] == "1"
    with open(os.path.join(work, drive, "replay", "frames.csv")) as f:
        rows = {int(r["frame"]): r for r in csv.DictReader(f)}
    return truth, rows


def breakdown(work, drive, alts):
    truth, rows = read_drive(work, drive)
    observable = [k for k, v in truth.items() if v and k in rows]
    counts = Counter()
    level_frames = []
    for k in observable:
        r = rows[k]
        if r["status"] == "tracking":
            counts["tracking"] += 1
            continue
        c = classify(r)
        counts[c] += 1
        if c in LEVEL_CLASSES:
            level_frames.append(k)
    freed = OrderedDict()
    for label, alt_work in alts:
        _, alt_rows = read_drive(alt_work, drive)
        freed[label] = sum(1 for k in level_frames
                           if k in alt_rows and alt_rows[k]["status"] == "tracking")
    return len(observable), counts, len(level_frames), freed


def main(argv):
    alts, rest = [], []
    i = 0
    while i < len(argv):
        if argv[i] == "--alt":
            label, path = argv[i + 1].split("=", 1)
            alts.append((label, path))
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    if not rest:
        print(__doc__)
        return 2
    work, drives = rest[0], rest[1:]
    if not drives:
        drives = sorted(d for d in os.listdir(work)
                        if os.path.exists(os.path.join(work, d, "replay", "frames.csv")))
    results = [breakdown(work, d, alts) for d in drives]
    print("| observable frames | " + " | ".join(drives) + " |")
    print("| --- |" + " --- |" * len(drives))

    def row(label, values):
        print("| " + label + " | " + " | ".join(values) + " |")

    row("observable", [str(n) for n, _, _, _ in results])
    row("`tracking`", ["%d (%.1f %%)" % (c["tracking"], 100.0 * c["tracking"] / n)
                       for n, c, _, _ in results])
    for key, label in CLASSES.items():
        row(label, ["%d (%.1f %%)" % (c[key], 100.0 * c[key] / n) for n, c, _, _ in results])
    for label, _ in alts:
        row("... of the level classes, `tracking` with the %s allowance changed" % label,
            ["%d of %d" % (f[label], m) for _, _, m, f in results])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
