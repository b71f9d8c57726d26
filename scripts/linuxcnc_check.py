#!/usr/bin/python3
"""Reads a galvoplan LinuxCNC program with LinuxCNC's own interpreter (the `gcode` module) and
compares its canonical moves with the toolpath's exact states (`galvoplan plan --waypoints`).

usage: linuxcnc_check.py PROGRAM.ngc WAYPOINTS.csv --tol-mm T [--axes XYUV]
--axes: the machine's axis words, the scanner's two last (default: XY, then Z, A, B for the
waypoints' z_mm, a_deg, b_deg columns, a machine with axes beyond X/Y, then UV). Z, A and B are
compared too: a move ends on its toolpath state when the stage, the scanner (mm) and each of Z
(mm), A and B (degrees) are within 1 um (1 mdeg) of it.
Prints one JSON object: parse result and errors, canonical moves, the largest distance of a
move's end from its toolpath state (um), and for on-the-fly programs the largest distance of a
skipped toolpath sample from the line that replaced it (mm).

Step-and-scan: every distinct toolpath state must be a move's end, in order (nothing skipped).
On the fly: every move's end must be a toolpath state, in order; samples between two ends are
merged lines and must lie within --tol-mm of them (stage and tool-centre point).
Needs LinuxCNC's Python modules: run with the system /usr/bin/python3.
"""
import argparse
import csv
import json
import math
import sys

import gcode

MM_PER_INCH = 25.4
MASK = {"X": 1, "Y": 2, "Z": 4, "A": 8, "B": 16, "C": 32, "U": 64, "V": 128, "W": 256}
MATCH_MM = 1e-3  # 1 um (and 1 mdeg for a rotary)
EXTRA = (("Z", "z_mm"), ("A", "a_deg"), ("B", "b_deg"))
ANGULAR = "ABC"


class Canon:
    """The interpreter's canonical machine: records straight moves (mm, rotaries in degrees),
    ignores the rest. A move's position: X, Y, the scanner's two axes (the last two of `axes`),
    then Z, A, B where the machine has them."""

    def __init__(self, axes):
        self.mask = sum(MASK[a] for a in axes)
        extra = [a for a, _ in EXTRA if a in axes]
        self.axes = ["X", "Y", axes[-2], axes[-1]] + extra
        self.moves = []
        self.g93 = False
        self.parameter_file = ""
        self.lineno = 0

    def get_axis_mask(self):
        return self.mask

    def get_external_length_units(self):
        return 1.0 / MM_PER_INCH

    def get_external_angular_units(self):
        return 1.0

    def get_tool(self, pocket):
        return -1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0

    def get_block_delete(self):
        return False

    def check_abort(self):
        return False

    def next_line(self, st):
        self.lineno = st.sequence_number

    def _pos(self, x, y, z, a, b, c, u, v, w):
        named = dict(zip("XYZABCUVW", (x, y, z, a, b, c, u, v, w)))
        return tuple(named[k] * (1.0 if k in ANGULAR else MM_PER_INCH) for k in self.axes)

    def straight_traverse(self, *args):
        self.moves.append(("G0", self.lineno) + self._pos(*args))

    def straight_feed(self, *args):
        self.moves.append(("G1", self.lineno) + self._pos(*args))

    def __getattr__(self, name):
        return lambda *a, **k: None


def waypoint_axes(path):
    """The axes beyond X/Y the waypoints have columns for (Z, A, B: z_mm, a_deg, b_deg)."""
    with open(path) as f:
        header = next(csv.reader(f), [])
    return [a for a, col in EXTRA if col in header]


def read_waypoints(path):
    """(t, x, y, u, v, then Z, A, B where the file has them) per row."""
    extra = [col for _, col in EXTRA]
    out = []
    with open(path) as f:
        for row in csv.DictReader(f):
            out.append((float(row["t_s"]), float(row["stage_x_mm"]), float(row["stage_y_mm"]),
                        float(row["scan_x_mm"]), float(row["scan_y_mm"]))
                       + tuple(float(row[c]) for c in extra if c in row))
    return out


def dist(p, q):
    """Largest of the stage and scanner distances, mm (p, q = x, y, u, v), and of the
    differences of Z, A and B (mm, degrees) after them."""
    d = max(math.hypot(p[0] - q[0], p[1] - q[1]), math.hypot(p[2] - q[2], p[3] - q[3]))
    for k in range(4, min(len(p), len(q))):
        d = max(d, abs(p[k] - q[k]))
    return d


