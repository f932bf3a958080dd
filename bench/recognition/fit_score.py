#!/usr/bin/env python3
"""Fits recognise()'s combined score and tabulates accept_score (see calibrate.sh).

Input: `sketchnav recognise --eval DIR --details FILE` lines (candidates with inliers, votes,
vote_share, bow_probability, verified, colour_probability). Logistic regression over the
candidates of known images (label: the candidate is the true class), features as in
RecognitionParams::combinedScore(): ln(1+inliers), vote share, ln(1+votes), SVM probability,
verified, colour-layout probability. Plain Python (no numpy).

Usage: fit_score.py [--no-colour] FIT.jsonl [EVAL.jsonl ...]  -- fits on the first, evaluates
                                                                on all (--no-colour: without
                                                                the colour feature).
       fit_score.py --weights b,i,s,v,p,ver[,col] FILE.jsonl ...  -- evaluates given weights.
"""
import json
import math
import sys

NAMES = ["score_bias", "score_inliers", "score_vote_share", "score_votes", "score_bow",
         "score_verified", "score_colour"]
USE_COLOUR = True


def features(c):
    f = [1.0, math.log1p(c["inliers"]), c["vote_share"], math.log1p(c["votes"]),
         c["bow_probability"], 1.0 if c["verified"] else 0.0]
    if USE_COLOUR:
        f.append(c.get("colour_probability", 0.0))
    return f


def load(path):
    return [json.loads(l) for l in open(path) if l.strip()]


def fit(rows, l2=1e-3, iters=3000, lr=0.5):
    X, y = [], []
    for r in rows:
        if not r["known"]:
            continue
        for c in r["candidates"]:
            X.append(features(c))
            y.append(1.0 if c["class"] == r["class"] else 0.0)
    d = len(X[0])
    # Standardise for the optimiser, map back at the end.
    mu = [sum(x[j] for x in X) / len(X) for j in range(d)]
    sd = [max(1e-6, math.sqrt(sum((x[j] - mu[j]) ** 2 for x in X) / len(X))) for j in range(d)]
    mu[0], sd[0] = 0.0, 1.0
    Z = [[(x[j] - mu[j]) / sd[j] for j in range(d)] for x in X]
    w = [0.0] * d
    n = len(Z)
    for _ in range(iters):
        g = [0.0] * d
        for z, t in zip(Z, y):
            s = sum(a * b for a, b in zip(w, z))
            p = 1.0 / (1.0 + math.exp(-max(-30.0, min(30.0, s))))
            for j in range(d):
                g[j] += (p - t) * z[j]
        for j in range(d):
            reg = l2 * w[j] if j else 0.0
            w[j] -= lr * (g[j] / n + reg)
    # Back to raw features.
    raw = [0.0] * d
    for j in range(1, d):
        raw[j] = w[j] / sd[j]
    raw[0] = w[0] - sum(w[j] * mu[j] / sd[j] for j in range(1, d))
    return raw


def decide(r, w):
    best = None
    for c in r["candidates"]:
        s = sum(a * b for a, b in zip(w, features(c)))
        if best is None or s > best[0]:
            best = (s, c["class"])
    return best


def old_rule(r):
    ver = [c for c in r["candidates"] if c["verified"]]
    if not ver:
        return None
    return max(ver, key=lambda c: (c["votes"], c["inliers"], c["bow_probability"]))["class"]


def table(rows, w, name):
    known = [r for r in rows if r["known"]]
    unknown = [r for r in rows if not r["known"]]
    dec = [(decide(r, w), r) for r in rows]
    any_ok = sum(1 for (s, cls), r in dec if r["known"] and cls == r["class"])
    old_ok = sum(1 for r in known if old_rule(r) == r["class"])
    old_rej = sum(1 for r in unknown if old_rule(r) is None)
    old_frej = sum(1 for r in known if old_rule(r) is None)
    print("%s: %d known, %d unknown images; best-scoring class right (no rejection) %.3f" %
          (name, len(known), len(unknown), any_ok / max(1, len(known))))
    print("  old rule (first verified by votes): top-1 %.3f, false rejections %.3f, unknown rejected %s" %
          (old_ok / max(1, len(known)), old_frej / max(1, len(known)),
           "%.3f" % (old_rej / len(unknown)) if unknown else "-"))
    # The pipeline's own answer as run (the default rule plus the colour rescue, or whatever
    # --set chose): the first candidate when it is not rejected.
    ran = lambda r: r["candidates"][0]["class"] if r["candidates"] and not r["candidates"][0]["rejected"] else None
    print("  as run (first candidate unless rejected): top-1 %.3f, false rejections %.3f, unknown rejected %s" %
          (sum(1 for r in known if ran(r) == r["class"]) / max(1, len(known)),
           sum(1 for r in known if ran(r) is None) / max(1, len(known)),
           "%.3f" % (sum(1 for r in unknown if ran(r) is None) / len(unknown)) if unknown else "-"))
    print("  accept_score | top-1 | false rejections | unknown rejected")
    for t in [-3, -2.5, -2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2, 3]:
        ok = sum(1 for (s, cls), r in dec if r["known"] and s >= t and cls == r["class"])
        frej = sum(1 for (s, cls), r in dec if r["known"] and s < t)
        urej = sum(1 for (s, cls), r in dec if not r["known"] and s < t)
        print("  %5.1f | %.3f | %.3f | %s" % (t, ok / max(1, len(known)), frej / max(1, len(known)),
                                         "%.3f" % (urej / len(unknown)) if unknown else "-"))


def main():
    global USE_COLOUR
    args = sys.argv[1:]
    if args and args[0] == "--no-colour":
        USE_COLOUR = False
        args = args[1:]
    if args and args[0] == "--weights":
        w = [float(v) for v in args[1].split(",")]
        USE_COLOUR = len(w) > 6
        files = args[2:]
    else:
        files = args
        w = fit(load(files[0]))
        print("fitted on %s:" % files[0])
        print("  " + ", ".join("%s=%.3f" % (n, v) for n, v in zip(NAMES, w)))
    for f in files:
        table(load(f), w, f)


if __name__ == "__main__":
    main()
