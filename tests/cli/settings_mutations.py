#!/usr/bin/env python3
"""Unknown settings are never silently accepted (issue 28): every subcommand that takes
settings is given keys mutated from the real ones (a character dropped, doubled, swapped or
changed, a section misspelt, a part added), each through --set and through a --config file,
and must exit 2 with "unknown setting" naming the key. A config file may also hold the
mutated key as an empty object ({"servo": {"lamda": {}}}), which sets nothing and must be
refused all the same.

  tests/cli/settings_mutations.py --exe build/release/apps/sketchnav --src . --per-command 12

The real keys are the settings a simulated run's summary.json lists (every Params a run
uses); a mutation that is itself one of them is not used. Seeded; bounded by --per-command
and a timeout per invocation. Prints a JSON summary (accepted = silent accepts, the target
is 0) and exits 1 when any mutation was not refused as unknown.
"""
import argparse
import json
import os
import random
import shutil
import string
import subprocess
import sys
import tempfile


def flatten(j, prefix=""):
    out = []
    for k, v in j.items():
        key = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict) and v:
            out += flatten(v, key)
        else:
            out.append(key)
    return out


def mutate(key, rng):
    parts = key.split(".")
    kind = rng.randrange(7)
    i = rng.randrange(len(parts))
    p = parts[i]
    if kind == 0 and len(p) > 1:  # a character dropped
        j = rng.randrange(len(p))
        parts[i] = p[:j] + p[j + 1:]
    elif kind == 1:  # a character doubled
        j = rng.randrange(len(p))
        parts[i] = p[:j] + p[j] + p[j:]
    elif kind == 2 and len(p) > 1:  # two neighbours swapped
        j = rng.randrange(len(p) - 1)
        parts[i] = p[:j] + p[j + 1] + p[j] + p[j + 2:]
    elif kind == 3:  # a character changed
        j = rng.randrange(len(p))
        parts[i] = p[:j] + rng.choice(string.ascii_lowercase + "_") + p[j + 1:]
    elif kind == 4:  # a part added at the end (a field below a value)
        parts.append(rng.choice(["x", "value", "enabled", "s"]))
    elif kind == 5:  # a unit suffix added or dropped
        parts[-1] = parts[-1][:-2] if parts[-1].endswith(("_s", "_m")) else parts[-1] + "_s"
    else:  # the first section misspelt
        parts[0] = parts[0].upper() if rng.random() < 0.5 else parts[0] + "s"
    return ".".join(parts)


def nested(key, value):
    j = value
    for part in reversed(key.split(".")):
        j = {part: j}
    return j


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exe", required=True)
    ap.add_argument("--src", required=True, help="the source tree (share/, fixtures)")
    ap.add_argument("--per-command", type=int, default=12, help="mutated keys per subcommand")
    ap.add_argument("--seed", type=int, default=28)
    ap.add_argument("--timeout-s", type=float, default=60)
    ap.add_argument("--keep", action="store_true", help="keep the scratch folder")
    a = ap.parse_args()
    if not 1 <= a.per_command <= 200:
        ap.error("--per-command must be in 1..200")
    rng = random.Random(a.seed)
    work = tempfile.mkdtemp(prefix="sketchnav-settings-")
    src = os.path.abspath(a.src)
    lab = f"{src}/share/sketches/lab.sketch.json"
    tiny = f"{src}/tests/cli/fixtures/tiny.png"
    os.makedirs(f"{work}/frames")
    shutil.copy(tiny, f"{work}/frames/")

    # The real keys: a short run's summary.
    r = subprocess.run([a.exe, "run", "--max-time", "0.5", "--world", "corridor", "--out",
                        f"{work}/base-run"], capture_output=True, text=True,
                       timeout=a.timeout_s * 5)
    with open(f"{work}/base-run/summary.json") as f:
        known = sorted(set(flatten(json.load(f)["settings"])))
    if len(known) < 50:
        sys.exit(f"settings_mutations: only {len(known)} settings in the run's summary")

    # Each command, as it would succeed quickly if the setting were taken.
    commands = {
        "run": ["run", "--max-time", "0.5", "--world", "corridor", "--out", f"{work}/r"],
        "route": ["route", lab],
        "sim map": ["sim", "map", "--world", "corridor", "-o", f"{work}/m.png"],
        "sim drive": ["sim", "drive", "--world", "corridor", "--seconds", "0.5", "--camera-hz",
                      "0", "--out", f"{work}/d"],
        "propose": ["propose", tiny, "-o", f"{work}/p.png"],
        "probe": ["probe", f"folder://{work}/frames", "--frames", "1"],
        "base-emulator": ["base-emulator", "--port", "0", "--seconds", "0.3"],
        "ui": ["ui", "--port", "0"],  # serves until stopped: a timeout is an accept
        "train": ["train", "--landmarks", f"{src}/share/landmarks", "-o", f"{work}/t.slm"],
    }
    results = {"accepted": [], "refused": 0, "other": [], "invocations": 0}
    per = {}
    for name, argv in commands.items():
        keys = set()
        while len(keys) < a.per_command:
            k = mutate(rng.choice(known), rng)
            if k not in known:
                keys.add(k)
        refused = 0
        for i, key in enumerate(sorted(keys)):
            value = 1
            ways = ["set", "config"]
            if i % 3 == 0:
                ways.append("config-empty-object")
            for way in ways:
                cfg = f"{work}/c.json"
                if way == "set":
                    full = [a.exe, "--set", f"{key}={json.dumps(value)}"] + argv
                else:
                    with open(cfg, "w") as f:
                        json.dump(nested(key, {} if way == "config-empty-object" else value), f)
                    full = [a.exe, "--config", cfg] + argv
                results["invocations"] += 1
                try:
                    # `ui` serves until stopped: refused at once, or taken (a timeout).
                    p = subprocess.run(full, capture_output=True, text=True,
                                       timeout=5 if name == "ui" else a.timeout_s)
                    rc, err = p.returncode, p.stderr
                except subprocess.TimeoutExpired:
                    rc, err = "timeout", ""
                case = {"command": name, "key": key, "way": way, "exit": rc,
                        "stderr": err.strip().splitlines()[-1][:200] if err.strip() else ""}
                if rc == 2 and f"unknown setting '{key}'" in err:
                    refused += 1
                    results["refused"] += 1
                elif rc in (0, "timeout"):
                    results["accepted"].append(case)
                else:
                    results["other"].append(case)
        per[name] = refused
    results["refused_per_command"] = per
    results["known_keys"] = len(known)
    results["silent_accepts"] = len(results["accepted"])
    print(json.dumps(results, indent=1))
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)
    sys.exit(0 if not results["accepted"] and not results["other"] else 1)


if __name__ == "__main__":
    main()
