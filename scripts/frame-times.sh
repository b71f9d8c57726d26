#!/usr/bin/env bash
# Frame times of the GUI on one job, measured headless: starts galvoplan under Xvfb with
# GALVOPLAN_FRAME_LOG, waits for the file to load, drives the canvas with xdotool through fixed
# phases and prints, per phase, the frames drawn and the median and 95th percentile of the
# whole-frame CPU time (eframe's figure, of the previous frame) and of the ui time.
#
#   scripts/frame-times.sh GALVOPLAN FILE.svg [PROFILE.toml]
#
# Phases (each a fixed number of seconds):
#   idle   nothing happens (egui repaints only on input, so few frames are expected)
#   zoom   wheel in and out over the canvas centre, ZOOM_CYCLES x (ZOOM_STEPS in, ZOOM_STEPS out)
#   pan    middle-button drag in circles over the canvas (the middle button always pans)
#   solve  "Run HHA", then the pointer keeps moving over the canvas; frames with solving=1 counted
#   after  the solve over and the plan shown, nothing happens (no frames expected)
#   play   "Play": the playback draws the job for PLAY_S s, the pointer still
# With PROFILE, the profile is loaded through the GUI (Machine profile > Load TOML… > path
# field) and the fields re-placed ("Re-place automatically") before the phases.
#
# Needs Xvfb, xdotool, python3 (ImageMagick's `import` for SHOTS). Environment (all optional):
#   DISPLAY_NUM  X display to use (default 98; an Xvfb is started on it when none answers)
#   OUT          folder for the frame log and screenshots (default: a temporary folder, removed)
#   SHOTS=1      take screenshots into OUT: after loading (fit) and zoomed in ZOOM_SHOT wheel steps
#                (before the phases), at the end of the playback (played), and once the solve is
#                over (solved, solved-zoomed)
#   IDLE_S ZOOM_CYCLES ZOOM_STEPS PAN_S SOLVE_S PLAY_S   phase lengths (defaults below)
#   LOAD_MAX_S   longest wait for the file (or the re-placement) to finish (default 300)
# The click positions assume the default 1500 x 950 window on a 1500 x 950 screen with egui's
# default scale; override BTN_* / CANVAS_* if the layout changes (take a screenshot to check).
set -euo pipefail

