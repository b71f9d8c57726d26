#!/usr/bin/env bash
# Real jobs at full size (issue 24): the issue's grid of 20 x 20 circles (r 6 mm, centres
# 10 + 14.2 i mm, 290 mm page) hatched ever finer, from about 10^3 to 10^6 strokes, one
# `galvoplan bench` process per job (so that each peak memory is the job's own). Prints a
# markdown table of strokes, time per stage, peak memory, job time, and the growth exponent of
# each stage's time between neighbouring sizes (log t2/t1 / log n2/n1). A job whose JSON is
# already in BENCH_SCALE_DIR is not run again.
#
#   scripts/bench-scale.sh [GALVOPLAN] [MOTION] [HATCHES...]
#
# MOTION: step (default), on-the-fly or auto. HATCHES: --hatch values (default: zigzag at
# 4.8, 0.48, 0.048 and 0.0048 mm, 45 deg: about 10^3, 10^4, 10^5 and 10^6 strokes).
set -euo pipefail
cd "$(dirname "$0")/.."
G="${1:-target/release/galvoplan}"
MOTION="${2:-step}"
shift $(( $# > 2 ? 2 : $# ))
HATCHES=("$@")
if [ ${#HATCHES[@]} -eq 0 ]; then
  HATCHES=(zigzag:4.8:45 zigzag:0.48:45 zigzag:0.048:45 zigzag:0.0048:45)
fi
# BENCH_SCALE_DIR keeps each job's JSON (a long run can be read before it ends)
work="${BENCH_SCALE_DIR:-}"
if [ -z "$work" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work"
python3 - "$work/circles.svg" <<'PY'
import sys
out = ['<svg xmlns="http://www.w3.org/2000/svg" width="290mm" height="290mm" viewBox="0 0 290 290">']
for i in range(20):
    for j in range(20):
        out.append(f'<circle cx="{10 + 14.2 * i:.1f}" cy="{10 + 14.2 * j:.1f}" r="6" fill="none" stroke="black"/>')
out.append('</svg>')
open(sys.argv[1], 'w').write('\n'.join(out) + '\n')
PY
for h in "${HATCHES[@]}"; do
  [ -s "$work/$h.json" ] && continue
  echo "bench-scale: $h ($MOTION)" >&2
  "$G" bench "$work/circles.svg" --hatch "$h" --motion "$MOTION" --json "$work/$h.json" >/dev/null
done
python3 - "$work" "$MOTION" "${HATCHES[@]}" <<'PY'
import json, math, sys
work, motion, hatches = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = []
for h in hatches:
    try:
        rows.append((h, json.load(open(f"{work}/{h}.json"))[0]))
    except FileNotFoundError:
        print(f"bench-scale: {h}: no result", file=sys.stderr)
stages = ["hatch_ms", "fields_ms", "order_ms", "export_ms", "total_ms"]
print(f"| hatch ({motion}) | strokes | hatch s | fields s | order s | export s | total s | peak MB | job s | order detail (s) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for h, r in rows:
    detail = ", ".join(f"{k} {v / 1e3:.2f}" for k, v in r["order_detail_ms"] if v >= 50)
    peak = "–" if r["peak_rss_mb"] is None else f"{r['peak_rss_mb']:.0f}"
    times = " | ".join(f"{r[s] / 1e3:.2f}" for s in stages)
    print(f"| {h} | {r['strokes']:,} | {times} | {peak} | {r['job_time_s']['mean']:.1f} | {detail} |")
print()
print("| growth exponent | " + " | ".join(s.replace("_ms", "") for s in stages) + " | peak memory |")
print("|---|" + "---|" * (len(stages) + 1))
for (h1, a), (h2, b) in zip(rows, rows[1:]):
    dn = math.log(b["strokes"] / a["strokes"])
    ex = [math.log(max(b[s], 1e-3) / max(a[s], 1e-3)) / dn for s in stages]
    mem = math.log(b["peak_rss_mb"] / a["peak_rss_mb"]) / dn if a["peak_rss_mb"] and b["peak_rss_mb"] else float("nan")
    print(f"| {a['strokes']:,} → {b['strokes']:,} | " + " | ".join(f"{e:.2f}" for e in ex) + f" | {mem:.2f} |")
PY
