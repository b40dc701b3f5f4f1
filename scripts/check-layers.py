#!/usr/bin/env python3
"""The layers of the source tree and the includes between them.

    scripts/check-layers.py [ROOT]     # exit 1, naming each offending include, if a folder
                                       # includes a folder it may not see

Each top-level folder is one layer; a file may include the public headers of the folders its
own folder may see (below), and quoted relative includes only within its own folder. Run by
ctest (test `architecture.layers`), so a library that reaches up a layer fails the suite.
"""
import os
import re
import sys

# Who may see whom: the libraries' one-way dependencies (docs/architecture.md), the study drivers
# above all libraries, the program layer (app/) on top. tests/, bench/ and fuzz/ may see anything.
SEES = {
    "common": {"common"},
    "mesh": {"common", "mesh"},
    "fem": {"common", "mesh", "fem"},
    "mss": {"common", "mesh", "mss"},
    "calibration": {"common", "mesh", "fem", "mss", "calibration"},
    "spine": {"common", "spine"},
    "output": {"common", "mesh", "mss", "output"},
    "haptics": {"common", "mesh", "mss", "spine", "output", "haptics"},
    "viewer": {"common", "viewer"},
    "studies": {"common", "mesh", "fem", "mss", "calibration", "spine", "output", "haptics",
                "studies"},
    "app": {"common", "mesh", "fem", "mss", "calibration", "spine", "output", "haptics", "viewer",
            "studies", "app"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def check(root):
    problems = []
    for layer, sees in SEES.items():
        top = os.path.join(root, layer)
        for folder, _, files in os.walk(top):
            for name in files:
                if not name.endswith((".cpp", ".hpp", ".h")):
                    continue
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        where = f"{os.path.relpath(path, root)}:{number}"
                        if target.startswith("spinesim/"):
                            module = target.split("/")[1]
                            if module not in sees:
                                problems.append(f"{where}: {layer}/ includes {target} "
                                                f"({module}/ is not below {layer}/)")
                            continue
                        # A private header: it must be a file of the same layer, found beside
                        # the includer or in the layer's own source folders.
                        resolved = os.path.realpath(os.path.join(folder, target))
                        inside = resolved.startswith(os.path.realpath(top) + os.sep)
                        if ".." in target.split("/") and not inside:
                            problems.append(f"{where}: {layer}/ includes {target}, outside {layer}/")
                        elif not os.path.exists(resolved) and not any(
                                os.path.exists(os.path.join(d, target))
                                for d, _, _ in os.walk(top)):
                            problems.append(f"{where}: {layer}/ includes {target}, which is not "
                                            f"a file of {layer}/")
    return problems


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    missing = [layer for layer in SEES if not os.path.isdir(os.path.join(root, layer))]
    if missing:
        print("check-layers: no folder " + ", ".join(missing) + " under " + root)
        return 1
    problems = check(root)
    for p in problems:
        print(p)
    print(f"check-layers: {len(SEES)} layers, {len(problems)} include(s) against the layering")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
