#!/usr/bin/env python3
"""Server RSS around a burst of large legal requests (issue 12, item 9; issue 19).

    python3 bench/memory_burst.py build/bin/beamcast-server

    python3 bench/memory_burst.py build/bin/beamcast-server 900000

Starts the server (--no-demo), sends one ping whose params hold 1.1 M small
keys (13.2 MB; over max_json_values, so refused after parsing 1 M values) or
the number of keys given (900 000: 10.7 MB, accepted and echoed), then 12 of
them at once, and prints the settled RSS after each, how far it is above the
baseline, the peak (VmHWM), and how many answers of each kind came back. Run
it on an old and a new binary back to back to compare (docs/performance.md,
"Memory after large requests").
"""
import collections
import os
import sys
import threading

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "python"))
import test_hostile as th  # noqa: E402


def main():
    th.SERVER = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1_100_000
    keys = ",".join(f'"k{i}":{i % 10}' for i in range(n))
    text = ('{"id":1,"method":"ping","params":{' + keys + "}}").encode()
    print(f"request: {len(text)} bytes")
    with th.Server("--no-demo") as srv:
        def one(out):
            try:
                c = th.Bcp(srv.port, timeout=120)
                c.send_text(text)
                r = c.recv()[0]
                c.close()
                out.append(r["error"]["code"] if not r.get("ok") else "ok")
            except OSError as e:  # the server closed the connection (timeout)
                out.append(type(e).__name__)

        base = th.settle_rss(srv, 1.0)
        first = []
        one(first)
        after1, peak1 = th.settle_rss(srv, 3.0), srv.status_mib("VmHWM")
        burst = []
        threads = [threading.Thread(target=one, args=(burst,)) for _ in range(12)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        after12, peak12 = th.settle_rss(srv, 3.0), srv.status_mib("VmHWM")
        print(f"baseline {base:.1f} MiB")
        print(f"after 1: {after1:.1f} MiB (+{after1 - base:.1f}), peak {peak1:.1f} MiB, answer {first[0]}")
        print(f"after 12 concurrent: {after12:.1f} MiB (+{after12 - base:.1f}), peak {peak12:.1f} MiB, "
              f"answers {dict(collections.Counter(burst))}")


if __name__ == "__main__":
    main()
