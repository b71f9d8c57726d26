#!/usr/bin/env bash
# Runs galvoplan's whole test suite on a fresh Debian machine with the Rust toolchain.
# Installs the system packages the build and tests need (only the missing ones), then runs the
# tests in debug with a target dir shared outside the clone.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}"

# Build: a C compiler for build scripts. The GUI loads X11/Wayland/EGL/fontconfig at run time
# only; the kittest GUI tests run headless and need none of them.
need=()
for pkg in gcc libc6-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${need[@]}"
fi

start=$(date +%s)
# A clean CI build gains nothing from incremental data (it only writes it).
if [ "${CI:-}" = true ]; then export CARGO_INCREMENTAL=0; fi
# Lints first: formatting, then clippy with warnings as errors (no unwrap/expect outside tests),
# on the shipped features (GUI and rerun) and on the headless core alone (no GUI, no rerun), which
# so also proves that the core builds without them.
rustup component list --installed 2>/dev/null | grep -q '^clippy' || rustup component add clippy rustfmt
cargo fmt --all -- --check
cargo clippy --all-targets -- -D warnings
cargo clippy --no-default-features --lib --bins -- -D warnings
# Everything, in one test build of the shipped features: library, CLI, integration, rerun
# recording and GUI (egui_kittest) tests.
cargo test --all-targets
# LinuxCNC itself reads and runs galvoplan's programs on a headless simulated machine (installs
# linuxcnc-uspace without recommends when missing: 123 packages, 80 MB; about 2 min of runs).
# The binary is the one the integration tests just built (a plain `cargo build` would unify
# features without the dev-dependencies and rebuild for 4 min).
bash scripts/check-linuxcnc.sh "$CARGO_TARGET_DIR/debug/galvoplan"
echo "test.sh: done in $(( $(date +%s) - start )) s"
