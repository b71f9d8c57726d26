#!/usr/bin/env python3
"""Independent check of a cylinder program (docs/BENCHMARKS.md, Cylinders): every G1 with the
laser on, sampled at 20 points, mapped back onto the cylinder (axial = X + U,
arc = R·(A·π/180 + asin(V/R))) and measured against the flattened drawing.

usage: scripts/cylinder_landing.py PROGRAM.ngc GEOMETRY.svg RADIUS_MM

PROGRAM.ngc: `galvoplan plan ART --cylinder D -o PROGRAM.ngc` (stage-scanner or linuxcnc
dialect: X, A, U, V words); GEOMETRY.svg: the same plan's `--export-geometry` (the drawing as
planned, flattened). Prints the worst landing, the deepest mark below the focus and the marked
length against the drawn length. Needs only the Python standard library; the test suite has its
own check (tests/cylinder.rs) and does not use this script.
"""
import math
import re
import sys
from collections import defaultdict

ngc, svg, R = sys.argv[1], sys.argv[2], float(sys.argv[3])
C = 2 * math.pi * R
paths = []
for d in re.findall(r'<path d="([^"]+)"', open(svg).read()):
    pts = [(float(a), float(b)) for a, b in re.findall(r'[ML]([-\d.]+) ([-\d.]+)', d)]
    if d.endswith('Z'):
        pts.append(pts[0])
    paths.append(pts)
segs = [(p[i], p[i + 1]) for p in paths for i in range(len(p) - 1)]
def psd(p, a, b):
    ax, ay = a; bx, by = b; px, py = p
    dx, dy = bx - ax, by - ay; l2 = dx * dx + dy * dy
    t = 0 if l2 == 0 else max(0, min(1, ((px - ax) * dx + (py - ay) * dy) / l2))
    return math.hypot(px - ax - t * dx, py - ay - t * dy)
# the drawing's segments in a 2 mm grid, for speed
G = 2.0
grid = defaultdict(list)
for s in segs:
    (ax, ay), (bx, by) = s
    for gx in range(int(min(ax, bx) // G) - 1, int(max(ax, bx) // G) + 2):
        for gy in range(int(min(ay, by) // G) - 1, int(max(ay, by) // G) + 2):
            grid[(gx, gy)].append(s)
def dist(p):
    best = 1e9
    for turns in (-1, 0, 1):
        q = (p[0], p[1] + turns * C)
        for s in grid.get((int(q[0] // G), int(q[1] // G)), []):
            best = min(best, psd(q, *s))
    return best
x = a = u = v = 0.0; on = False; worst = 0.0; defocus = 0.0; n = 0; marked = 0.0
for line in open(ngc):
    line = line.split(';')[0].split('(')[0].strip()
    if not line: continue
    w = line.split(); cmd = w[0]
    nx, na, nu, nv = x, a, u, v
    for t in w[1:]:
        k, val = t[0], t[1:]
        try: f = float(val)
        except ValueError: continue
        if k == 'X': nx = f
        elif k == 'A': na = f
        elif k == 'U': nu = f
        elif k == 'V': nv = f
    if cmd == 'M3' or cmd.startswith('M62') or cmd.startswith('M64'): on = True
    elif cmd == 'M5' or cmd.startswith('M63') or cmd.startswith('M65'): on = False
    elif cmd == 'G1' and on:
        prev = None
        for k in range(21):
            t = k / 20; su = u + t * (nu - u); sv = v + t * (nv - v)
            phi = math.asin(sv / R); defocus = max(defocus, R * (1 - math.cos(phi)))
            p = (x + su, R * (math.radians(a) + phi))
            worst = max(worst, dist(p)); n += 1
            if prev: marked += math.hypot(p[0] - prev[0], p[1] - prev[1])
            prev = p
    x, a, u, v = nx, na, nu, nv
drawn = sum(math.hypot(b[0] - a_[0], b[1] - a_[1]) for a_, b in segs)
print(f"samples {n}, worst landing {worst*1000:.2f} um, deepest defocus {defocus:.4f} mm, marked {marked:.3f} mm of {drawn:.3f} mm drawn ({100*(marked/drawn-1):+.4f} %)")