def off_line(a, b, s, ta, tb, ts):
    """Distance (mm) of sample s at time ts from the line a -> b (times ta, tb): stage and tool
    centre point (stage + scanner)."""
    u = (ts - ta) / (tb - ta) if tb > ta else 1.0
    lerp = [a[k] + (b[k] - a[k]) * u for k in range(4)]
    stage = math.hypot(lerp[0] - s[0], lerp[1] - s[1])
    tcp = math.hypot(lerp[0] + lerp[2] - s[0] - s[2], lerp[1] + lerp[3] - s[1] - s[3])
    return max(stage, tcp)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("program")
    ap.add_argument("waypoints")
    ap.add_argument("--tol-mm", type=float, required=True)
    ap.add_argument("--axes", default=None)
    a = ap.parse_args()
    extra = waypoint_axes(a.waypoints)
    axes = a.axes or "XY" + "".join(extra) + "UV"
    missing = [x for x in extra if x not in axes]
    if missing:
        sys.exit("linuxcnc_check: --axes %s lacks the waypoints' %s" % (axes, ", ".join(missing)))
    canon = Canon(axes)
    result, seq = gcode.parse(a.program, canon, "G21", "")
    errors = []
    if result > gcode.MIN_ERROR:
        errors.append("line %d: %s" % (seq, gcode.strerror(result)))
    otf = any("G93" in line for line in open(a.program))
    wps = read_waypoints(a.waypoints)
    pts = [w[1:] for w in wps]
    moves = [m[2:] for m in canon.moves]
    worst_um = 0.0
    worst_skip_mm = 0.0
    if not moves or not pts:
        errors.append("no moves" if not moves else "no waypoints")
    elif not otf:
        # distinct consecutive toolpath states, each the end of one move, in order
        distinct = [pts[0]]
        for p in pts[1:]:
            if dist(p, distinct[-1]) > 1e-9:
                distinct.append(p)
        if len(distinct) != len(moves):
            errors.append("%d moves for %d distinct toolpath states" % (len(moves), len(distinct)))
        for k, (m, p) in enumerate(zip(moves, distinct)):
            d = dist(m, p)
            worst_um = max(worst_um, d * 1e3)
            if d > MATCH_MM and len(errors) < 5:
                errors.append("move %d (line %d) ends %.4f %s from the toolpath"
                              % (k + 1, canon.moves[k][1], d, "mm (or deg)" if extra else "mm"))
    else:
        j = 0  # the last matched sample
        if dist(moves[0], pts[0]) > MATCH_MM:
            errors.append("the program does not start at the toolpath's start")
        for k, m in enumerate(moves[1:], start=1):
            i = j + 1
            while i < len(pts) and dist(m, pts[i]) > MATCH_MM:
                i += 1
            if i >= len(pts):
                errors.append("move %d (line %d) is not on the toolpath after sample %d"
                              % (k + 1, canon.moves[k][1], j))
                break
            # the nearest of the samples in reach (the machine may stand nearly still)
            while i + 1 < len(pts) and dist(m, pts[i + 1]) < dist(m, pts[i]):
                i += 1
            worst_um = max(worst_um, dist(m, pts[i]) * 1e3)
            for s in range(j + 1, i):
                d = off_line(pts[j], pts[i], pts[s], wps[j][0], wps[i][0], wps[s][0])
                worst_skip_mm = max(worst_skip_mm, d)
            j = i
        else:
            if j != len(pts) - 1 and dist(pts[j], pts[-1]) > MATCH_MM:
                errors.append("the program ends before the toolpath (sample %d of %d)"
                              % (j, len(pts) - 1))
        if worst_skip_mm > a.tol_mm + 1e-6:
            errors.append("a merged line leaves the toolpath by %.4f mm (tolerance %.4f)"
                          % (worst_skip_mm, a.tol_mm))
    print(json.dumps({
        "parse_result": result, "canonical_moves": len(moves), "waypoints": len(pts),
        "max_move_error_um": round(worst_um, 4), "max_merge_error_mm": round(worst_skip_mm, 6),
        "errors": errors, "ok": not errors,
    }))
    return 0 if not errors else 1


sys.exit(main())
