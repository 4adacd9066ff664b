#!/usr/bin/env python3
"""The folders' floors (docs/architecture.md, "Folders and what they may use").

Reads every #include of every C++ file in the product's top-level folders and
fails on one that reaches a folder its own folder may not use: one above it in
the order below, or one beside it. Each failure names the file, the line and
the two folders. Run by ctest (layering.includes); usage:

    scripts/check_layering.py [ROOT]   # ROOT: the repository (default: this script's parent's parent)

Before the check it runs itself on a small planted tree (upward, sideways and
relative includes) and fails if any of them goes unreported, so a broken
pattern cannot pass silently.
"""
import os
import re
import sys
import tempfile

# Each folder and the folders it uses directly; it may include those and
# whatever they may include (the transitive closure). Lowest first. A new
# top-level folder with a CMakeLists.txt must be added here.
USES = {
    "protocol": [],             # scene model, JSON, wire format: the floor
    "shaders": [],              # GLSL sources embedded as strings
    "gi": ["protocol"],         # CPU photon tracing (Embree)
    "slim": ["protocol"],       # SLIM surface fitting
    "render": ["gi", "shaders"],  # GL renderer, CPU reference, images, accuracy controller
    "client": ["protocol"],     # C++ client of the wire protocol
    "server": ["render"],       # beamcast-server
    "bench": ["render", "slim", "client"],  # benchmarks, `beamcast load`'s engine
    "cli": ["bench"],           # the `beamcast` tool
    "tests": ["cli", "server"],  # everything
    "fuzz": ["protocol"],       # libFuzzer targets (the fuzz build has protocol/ only)
}

SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".inl")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def closure(uses):
    """For each folder, every folder it may include (not itself)."""
    allowed = {}

    def visit(folder, stack):
        if folder in allowed:
            return allowed[folder]
        if folder in stack:
            raise SystemExit(f"check_layering.py: USES has a cycle through {folder}")
        reach = set()
        for below in uses[folder]:
            reach.add(below)
            reach |= visit(below, stack + [folder])
        allowed[folder] = reach
        return reach

    for folder in uses:
        visit(folder, [])
    return allowed


def target_folder(root, source, quote, name):
    """The top-level folder an include names, or None (system, same-folder or generated)."""
    if quote == '"':
        # The compiler looks next to the including file first.
        beside = os.path.normpath(os.path.join(os.path.dirname(source), name))
        if os.path.isfile(beside):
            rel = os.path.relpath(beside, root)
            if rel.startswith(".."):
                return None
            return rel.split(os.sep)[0]
    first = name.split("/")[0]
    return first if first in USES else None


def check(root):
    """Failure lines for the tree at root."""
    allowed = closure(USES)
    failures = []
    for entry in sorted(os.listdir(root)):
        path = os.path.join(root, entry)
        if (os.path.isdir(path) and entry not in USES
                and os.path.isfile(os.path.join(path, "CMakeLists.txt"))):
            failures.append(f"{entry}/: a top-level folder with code that is not in the order; "
                            "add it to USES in scripts/check_layering.py and to docs/architecture.md")
    for folder in USES:
        top = os.path.join(root, folder)
        for dirpath, dirnames, filenames in os.walk(top):
            dirnames.sort()
            for filename in sorted(filenames):
                if not filename.endswith(SOURCE_SUFFIXES):
                    continue
                source = os.path.join(dirpath, filename)
                rel = os.path.relpath(source, root)
                with open(source, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = target_folder(root, source, m.group(1), m.group(2))
                        if target is None or target == folder or target in allowed[folder]:
                            continue
                        if folder in allowed.get(target, ()):
                            why = f"{folder}/ is below {target}/"
                        else:
                            why = f"{folder}/ may not use {target}/ (neither is below the other)"
                        failures.append(f"{rel}:{number}: includes {m.group(2)}: {why}")
    return failures


def self_test():
    """The check on a planted tree: every bad include reported, no good one."""
    planted = {
        "gi/up.hpp": '#include "render/image.hpp"\n',                  # upward
        "client/side.cpp": '#include <render/renderer.hpp>\n',          # sideways
        "fuzz/f.cpp": '  #  include "server/limits.hpp"\n',            # fuzz: protocol only
        "protocol/sub/rel.cpp": '#include "../../bench/views.hpp"\n',  # relative, upward
        "extra/CMakeLists.txt": "",                                   # folder not in the order
        "render/ok.cpp": '#include "gi/gi_scene.hpp"\n#include "protocol/vec.hpp"\n'
                         '#include "render/image.hpp"\n#include <vector>\n#include "local.hpp"\n',
        "tests/ok.cpp": '#include "server/limits.hpp"\n#include "cli/commands.hpp"\n',
        "render/image.hpp": "", "render/renderer.hpp": "", "bench/views.hpp": "",
    }
    expected = ["gi/up.hpp:1:", "client/side.cpp:1:", "fuzz/f.cpp:1:",
                "protocol/sub/rel.cpp:1:", "extra/:"]
    with tempfile.TemporaryDirectory() as tmp:
        for rel, text in planted.items():
            os.makedirs(os.path.dirname(os.path.join(tmp, rel)), exist_ok=True)
            with open(os.path.join(tmp, rel), "w", encoding="utf-8") as f:
                f.write(text)
        got = check(tmp)
    starts = sorted(line.split(" ")[0] for line in got)
    if starts != sorted(expected):
        print("check_layering.py: self-test failed; planted tree reported:", *got, sep="\n  ")
        return False
    return True


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    root = os.path.abspath(root)
    if not self_test():
        return 1
    failures = check(root)
    for line in failures:
        print(line)
    if failures:
        print(f"{len(failures)} include(s) against the order in scripts/check_layering.py "
              "(docs/architecture.md, \"Folders and what they may use\")")
        return 1
    print("layering: every include keeps to the order")
    return 0


if __name__ == "__main__":
    sys.exit(main())
