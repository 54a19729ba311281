#!/usr/bin/env bash
# Times `wirepass drawing` on this machine's CPU and writes docs/drawing-times.md: for each case
# the median of RUNS runs (default 5) of each phase, and the size of what it wrote; and
# docs/drawing-fandisk.svg, the drawing the docs show.
#
#   bench/drawing.sh               RUNS narrows or widens the run
#
# It measures the commit checked out, so the tree must be clean; commit its output on its
# own. It takes about a minute.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "$(git status --porcelain --untracked-files=no)" ]; then
    echo "bench/drawing.sh measures a commit: commit or stash the changes first" >&2
    exit 1
fi
commit="$(git rev-parse --short HEAD)"
date="$(date -u +%F)"
runs="${RUNS:-5}"
cargo build --release --locked -p wirepass-cli
bin="${CARGO_TARGET_DIR:-target}/release/wirepass"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# name | scene and options (one line each)
cases=(
    "fandisk, feature edges, dashed hidden|tests/data/meshes/fandisk.obj --edges feature:30 --hidden dashed"
    "fandisk, front view to scale, solid hidden|tests/data/meshes/fandisk.obj --edges feature:30 --hidden solid --view front --scale 1:1"
    "teapot, all edges, dashed hidden|tests/data/meshes/teapot.obj --edges all --hidden dashed"
    "cube:1M, feature edges, dashed hidden|cube:1000000 --edges feature:30 --hidden dashed"
    "sphere:2M, outlines, dashed hidden|sphere:2000000 --edges feature:30 --hidden dashed"
    "200 instances of five meshes, feature edges, dashed hidden|bench/scenes/assembly-200.json --edges feature:30 --hidden dashed --view iso"
)

median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
field() { grep "^$1" "$2" | awk '{ print $(NF - 1) }'; }

{
    echo "# Drawing times"
    echo
    echo "\`wirepass drawing\` on this machine's CPU ($(nproc) cores), 800x600, median of $runs runs"
    echo "(\`--timings\`), commit $commit, $date; written by \`bench/drawing.sh\`. Each SVG"
    echo "has one path per run of a chain, so its size follows the lines in view, not the"
    echo "triangles."
    echo
    echo "| case | triangles | occluders ms | lines and visibility ms | write ms | total ms | paths | points | SVG bytes |"
    echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
} >"$out/drawing.md"
for c in "${cases[@]}"; do
    name="${c%%|*}"
    read -r -a args <<<"${c#*|}"
    for r in $(seq "$runs"); do
        "$bin" drawing "${args[@]}" -o "$out/d.svg" --timings 2>"$out/t$r.txt"
    done
    col() { for r in $(seq "$runs"); do field "$1" "$out/t$r.txt"; done | median; }
    summary="$(grep '^wrote' "$out/t1.txt")"
    paths="$(sed 's/.*(\([0-9]*\) paths.*/\1/' <<<"$summary")"
    points="$(sed 's/.* \([0-9]*\) points.*/\1/' <<<"$summary")"
    bytes="$(sed 's/.* \([0-9]*\) bytes.*/\1/' <<<"$summary")"
    triangles="$(sed 's/.* \([0-9]*\) triangles.*/\1/' <<<"$summary")"
    echo "| $name | $triangles | $(col occluders) | $(col 'lines and') | $(col 'write') | $(col total) | $paths | $points | $bytes |" \
        >>"$out/drawing.md"
    echo "$name: done" >&2
done
# The picture the docs show: what a drawing looks like.
"$bin" drawing tests/data/meshes/fandisk.obj --edges feature:30 --hidden dashed --view iso \
    --size 640x480 -o docs/drawing-fandisk.svg 2>/dev/null
{
    echo
    echo "fandisk, iso view, feature edges and dashed hidden lines (\`docs/drawing-fandisk.svg\`):"
    echo
    echo "![fandisk as an SVG drawing](drawing-fandisk.svg)"
} >>"$out/drawing.md"
cp "$out/drawing.md" docs/drawing-times.md
cat docs/drawing-times.md
