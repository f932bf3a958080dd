#!/usr/bin/env bash
# Calibration of recognise()'s combined score (landmarks.recognition.score_* and accept_score)
# WITHOUT the val set: grocery-packages/train is split into
#   fit/   the first three quarters of each class's photos (sorted by name: a contiguous block,
#          so held-out views are not the immediate neighbours of training views), minus the
#          classes in CALIB_UNKNOWN, which are left out of training altogether;
#   held/  the last quarter of every known class (known images) and all photos of the
#          CALIB_UNKNOWN classes (unknown images, to be rejected).
# A model trained on fit/ is run on held/ with every shortlisted class verified, the evidence of
# each candidate is written per image (--details), and fit_score.py fits the weights by logistic
# regression (the true class against the other candidates, known images only) and prints the
# top-1 / unknown-rejection trade-off for accept_score on held/.
# The CALIB_UNKNOWN classes differ from bench/recognition/run.sh's excluded classes.
#
# Usage: bench/recognition/calibrate.sh [SKETCHNAV_BINARY] [GROCERY_DIR] [OUT_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
BIN=${1:-$root/build/release/apps/sketchnav}
DATA=${2:-${SKETCHNAV_DATA:-$root/../shared/data}/grocery-packages}
OUT=${3:-$root/runs/bench-recognition/calib}
CALIB_UNKNOWN="Arla-Medium-Fat-Milk God-Morgon-Apple-Juice Alpro-Vanilla-Soyghurt Tropicana-Juice-Smooth"
mkdir -p "$OUT"

if [ ! -d "$OUT/fit" ]; then
  for dir in "$DATA"/train/*/*/; do
    cls=$(basename "$dir")
    group=$(basename "$(dirname "$dir")")
    mapfile -t photos < <(find "$dir" -maxdepth 1 -name '*.jpg' | sort)
    n=${#photos[@]}
    keep=$(((n * 3 + 3) / 4))
    unknown=0
    for u in $CALIB_UNKNOWN; do [ "$u" = "$cls" ] && unknown=1; done
    mkdir -p "$OUT/held/$group/$cls"
    for i in "${!photos[@]}"; do
      if [ $unknown = 1 ] || [ "$i" -ge "$keep" ]; then
        ln -sf "${photos[$i]}" "$OUT/held/$group/$cls/"
      else
        mkdir -p "$OUT/fit/$group/$cls"
        ln -sf "${photos[$i]}" "$OUT/fit/$group/$cls/"
      fi
    done
  done
fi

PROBE=$(find "$DATA/val" -name '*.jpg' | sort | sed -n 1p)  # not head: SIGPIPE under pipefail
[ -f "$OUT/fit.slm" ] && "$BIN" recognise --model "$OUT/fit.slm" "$PROBE" >/dev/null 2>&1 ||
  "$BIN" --json train --landmarks "$OUT/fit" -o "$OUT/fit.slm" > "$OUT/train_fit.json"

# Evidence of every shortlisted class (no photo budget), on photos and on 640x480 frames.
"$BIN" --json recognise --model "$OUT/fit.slm" --eval "$OUT/held" --details "$OUT/held_photos.jsonl" \
  --set landmarks.recognition.max_verified_photos=0 > "$OUT/eval_held_photos.json"
python3 "$here/fit_score.py" "$OUT/held_photos.jsonl" | tee "$OUT/fit_photos.txt"
