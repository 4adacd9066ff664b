#!/usr/bin/env bash
# Starts N beamcast-server processes and HAProxy in front of them, all on
# loopback (docs/deploy.md): clients use 127.0.0.1:7878 (BCP1) and
# http://127.0.0.1:7879/ (preview), the single server's defaults, and
# HAProxy spreads them over servers 1..N on ports 7901.. (BCP1) and 7951..
# (HTTP). Installs haproxy and builds like scripts/run.sh. Ctrl-C (or
# SIGTERM) stops them all; the servers drain first.
#
#   scripts/run-cluster.sh N [--gpus] [extra beamcast-server options]
#
# --gpus: server i runs on EGL device i-1 (--device), one process per GPU;
# without it every server uses the default device (llvmpipe here), which
# on one machine only shows the wiring: they share its cores.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ] || ! [[ "$1" =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: scripts/run-cluster.sh N [--gpus] [beamcast-server options]" >&2
  exit 2
fi
n="$1"
shift
gpus=0
if [ "${1:-}" = "--gpus" ]; then gpus=1; shift; fi
scripts/build.sh run
if ! command -v haproxy >/dev/null; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq haproxy >/dev/null
fi

run_dir="$(mktemp -d /tmp/beamcast-cluster.XXXXXX)"
pids=()
cleanup() {
  trap - EXIT INT TERM
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$run_dir"
}
trap cleanup EXIT INT TERM

bcp_servers=""
http_servers=""
for i in $(seq 1 "$n"); do
  port=$((7900 + i))
  http=$((7950 + i))
  device=()
  if [ "$gpus" -eq 1 ]; then device=(--device $((i - 1))); fi
  build/bin/beamcast-server --bind 127.0.0.1 --port "$port" --http-port "$http" \
    "${device[@]}" "$@" >"$run_dir/server$i.log" 2>&1 &
  pids+=($!)
  bcp_servers+="  server s$i 127.0.0.1:$port check port $http"$'\n'
  http_servers+="  server s$i 127.0.0.1:$http check"$'\n'
done
python3 - "$run_dir" "$bcp_servers" "$http_servers" <<'EOF'
import sys
run, bcp, http = sys.argv[1:4]
text = open("deploy/haproxy.cfg.in").read()
for k, v in {"@RUN_DIR@": run, "@BIND@": "127.0.0.1", "@BCP_PORT@": "7878",
             "@HTTP_PORT@": "7879", "@BCP_SERVERS@": bcp.rstrip("\n"),
             "@HTTP_SERVERS@": http.rstrip("\n")}.items():
    text = text.replace(k, v)
open(run + "/haproxy.cfg", "w").write(text)
EOF
haproxy -f "$run_dir/haproxy.cfg" -db >"$run_dir/haproxy.log" 2>&1 &
pids+=($!)
echo "beamcast cluster: $n servers behind HAProxy; BCP1 127.0.0.1:7878, preview http://127.0.0.1:7879/"
echo "  logs and the HAProxy admin socket: $run_dir (echo 'show stat' | socat - $run_dir/haproxy.sock)"
wait -n "${pids[@]}"
echo "beamcast cluster: a process exited; stopping the rest" >&2
