#!/usr/bin/env bash
# Builds the npm package of <wirepass-viewer> into OUT (default web/package): the viewer crate
# for the browser, its wasm-bindgen bindings, the element's module and types, package.json,
# and the demo page (web/element/index.html, served from the package). Prints the size of the
# WebAssembly, raw and gzipped. Needs the wasm32 target and wasm-bindgen-cli (see the README).
set -euo pipefail
web="$(cd "$(dirname "$0")" && pwd)"
out="${1:-$web/package}"
target="${CARGO_TARGET_DIR:-$web/../target}"
cargo build -p wirepass-web --release --target wasm32-unknown-unknown
rm -rf "$out"
wasm-bindgen --target web --out-dir "$out" "$target/wasm32-unknown-unknown/release/wirepass_web.wasm"
cp "$web"/element/{wirepass-viewer.js,wirepass-viewer.d.ts,package.json,README.md,index.html} "$out/"
wasm="$out/wirepass_web_bg.wasm"
echo "package: $out; wasm $(wc -c <"$wasm") bytes, gzipped $(gzip -9 -c "$wasm" | wc -c) bytes"
