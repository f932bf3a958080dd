#!/usr/bin/env python3
"""Prints the `propose --eval --json` results as a Markdown table (recall at IoU 0.5 / 0.7 for
each budget, AR and MABO at 100 windows, ms per image)."""
import json
import os
import sys


def main(paths):
    for path in paths:
        with open(path) as f:
            j = json.load(f)
        budgets = [str(b) for b in j["windows"]]
        print(f"\n### {os.path.basename(path)[:-5]}: {j['images']} images, {j['objects']} objects\n")
        head = ["method"] + [f"R@0.5/0.7 ({b})" for b in budgets] + [
            "AR@100", "MABO@100", "ms mean", "ms median", "cpu ms mean"]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for name, m in j["methods"].items():
            row = [name]
            for b in budgets:
                r = m["recall"][b]
                row.append(f"{r['0.5']:.3f} / {r['0.7']:.3f}")
            row += [f"{m['ar'].get('100', float('nan')):.3f}",
                    f"{m['mabo'].get('100', float('nan')):.3f}",
                    f"{m['ms_mean']:.1f}", f"{m['ms_median']:.1f}",
                    f"{m.get('cpu_ms_mean', float('nan')):.1f}"]
            print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
