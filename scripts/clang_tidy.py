#!/usr/bin/env python3
"""The clang-tidy stage of scripts/test.sh: clang-tidy-14 (.clang-tidy) over
every translation unit of build/compile_commands.json in the given folders,
one process per core this process may use (as nproc counts), the slowest
files first.

run-clang-tidy-14 does the same from a Python set, whose order changes from
run to run (string hashing is seeded per process): when the slowest file
(server/http_server.cpp, ~3 minutes of the analyzer) came last, one core sat
idle for most of that time. Here the files known to be slow start first and
the others follow in the database's order, so the last minutes are short files
on both cores.

usage: clang_tidy.py BUILD_DIR LOG FOLDER...
Exit status 1 when any file has a finding (WarningsAsErrors) or clang-tidy
fails; the findings are printed, every file's output is in LOG.
"""
import concurrent.futures
import json
import os
import subprocess
import sys

# Slowest first, by clang-tidy's time per file on the 2-core test machine:
# server/http_server.cpp 176 s (2026-11-28; the analyzer through Beast's HTTP
# and WebSocket code for plain and TLS streams), then, one at a time
# (2026-11-30), 49, 37, 32 and 31 s; the other 126 files ~7.5 s on average
# (1 274 CPU-s for all 131, beside a benchmark). See
# docs/performance.md, "The test command's time".
SLOW_FIRST = [
    "server/http_server.cpp",
    "server/session.cpp",
    "bench/load_generator.cpp",
    "server/server.cpp",
    "server/render_service.cpp",
]


def main():
    if len(sys.argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    build, log_path, folders = sys.argv[1], sys.argv[2], sys.argv[3:]
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(build, "compile_commands.json")) as f:
        entries = json.load(f)
    prefixes = [os.path.join(root, d.strip("/")) + "/" for d in folders]
    files = []
    for e in entries:
        path = os.path.normpath(os.path.join(e["directory"], e["file"]))
        if any(path.startswith(p) for p in prefixes) and path not in files:
            files.append(path)
    rank = {os.path.join(root, f): i for i, f in enumerate(SLOW_FIRST)}
    files.sort(key=lambda p: rank.get(p, len(SLOW_FIRST)))  # stable: the rest in order

    def tidy(path):
        r = subprocess.run(["clang-tidy-14", "-p", build, "-quiet", path],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        return path, r.returncode, r.stdout

    failed = []
    cores = len(os.sched_getaffinity(0))
    with open(log_path, "w") as log, concurrent.futures.ThreadPoolExecutor(cores) as pool:
        for path, rc, out in pool.map(tidy, files):
            log.write(f"== {os.path.relpath(path, root)} (exit {rc})\n{out}")
            if rc != 0:
                failed.append((path, out))
    for path, out in failed:
        findings = [l for l in out.splitlines() if " error: " in l or " warning: " in l]
        print(f"{os.path.relpath(path, root)}:")
        print("\n".join(findings) if findings else out)
    print(f"clang-tidy: {len(files)} files, {len(failed)} with findings")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
