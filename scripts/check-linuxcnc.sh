#!/usr/bin/env bash
# Runs galvoplan's LinuxCNC programs on LinuxCNC itself (part of the test command).
#
# usage: scripts/check-linuxcnc.sh [BINARY] [--shared BENCH_DIR]
#
# With --shared (e.g. ../shared/bench), also the 14 shared instances step-and-scan and the three
# on-the-fly patterns on the fly (docs/BENCHMARKS.md's LinuxCNC table; about 10 min more).
#
# For each job: plans it with the built-in `linuxcnc` profile, reads the program with LinuxCNC's
# interpreter and compares its canonical moves with the toolpath (scripts/linuxcnc_check.py),
# then runs it on the headless simulated machine that `galvoplan linuxcnc-config` writes.
# Prints one JSON line per job: job, mode, linuxcnc_s (LinuxCNC's time from the laser's first
# switch-on to the end), galvoplan_s (galvoplan's job time), ratio, laser_on_s (the laser output
# on while the machine moves), marking_s (galvoplan's), ok. A job is ok when the interpreter reads
# it with no error, every move ends on the toolpath (1 um), the machine runs it to the end with no
# error, and the ratio lies within 0.95-1.05 (step-and-scan; laser-on time too) or 0.90-1.10
# (on the fly). Exits 1 when a job is not ok.
# Installs linuxcnc-uspace (without recommends) when it is missing.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
B="${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/debug/galvoplan}"
SHARED=""
if [ "${2:-}" = "--shared" ]; then SHARED="${3:?--shared needs a folder}"; fi
if [ ! -x "$B" ]; then
  echo "check-linuxcnc: no galvoplan binary at $B" >&2
  exit 1
fi
if ! command -v linuxcnc >/dev/null || ! /usr/bin/python3 -c 'import linuxcnc, gcode' 2>/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q >/dev/null
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends linuxcnc-uspace >/dev/null
fi
OUT="${OUT:-$(mktemp -d /tmp/galvoplan-linuxcnc.XXXXXX)}"
# rtapi_app runs as another user (below) and must reach its socket folder
mkdir -p "$OUT/rtapi" && chmod 755 "$OUT" && chmod 1777 "$OUT/rtapi"
OUT="$(realpath "$OUT")"
CFG="$OUT/machine"
"$B" linuxcnc-config --profile linuxcnc --out "$CFG" >/dev/null || exit 1
# rtapi_app refuses to run as root without a user id, and then needs a socket folder it can write
if [ "$(id -u)" -eq 0 ]; then
  export RTAPI_UID=65534 RTAPI_FIFO_PATH="$OUT/rtapi/.rtapi_fifo"
fi
export RUNTESTS=1

sim() { # program result -> runs it; one retry when LinuxCNC did not come up
  local try
  for try in 1 2; do
    rm -f "$2"
    GALVOPLAN_PROGRAM="$1" GALVOPLAN_RESULT="$2" timeout 900 linuxcnc "$CFG/galvoplan.ini" >"$2.log" 2>&1
    [ -s "$2" ] && return 0
    sleep 2
  done
  return 1
}

status=0
job() { # name svg mode [plan options...]
  local name=$1 svg=$2 mode=$3; shift 3
  local o="$OUT/$name"
  if ! "$B" plan "$svg" --profile linuxcnc --motion "$mode" -o "$o.ngc" --report "$o.json" \
      --waypoints "$o.waypoints.csv" "$@" 2>"$o.plan.log"; then
    echo "{\"job\": \"$name\", \"mode\": \"$mode\", \"ok\": false, \"error\": \"plan failed\"}"
    status=1; return
  fi
  # from $OUT: the interpreter writes its parameter file (rs274ngc.var) where it runs
  (cd "$OUT" && /usr/bin/python3 "$ROOT/scripts/linuxcnc_check.py" "$o.ngc" "$o.waypoints.csv" \
    --tol-mm 0.005 >"$o.interp.json" 2>"$o.interp.log")
  sim "$(realpath "$o.ngc")" "$o.sim.json"
  python3 - "$name" "$mode" "$o" <<'PY' || status=1
import json, sys
name, mode, o = sys.argv[1:]
rep = json.load(open(o + ".json"))["metrics"]
try:
    interp = json.load(open(o + ".interp.json"))
except (OSError, ValueError):
    interp = {"ok": False, "errors": ["the interpreter check did not run"]}
try:
    sim = json.load(open(o + ".sim.json"))
except (OSError, ValueError):
    sim = {"ok": False, "errors": ["LinuxCNC did not run (see %s.sim.json.log)" % o]}
g = rep.get("job_time_s") or 0.0
marking = (rep.get("job_time_breakdown_s") or {}).get("mark", 0.0)
lc = sim.get("job_s")
laser = sim.get("laser_on_moving_s")
ratio = lc / g if lc and g else None
lo, hi = (0.95, 1.05) if mode == "step" else (0.90, 1.10)
laser_ratio = laser / marking if laser and marking else None
ok = (interp.get("ok") and sim.get("ok") and ratio is not None and lo <= ratio <= hi
      and (mode != "step" or (laser_ratio is not None and 0.95 <= laser_ratio <= 1.05)))
row = {"job": name, "mode": mode, "linuxcnc_s": lc, "galvoplan_s": round(g, 4),
       "ratio": round(ratio, 4) if ratio else None, "laser_on_s": laser,
       "marking_s": round(marking, 4), "ok": bool(ok),
       "canonical_moves": interp.get("canonical_moves"),
       "max_move_error_um": interp.get("max_move_error_um"),
       "errors": interp.get("errors", []) + sim.get("errors", [])}
print(json.dumps(row))
sys.exit(0 if ok else 1)
PY
}

job demo assets/examples/demo.svg step
job ISW-1017 tests/data/linuxcnc/ISW-1017.svg step
job two-layers assets/examples/two-layers.svg step --pens assets/examples/two-layers.pens.toml
job oversize assets/examples/oversize.svg on-the-fly
job lissajous tests/data/linuxcnc/lissajous.svg on-the-fly
# a production job: a 2 × 2 tray of parts, each with its serial number as text
job tray-2x2 assets/examples/part.svg step --array 2x2@40,32 --serial 1001 --date 2026-12-07
# a dotted DataMatrix on each part (one spot per module, fired for the dwell) on the fly
job tray-dots assets/examples/part.svg on-the-fly --array 2x2@40,32 --serial 1001 --code "datamatrix:GP{serial:05}@3,3:6:dots"
if [ -n "$SHARED" ]; then
  for f in "$SHARED"/instances/*.svg; do
    n=$(basename "$f" .svg)
    [ "$n" = ISW-1017 ] || job "$n" "$f" step
  done
  for n in spiral tree; do job "$n" "$SHARED/otf/$n.svg" on-the-fly; done
fi
exit $status
