#!/usr/bin/env bash
# Production jobs measured (docs/BENCHMARKS.md, "Trays as one job"):
#  1. the 6 × 8 tray of assets/examples/part.svg planned as one job, against the same 48 parts
#     planned as 48 separate jobs (each part placed at its cell, its own serial);
#  2. planning time of 20 × 20 parts of 12 × 12 mm at a 15 mm pitch (tests/data/tray/part12.svg).
# Usage: scripts/tray-bench.sh [BINARY] [PROFILE]   (default: the release build, seed000)
set -euo pipefail
cd "$(dirname "$0")/.."
B="${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}"
P="${2:-seed000}"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
DATE=2026-12-07T08:00
now() { date +%s.%N; }

t0=$(now)
"$B" plan assets/examples/part.svg --profile "$P" --array 6x8@40,32 --serial 1001 \
  --data assets/examples/lots.csv --date $DATE -o "$OUT/tray.gcode" --report "$OUT/tray.json" \
  2>/dev/null
t1=$(now)
k=0
for r in 0 1 2 3 4 5 6 7; do
  for c in 0 1 2 3 4 5; do
    "$B" plan assets/examples/part.svg --profile "$P" --place "corner:$((c * 40)),$((r * 32))" \
      --serial $((1001 + k)) --date $DATE -o "$OUT/p$k.gcode" --report "$OUT/p$k.json" 2>/dev/null
    k=$((k + 1))
  done
done
t2=$(now)
"$B" plan tests/data/tray/part12.svg --profile "$P" --array 20x20@15,15 --serial 1 --date $DATE \
  -o "$OUT/t400.gcode" --report "$OUT/t400.json" 2>/dev/null
t3=$(now)
python3 - "$OUT" "$t0" "$t1" "$t2" "$t3" <<'PY'
import json, sys, glob
out, t0, t1, t2, t3 = sys.argv[1], *map(float, sys.argv[2:])
def m(p):
    r = json.load(open(p))
    return r["metrics"], len(r["fields"]), len(r.get("parts", []))
tray, tf, tp = m(f"{out}/tray.json")
sep = [m(f"{out}/p{k}.json") for k in range(48)]
sep_job = sum(s[0]["job_time_s"] for s in sep)
sep_fields = sum(s[1] for s in sep)
sep_plan = sum(s[0]["solve_s"]["total"] for s in sep)
big, bf, bp = m(f"{out}/t400.json")
print("| job | parts | fields | job time s | planning s (report) | wall s |")
print("|---|---|---|---|---|---|")
print(f"| 6 × 8 tray, one job | {tp} | {tf} | {tray['job_time_s']:.3f} | {tray['solve_s']['total']:.3f} | {t1 - t0:.2f} |")
print(f"| the same 48 parts, 48 jobs | 48 | {sep_fields} | {sep_job:.3f} | {sep_plan:.3f} | {t2 - t1:.2f} |")
print(f"| ratio one job / 48 jobs | | {tf / sep_fields:.3f} | {tray['job_time_s'] / sep_job:.3f} | | |")
print(f"| 20 × 20 parts of 12 × 12 mm at 15 mm | {bp} | {bf} | {big['job_time_s']:.3f} | {big['solve_s']['total']:.3f} | {t3 - t2:.2f} |")
PY
