#!/usr/bin/env bash
# Landmark recognition benchmark on grocery-packages (issue #6): train on train/, evaluate on
# val/, one JSON file per configuration plus summary.json, so each part's contribution shows:
#   rootsift        RootSIFT + BoW/SVM + NN votes + geometric verification (the product)
#   rootsift_bow    the same model, BoW + linear SVM only (the classic pipeline)
#   sift, sift_bow  plain SIFT instead of RootSIFT
#   rootsift_1000   1000 SIFT keypoints per image instead of 500
#   windows         objectness windows (10 per image) instead of the whole image
#   frame           each photo letterboxed into a 640x480 frame, recognise + match timed
#   rejection       three classes left out of training: their val images must be rejected
#   demo            the product's 8-class demo set (share/landmarks) on all val photos in
#                   640x480 frames with match: 6 classes known, 14 unknown (to be rejected)
#
# Usage: bench/recognition/run.sh [SKETCHNAV_BINARY] [GROCERY_DIR] [OUT_DIR]
# Times are wall-clock ms (ms_mean) and the recognising thread's CPU ms (cpu_ms_mean) with
# OpenCV on one thread; the machine's load shows in the difference.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
BIN=${1:-$root/build/release/apps/sketchnav}
DATA=${2:-${SKETCHNAV_DATA:-$root/../shared/data}/grocery-packages}
OUT=${3:-$root/runs/bench-recognition}
EXCLUDED=Oatly-Oat-Milk,Yoggi-Vanilla-Yoghurt,Bravo-Orange-Juice
mkdir -p "$OUT"

train() {  # name, extra args...
  local name=$1; shift
  [ -f "$OUT/$name.slm" ] || "$BIN" --json train --landmarks "$DATA/train" -o "$OUT/$name.slm" "$@" \
    > "$OUT/train_$name.json"
}
evaluate() {  # name, model, extra args...
  local name=$1 model=$2; shift 2
  echo "eval $name" >&2
  "$BIN" --json recognise --model "$OUT/$model.slm" --eval "$DATA/val" "$@" > "$OUT/eval_$name.json"
}

train rootsift
train sift --plain-sift
train rootsift_1000 --max-features 1000
train rootsift_excluded --exclude "$EXCLUDED"
[ -f "$OUT/demo.slm" ] || "$BIN" --json train --landmarks "$root/share/landmarks" -o "$OUT/demo.slm" \
  > "$OUT/train_demo.json"

evaluate rootsift rootsift
evaluate rejection rootsift_excluded
evaluate frame rootsift --frame 640x480 --match
evaluate demo demo --frame 640x480 --match
evaluate rootsift_bow rootsift --no-verify
evaluate sift sift
evaluate sift_bow sift --no-verify
evaluate windows rootsift --windows 10
evaluate rootsift_1000 rootsift_1000

python3 - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
summary = {}
for f in sorted(os.listdir(out)):
    if f.startswith("eval_") and f.endswith(".json"):
        j = json.load(open(os.path.join(out, f)))
        summary[f[5:-5]] = {k: j.get(k) for k in ("images", "classes", "top1", "top1_ignoring_rejection", "top3", "rejected",
                            "false_rejected", "ms_mean", "cpu_ms_mean", "ms_p95")}
    if f.startswith("train_") and f.endswith(".json"):
        j = json.load(open(os.path.join(out, f)))
        summary.setdefault("training", {})[f[6:-5]] = {k: j.get(k) for k in ("seconds", "photos", "words")}
json.dump(summary, open(os.path.join(out, "summary.json"), "w"), indent=2)
print(json.dumps(summary, indent=2))
PY