if [ $# -lt 2 ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' >&2
  exit 2
fi
BIN=$(realpath "$1")
SVG=$(realpath "$2")
PROFILE=${3:+$(realpath "$3")}

DISPLAY_NUM=${DISPLAY_NUM:-98}
export DISPLAY=":$DISPLAY_NUM"
IDLE_S=${IDLE_S:-5}
ZOOM_CYCLES=${ZOOM_CYCLES:-4}
ZOOM_STEPS=${ZOOM_STEPS:-6}
ZOOM_SHOT=${ZOOM_SHOT:-5}
PAN_S=${PAN_S:-6}
SOLVE_S=${SOLVE_S:-30}
PLAY_S=${PLAY_S:-10}
LOAD_MAX_S=${LOAD_MAX_S:-300}
# screen positions (px) in the default layout
CANVAS_X=${CANVAS_X:-809}          # centre of the work-area canvas
CANVAS_Y=${CANVAS_Y:-508}
BTN_PROFILE_TAB=${BTN_PROFILE_TAB:-"248 62"}   # left panel: "Machine profile"
BTN_LAYERS_TAB=${BTN_LAYERS_TAB:-"43 62"}      # left panel: "Layers"
BTN_LOAD_TOML=${BTN_LOAD_TOML:-"55 163"}       # profile section: "Load TOML…"
PATH_FIELD=${PATH_FIELD:-"743 494"}            # the path field of the "Load a machine profile" window
BTN_REPLACE=${BTN_REPLACE:-"617 37"}           # toolbar: "Re-place automatically"
BTN_RUN_HHA=${BTN_RUN_HHA:-"746 37"}           # toolbar: "Run HHA"
BTN_PLAY=${BTN_PLAY:-"472 68"}                 # playback strip: "Play" (then "Pause")
BTN_REWIND=${BTN_REWIND:-"407 68"}             # playback strip: "Rewind"
AWAY=${AWAY:-"1300 700"}                       # off the canvas (right panel), for screenshots

KEEP_OUT=${OUT:+1}
OUT=${OUT:-$(mktemp -d)}
mkdir -p "$OUT"
WORK=$(mktemp -d)                 # a fresh HOME: no stored preferences (profile, view) carried over
LOG="$OUT/frames.log"
APP_PID=""
XVFB_PID=""
cleanup() {
  [ -n "$APP_PID" ] && kill "$APP_PID" 2>/dev/null && wait "$APP_PID" 2>/dev/null || true
  [ -n "$XVFB_PID" ] && kill "$XVFB_PID" 2>/dev/null || true
  rm -rf "$WORK"
  [ -z "$KEEP_OUT" ] && rm -rf "$OUT"
  return 0
}
trap cleanup EXIT

say() { echo "frame-times: $*" >&2; }

# --- X server ------------------------------------------------------------------------------
if ! xdotool getmouselocation >/dev/null 2>&1; then
  say "starting Xvfb on $DISPLAY"
  Xvfb "$DISPLAY" -screen 0 1500x950x24 >/dev/null 2>&1 &
  XVFB_PID=$!
  for _ in $(seq 1 50); do xdotool getmouselocation >/dev/null 2>&1 && break; sleep 0.2; done
fi

# --- helpers -------------------------------------------------------------------------------
lines() { if [ -f "$LOG" ]; then wc -l <"$LOG"; else echo 0; fi; }
cpu_ticks() { awk '{print $14 + $15}' "/proc/$APP_PID/stat"; }   # user + system, in clock ticks
alive() { kill -0 "$APP_PID" 2>/dev/null || { say "the app exited"; exit 1; }; }
# Wait until the app has been quiet (< 0.1 s of CPU per second) for 3 s in a row, at least
# $1 s after the call and at most LOAD_MAX_S: loading, re-placing and the repaint after them
# all run in the app's process, and an idle egui app uses no CPU.
wait_quiet() {
  local min_s=$1 hz quiet=0 t=0 prev now
  hz=$(getconf CLK_TCK)
  prev=$(cpu_ticks)
  while [ "$t" -lt "$LOAD_MAX_S" ]; do
    sleep 1; t=$((t + 1)); alive
    now=$(cpu_ticks)
    if [ $((now - prev)) -le $((hz / 10)) ]; then quiet=$((quiet + 1)); else quiet=0; fi
    prev=$now
    if [ "$t" -ge "$min_s" ] && [ "$quiet" -ge 3 ]; then return 0; fi
  done
  say "still busy after ${LOAD_MAX_S} s; going on"
}
# Wait until no frame has been logged for 1 s (at most 20 s). A slow frame takes all the input
# queued meanwhile in one batch and attributes a click to where the pointer is at the end of it,
# so every press waits for the moves before it to be drawn, and the next move for the press.
settle() {
  local n m i
  n=$(lines)
  for i in $(seq 1 20); do
    sleep 1
    m=$(lines)
    [ "$m" -eq "$n" ] && return 0
    n=$m
  done
}
click_at() { xdotool mousemove $1; settle; xdotool click 1; settle; }
focus() { xdotool windowfocus --sync "$WIN" 2>/dev/null || true; }
fit_view() { xdotool mousemove "$CANVAS_X" "$CANVAS_Y"; settle; focus; xdotool key f; settle; }
# the pointer on a circle of radius $2 px about the canvas centre for $1 s (optionally with a
# button held: pass "2" as $3 for a middle-button drag)
circle() {
  local secs=$1 r=$2 button=${3:-} end
  xdotool mousemove "$CANVAS_X" "$CANVAS_Y"
  [ -n "$button" ] && xdotool mousedown "$button"
  end=$(($(date +%s%N) + secs * 1000000000))
  local k=0
  while [ "$(date +%s%N)" -lt "$end" ]; do
    read -r x y < <(awk -v k="$k" -v r="$r" -v cx="$CANVAS_X" -v cy="$CANVAS_Y" \
      'BEGIN { a = k * 0.15; printf "%d %d\n", cx + r * cos(a), cy + r * sin(a) }')
    xdotool mousemove "$x" "$y"
    sleep 0.02
    k=$((k + 1))
  done
  [ -n "$button" ] && xdotool mouseup "$button"
  return 0
}
# a screenshot with the pointer off the canvas (no hover tooltip), when SHOTS is set
shot() {
  [ -n "${SHOTS:-}" ] || return 0
  xdotool mousemove $AWAY; settle
  import -window root "$OUT/$1.png" && say "screenshot $OUT/$1.png"
  xdotool mousemove "$CANVAS_X" "$CANVAS_Y"; settle
}

# --- start and load ------------------------------------------------------------------------
say "$BIN $SVG ${PROFILE:+(profile $PROFILE)}"
env HOME="$WORK" LIBGL_ALWAYS_SOFTWARE=1 GALVOPLAN_FRAME_LOG="$LOG" \
  "$BIN" "$SVG" >"$OUT/app.out" 2>&1 &
APP_PID=$!
WIN=""
for _ in $(seq 1 120); do
  WIN=$(xdotool search --pid "$APP_PID" --name galvoplan 2>/dev/null | head -1 || true)
  [ -n "$WIN" ] && break
  alive; sleep 0.5
done
[ -n "$WIN" ] || { say "no window"; exit 1; }
t0=$(date +%s)
wait_quiet 8
say "loaded after $(( $(date +%s) - t0 )) s"
if [ -n "$PROFILE" ]; then
  focus
  click_at "$BTN_PROFILE_TAB"
  click_at "$BTN_LOAD_TOML"
  sleep 1
  click_at "$PATH_FIELD"            # egui does not focus the field by itself
  xdotool key ctrl+a
  xdotool type --delay 20 "$PROFILE"
  settle
  xdotool key Return
  wait_quiet 3
  click_at "$BTN_REPLACE"
  t0=$(date +%s)
  wait_quiet 5
  say "fields re-placed after $(( $(date +%s) - t0 )) s"
  click_at "$BTN_LAYERS_TAB"        # back to the default left panel
fi
fit_view
xdotool mousemove "$CANVAS_X" "$CANVAS_Y"
sleep 2
shot fit
if [ -n "${SHOTS:-}" ]; then
  xdotool click --repeat "$ZOOM_SHOT" --delay 100 4
  settle
  shot zoomed
  fit_view
fi

# --- phases --------------------------------------------------------------------------------
declare -a NAMES=() STARTS=() ENDS=()
phase_begin() { NAMES+=("$1"); STARTS+=("$(lines)"); }
# a phase ends once the frames its input queued are drawn (none logged for 1 s)
phase_end() { settle; ENDS+=("$(lines)"); }

phase_begin idle
sleep "$IDLE_S"
phase_end

phase_begin zoom
for _ in $(seq 1 "$ZOOM_CYCLES"); do
  xdotool mousemove "$CANVAS_X" "$CANVAS_Y"
  xdotool click --repeat "$ZOOM_STEPS" --delay 50 4   # wheel up: zoom in
  xdotool click --repeat "$ZOOM_STEPS" --delay 50 5   # wheel down: zoom out
done
phase_end
fit_view

phase_begin pan
circle "$PAN_S" 120 2
phase_end
fit_view

focus
xdotool mousemove $BTN_RUN_HHA
settle
phase_begin solve
xdotool click 1
sleep 0.5
circle "$SOLVE_S" 150
ENDS+=("$(lines)")                # no settling: a running solve repaints continuously
alive
# the plan, once the solve is over (at most LOAD_MAX_S)
for _ in $(seq 1 "$LOAD_MAX_S"); do [ "$(tail -n 1 "$LOG" | cut -d' ' -f3)" = 0 ] && break; sleep 1; done
fit_view
xdotool mousemove $AWAY
settle
phase_begin after                  # the plan shown, nothing happens: no frames expected
sleep "$IDLE_S"
phase_end

xdotool mousemove $BTN_PLAY
settle
phase_begin play                   # the playback repaints every frame, the pointer still
xdotool click 1
sleep "$PLAY_S"
ENDS+=("$(lines)")
shot played
xdotool mousemove $BTN_PLAY; settle; xdotool click 1; settle   # pause
if [ -n "${SHOTS:-}" ]; then
  click_at "$BTN_REWIND"
  fit_view
  shot solved
  xdotool click --repeat "$ZOOM_SHOT" --delay 100 4
  settle
  shot solved-zoomed
fi

kill "$APP_PID" 2>/dev/null || true
wait "$APP_PID" 2>/dev/null || true
APP_PID=""

# --- statistics ----------------------------------------------------------------------------
python3 - "$LOG" "$BIN" "$SVG" "${PROFILE:-default}" \
  "${NAMES[*]}" "${STARTS[*]}" "${ENDS[*]}" <<'PY'
import math, sys
log, binary, svg, profile, names, starts, ends = sys.argv[1:8]
rows = [l.split() for l in open(log)]
def pct(xs, p):
    xs = sorted(x for x in xs if not math.isnan(x))
    if not xs:
        return float("nan")
    k = (len(xs) - 1) * p
    lo, hi = math.floor(k), math.ceil(k)
    return xs[lo] + (xs[hi] - xs[lo]) * (k - lo)
print(f"# {binary}  {svg}  profile: {profile}")
print(f"| phase | frames | cpu median ms | cpu p95 ms | ui median ms | ui p95 ms | solving frames |")
print(f"|---|---:|---:|---:|---:|---:|---:|")
for name, a, b in zip(names.split(), map(int, starts.split()), map(int, ends.split())):
    ph = [r for r in rows[a:b] if len(r) == 3]
    ui = [float(r[0]) for r in ph]
    cpu = [float(r[1]) for r in ph]
    solving = sum(r[2] == "1" for r in ph)
    note = ""
    if name == "solve" and ph and ph[-1][2] == "1":
        note = " (still solving at the end)"
    print(f"| {name} | {len(ph)} | {pct(cpu, .5):.1f} | {pct(cpu, .95):.1f} | "
          f"{pct(ui, .5):.1f} | {pct(ui, .95):.1f} | {solving}{note} |")
PY
