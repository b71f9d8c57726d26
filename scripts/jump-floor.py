#!/usr/bin/env python3
"""Lower bound on a texture job's time: marks, laser delays and the least scanner travel.

For artwork of cells of concentric circles (bench/texture/gen_texture.py), whatever the order:
the scanner visits a point of every cell's smallest circle (radius r), so between two such
visits it travels at least |c_i - c_j| - 2r; over the cells in visiting order that is a path
through all centres, at least their minimum spanning tree. Jumps run at jump speed (galvoplan's
time law: the tool's jump is timed in the workpiece frame), so

  floor = marked/mark_speed + n_marks*(on+off delay) + (n_marks-1)*jump_delay
          + (MST(centres) - (cells-1)*2r) / jump_speed.

usage: jump-floor.py SVG MARKED_MM [--mark 500 --jump 2000 --on 1e-4 --off 1e-4 --jd 2e-4]
"""
import argparse
import math
import re
from collections import defaultdict

ap = argparse.ArgumentParser()
ap.add_argument("svg")
ap.add_argument("marked_mm", type=float, help="the report's marked_mm")
ap.add_argument("--mark", type=float, default=500.0)
ap.add_argument("--jump", type=float, default=2000.0)
ap.add_argument("--on", type=float, default=1e-4)
ap.add_argument("--off", type=float, default=1e-4)
ap.add_argument("--jd", type=float, default=2e-4)
a = ap.parse_args()

cells = defaultdict(list)
for m in re.finditer(r'<circle cx="([-\d.]+)" cy="([-\d.]+)" r="([\d.]+)"', open(a.svg).read()):
    cells[(float(m.group(1)), float(m.group(2)))].append(float(m.group(3)))
centres = list(cells)
marks = sum(len(r) for r in cells.values())
r_min = min(min(r) for r in cells.values())

# Prim's algorithm, O(n^2)
n = len(centres)
best = [math.inf] * n
done = [False] * n
best[0] = 0.0
mst = 0.0
for _ in range(n):
    u = min((i for i in range(n) if not done[i]), key=lambda i: best[i])
    done[u] = True
    mst += best[u]
    ux, uy = centres[u]
    for i in range(n):
        if not done[i]:
            d = math.hypot(centres[i][0] - ux, centres[i][1] - uy)
            if d < best[i]:
                best[i] = d

travel = mst - (n - 1) * 2 * r_min
mark_s = a.marked_mm / a.mark
delays_s = marks * (a.on + a.off) + (marks - 1) * a.jd
jump_s = travel / a.jump
print(f"cells {n}, marks {marks}, MST {mst:.1f} mm, least jump travel {travel:.1f} mm")
print(f"floor {mark_s + delays_s + jump_s:.3f} s = marks {mark_s:.3f} + delays {delays_s:.3f} + jumps {jump_s:.3f}")
