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
#
# Streamed on-the-fly jobs (mode "on-the-fly-streamed": the `linuxcnc` profile streams on the
# fly, docs/GCODE.md): plans with --stream, runs the program while galvoplan-run.py feeds the
# stream, and compares halsampler's record of the joints and the laser with the stream
# (scripts/linuxcnc_stream_check.py): positions within 1 um, the same laser edges, no underrun,
# laser span ratio 0.99-1.01. Then three checks of the wiring: a starved stream (fed too
# slowly) stops with the laser off in the period it runs dry and says so; a stream with a
# sample beyond the INI's limits is refused before it runs; `--motion auto` picks streamed on
# the fly for oversize.svg at no more than half the step-and-scan job time.
#
# Seed 002's 5-axis machine (mode "step-five-axis"): a LinuxCNC copy of the built-in five-axis
# profile and its XYZABUV machine (`linuxcnc-config`: trivkins, seven joints, A and B angular),
# running the 5-axis stand-in (tests/data/linuxcnc/five-axis-stand-in.galvoplan: `galvoplan
# cap-bench` with texture-3043's fields on a spherical cap, 300 placements of one spot each)
# planned --cost time step-and-scan: stage moves of X, Y, Z, A and B between dots. The
# interpreter check compares Z, A and B too; ok when it and the run are clean, the ratio lies
# within 0.95-1.05, and the laser is never on while the machine moves (dots: M64, G4, M65 at
# rest). About 50 s.
#
# A cylinder (mode "step-cylinder"): sleeve.svg around a 40 mm tube on a LinuxCNC copy of the
# built-in rotary machine (XAUV): A turns between strips, each edge of the pre-distorted marks
# has its own feed; ok like the 5-axis job, with the laser on while moving within 0.95-1.05 of
# galvoplan's marking time. About 30 s.
#
# demo-delays (mode "step"): demo.svg on the `linuxcnc` profile with a scan head's delays (laser
# on 0.1 ms, off 0.1 ms, jump 0.2 ms) and 5 ms settling: dwells around every mark, written with
# their own times, and M62/M63 after them (the task law in src/motion/controller.rs).
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
  # (a streamed job: GALVOPLAN_STREAM and GALVOPLAN_TRACE in the environment; another machine
  # than $CFG: MACHINE)
  local try
  for try in 1 2; do
    rm -f "$2"
    GALVOPLAN_PROGRAM="$1" GALVOPLAN_RESULT="$2" timeout 900 linuxcnc "${MACHINE:-$CFG}/galvoplan.ini" \
      >"$2.log" 2>&1
    [ -s "$2" ] && return 0
    sleep 2
  done
  return 1
}

