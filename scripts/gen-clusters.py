#!/usr/bin/env python3
"""Test artwork for mixed motion (issue 26 item 3): jobs where step-and-scan was expected to win
some regions. 300 x 300 mm, for the seed000 profile (70 mm fields).

  clusters-hatch.svg  four 60 mm blocks of 31 lines at the corners of the stroke
  clusters-dots.svg   five clusters of 60 circles (r 1 mm) within 62 mm
  dense-sparse.svg    200 circles (r 0.8 mm) within 64 mm in the middle, 40 (r 2 mm) spread out

usage: gen-clusters.py OUT_DIR [--seed S]
"""
import argparse
import os
import random

ap = argparse.ArgumentParser()
ap.add_argument("out_dir")
ap.add_argument("--seed", type=int, default=11)
a = ap.parse_args()
rng = random.Random(a.seed)


def svg(name, shapes):
    head = '<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="300mm" viewBox="0 0 300 300">'
    with open(os.path.join(a.out_dir, name), "w") as f:
        f.write(head + "\n" + "\n".join(shapes) + "\n</svg>\n")


def circle(x, y, r):
    return f'<circle cx="{x:.3f}" cy="{y:.3f}" r="{r}" fill="none" stroke="black"/>'


corners = [(40, 40), (260, 40), (40, 260), (260, 260)]
lines = []
for cx, cy in corners:
    for k in range(31):
        y = cy - 30 + 2 * k
        lines.append(f'<path d="M {cx - 30} {y} L {cx + 30} {y}" fill="none" stroke="black"/>')
svg("clusters-hatch.svg", lines)
dots = []
for cx, cy in corners + [(150, 150)]:
    for _ in range(60):
        dots.append(circle(cx + rng.uniform(-31, 31), cy + rng.uniform(-31, 31), 1))
svg("clusters-dots.svg", dots)
mixed = [circle(150 + rng.uniform(-32, 32), 150 + rng.uniform(-32, 32), 0.8) for _ in range(200)]
mixed += [circle(rng.uniform(5, 295), rng.uniform(5, 295), 2) for _ in range(40)]
svg("dense-sparse.svg", mixed)
