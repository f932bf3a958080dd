#!/usr/bin/env bash
# compare_runs.sh A B: whether two run folders (or two folders of run folders, e.g. two
# `sketchnav experiments --out` trees) hold the same behaviour: every telemetry.csv and
# events.jsonl under A must exist under B at the same relative path with the same bytes.
# summary.json is not compared: it holds wall-clock figures (real-time factor, perception ms).
# Prints one line per file, the first differing line of each that differs; exit 0 when all
# are identical, 1 when any differs or is missing, 2 on bad usage.
set -u
if [ $# -ne 2 ] || [ ! -d "$1" ] || [ ! -d "$2" ]; then
  echo "usage: compare_runs.sh RUN_DIR_A RUN_DIR_B (two existing folders)" >&2
  exit 2
fi
a=$1 b=$2 n=0 bad=0
while IFS= read -r -d '' f; do
  rel=${f#"$a"/}
  n=$((n + 1))
  if [ ! -f "$b/$rel" ]; then
    echo "MISSING $rel (in $a, not in $b)"
    bad=$((bad + 1))
  elif cmp -s "$f" "$b/$rel"; then
    echo "same    $rel ($(wc -l <"$f") lines)"
  else
    out=$(cmp "$f" "$b/$rel" 2>&1)
    line=$(echo "$out" | sed -n 's/.* line \([0-9]*\).*/\1/p')
    case $out in *EOF*) echo "DIFFER  $rel: one is a prefix of the other ($out)"; line=$((line + 1)) ;;
      *) echo "DIFFER  $rel from line ${line:-?}:" ;; esac
    echo "  A: $(sed -n "${line:-1}p" "$f" | cut -c1-300)"
    echo "  B: $(sed -n "${line:-1}p" "$b/$rel" | cut -c1-300)"
    bad=$((bad + 1))
  fi
done < <(find "$a" \( -name telemetry.csv -o -name events.jsonl \) -print0 | sort -z)
if [ "$n" -eq 0 ]; then
  echo "no telemetry.csv or events.jsonl under $a" >&2
  exit 1
fi
echo "$n files compared, $bad differ or are missing"
[ "$bad" -eq 0 ]
