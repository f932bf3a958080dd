#!/usr/bin/env bash
# A fixed-time libFuzzer run of each harness (issue 28), one at a time, printing one table row
# per harness for doc/reliability.md's campaign table:
#   harness | seconds | executions | exec/s | cov / ft | crashes | hangs | OOMs
#
#   cmake --preset fuzz && cmake --build --preset fuzz     # clang-14, ASan + UBSan
#   bench/fuzz/run.sh 60                                  # every harness, 60 s each
#   bench/fuzz/run.sh 600 rawlog model                    # these harnesses, 10 minutes each
#
# Seeds: the shipped files and fuzz/regressions/<parser>/ copied into a scratch corpus per
# harness (the repository's folders are never written). A crash, hang or OOM input is left in
# the scratch folder (its path is printed): it belongs in fuzz/regressions/<parser>/ once fixed.
# FUZZ_BUILD (default build/fuzz) and FUZZ_WORK (default a new mktemp folder) override paths.
set -euo pipefail
cd "$(dirname "$0")/../.."
SECONDS_EACH=${1:-60}
shift || true
HARNESSES=("$@")
if ((${#HARNESSES[@]} == 0)); then
  HARNESSES=(sketch world config model model_sealed protocol protocol_sealed image voc truth
             webui rawlog)
fi
BUILD=${FUZZ_BUILD:-build/fuzz}
WORK=${FUZZ_WORK:-$(mktemp -d -t sketchnav-fuzz.XXXXXX)}

seeds() {  # the seed files of one harness
  case $1 in
    sketch) ls share/sketches/*.json ;;
    world) ls share/worlds/*.json ;;
    model_sealed) ls fuzz/regressions/model/* ;;
    protocol_sealed) ls fuzz/regressions/protocol/* ;;
  esac
  [ -d "fuzz/regressions/$1" ] && ls -d fuzz/regressions/"$1"/* || true
}

echo "| harness | time | executions | exec/s | cov / ft | crashes | hangs | OOMs |"
echo "|---|---|---|---|---|---|---|---|"
for h in "${HARNESSES[@]}"; do
  exe="$BUILD/fuzz/fuzz_$h"
  if [ ! -x "$exe" ]; then
    echo "| fuzz_$h | not built ($exe) | | | | | | |"
    continue
  fi
  dir="$WORK/$h"
  mkdir -p "$dir/corpus" "$dir/found"
  for f in $(seeds "$h"); do cp -f "$f" "$dir/corpus/"; done
  start=$(date +%s)
  # -fork mode is not used: a crash ends the run (and is reported) instead of being skipped.
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 nice -n 19 "$exe" \
    -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 -artifact_prefix="$dir/found/" "$dir/corpus" >"$dir/log.txt" 2>&1 || true
  secs=$(($(date +%s) - start))
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$dir/log.txt" | grep -o '[0-9]*$' || echo 0)
  last=$(grep -E '^#[0-9]+' "$dir/log.txt" | tail -1)
  cov=$(echo "$last" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*' || echo "?")
  ft=$(echo "$last" | grep -o 'ft: [0-9]*' | grep -o '[0-9]*' || echo "?")
  crashes=$(ls "$dir/found" | grep -c '^crash-' || true)
  hangs=$(ls "$dir/found" | grep -c '^timeout-' || true)
  ooms=$(ls "$dir/found" | grep -c '^oom-' || true)
  leaks=$(ls "$dir/found" | grep -c '^leak-' || true)
  crashes=$((crashes + leaks))
  rate=$((secs > 0 ? runs / secs : 0))
  echo "| fuzz_$h | $secs s | $runs | $rate | $cov / $ft | $crashes | $hangs | $ooms |"
  if ((crashes + hangs + ooms > 0)); then
    echo "  fuzz_$h found inputs in $dir/found (log: $dir/log.txt)" >&2
  fi
done
echo "work folder: $WORK" >&2
