# Sourced by scripts/check-motion.sh and scripts/check-otf.sh.
# A trajectory samples the plan on the profile's clock; a continuous plan's short marks fall between
# 1 ms samples, so those checks plan on a copy of the profile with a 1 ms scan-head clock.
clocked() { # profile.toml -> a copy in $OUT with [controller] clock_period_s = 0.001
  local c="$OUT/$(basename "$1" .toml)-clock-1ms.toml"
  if grep -q '^\[controller\]' "$1"; then
    sed 's/^\[controller\]/[controller]\nclock_period_s = 0.001/' "$1" >"$c"
  else
    { cat "$1"; printf '\n[controller]\nclock_period_s = 0.001\n'; } >"$c"
  fi
  echo "$c"
}
