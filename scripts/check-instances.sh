#!/usr/bin/env bash
# Plans every shared benchmark instance and runs the independent checker on it.
# Usage: scripts/check-instances.sh [galvoplan plan options...]   (e.g. --fields paper --algo hha)
# Needs ../shared (the project's shared folder) and a release build of galvoplan.
set -uo pipefail
cd "$(dirname "$0")/.."
SHARED="${SHARED:-../shared}"
BIN="${GALVOPLAN:-${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}/release/galvoplan}"
# shellcheck disable=SC1091
source "$SHARED/tools/setup.sh" >/dev/null
out=$(mktemp -d)
fails=0
for f in "$SHARED"/bench/instances/*.svg; do
  n=$(basename "$f" .svg)
  if ! "$BIN" plan "$f" -o "$out/$n.gcode" --report "$out/$n.json" "$@" 2>"$out/$n.err"; then
    echo "$n: plan failed: $(cat "$out/$n.err")"; fails=$((fails + 1)); continue
  fi
  line=$("$CHECK_PY" "$SHARED/tools/check_job.py" "$f" "$out/$n.gcode" --report "$out/$n.json")
  ok=$(echo "$line" | python3 -c 'import json,sys; d=json.load(sys.stdin); print("ok" if d["ok"] else "FAIL " + "; ".join(d["fails"]), d.get("idle_mm"), d.get("fields"))')
  echo "$n: $ok"
  case "$ok" in ok*) ;; *) fails=$((fails + 1));; esac
done
rm -rf "$out"
echo "check-instances: $fails failing"
[ "$fails" -eq 0 ]
