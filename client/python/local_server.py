"""Starts a local beamcast-server on a free port for tests and benchmarks."""
import subprocess
import sys
import threading


def start_server(argv, echo=False, port=0):
    """Runs `argv` (the server binary and its options) with --port `port` (0:
    a free one); returns (process, port) once it prints its 'listening on
    HOST:PORT' line. Its further output is drained (echoed with echo=True) so
    a chatty server never blocks on a full pipe."""
    proc = subprocess.Popen(list(argv) + ["--port", str(port)], stdout=subprocess.PIPE,
                            stderr=None if echo else subprocess.DEVNULL, text=True)
    line = []
    reader = threading.Thread(target=lambda: line.append(proc.stdout.readline()), daemon=True)
    reader.start()
    reader.join(60)
    if not line or "listening on" not in line[0]:
        proc.kill()
        raise SystemExit(f"the server printed no 'listening on' line: {list(argv)}")
    port = int(line[0].strip().rsplit(":", 1)[1])

    def drain():
        for text in proc.stdout:
            if echo:
                sys.stdout.write("server: " + text)

    threading.Thread(target=drain, daemon=True).start()
    return proc, port


def stop_server(proc):
    """SIGTERM (the server's clean shutdown), then SIGKILL after 30 s."""
    proc.terminate()
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
