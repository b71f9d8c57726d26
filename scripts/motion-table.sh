#!/usr/bin/env bash
# Developer check (not part of the test suite): the issue-26 table. Plans the 14 shared
# instances, the three on-the-fly patterns, oversize.svg and texture-3043 (texture.toml and
# texture-10.toml) with --motion step, on-the-fly and auto, and prints one row per job: the
# reports' job times (unclocked), auto / step, auto's planning time and the motion auto runs.
# usage: scripts/motion-table.sh [BINARY] [extra plan options...]
set -uo pipefail
cd "$(dirname "$0")/.."
B="${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}"
shift || true
S=../shared
OUT="${OUT:-/tmp/galvoplan-motion-table}"
mkdir -p "$OUT"
EXTRA=("$@")
job() { # name svg profile [split]
  local name=$1 svg=$2 prof=$3 split=${4:-}
  local row=("$name")
  for m in step on-the-fly auto; do
    local o="$OUT/$name-$m" opts=()
    [ "$m" = step ] && [ -n "$split" ] && opts=(--split-oversize)
    if "$B" plan "$svg" --profile "$prof" --motion "$m" -o "$o.gcode" --report "$o.json" \
        "${opts[@]}" "${EXTRA[@]}" 2>"$o.log"; then
      row+=("$o.json")
    else
      row+=("FAILED:$(tail -1 "$o.log")")
    fi
  done
  python3 - "${row[@]}" <<'PY'
import json, sys
name, *reps = sys.argv[1:]
def load(r):
    if r.startswith("FAILED"): return None
    return json.load(open(r))
s, f, a = map(load, reps)
if None in (s, f, a):
    print(name, "FAILED", reps); sys.exit()
jt = lambda r: r["metrics"]["job_time_s"]
best = min(jt(s), jt(f))
flag = "ok" if jt(a) <= best + 1e-9 else "SLOWER"
print(f"| {name} | {jt(s):.3f} | {jt(f):.3f} | {jt(a):.3f} | {jt(a)/jt(s):.3f} | {a['metrics']['solve_s']['total']:.2f} | {a['plan'].split(' · ')[2]} | {flag} |")
PY
}
echo "| job | step s | on the fly s | auto s | auto / step | auto plan s | auto runs | auto <= both |"
echo "|---|---|---|---|---|---|---|---|"
for svg in "$S"/bench/instances/*.svg; do job "$(basename "$svg" .svg)" "$svg" assets/profiles/seed000.toml; done
for p in lissajous spiral tree; do job "$p" "$S/bench/otf/$p.svg" assets/profiles/seed000.toml split; done
job oversize assets/examples/oversize.svg assets/profiles/seed000.toml split
job texture-10 "$S/bench/texture/texture-3043.svg" "$S/bench/texture/texture-10.toml"
job texture-4 "$S/bench/texture/texture-3043.svg" "$S/bench/texture/texture.toml"
