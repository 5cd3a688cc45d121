#!/usr/bin/env python3
"""Errors of tracked camera poses against the truth: two TUM files (t x y z qx qy qz qw,
world_from_cam), e.g. a simulated `linetrack live` run's poses.txt and truth.txt. Poses are paired
by time (within 1 ms); prints the count, and the median, 95th percentile and largest position
(cm) and rotation (deg) errors. Python's standard library only.

Usage: python3 scripts/pose_errors.py OUT/poses.txt OUT/truth.txt
"""
import math
import sys


def read_tum(path):
    poses = {}
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            t, x, y, z, qx, qy, qz, qw = map(float, fields)
            poses[round(t, 3)] = ((x, y, z), (qw, qx, qy, qz))
    return poses


def angle_between(a, b):
    dot = abs(sum(p * q for p, q in zip(a, b)))
    return math.degrees(2.0 * math.acos(min(1.0, dot)))


def quantile(values, q):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    poses, truth = read_tum(sys.argv[1]), read_tum(sys.argv[2])
    position, rotation = [], []
    for t, (centre, q) in poses.items():
        if t not in truth:
            continue
        true_centre, true_q = truth[t]
        position.append(100.0 * math.dist(centre, true_centre))
        rotation.append(angle_between(q, true_q))
    if not position:
        sys.exit("no pose has a truth at its time")
    print(f"{len(position)} poses; position cm: median {quantile(position, 0.5):.2f}, "
          f"95 % {quantile(position, 0.95):.2f}, max {max(position):.2f}; rotation deg: median "
          f"{quantile(rotation, 0.5):.3f}, 95 % {quantile(rotation, 0.95):.3f}, "
          f"max {max(rotation):.3f}")


if __name__ == "__main__":
    main()
