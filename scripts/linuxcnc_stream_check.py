#!/usr/bin/env python3
"""Compares what LinuxCNC's joints and laser got (halsampler's trace of a streamed job) with the
stream galvoplan planned (scripts/check-linuxcnc.sh).

usage: linuxcnc_stream_check.py JOB.stream TRACE.txt --period-s P

The stream: `X Y U V laser end [power]` per period. The trace: `X Y U V laser end empty
underruns` per period while the joints follow the stream (sampler.0 in galvoplan-stream.hal),
row k being stream sample k. Prints one JSON object: samples, trace_rows, max_position_error_um
(over the stream's samples), laser_edges_ok (the laser switches on the same samples),
underruns (before the last sample), planned_laser_s and linuxcnc_laser_s (first laser-on to
last laser-off), ratio, and ok (errors under 1 um, edges the same, no underrun, ratio
0.99-1.01).
"""
import argparse
import json


def rows(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip()]


def laser_span(laser, period_s):
    on = [k for k, v in enumerate(laser) if v]
    return (on[-1] + 1 - on[0]) * period_s if on else 0.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("stream")
    ap.add_argument("trace")
    ap.add_argument("--period-s", type=float, required=True)
    a = ap.parse_args()
    plan = rows(a.stream)
    got = rows(a.trace)
    n = len(plan)
    out = {"samples": n, "trace_rows": len(got), "errors": []}
    if len(got) < n:
        out["errors"].append("the trace holds %d rows for %d samples" % (len(got), n))
    m = min(n, len(got))
    err_mm = max((abs(float(p[i]) - float(g[i])) for p, g in zip(plan[:m], got[:m])
                  for i in range(4)), default=None)
    planned_laser = [p[4] == "1" for p in plan]
    got_laser = [g[4] == "1" for g in got[:m]]
    edges_ok = m == n and planned_laser == got_laser
    underruns = int(got[m - 1][7]) if m else None
    planned_s = laser_span(planned_laser, a.period_s)
    linuxcnc_s = laser_span(got_laser, a.period_s)
    ratio = linuxcnc_s / planned_s if planned_s else None
    out.update({
        "max_position_error_um": None if err_mm is None else round(err_mm * 1e3, 4),
        "laser_edges_ok": edges_ok,
        "underruns": underruns,
        "planned_laser_s": round(planned_s, 6),
        "linuxcnc_laser_s": round(linuxcnc_s, 6),
        "ratio": None if ratio is None else round(ratio, 6),
    })
    out["ok"] = bool(err_mm is not None and err_mm <= 1e-3 and edges_ok and underruns == 0
                     and ratio is not None and 0.99 <= ratio <= 1.01 and not out["errors"])
    print(json.dumps(out))


main()
