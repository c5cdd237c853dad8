#!/usr/bin/env python3
"""The include graph's rules, checked on the sources (docs/architecture.md):

- core/'s rooms include only rooms above them in ROOMS, and every core source and header sits in
  a room;
- the layers' arrows point down: core includes no other layer, wire/ neither server/, client/,
  robot/ nor view/, robot/ only core, view/ only robot/ and core, server/ not client/.

Prints each broken rule as FILE: LINE and exits 1 when there is one."""
import os
import re
import sys

ROOMS = ["base", "geometry", "mesh", "solid", "balls", "medial", "cover", "generation",
         "distance", "scene", "env"]
# The layers each layer may include (besides its own and proto/'s generated code).
LAYERS = {
    "core": set(),
    "wire": {"core"},
    "robot": {"core"},
    "view": {"core", "robot"},
    "server": {"core", "wire"},
    "client": {"core", "wire", "server", "robot", "view"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def layer_of_include(path):
    """The layer an include path names: inscribe/<layer>/... or a core room's path."""
    parts = path.split("/")
    if parts[0] == "inscribe" and len(parts) > 2:
        if parts[1] in ROOMS:
            return "core", parts[1]
        return parts[1], None
    if parts[0] == "inscribe":
        return "flat", None
    if parts[0] in ROOMS and len(parts) == 2:
        return "core", parts[0]  # a private core header, through core/src
    return None, None


def sources(top, layer):
    for root, _, files in os.walk(os.path.join(top, layer)):
        for name in files:
            if name.endswith((".h", ".cpp", ".cc")):
                yield os.path.join(root, name)


def main(top):
    problems = []
    for layer, allowed in LAYERS.items():
        for path in sources(top, layer):
            rel = os.path.relpath(path, top)
            room = None
            if layer == "core":
                parts = rel.split(os.sep)
                # core/src/<room>/x or core/include/inscribe/<room>/x
                room = parts[2] if parts[1] == "src" else parts[3] if len(parts) > 4 else None
                if room not in ROOMS or len(parts) != (4 if parts[1] == "src" else 5):
                    problems.append(f"{rel}: not in one of core's rooms {ROOMS}")
                    continue
            text = open(path, encoding="utf-8").read()
            for match in INCLUDE.finditer(text):
                line = text.count("\n", 0, match.start()) + 1
                target, target_room = layer_of_include(match.group(1))
                if target == "flat":
                    problems.append(f"{rel}:{line}: {match.group(1)} is not in a room")
                elif target in LAYERS and target != layer and target not in allowed:
                    problems.append(f"{rel}:{line}: {layer}/ includes {target}/ "
                                    f"({match.group(1)})")
                elif room and target_room and ROOMS.index(target_room) > ROOMS.index(room):
                    problems.append(f"{rel}:{line}: core room {room}/ includes {target_room}/, "
                                    f"which comes after it ({match.group(1)})")
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else
                  os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