status=0
job() { # name svg mode [plan options...]; JOB_PROFILE: another profile than `linuxcnc`
  local name=$1 svg=$2 mode=$3; shift 3
  local o="$OUT/$name" profile=${JOB_PROFILE:-linuxcnc}
  # on the fly as an inverse-time program: the profile without its stream (a LinuxCNC machine
  # without the streamer wiring; the program runs on this one too)
  [ "$mode" = on-the-fly ] && profile="$G93_PROFILE"
  if ! "$B" plan "$svg" --profile "$profile" --motion "$mode" -o "$o.ngc" --report "$o.json" \
      --waypoints "$o.waypoints.csv" "$@" 2>"$o.plan.log"; then
    echo "{\"job\": \"$name\", \"mode\": \"$mode\", \"ok\": false, \"error\": \"plan failed\"}"
    status=1; return
  fi
  # from $OUT: the interpreter writes its parameter file (rs274ngc.var) where it runs
  (cd "$OUT" && /usr/bin/python3 "$ROOT/scripts/linuxcnc_check.py" "$o.ngc" "$o.waypoints.csv" \
    --tol-mm 0.005 >"$o.interp.json" 2>"$o.interp.log")
  sim "$(realpath "$o.ngc")" "$o.sim.json"
  PYTHONPATH="$ROOT/scripts" python3 - "$name" "$mode" "$o" <<'PY' || status=1
import json, sys
from linuxcnc_result import load
name, mode, o = sys.argv[1:]
rep = json.load(open(o + ".json"))["metrics"]
interp = load(o + ".interp.json", "the interpreter check did not run")
sim = load(o + ".sim.json", "LinuxCNC did not run (see %s.sim.json.log)" % o)
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

PERIOD_S=$(sed -n 's/^stream_period_s = //p' assets/profiles/linuxcnc.toml)
DELAYS_PROFILE="$OUT/linuxcnc-delays.toml"
sed -e 's/^on_delay_s = .*/on_delay_s = 0.0001/' -e 's/^off_delay_s = .*/off_delay_s = 0.0001/' \
  -e 's/^jump_delay_s = .*/jump_delay_s = 0.0002/' \
  -e 's/^\(max_accel_mm_s2 = .*\)/\1\nsettle_s = 0.005/' assets/profiles/linuxcnc.toml >"$DELAYS_PROFILE"
G93_PROFILE="$OUT/linuxcnc-g93.toml"
sed '/^stream_period_s/d' assets/profiles/linuxcnc.toml >"$G93_PROFILE"

stream_job() { # name svg
  local name=$1 svg=$2
  local o="$OUT/$name-streamed"
  if ! "$B" plan "$svg" --profile linuxcnc --motion on-the-fly -o "$o.ngc" --report "$o.json" \
      --stream "$o.stream" 2>"$o.plan.log"; then
    echo "{\"job\": \"$name\", \"mode\": \"on-the-fly-streamed\", \"ok\": false, \"error\": \"plan failed: $(tail -1 "$o.plan.log" | tr -d '"')\"}"
    status=1; return
  fi
  GALVOPLAN_STREAM="$o.stream" GALVOPLAN_TRACE="$o.trace" sim "$(realpath "$o.ngc")" "$o.sim.json"
  python3 "$ROOT/scripts/linuxcnc_stream_check.py" "$o.stream" "$o.trace" --period-s "$PERIOD_S" \
    >"$o.check.json" 2>"$o.check.log"
  PYTHONPATH="$ROOT/scripts" python3 - "$name" "$o" <<'PY' || status=1
import json, sys
from linuxcnc_result import load
name, o = sys.argv[1:]
rep = json.load(open(o + ".json"))["metrics"]
sim = load(o + ".sim.json", "LinuxCNC did not run (see %s.sim.json.log)" % o)
chk = load(o + ".check.json", "the trace check did not run (see %s.check.log)" % o)
ok = bool(sim.get("ok") and chk.get("ok"))
row = {"job": name, "mode": "on-the-fly-streamed", "linuxcnc_s": chk.get("linuxcnc_laser_s"),
       "galvoplan_s": chk.get("planned_laser_s"), "ratio": chk.get("ratio"),
       "job_time_s": round(rep.get("job_time_s") or 0.0, 4), "samples": chk.get("samples"),
       "max_position_error_um": chk.get("max_position_error_um"),
       "laser_edges_ok": chk.get("laser_edges_ok"), "underruns": chk.get("underruns"), "ok": ok,
       "errors": sim.get("errors", []) + chk.get("errors", [])}
print(json.dumps(row))
sys.exit(0 if ok else 1)
PY
}

starved_job() { # a stream fed at a third of its pace: it must stop, laser off, and say so
  local o="$OUT/oversize-streamed" s="$OUT/starved"
  GALVOPLAN_STREAM="$o.stream" GALVOPLAN_TRACE="$s.trace" GALVOPLAN_STREAM_RATE=3000 \
    sim "$(realpath "$o.ngc")" "$s.sim.json"
  python3 - "$s" <<'PY' || status=1
import json, sys
s = sys.argv[1]
sim = json.load(open(s + ".sim.json"))
rows = [l.split() for l in open(s + ".trace") if l.strip()]
# the first period the FIFO ran dry before the last sample: the laser must be off in it
dry = next((r for r in rows if r[6] == "1" and r[5] == "0"), None)
said = any("ran dry" in e for e in sim.get("errors", []))
ok = (not sim.get("ok")) and said and dry is not None and dry[4] == "0" and int(rows[-1][7]) > 0
print(json.dumps({"job": "oversize-starved", "mode": "on-the-fly-streamed",
                  "stopped": not sim.get("ok"), "laser_off_when_dry": dry is not None and dry[4] == "0",
                  "underruns": int(rows[-1][7]) if rows else None, "said": said, "ok": ok,
                  "errors": sim.get("errors", [])}))
sys.exit(0 if ok else 1)
PY
}

beyond_job() { # a sample past U's limit: refused before anything runs
  local o="$OUT/oversize-streamed" s="$OUT/beyond"
  awk 'NR == 100 { $3 = "40.0" } { print }' "$o.stream" >"$s.stream"
  GALVOPLAN_STREAM="$s.stream" sim "$(realpath "$o.ngc")" "$s.sim.json"
  python3 - "$s" <<'PY' || status=1
import json, sys
sim = json.load(open(sys.argv[1] + ".sim.json"))
ok = bool(sim.get("stream_refused")) and any("beyond" in e for e in sim.get("errors", []))
print(json.dumps({"job": "oversize-beyond-limits", "mode": "on-the-fly-streamed",
                  "refused": bool(sim.get("stream_refused")), "ok": ok,
                  "errors": sim.get("errors", [])}))
sys.exit(0 if ok else 1)
PY
}

axes_job() { # name mode builtin input [plan options...]: a job on a built-in machine with
  # axes beyond X/Y, as LinuxCNC runs it (see the top of this file)
  local name=$1 mode=$2 builtin=$3 input=$4; shift 4
  local o="$OUT/$name" p="$OUT/$name-linuxcnc.toml" machine="$OUT/machine-$name"
  # the built-in profile in the LinuxCNC dialect: its laser words and feed are the other
  # dialect's; the laser on digital output 0, LinuxCNC's clock with a 1 ms servo period
  sed -e '/^laser_on = /d' -e '/^laser_off = /d' -e '/^feed_mm_min = /d' \
    -e 's/^mode = .*/mode = "linuxcnc"\nlaser_output = 0/' "assets/profiles/$builtin.toml" >"$p"
  if grep -q '^\[controller\]' "$p"; then
    sed -i 's/^\[controller\]/[controller]\nkind = "linuxcnc"\nservo_period_s = 0.001/' "$p"
  else
    printf '\n[controller]\nkind = "linuxcnc"\nservo_period_s = 0.001\n' >>"$p"
  fi
  if ! { "$B" linuxcnc-config --profile "$p" --out "$machine" >"$o.config.log" 2>&1 &&
      "$B" plan "$input" --profile "$p" --motion step -o "$o.ngc" --report "$o.json" \
        --waypoints "$o.waypoints.csv" "$@" 2>"$o.plan.log"; }; then
    echo "{\"job\": \"$name\", \"mode\": \"$mode\", \"ok\": false, \"error\": \"config or plan failed: $(cat "$o.config.log" "$o.plan.log" | tail -1 | tr -d '"')\"}"
    status=1; return
  fi
  # the waypoints' z_mm, a_deg, b_deg columns: the check compares Z, A and B too
  (cd "$OUT" && /usr/bin/python3 "$ROOT/scripts/linuxcnc_check.py" "$o.ngc" "$o.waypoints.csv" \
    --tol-mm 0.005 >"$o.interp.json" 2>"$o.interp.log")
  MACHINE="$machine" sim "$(realpath "$o.ngc")" "$o.sim.json"
  PYTHONPATH="$ROOT/scripts" python3 - "$name" "$mode" "$o" "$machine/galvoplan.ini" <<'PY' || status=1
import json, re, sys
from linuxcnc_result import load
name, mode, o, ini = sys.argv[1:]
rep = json.load(open(o + ".json"))["metrics"]
interp = load(o + ".interp.json", "the interpreter check did not run (see %s.interp.log)" % o)
sim = load(o + ".sim.json", "LinuxCNC did not run (see %s.sim.json.log)" % o)
coords = re.search(r"^COORDINATES = (\S+)", open(ini).read(), re.M)
g = rep.get("job_time_s") or 0.0
lc = sim.get("job_s")
ratio = lc / g if lc and g else None
moving_lit = sim.get("laser_on_moving_s")
errors = interp.get("errors", []) + sim.get("errors", [])
marking = (rep.get("job_time_breakdown_s") or {}).get("mark", 0.0)
if mode == "step-five-axis":
    # dots: fired at rest
    laser_ok = moving_lit is not None and moving_lit <= 0.01
    if not laser_ok:
        errors.append("the laser is on while the machine moves (%s s): dots are fired at rest"
                      % moving_lit)
else:
    # marks: the laser on while the scanner marks, for the time galvoplan marks
    laser_ok = bool(moving_lit and marking and 0.95 <= moving_lit / marking <= 1.05)
    if not laser_ok:
        errors.append("laser on while moving %s s against %s s of marking" % (moving_lit, marking))
ok = bool(interp.get("ok") and sim.get("ok") and ratio is not None and 0.95 <= ratio <= 1.05
          and laser_ok)
row = {"job": name, "mode": mode, "axes": coords.group(1) if coords else None,
       "linuxcnc_s": lc, "galvoplan_s": round(g, 4),
       "ratio": round(ratio, 4) if ratio else None, "laser_on_moving_s": moving_lit,
       "laser_s": sim.get("laser_s"), "marking_s": round(marking, 4),
       "fields": rep.get("fields"), "ok": ok,
       "canonical_moves": interp.get("canonical_moves"),
       "max_move_error_um": interp.get("max_move_error_um"), "errors": errors}
print(json.dumps(row))
sys.exit(0 if ok else 1)
PY
}

auto_job() { # --motion auto picks the stream for oversize.svg, at most half step-and-scan's time
  local o="$OUT/auto"
  "$B" plan assets/examples/oversize.svg --profile linuxcnc --motion auto -o "$o.ngc" \
    --report "$o.json" --stream "$o.stream" 2>"$o.log" &&
  "$B" plan assets/examples/oversize.svg --profile linuxcnc --motion step --split-oversize \
    -o "$o.step.ngc" --report "$o.step.json" 2>"$o.step.log"
  python3 - "$o" <<'PY' || status=1
import json, sys
o = sys.argv[1]
try:
    auto = json.load(open(o + ".json"))["metrics"]["job_time_s"]
    step = json.load(open(o + ".step.json"))["metrics"]["job_time_s"]
    streamed = "streamed on the fly" in open(o + ".log").read()
except (OSError, ValueError, KeyError) as e:
    print(json.dumps({"job": "oversize-auto", "ok": False, "errors": [str(e)]})); sys.exit(1)
ok = streamed and auto <= 0.5 * step
print(json.dumps({"job": "oversize-auto", "mode": "auto", "streamed": streamed, "auto_s": auto,
                  "step_s": step, "ratio": round(auto / step, 4), "ok": ok}))
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
JOB_PROFILE="$DELAYS_PROFILE" job demo-delays assets/examples/demo.svg step
axes_job five-axis-stand-in step-five-axis five-axis \
  tests/data/linuxcnc/five-axis-stand-in.galvoplan --cost time
# a cylinder: sleeve.svg around a 40 mm tube on the rotary machine (X, A, U, V)
axes_job cylinder-sleeve step-cylinder rotary assets/examples/sleeve.svg --cylinder 40 --cost time
for n in oversize lissajous spiral tree; do
  f=tests/data/linuxcnc/$n.svg; [ "$n" = oversize ] && f=assets/examples/oversize.svg
  stream_job "$n" "$f"
done
starved_job
beyond_job
auto_job
if [ -n "$SHARED" ]; then
  for f in "$SHARED"/instances/*.svg; do
    n=$(basename "$f" .svg)
    [ "$n" = ISW-1017 ] || job "$n" "$f" step
  done
  for n in spiral tree; do job "$n" "$SHARED/otf/$n.svg" on-the-fly; done
fi
exit $status
