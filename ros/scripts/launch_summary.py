#!/usr/bin/python3
"""Parses roslaunch files with roslaunch's own loader and prints, as JSON, each node (name,
package, type, args, remappings) and each parameter: what test_ros checks of ros/launch/."""
import json
import sys

import roslaunch.config


def main():
    # Launch arguments (name:=value) stay in sys.argv, where roslaunch's loader reads them.
    files = [a for a in sys.argv[1:] if ":=" not in a]
    cfg = roslaunch.config.load_config_default(files, None, verbose=False)
    out = {"nodes": [], "params": {}}
    for n in cfg.nodes:
        out["nodes"].append({"name": n.name, "namespace": n.namespace, "package": n.package,
                             "type": n.type, "args": n.args,
                             "remap": {a: b for a, b in n.remap_args},
                             "required": bool(n.required)})
    for k, p in cfg.params.items():
        out["params"][k] = p.value
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
