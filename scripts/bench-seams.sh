#!/usr/bin/env bash
# Tiling and seams on large artwork (issue 25): fields, cuts, seams, seam length through marked
# area, split strokes, job time, for plates and fills larger than a field, per seam form and
# with shifted passes. Prints a markdown table. Every job is checked with check_job.py
# --allow-split (on the geometry the plan marks) when the checker's venv is there.
#
#   scripts/bench-seams.sh [GALVOPLAN] [BEFORE_GALVOPLAN]
#
# BEFORE_GALVOPLAN (optional): an older binary planned on the same jobs (fields and job time
# only; it has no seam figures).
set -euo pipefail
cd "$(dirname "$0")/.."
G="${1:-target/release/galvoplan}"
BEFORE="${2:-}"
CHECK_PY="${CHECK_PY:-/tmp/galvoplan-check-venv/bin/python}"
CHECKER="../shared/tools/check_job.py"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

svg() { # name, body
  printf '<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="200mm" viewBox="0 0 300 200">\n%s\n</svg>\n' "$2" >"$work/$1.svg"
}
rect='<rect x="30" y="40" width="240" height="120" fill="none" stroke="black"/>'
svg plate "$rect"
svg plate-circle-text "$rect
<circle cx=\"100\" cy=\"100\" r=\"45\" fill=\"none\" stroke=\"black\"/>
<text x=\"160\" y=\"110\" font-family=\"DejaVu Sans\" font-size=\"14\" fill=\"black\">GALVOPLAN 2026</text>"
svg disc '<circle cx="150" cy="100" r="95" fill="none" stroke="black"/>'
cat >"$work/pens2.toml" <<'EOF'
version = 1
[default]
passes = 2
shift_passes = SHIFT
[default.hatch]
style = "zigzag"
spacing_mm = 0.5
EOF
sed 's/SHIFT/true/' "$work/pens2.toml" >"$work/shift.toml"
# the seed000 machine with a 40 mm field: the shared hatch drawings (47 × 63 mm) need cutting
sed 's/^field_mm = .*/field_mm = [40.0, 40.0]/' assets/profiles/seed000.toml >"$work/f40.toml"
sed 's/SHIFT/false/' "$work/pens2.toml" >"$work/noshift.toml"

row() { # label, input, whether the older binary plans it too (y/n), extra args...
  local label=$1 input=$2 old=$3
  shift 3
  "$G" plan "$input" -o "$work/o.gcode" --report "$work/o.json" --export-geometry "$work/o.svg" \
    --motion step --split-oversize "$@" >/dev/null 2>&1
  local ok="–"
  if [ -x "$CHECK_PY" ] && [ -f "$CHECKER" ]; then
    if "$CHECK_PY" "$CHECKER" "$work/o.svg" "$work/o.gcode" --report "$work/o.json" \
      --allow-split --allow-passes >/dev/null 2>&1; then ok="ok"; else ok="FAIL"; fi
  fi
  local before="–|–"
  if [ -n "$BEFORE" ] && [ "$old" = y ]; then
    if "$BEFORE" plan "$input" -o "$work/b.gcode" --report "$work/b.json" --motion step \
      --split-oversize "$@" >/dev/null 2>&1; then
      before=$(python3 -c "import json;r=json.load(open('$work/b.json'));print(f\"{len(r['fields'])}|{r['metrics']['job_time_s']:.3f}\")")
    fi
  fi
  python3 - "$work/o.json" "$label" "$before" "$ok" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
s, m = r["seams"], r["metrics"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {len(r['fields'])} | {s['count']} | {s['cuts']} | "
      f"{s['length_mm']:.0f} | {s['split_strokes']} | {s['extra_marked_mm']:.1f} | "
      f"{m['job_time_s']:.3f} | {sys.argv[4]} |")
EOF
}

echo "| job | before: fields | before: job s | fields | seams | cuts | seam length mm | split strokes | marked twice mm | job s | check |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
row "plate 240×120, zigzag 0.5 mm 0°" "$work/plate.svg" y --hatch zigzag:0.5:0
row "plate, zigzag 0.5 mm 45°" "$work/plate.svg" y --hatch zigzag:0.5:45
row "plate, lines 0.3 mm 30°" "$work/plate.svg" y --hatch lines:0.3:30
row "plate + 90 mm circle + 14 mm text, filled together" "$work/plate-circle-text.svg" y --hatch zigzag:0.5:0
row "the same, filled apart" "$work/plate-circle-text.svg" n --hatch zigzag:0.5:0 --hatch-shapes apart
row "disc ⌀190, cross 0.5 mm 15°" "$work/disc.svg" y --hatch cross:0.5:15
row "apmcm-multi, 40 mm field, zigzag 0.2 mm" ../shared/bench/hatch/apmcm-multi.svg y --profile "$work/f40.toml" --hatch zigzag:0.2:0
row "apmcm-single, 40 mm field, lines 0.1 mm 45°" ../shared/bench/hatch/apmcm-single.svg y --profile "$work/f40.toml" --hatch lines:0.1:45
row "plate, seam overlap 0.3 mm (dose kept)" "$work/plate.svg" n --hatch zigzag:0.5:0 --seam overlap:0.3
row "plate, seam overlap 0.3 mm (marked twice)" "$work/plate.svg" n --hatch zigzag:0.5:0 --seam overlap:0.3:doubled
row "plate, seam interlocked 0.5 mm" "$work/plate.svg" n --hatch zigzag:0.5:0 --seam interlocked:0.5
row "plate, seam staggered 0.5 mm" "$work/plate.svg" n --hatch zigzag:0.5:0 --seam staggered:0.5
row "plate, 2 passes" "$work/plate.svg" n --pens "$work/noshift.toml"
row "plate, 2 passes, shifted" "$work/plate.svg" n --pens "$work/shift.toml"
