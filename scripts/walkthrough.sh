#!/usr/bin/env bash
# An operator's walkthrough of the GUI, replayed headless: starts the release build on its own
# Xvfb display, drives it with xdotool and saves a PNG screenshot after each step, with
# steps.txt listing "NN-name.png: what the step did / what to look at". Run it after a GUI
# change and look at every picture. About 80 s.
#
#   scripts/walkthrough.sh [BINARY]
#
# BINARY defaults to ${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan.
# Environment (all optional):
#   OUT          folder for the screenshots, steps.txt and app.log (default
#                /tmp/galvoplan-walkthrough; its old PNGs are removed first)
#   STEPS        which sections to replay (default "oversize texture isw dxf cylinder")
#   SHARED       the shared bench folder (default ../shared/bench beside the repository);
#                a section whose files are missing is skipped, and steps.txt says so
#   DISPLAY_NUM  the X display number for this script's Xvfb (default 77; must be free)
#
# Sections:
#   oversize  assets/examples/oversize.svg: opened; F (fit); a left drag on empty space (pan);
#             hover tooltips of a geometry and of the disabled Run HHA; the advice followed
#             (Split oversize geometries + Re-place automatically); hover a field; Run HHA;
#             the metrics; the Compare tab
#   texture   SHARED/texture/texture-3043.svg, texture.toml loaded through Machine profile >
#             Load TOML…; Motion "On the fly"; Run HHA; the status bar at ~2 s and ~6 s; Cancel
#   isw       SHARED/instances/ISW-1017.svg: Run HHA (step-and-scan), Motion "On the fly",
#             Run HHA again (motion plots); Compare; both again in 1500 x 1000 and 1280 x 720
#   dxf       tests/data/dxf/entities-inch.dxf (layers CUT, ENGRAVE, BLOCKS, 0): layer colours
#   cylinder  assets/examples/sleeve.svg (a tube's unrolled surface) on the built-in rotary
#             machine: its advice; Cylinder diameter 40 mm (strips, wrap lines), F; Run HHA
#             (motion plots with X and A); the Time slider mid-job (strip, spot, "A …°");
#             diameter 30 mm, too small for the drawing: its words and the disabled Run HHA
# Each section starts a fresh GUI session (its own empty HOME: no stored preferences).
#
# Every coordinate below is a control in the default layout of a 1600 x 1000 window at egui's
# default scale; when the layout changes, look at the screenshots and move the constants.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}
OUT=${OUT:-/tmp/galvoplan-walkthrough}
STEPS=${STEPS:-oversize texture isw dxf cylinder}
SHARED=$(realpath -m "${SHARED:-$ROOT/../shared/bench}")
DISPLAY_NUM=${DISPLAY_NUM:-77}
W=1600 H=1000                # the screen, and the window's size unless a step resizes it

