#!/bin/sh
# The objectness benchmark of issue #5: our union (and CCS / SCS alone) against BING,
# Selective Search (fast), EdgeBoxes on Sobel edges and a sliding-window grid, on the two VOC-
# layout sets in shared/data. One thread (main() sets cv::setNumThreads(1)), native image size.
#
#   bench/objectness/propose_eval.sh [SKETCHNAV_BINARY] [OUTPUT_DIR]
#
# Writes OUTPUT_DIR/<set>.json (the `propose --eval --json` object) and prints a table.
# Takes ~15 min on an idle core, most of it Selective Search on raccoon (≈2.5 s per image).
# Environment overrides (defaults = the full benchmark): METHODS, SETS, MAX_IMAGES (0 = all),
# PART (all / first-half / second-half), OURS_SET (global options for ours, e.g.
# "--set objectness.use_edgeboxes=true").
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${1:-$root/build/release/apps/sketchnav}
out=${2:-$root/runs/propose-eval-$(date -u +%Y%m%dT%H%M%SZ)}
data=${SKETCHNAV_DATA:-$root/../shared/data}
methods=${METHODS:-ours,ccs,scs,bing,selective-search,selective-search-as-returned,selective-search-random,edgeboxes,sliding-window}
sets=${SETS:-voc07-mini raccoon}
max_images=${MAX_IMAGES:-0}
part=${PART:-all}  # all, first-half (dev) or second-half (held out)
mkdir -p "$out"
for set in $sets; do
  echo "== $set" >&2
  "$bin" ${OURS_SET:-} propose --eval "$data/$set" --methods "$methods" --windows 10,100,1000 \
    --max-images "$max_images" --part "$part" --json > "$out/$set.json"
done
if command -v python3 >/dev/null 2>&1; then
  for set in $sets; do python3 "$here/table.py" "$out/$set.json"; done
fi
echo "results in $out" >&2
