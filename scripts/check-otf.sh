#!/usr/bin/env bash
# Developer check (not part of the test suite): plans the shared instances, the three on-the-fly
# patterns and the texture job on the fly, writes trajectories and runs
# ../shared/tools/check_trajectory.py --mode otf and check_job.py on them. Prints one line per job:
# ok flags, the checker's job time and stage route.
# usage: scripts/check-otf.sh [BINARY] [extra plan options...]
set -uo pipefail
cd "$(dirname "$0")/.."
B="${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}"
shift || true
S=../shared
source "$S/tools/setup.sh" >/dev/null
OUT="${OUT:-/tmp/galvoplan-otf}"
mkdir -p "$OUT"
source scripts/clocked-profile.sh
EXTRA=("$@")
run() { # name svg profile
  local name=$1 svg=$2 prof; prof=$(clocked "$3")
  local o="$OUT/$name"
  local t0=$(date +%s.%N)
  if ! "$B" plan "$svg" --profile "$prof" --motion on-the-fly -o "$o.gcode" --report "$o.json" \
      --trajectory "$o.csv" --export-geometry "$o.geom.svg" "${EXTRA[@]}" 2>"$o.log"; then
    echo "$name PLAN-FAILED $(tail -1 "$o.log")"; return
  fi
  local tj job
  tj=$("$CHECK_PY" "$S/tools/check_trajectory.py" "$svg" "$o.csv" --profile "$prof" --report "$o.json" --mode otf)
  job=$("$CHECK_PY" "$S/tools/check_job.py" "$o.geom.svg" "$o.gcode" --report "$o.json" 2>&1 | tail -1)
  python3 - "$name" "$tj" "$job" "$o.json" <<'PY'
import json, sys
name, tj, job, rep = sys.argv[1:]
t = json.loads(tj); r = json.load(open(rep))["metrics"]
try: j = json.loads(job).get("ok")
except Exception: j = job[:80]
print(f"{name:14s} traj_ok={t['ok']} job_ok={j} job_s={t['job_time_s']:.3f} route_mm={t['stage_path_mm']:.0f} "
      f"peak_mm_s={t['stage_max_speed_mm_s']:.0f} variation_mm_s={t['stage_speed_variation_mm_s']:.0f} "
      f"offset_mm={max(t['scan_max_offset_mm']):.2f} plan_s={r['solve_s']['total']:.2f} {' | '.join(t['fails'])[:200]}")
PY
}
for p in lissajous tree spiral; do run "$p" "$S/bench/otf/$p.svg" assets/profiles/seed000.toml; done
for svg in "$S"/bench/instances/*.svg; do run "$(basename "$svg" .svg)" "$svg" assets/profiles/seed000.toml; done
run texture-10 "$S/bench/texture/texture-3043.svg" "$S/bench/texture/texture-10.toml"
run texture-4 "$S/bench/texture/texture-3043.svg" "$S/bench/texture/texture.toml"