missing=()
command -v Xvfb >/dev/null || missing+=(xvfb)
command -v xdotool >/dev/null || missing+=(xdotool)
command -v import >/dev/null || missing+=(imagemagick)
if [ ${#missing[@]} -gt 0 ]; then
  echo "walkthrough: ${missing[*]} missing; install with:" >&2
  echo "  sudo apt-get install -y ${missing[*]}" >&2
  exit 2
fi
if [ ! -x "$BIN" ]; then
  echo "walkthrough: no galvoplan at $BIN (cargo build --release, or pass the binary)" >&2
  exit 2
fi
BIN=$(realpath "$BIN")

# --- the layout: screen positions (px) of controls in a 1600 x 1000 window -------------------
TAB_SOLVER="136 62"          # left panel tabs: "Solver settings"
TAB_PROFILE="248 62"         #   "Machine profile"
TAB_CYLINDER="39 85"         #   "Cylinder" (the fifth tab, wrapped to a second row)
MOTION_COMBO="115 186"       # Solver settings: the "Motion" combo box
MOTION_OTF="185 260"         #   its open list: "On the fly (stage moves while marking)"
SPLIT_OVERSIZE="15 255"      # Solver settings: "Split oversize geometries (on re-place)"
LOAD_TOML="55 200"           # Machine profile: "Load TOML…" (below the machine's two-line name)
MACHINE_COMBO="205 123"      # Machine profile: the "Machine" combo box
MACHINE_ROTARY="255 250"     #   its open list: "Rotary machine: 300 mm X stage, A axis under it, …"
CYL_DIAMETER="196 216"       # Cylinder: the "Cylinder diameter (mm)" field
BTN_REPLACE="617 37"         # toolbar: "Re-place automatically"
BTN_RUN_HHA="745 37"         # toolbar: "Run HHA" (it has no keyboard shortcut)
BTN_WORKBENCH="1090 37"      # toolbar: the "Workbench" tab
BTN_COMPARE="1174 37"        # toolbar: the "Compare" tab
BTN_FIT_VIEW="889 68"        # Compare tab, its top row: "Fit view" (with two plans A and B)
PROMPT_PATH="790 519"        # the path field of the in-window "Load a machine profile" prompt
BTN_CANCEL="186 987"         # status bar while a job runs: "Cancel" (right of the progress bar)
TIME_SLIDER="699 68"         # playback row above the canvas: the Time slider's handle at t = 0
TIME_MID="880 68"            #   the same slider about half way along (mid-job)
CANVAS="820 520"             # the middle of the work-area canvas
AWAY="1450 960"              # the right panel's empty bottom: no hover tooltip

# --- X server, output ------------------------------------------------------------------------
if [ -e "/tmp/.X$DISPLAY_NUM-lock" ]; then
  echo "walkthrough: display :$DISPLAY_NUM is taken (/tmp/.X$DISPLAY_NUM-lock); set DISPLAY_NUM" >&2
  exit 1
fi
export DISPLAY=":$DISPLAY_NUM"
unset DBUS_SESSION_BUS_ADDRESS       # no desktop portal: the app asks for paths in its window
WORK=$(mktemp -d)
export XDG_RUNTIME_DIR="$WORK/xdg"   # empty: no session bus socket either
mkdir -m 700 "$XDG_RUNTIME_DIR"
mkdir -p "$OUT"
rm -f "$OUT"/[0-9][0-9]-*.png "$OUT/steps.txt" "$OUT/app.log"
APP_PID="" XVFB_PID="" WIN=""
cleanup() {
  if [ -n "$APP_PID" ]; then kill "$APP_PID" 2>/dev/null || true; wait "$APP_PID" 2>/dev/null || true; fi
  if [ -n "$XVFB_PID" ]; then kill "$XVFB_PID" 2>/dev/null || true; wait "$XVFB_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT
# -noreset: no server reset (and refused connections meanwhile) when the last client leaves
Xvfb "$DISPLAY" -screen 0 "${W}x${H}x24" -nolisten tcp -noreset >"$WORK/xvfb.log" 2>&1 &
XVFB_PID=$!
for _ in $(seq 1 50); do xdotool getmouselocation >/dev/null 2>&1 && break; sleep 0.1; done
if ! kill -0 "$XVFB_PID" 2>/dev/null || ! xdotool getmouselocation >/dev/null 2>&1; then
  echo "walkthrough: Xvfb did not start on $DISPLAY:" >&2
  cat "$WORK/xvfb.log" >&2
  exit 1
fi

# --- helpers ---------------------------------------------------------------------------------
say() { echo "walkthrough: $*" >&2; }
want() { case " $STEPS " in *" $1 "*) return 0 ;; esac; return 1; }
T0=$(date +%s)
N=0
# shot NAME "what the step did / what to look at": the whole screen into OUT/NN-NAME.png
shot() {
  N=$((N + 1))
  local f
  f=$(printf '%02d-%s.png' "$N" "$1")
  sleep 0.3
  import -window root "$OUT/$f"
  printf '%s: %s\n' "$f" "$2" >>"$OUT/steps.txt"
  say "$f ($(($(date +%s) - T0)) s)"
}
skip() { printf 'skipped: %s\n' "$1" >>"$OUT/steps.txt"; say "skipped: $1"; }
move() { xdotool mousemove $1; sleep 0.3; }                         # move "X Y"
click() { xdotool mousemove $1; sleep 0.2; xdotool click 1; sleep 0.5; }   # click "X Y"
away() { move "$AWAY"; }
key() { xdotool windowfocus --sync "$WIN" 2>/dev/null || true; xdotool key "$@"; sleep 0.5; }
# drag X1 Y1 X2 Y2: a left-button drag in small steps (egui sees a drag, not a jump)
drag() {
  local x1=$1 y1=$2 x2=$3 y2=$4 i
  xdotool mousemove "$x1" "$y1"; sleep 0.2
  xdotool mousedown 1; sleep 0.1
  for i in $(seq 1 10); do
    xdotool mousemove $((x1 + (x2 - x1) * i / 10)) $((y1 + (y2 - y1) * i / 10)); sleep 0.05
  done
  sleep 0.2; xdotool mouseup 1; sleep 0.5
}
# sleep_until T0 S: sleep until S seconds after the time T0 (date +%s.%N)
sleep_until() {
  sleep "$(awk -v t0="$1" -v s="$2" -v now="$(date +%s.%N)" \
    'BEGIN { d = t0 + s - now; printf "%.2f", (d > 0 ? d : 0) }')"
}
cpu_ticks() { awk '{print $14 + $15}' "/proc/$APP_PID/stat" 2>/dev/null || echo 0; }
# wait_quiet MAX: until the app has used < 0.05 s of CPU per half second for 1 s in a row, at
# most MAX s (opening, placing and solving run in its process; an idle egui app uses none)
wait_quiet() {
  local max=$1 hz quiet=0 t=0 prev now
  hz=$(getconf CLK_TCK)
  prev=$(cpu_ticks)
  while [ "$t" -lt $((max * 2)) ]; do
    sleep 0.5; t=$((t + 1))
    kill -0 "$APP_PID" 2>/dev/null || { say "the app exited; its log:"; cat "$OUT/app.log" >&2; exit 1; }
    now=$(cpu_ticks)
    if [ $((now - prev)) -le $((hz / 20)) ]; then quiet=$((quiet + 1)); else quiet=0; fi
    prev=$now
    [ "$quiet" -ge 2 ] && return 0
  done
  say "still busy after $max s; going on"
}
resize() { xdotool windowmove "$WIN" 0 0 windowsize "$WIN" "$1" "$2"; sleep 1; }
# start_gui FILE: a fresh GUI session (empty HOME) on FILE, its window filling the screen
start_gui() {
  stop_gui
  local home
  home=$(mktemp -d "$WORK/home.XXXX")
  echo "=== galvoplan $1" >>"$OUT/app.log"
  (cd "$ROOT" && exec env HOME="$home" LIBGL_ALWAYS_SOFTWARE=1 "$BIN" "$1") >>"$OUT/app.log" 2>&1 &
  APP_PID=$!
  WIN=""
  for _ in $(seq 1 100); do
    WIN=$(xdotool search --pid "$APP_PID" --name galvoplan 2>/dev/null | head -1 || true)
    [ -n "$WIN" ] && break
    sleep 0.2
  done
  [ -n "$WIN" ] || { say "no galvoplan window; its log:"; cat "$OUT/app.log" >&2; exit 1; }
  resize "$W" "$H"
  wait_quiet 60
}
stop_gui() {
  [ -n "$APP_PID" ] || return 0
  kill "$APP_PID" 2>/dev/null || true
  wait "$APP_PID" 2>/dev/null || true
  APP_PID=""
}
# choose_on_the_fly: Solver settings > Motion > On the fly (fields are re-placed at once when
# the old ones leave geometries uncovered)
choose_on_the_fly() {
  click "$TAB_SOLVER"
  click "$MOTION_COMBO"
  click "$MOTION_OTF"
  wait_quiet 60
}

# --- sections --------------------------------------------------------------------------------
oversize() {
  start_gui assets/examples/oversize.svg
  away
  shot oversize-opened "oversize.svg just opened (built-in 70 mm field): canvas legend, the right panel's advice (dashed purple = larger than a field, magenta halo = not covered; words only, no advice buttons), the red problem line, the status bar"

  move "$CANVAS"; key f
  away
  shot oversize-fit "F pressed: the machine's whole reach (base stroke + half a field) fits the canvas"

  drag 737 645 857 725         # from inside the ring, on no geometry, 120 px right, 80 px down
  away
  shot oversize-panned "left drag on empty space (737,645) -> (857,725): the view pans 120 px right and 80 px down; nothing is selected or moved"

  move "$CANVAS"; key f
  move "820 749"               # the ring's rim (bottom of the 180 mm circle), fitted view
  sleep 0.7
  shot oversize-hover-geometry "pointer on the ring's rim: the hover tooltip (position, geometry, why no field holds it)"

  move "$BTN_RUN_HHA"
  sleep 1
  shot oversize-hha-disabled "pointer on the disabled Run HHA: its tooltip says why it cannot run"

  # the advice's first remedy: tick Split oversize geometries, press Re-place automatically
  click "$TAB_SOLVER"
  click "$SPLIT_OVERSIZE"
  click "$BTN_REPLACE"
  wait_quiet 30
  click "1333 192"             # right panel: the "Warnings (n)" header, opened
  away
  shot oversize-replaced "Split oversize geometries ticked, Re-place automatically pressed: fields placed, the large shapes cut at field borders; the Warnings list opened; status bar"

  move "806 622"               # inside field 12 (middle of the canvas), on no geometry
  sleep 0.7
  shot oversize-hover-field "pointer inside field 12: the field's hover tooltip (the canvas has no hover highlight)"

  click "$BTN_RUN_HHA"
  wait_quiet 60
  away
  shot oversize-hha "Run HHA finished: the plan on the canvas (field numbers now in visiting order), Plans and Metrics in the right panel, the status bar's summary"

  click "$BTN_COMPARE"
  away
  shot oversize-compare "Compare tab with the one plan: plan A/B pickers, Side by side / Overlay, the canvas, the metrics table below"
}

texture() {
  local tex=$SHARED/texture t_run
  if [ ! -f "$tex/texture-3043.svg" ] || [ ! -f "$tex/texture.toml" ]; then
    skip "texture: $tex/texture-3043.svg or texture.toml missing"
    return 0
  fi
  start_gui "$tex/texture-3043.svg"
  click "$TAB_PROFILE"
  click "$LOAD_TOML"
  sleep 0.5
  click "$PROMPT_PATH"         # egui does not focus the path field by itself
  key ctrl+a
  xdotool type --delay 10 "$tex/texture.toml"
  away
  shot texture-load-prompt "texture-3043.svg opened (built-in profile, 25 fields); Machine profile > Load TOML…: the in-window path prompt (no desktop portal) with texture.toml typed in"

  key Return
  wait_quiet 30
  away
  shot texture-profile-loaded "Enter: texture.toml loaded (4 mm field): the fields keep their centres but shrink, nearly everything is uncovered (magenta)"

  choose_on_the_fly
  away
  shot texture-otf "Solver settings > Motion: On the fly: the fields are re-placed at once (one per cell)"

  move "$BTN_RUN_HHA"
  t_run=$(date +%s.%N)
  xdotool click 1
  away
  sleep_until "$t_run" 2
  shot texture-hha-2s "Run HHA, ~2 s in: the status bar's progress bar, elapsed time, Cancel and progress words"
  sleep_until "$t_run" 6
  shot texture-hha-6s "Run HHA, ~6 s in: the status bar's progress words"
  move "$BTN_CANCEL"
  xdotool click 1
  shot texture-cancel "Cancel pressed (~6.5 s): the status bar right after"
  wait_quiet 60
  away
  shot texture-cancelled "after the cancel: what was kept (a '(stopped)' plan or none; it depends on when the cancel lands) and the status bar's words"
}

isw() {
  local isw=$SHARED/instances/ISW-1017.svg size
  if [ ! -f "$isw" ]; then
    skip "isw: $isw missing"
    return 0
  fi
  start_gui "$isw"
  click "$BTN_RUN_HHA"
  wait_quiet 90
  away
  shot isw-hha "ISW-1017.svg opened (built-in profile), Run HHA (step-and-scan) finished: plan, metrics"

  choose_on_the_fly
  click "$BTN_RUN_HHA"
  wait_quiet 120
  away
  shot isw-hha-otf "Motion: On the fly, Run HHA again: the second plan, the motion plots under the canvas (1600 x 1000)"

  click "$BTN_COMPARE"
  away
  shot isw-compare "Compare tab: step-and-scan (A) and on the fly (B) side by side, the metrics table (1600 x 1000)"

  # the same two views in smaller windows (the rest of the screen stays black)
  for size in "1500 1000" "1280 720"; do
    set -- $size
    resize "$1" "$2"
    away
    shot "isw-compare-$1x$2" "Compare tab in a $1 x $2 window (not refitted): what is cut off, what wraps"
    click "$BTN_FIT_VIEW"
    away
    shot "isw-compare-$1x$2-fit" "the same after Compare's Fit view button"
    click "$BTN_WORKBENCH"
    move "$CANVAS"; key f
    away
    shot "isw-plots-$1x$2" "Workbench in a $1 x $2 window, F pressed: canvas, motion plots, metrics"
    click "$BTN_COMPARE"
  done
}

dxf() {
  local dxf=tests/data/dxf/entities-inch.dxf
  if [ ! -f "$ROOT/$dxf" ]; then
    skip "dxf: $dxf missing"
    return 0
  fi
  start_gui "$dxf"
  away
  shot dxf-opened "entities-inch.dxf opened: the Layers panel (a row per layer with its colour), the canvas in those colours, the warnings (layer 0 holds only skipped entities)"
  move "$CANVAS"; key f
  away
  shot dxf-fit "F pressed: the whole reach with the drawing"
}

cylinder() {
  start_gui assets/examples/sleeve.svg
  click "$TAB_PROFILE"
  click "$MACHINE_COMBO"
  click "$MACHINE_ROTARY"
  wait_quiet 30
  away
  shot cylinder-rotary "sleeve.svg (a tube's unrolled surface, 120 x 110 mm) opened; Machine profile > Machine: the built-in rotary machine (A axis): the right panel's advice says the machine turns the part on its A axis and to give the part's diameter in the Cylinder section"

  click "$TAB_CYLINDER"
  click "$CYL_DIAMETER"        # egui focuses the field; key focuses the window for the typing
  key ctrl+a
  xdotool type --delay 10 40
  key Return
  wait_quiet 30
  away
  shot cylinder-40 "Cylinder tab, diameter 40 + Enter: 'Cylinder ⌀40 mm: strips in focus are 11.35 mm high …' on the left; 25 strips about 70 x 11 mm on the canvas; the dashed blue wrap lines (0°, 1 turn at 125.7 mm); Warnings (1)"

  move "$CANVAS"; key f
  away
  shot cylinder-40-fit "F pressed: the whole reach, with the wrap lines at 0°, 1 turn (125.7 mm) and 2 turns (251.3 mm)"

  click "$BTN_RUN_HHA"
  wait_quiet 60
  away
  shot cylinder-hha "Run HHA finished: the plan on the strips, the metrics, the 'Motion plots (axis speeds)' plot under the canvas with X and A"

  # the Time slider's handle from t = 0 to mid-job (each "X Y" is two of drag's four numbers)
  # shellcheck disable=SC2086
  drag $TIME_SLIDER $TIME_MID
  away
  shot cylinder-playback "Time slider dragged to about half the job: the strip being marked outlined and the laser spot on the drawing, the readout 'marking stroke … stage (…) mm, A …°; laser on', the time line on the motion plot"

  click "$TAB_CYLINDER"
  click "$CYL_DIAMETER"
  key ctrl+a
  xdotool type --delay 10 30
  key Return
  wait_quiet 30
  away
  shot cylinder-30 "diameter 30 + Enter: 'Cylinder ⌀30 mm cannot be marked: the drawing spans 106.00 mm around the cylinder, more than its circumference 94.25 mm …' on the left, the red status bar; the plan is marked stale"

  move "$BTN_RUN_HHA"
  sleep 1
  shot cylinder-hha-disabled "pointer on the disabled Run HHA: its tooltip gives the same reason (the drawing spans 106.00 mm around a 94.25 mm circumference)"
}

say "$BIN; screenshots in $OUT"
for section in oversize texture isw dxf cylinder; do
  if want "$section"; then
    "$section"
    stop_gui
  fi
done
say "done in $(($(date +%s) - T0)) s: $N screenshots, listed in $OUT/steps.txt"
