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
"$B" plan assets/examples/part.svg --profile "$P" --array 6x8@40,32 --serial 1001 \
  --data assets/examples/lots.csv --date $DATE --motion step -o "$OUT/tray-step.gcode" \
  --report "$OUT/tray-step.json" 2>/dev/null
t2b=$(now)
"$B" plan tests/data/tray/part12.svg --profile "$P" --array 20x20@15,15 --serial 1 --date $DATE \
  -o "$OUT/t400.gcode" --report "$OUT/t400.json" 2>/dev/null
t3=$(now)
PROFILE_TOML="$P"
[ -f "$PROFILE_TOML" ] || PROFILE_TOML="assets/profiles/$P.toml"
python3 - "$OUT" "$PROFILE_TOML" "$t0" "$t1" "$t2" "$t2b" "$t3" <<'PY'
import json, sys, tomllib
out, profile = sys.argv[1], sys.argv[2]
t0, t1, t2, t2b, t3 = map(float, sys.argv[3:])
prof = tomllib.load(open(profile, "rb"))
def axis_s(d, ax):
    # rest-to-rest trapezoid (the profile's velocity and acceleration), as the lowering's
    v, a = ax["max_velocity_mm_s"], ax["max_accel_mm_s2"]
    return d / v + v / a if d >= v * v / a else 2 * (d / a) ** 0.5
def move_s(dx, dy):
    return max(axis_s(abs(dx), prof["axis_x"]), axis_s(abs(dy), prof["axis_y"]))
# between separate jobs the stage still goes from part to part: serpentine over the rows
cells = [(c, r) for r in range(8) for c in (range(6) if r % 2 == 0 else range(5, -1, -1))]
between = sum(move_s((b[0] - a[0]) * 40, (b[1] - a[1]) * 32) for a, b in zip(cells, cells[1:]))
def m(p):
    r = json.load(open(p))
    return r["metrics"], len(r["fields"]), len(r.get("parts", []))
tray, tf, tp = m(f"{out}/tray.json")
sep = [m(f"{out}/p{k}.json") for k in range(48)]
sep_job = sum(s[0]["job_time_s"] for s in sep)
sep_fields = sum(s[1] for s in sep)
sep_plan = sum(s[0]["solve_s"]["total"] for s in sep)
big, bf, bp = m(f"{out}/t400.json")
step, sf, sp = m(f"{out}/tray-step.json")
print("| job | parts | fields | job time s | planning s (report) | wall s |")
print("|---|---|---|---|---|---|")
print(f"| 6 × 8 tray, one job | {tp} | {tf} | {tray['job_time_s']:.3f} | {tray['solve_s']['total']:.3f} | {t1 - t0:.2f} |")
print(f"| the same 48 parts, 48 jobs | 48 | {sep_fields} | {sep_job:.3f} | {sep_plan:.3f} | {t2 - t1:.2f} |")
print(f"| … plus the stage's moves from part to part between them (47, serpentine) | | | {sep_job + between:.3f} | | |")
print(f"| 6 × 8 tray, one job, step-and-scan | {sp} | {sf} | {step['job_time_s']:.3f} | {step['solve_s']['total']:.3f} | {t2b - t2:.2f} |")
print(f"| one job (auto) / 48 jobs with their moves | | {tf / sep_fields:.3f} | {tray['job_time_s'] / (sep_job + between):.3f} | | |")
print(f"| 20 × 20 parts of 12 × 12 mm at 15 mm | {bp} | {bf} | {big['job_time_s']:.3f} | {big['solve_s']['total']:.3f} | {t3 - t2b:.2f} |")
PY
