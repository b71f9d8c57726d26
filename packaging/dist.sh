#!/usr/bin/env bash
# Builds a release binary and packs it with its desktop integration into
#   dist/galvoplan-VERSION-ARCH-linux.tar.gz
# Usage: packaging/dist.sh [--headless]   (--headless: CLI only, no GUI dependencies)
# The archive unpacks into one folder with bin/, share/ and install.sh (PREFIX=~/.local by default).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/galvoplan-target}"
features=()
flavour=""
if [ "${1:-}" = "--headless" ]; then
  features=(--no-default-features)
  flavour="-headless"
fi
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n1)
arch=$(uname -m)
name="galvoplan-$version-$arch-linux$flavour"
cargo build --release --locked "${features[@]}"
stage=$(mktemp -d)
root="$stage/$name"
install -Dm755 "$CARGO_TARGET_DIR/release/galvoplan" "$root/bin/galvoplan"
install -Dm644 packaging/linux/galvoplan.desktop "$root/share/applications/galvoplan.desktop"
install -Dm644 packaging/linux/galvoplan.svg "$root/share/icons/hicolor/scalable/apps/galvoplan.svg"
install -Dm644 packaging/linux/io.github.galvoplan.galvoplan.metainfo.xml \
  "$root/share/metainfo/io.github.galvoplan.galvoplan.metainfo.xml"
install -Dm644 packaging/linux/galvoplan-mime.xml "$root/share/mime/packages/galvoplan.xml"
for f in assets/profiles/*.toml; do install -Dm644 "$f" "$root/share/galvoplan/profiles/$(basename "$f")"; done
for f in assets/examples/*.svg assets/examples/*.toml; do install -Dm644 "$f" "$root/share/galvoplan/examples/$(basename "$f")"; done
for f in README.md LICENSE-MIT LICENSE-APACHE docs/ARCHITECTURE.md docs/BENCHMARKS.md \
  assets/fonts/DejaVuSans-LICENSE.txt; do
  install -Dm644 "$f" "$root/share/doc/galvoplan/$(basename "$f")"
done
install -Dm755 packaging/install.sh "$root/install.sh"
mkdir -p dist
tar -C "$stage" -czf "dist/$name.tar.gz" "$name"
rm -rf "$stage"
"$CARGO_TARGET_DIR/release/galvoplan" --version
echo "dist/$name.tar.gz"
