#!/usr/bin/env bash
# The floor of the SLIM patch evaluation's frame on this machine (issue 16,
# docs/slim.md "The floor"): the same frame with the two rectangle passes'
# fragment work taken away, to tell what any cheaper evaluation inside them
# could save from what drawing the rectangles, blending their targets and
# the full-screen passes cost anyway.
#
#   bench/slim_floor.sh OUT MODEL.bslm [MODEL.bslm ...]
#
# Builds `beamcast` from HEAD twice in a scratch worktree, each time with
# one pass's fragment shader returning at its start with constant outputs:
#   floor_depth       slim_patch_depth.frag writes a constant nearest depth
#                     (every pixel a rectangle reaches is "covered"); its
#                     slim_depth time is that pass's floor (the accumulate
#                     and resolve then see a wrong surface: ignore them);
#   floor_accumulate  slim_patch_accumulate.frag, after its first read of
#                     the nearest depth, writes constants to its five
#                     targets (the real depth pass before it, so the same
#                     rectangles pass the early depth test); its
#                     slim_accumulate time is that pass's floor.
# then runs bench/compare_slim.py on build/bin/beamcast (the baseline,
# built from the same tree by the caller) and the two, interleaved, at
# zoom 1, into OUT/floor.txt. The floor of a frame is
#   floor_depth's slim_depth + floor_accumulate's slim_accumulate
#   + the baseline's slim_resolve, surfaces and tonemap.
# About 10 minutes on 2 cores (most of it the build).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OUT MODEL.bslm [MODEL.bslm ...]" >&2
  exit 1
fi
repo=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
out=$(realpath -m "$1")
shift
mkdir -p "$out"
base="$repo/build/bin/beamcast"
[ -x "$base" ] || { echo "slim_floor: build $base first (cmake --build build)" >&2; exit 1; }
tree=$(mktemp -d /tmp/slim_floor.XXXXXX)
cleanup() { git -C "$repo" worktree remove --force "$tree" >/dev/null 2>&1 || rm -rf "$tree"; }
trap cleanup EXIT
git -C "$repo" worktree add --detach "$tree" HEAD >/dev/null
cd "$tree"
cmake --preset default >/dev/null

# $1: shader file, $2: the line after which the early return goes (a
# regular expression matching one line), $3: the return's body.
floor_variant() {
  /usr/bin/python3 - "$1" "$2" "$3" <<'EOF'
import re, sys
path, after, body = sys.argv[1:]
text = open(path).read().split("\n")
hits = [i for i, line in enumerate(text) if re.search(after, line)]
if len(hits) != 1:
    sys.exit(f"slim_floor: {path}: {len(hits)} lines match {after!r}")
text.insert(hits[0] + 1, "  " + body + "  // slim_floor.sh")
open(path, "w").write("\n".join(text))
EOF
}

floor_variant shaders/slim_patch_depth.frag '^void main\(\) \{' \
  'out_near = 1.0 + 1e-3 * gl_FragCoord.x; out_radius = v_p2.w; return;'
cmake --build build --target beamcast >/dev/null
cp build/bin/beamcast "$out/beamcast_floor_depth"
git checkout -- shaders
floor_variant shaders/slim_patch_accumulate.frag 'if \(near >= 1e29\) discard;' \
  'out_albedo = vec4(1.0); out_field = vec4(near); out_weight = vec4(1.0); out_field2 = vec4(1.0); out_weight2 = vec4(1.0); return;'
cmake --build build --target beamcast >/dev/null
cp build/bin/beamcast "$out/beamcast_floor_accumulate"
git checkout -- shaders

models=()
for m in "$@"; do models+=(--model "$(realpath "$m")"); done
cd "$out"
/usr/bin/python3 "$repo/bench/compare_slim.py" --binary "baseline=$base" \
  --binary "floor_depth=$out/beamcast_floor_depth" \
  --binary "floor_accumulate=$out/beamcast_floor_accumulate" "${models[@]}" \
  --rounds "${ROUNDS:-5}" | tee "$out/floor.txt"
