#!/usr/bin/env bash
# scripts/make-scene, the generator of large scenes: the same arguments give
# the same bytes, another seed another forest, and what it writes is a
# scene flatrad reads and solves with the segments asked for (a forest of N
# segments: 4 walls and K lamps lit on one side, N - 4 - K two-sided
# blockers; a round room: N walls lit inside, nothing that can block).
# Usage: make_scene_test.sh FLATRAD MAKE_SCENE
set -euo pipefail
flatrad=$1
make_scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

python3 "$make_scene" 300 --seed 3 > "$tmp/a.json"
python3 "$make_scene" 300 --seed 3 > "$tmp/b.json"
cmp "$tmp/a.json" "$tmp/b.json"
python3 "$make_scene" 300 --seed 4 > "$tmp/c.json"
if cmp -s "$tmp/a.json" "$tmp/c.json"; then
    echo "make-scene: seeds 3 and 4 gave the same scene" >&2
    exit 1
fi
python3 "$make_scene" 300 --seed 3 --density 30 --lamps 3 > "$tmp/d.json"
python3 "$make_scene" 500 --round > "$tmp/r.json"

# expect FILE PATCHES ZERO_QUERIES: solves FILE, checks the patch count, the
# energy balance's being reported, and (ZERO_QUERIES 1) that no visibility
# query was made.
expect() {
    "$flatrad" solve "$1" --eps 1 --quiet -o "$1.result"
    python3 - "$1.result" "$2" "$3" <<'PY'
import json, sys
result, patches, zero = json.load(open(sys.argv[1])), int(sys.argv[2]), sys.argv[3] == "1"
got = len(result["patches"])
assert got == patches, f"{sys.argv[1]}: {got} patches, expected {patches}"
assert all(b == b and b >= 0 for b in result["totals"]["balance"]), "balance not reported"
queries = result["stats"]["visibility"]["queries"]
assert not zero or queries == 0, f"{sys.argv[1]}: {queries} visibility queries in a convex room"
assert zero or queries > 0, f"{sys.argv[1]}: no visibility query in a forest"
PY
}
expect "$tmp/a.json" $((4 + 1 + 2 * (300 - 5))) 0
expect "$tmp/d.json" $((4 + 3 + 2 * (300 - 7))) 0
expect "$tmp/r.json" 500 1
echo "make-scene: deterministic, and its forests and round room solve with the patches expected"
