#!/usr/bin/env bash
# Builds the Debian package with cargo-deb (assets and control fields: [package.metadata.deb] in
# Cargo.toml) and prints its path, $CARGO_TARGET_DIR/debian/galvoplan_VERSION-1_ARCH.deb.
# Usage: packaging/deb.sh        then: sudo apt install <printed path>   (or sudo dpkg -i)
# Installs cargo-deb first when it is missing. Packs the working tree as it is (a warning says when
# it has uncommitted changes).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}"
if ! cargo deb --version >/dev/null 2>&1; then
  echo "deb.sh: installing cargo-deb" >&2
  cargo install cargo-deb --locked
fi
if command -v git >/dev/null 2>&1 && [ -n "$(git status --porcelain 2>/dev/null)" ]; then
  echo "deb.sh: warning: the working tree has uncommitted changes; they go into the package" >&2
fi
# the same release build as packaging/dist.sh (GUI, default features), then cargo-deb packs it
# without building again; it finds the binary under $CARGO_TARGET_DIR (the target/release/ asset
# paths in Cargo.toml stand for it)
cargo build --release --locked
deb=$(cargo deb --no-build | tail -n1)
if command -v dpkg-deb >/dev/null 2>&1; then dpkg-deb -f "$deb" Package Version Depends >&2; fi
echo "$deb"
