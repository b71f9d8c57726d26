#!/usr/bin/env sh
# Installs an unpacked galvoplan archive: PREFIX=/usr/local sudo ./install.sh (default ~/.local).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
prefix="${PREFIX:-$HOME/.local}"
mkdir -p "$prefix"
cp -R "$here/bin" "$here/share" "$prefix/"
command -v update-desktop-database >/dev/null 2>&1 && update-desktop-database -q "$prefix/share/applications" || true
command -v update-mime-database >/dev/null 2>&1 && update-mime-database "$prefix/share/mime" || true
echo "galvoplan installed under $prefix (binary: $prefix/bin/galvoplan)"
