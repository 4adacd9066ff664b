#!/usr/bin/env python3
"""A ping's latency beside a large legal asset file being parsed (issue 43:
files read off the network thread).

    python3 bench/ping_beside_load.py build/bin/beamcast-server [--rounds 5] [--grid 450]

A fresh server (--no-demo, --assets a temporary directory holding an OBJ
grid of 2 * grid^2 triangles: 450 gives 405 000 triangles, 14 MB; the limit
is max_mesh_triangles = 1 000 000). Per round: connection A sends scene.put
of a scene whose occluder is that file, 20 ms later connection B sends a
ping; prints the ping's latency and the put's, and their medians. On a
server that parses the file on its network thread the ping waits for the
parse.
"""
import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__))))
import memory_burst as mb  # noqa: E402
import test_hostile as th  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("server")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--grid", type=int, default=450)
    args = ap.parse_args()
    th.SERVER = args.server
    assets = tempfile.mkdtemp(prefix="beamcast_ping_")
    try:
        mb.write_grid_obj(os.path.join(assets, "grid.obj"), args.grid)
        with th.Server("--no-demo", "--assets", assets) as srv:
            a, b = th.Bcp(srv.port, timeout=60), th.Bcp(srv.port, timeout=60)
            b.send_text(b'{"id":0,"method":"ping"}')
            b.recv()
            put = ('{"id":"put","method":"scene.put","params":{"scene_id":"m","scene":'
                   '{"beams":[],"occluders":[{"type":"mesh","file":"grid.obj"}],'
                   '"cameras":[{"width":8,"height":8}]}}}').encode()
            pings, puts = [], []
            for i in range(args.rounds):
                t0 = time.time()
                a.send_text(put)
                time.sleep(0.02)
                p0 = time.time()
                b.send_text(b'{"id":1,"method":"ping"}')
                assert b.recv()[0].get("ok")
                pings.append((time.time() - p0) * 1000)
                r = a.recv()[0]
                assert r.get("ok"), r
                puts.append((time.time() - t0) * 1000)
                print(f"round {i}: ping {pings[-1]:.1f} ms beside a scene.put of {puts[-1]:.1f} ms",
                      flush=True)
            print(f"median: ping {statistics.median(pings):.1f} ms, scene.put "
                  f"{statistics.median(puts):.1f} ms")
    finally:
        shutil.rmtree(assets, ignore_errors=True)


if __name__ == "__main__":
    main()
