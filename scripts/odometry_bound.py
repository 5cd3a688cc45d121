#!/usr/bin/python3
"""The odometry's error against the truth over short windows, on rendered drives
(docs/integrity.md 5.1): for every window of 1 to 40 frames, the translation error of the
odometry's step (in the base frame at the window's start) against the distance, and the heading
error against the distance and the camera's turn; the largest ratio to candidate bounds.

  scripts/odometry_bound.py WORK/hall-tour/frames WORK/office-ring/frames ...

Reads priors.csv (t,x,y,heading_deg: the camera heading = odometry base heading + pan),
groundtruth.txt (TUM world_from_cam) and frame_truth.csv (pan_deg). Standard library only.
"""
import csv
import math
import sys

MAX_FRAMES = 40
POSITION_SHARES = (0.08, 0.10, 0.12, 0.15)
HEADING_BOUNDS = [(a, b) for a in (1.0, 2.0, 3.0, 4.0) for b in (0.10, 0.15, 0.30)]


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def rotate(a, v):
    c, s = math.cos(a), math.sin(a)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def camera_heading(q):
    x, y, z, w = q  # the optical axis (third column of R) projected on the floor
    return math.atan2(2 * (y * z - w * x), 2 * (x * z + w * y))


def load(folder):
    priors = list(csv.DictReader(open(folder + "/priors.csv")))
    truth = list(csv.DictReader(open(folder + "/frame_truth.csv")))
    poses = [list(map(float, l.split())) for l in open(folder + "/groundtruth.txt")
             if not l.startswith("#")]
    n = min(len(priors), len(poses), len(truth))
    pan = [math.radians(float(truth[k]["pan_deg"])) for k in range(n)]
    camera_odometry = [math.radians(float(priors[k]["heading_deg"])) for k in range(n)]
    return {
        "base": [camera_heading(poses[k][4:8]) - pan[k] for k in range(n)],
        "base_odometry": [camera_odometry[k] - pan[k] for k in range(n)],
        "camera_odometry": camera_odometry,
        "p": [(poses[k][1], poses[k][2]) for k in range(n)],
        "p_odometry": [(float(priors[k]["x"]), float(priors[k]["y"])) for k in range(n)],
    }


def main(folders):
    worst_position = {s: 0.0 for s in POSITION_SHARES}
    worst_heading = {b: 0.0 for b in HEADING_BOUNDS}
    for folder in folders:
        d = load(folder)
        th, tho, p, po = d["base"], d["base_odometry"], d["p"], d["p_odometry"]
        n = len(p)
        driven, turned = [0.0], [0.0]
        for k in range(1, n):
            driven.append(driven[-1] + math.dist(po[k], po[k - 1]))
            turned.append(turned[-1] + abs(wrap(d["camera_odometry"][k] - d["camera_odometry"][k - 1])))
        for a in range(n):
            for b in range(a + 1, min(n, a + MAX_FRAMES + 1)):
                distance = driven[b] - driven[a]
                turn = math.degrees(turned[b] - turned[a])
                u = rotate(-th[a], (p[b][0] - p[a][0], p[b][1] - p[a][1]))
                uo = rotate(-tho[a], (po[b][0] - po[a][0], po[b][1] - po[a][1]))
                error = math.dist(u, uo)
                heading = math.degrees(abs(wrap((tho[b] - tho[a]) - (th[b] - th[a]))))
                for s in POSITION_SHARES:
                    if distance > 0:
                        worst_position[s] = max(worst_position[s], error / (s * distance))
                for h, t in HEADING_BOUNDS:
                    bound = h * distance + t * turn
                    if bound > 0:
                        worst_heading[(h, t)] = max(worst_heading[(h, t)], heading / bound)
    for s, r in worst_position.items():
        print("translation <= %.2f x distance: largest error / bound %.2f" % (s, r))
    for (h, t), r in worst_heading.items():
        print("heading <= %.1f deg/m x distance + %.2f x turn: largest error / bound %.2f" % (h, t, r))


if __name__ == "__main__":
    main(sys.argv[1:])
