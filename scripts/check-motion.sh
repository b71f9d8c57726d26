#!/usr/bin/env bash
# Developer check (not part of the test suite): plans every shared instance with --cost time and
# --cost distance, writes trajectories and runs ../shared/tools/check_trajectory.py and
# check_job.py on them. Prints one line per instance and cost: ok flags and the checker's job time.
# usage: scripts/check-motion.sh [BINARY] [extra plan options...]
set -uo pipefail
cd "$(dirname "$0")/.."
B="${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}"
shift || true
S=../shared
source "$S/tools/setup.sh" >/dev/null
OUT="${OUT:-/tmp/galvoplan-motion}"
mkdir -p "$OUT"
source scripts/clocked-profile.sh
run() { # name svg profile cost
  local name=$1 svg=$2 cost=$4 prof; prof=$(clocked "$3")
  local o="$OUT/$name-$cost"
  if ! "$B" plan "$svg" --profile "$prof" --motion step --cost "$cost" -o "$o.gcode" --report "$o.json" \
      --trajectory "$o.csv" "${EXTRA[@]}" 2>"$o.log"; then
    echo "$name $cost PLAN-FAILED $(tail -1 "$o.log")"; return
  fi
  local tj job
  tj=$("$CHECK_PY" "$S/tools/check_trajectory.py" "$svg" "$o.csv" --profile "$prof" --report "$o.json" --mode step)
  job=$("$CHECK_PY" "$S/tools/check_job.py" "$svg" "$o.gcode" --report "$o.json" 2>&1 | tail -1)
  python3 - "$name" "$cost" "$tj" "$job" "$o.json" <<'PY'
import json, sys
name, cost, tj, job, rep = sys.argv[1:]
t = json.loads(tj); j = json.loads(job); r = json.load(open(rep))["metrics"]
print(f"{name:12s} {cost:8s} traj_ok={t['ok']} job_ok={j.get('ok')} checker_job_time_s={t['job_time_s']:.4f} "
      f"report={r['job_time_s']:.4f} fields={r['fields']} solve_s={r['solve_s']['total']:.3f} {' | '.join(t['fails'])[:200]}")
PY
}
EXTRA=("$@")
for svg in "$S"/bench/instances/*.svg; do
  name=$(basename "$svg" .svg)
  for cost in distance time; do run "$name" "$svg" assets/profiles/seed000.toml "$cost"; done
done
for cost in distance time; do
  run texture-3043 "$S/bench/texture/texture-3043.svg" "$S/bench/texture/texture.toml" "$cost"
done
