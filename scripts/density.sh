#!/usr/bin/env bash
# How many concurrent game-server matches this machine holds (docs/SCALE.md, "Density").
#
# For each M: M `detsim serve` processes (an 8-player arena match each, input authority, 60 Hz,
# --agones against a fake sidecar per server: scripts/fake_agones_sidecar.py) on loopback UDP,
# driven by one serve_load process (bench/serve_load.cpp: 8 bot clients a match that speak the
# protocol without simulating). Per M it prints the servers' p99 and worst tick lateness (how late
# frames were simulated after their time), the CPU each match used, and the longest gap between
# two health pings a server sent its sidecar while its match ran.
#
#   bash scripts/density.sh [--matches "8 16 24 32 40 48"] [--seconds 30] [--out FILE.md]
#
# Needs the dev build's detsim (build/dev) and the bench build's serve_load (build/bench); builds
# both when missing. Ports: servers from 7200, sidecars from 9400.
set -euo pipefail
cd "$(dirname "$0")/.."

matches_list="8 16 24 32 40 48"
seconds=30
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --matches) matches_list=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "density.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done

bash scripts/install-deps.sh
if [ ! -f build/dev/build.ninja ]; then
  cmake -S . -B build/dev -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
    -DCMAKE_UNITY_BUILD=ON >/dev/null
fi
ninja -C build/dev detsim >/dev/null
if [ ! -f build/bench/build.ninja ]; then
  cmake -S . -B build/bench -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
    -DDETSIM_BUILD_BENCH=ON -DCMAKE_UNITY_BUILD=ON >/dev/null
fi
ninja -C build/bench serve_load >/dev/null
detsim=build/dev/tools/detsim
load=build/bench/bench/serve_load
agones=()
if "$detsim" serve --help | grep -q -- '--agones'; then agones=(--agones); fi

frames=$((seconds * 60))
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
server_port=7200
sidecar_port=9400

table="| matches | clients | p99 tick lateness (worst server) | worst tick | CPU per match | machine CPU | longest health gap | clients that finished |
|--:|--:|--:|--:|--:|--:|--:|--:|"
echo "density: $(nproc) cores ($(lscpu | sed -n 's/^Model name: *//p')), ${seconds} s matches of ${frames} frames"
for m in $matches_list; do
  run="$work/m$m"
  mkdir -p "$run"
  ports=()
  for ((i = 0; i < m; ++i)); do ports+=($((sidecar_port + i))); done
  python3 scripts/fake_agones_sidecar.py --log "$run/sidecar.jsonl" "${ports[@]}" 2>/dev/null &
  sidecar=$!
  sleep 1
  cpu_before=$(awk '/^cpu /{print $2+$3+$4+$7+$8+$9, $2+$3+$4+$5+$6+$7+$8+$9}' /proc/stat)
  pids=()
  for ((i = 0; i < m; ++i)); do
    AGONES_SDK_HTTP_PORT=$((sidecar_port + i)) "$detsim" serve --scenario arena --players 8 \
      --frames "$frames" --fps 60 --authority inputs --bind "127.0.0.1:$((server_port + i))" \
      --timeout 20 --json "${agones[@]}" >"$run/serve$i.json" 2>"$run/serve$i.err" &
    pids+=($!)
  done
  sleep 0.5
  "$load" --port "$server_port" --matches "$m" --players 8 --seconds $((seconds + 30)) \
    >"$run/load.jsonl" 2>"$run/load.err" || true
  for p in "${pids[@]}"; do wait "$p" || true; done
  cpu_after=$(awk '/^cpu /{print $2+$3+$4+$7+$8+$9, $2+$3+$4+$5+$6+$7+$8+$9}' /proc/stat)
  kill "$sidecar" 2>/dev/null || true
  wait "$sidecar" 2>/dev/null || true
  row=$(python3 - "$run" "$m" "$cpu_before" "$cpu_after" <<'EOF'
import json, sys, glob, os
run, m = sys.argv[1], int(sys.argv[2])
busy0, total0 = map(float, sys.argv[3].split())
busy1, total1 = map(float, sys.argv[4].split())
p99s, worst, cpus, bad = [], 0, [], 0
for i in range(m):
    try:
        d = json.load(open(os.path.join(run, "serve%d.json" % i)))
    except (OSError, ValueError):
        bad += 1
        continue
    p99s.append(d["tick_lateness_us"]["p99"])
    worst = max(worst, d["tick_lateness_us"]["max"])
    cpus.append(d["cpu_seconds"] / max(d["match_seconds"], 1e-9))
gaps = {}
for line in open(os.path.join(run, "sidecar.jsonl")):
    c = json.loads(line)
    if c["path"] == "/health":
        gaps.setdefault(c["port"], []).append(c["t"])
longest = 0.0
for times in gaps.values():
    for a, b in zip(times, times[1:]):
        longest = max(longest, b - a)
finished = sum(json.loads(l)["finished"] for l in open(os.path.join(run, "load.jsonl")))
machine = 100.0 * (busy1 - busy0) / max(total1 - total0, 1)
health = "%.2f s" % longest if gaps else "n/a"
print("| %d | %d | %.1f ms | %.1f ms | %.1f %% of a core | %.0f %% | %s | %d of %d%s |" % (
    m, 8 * m, max(p99s or [0]) / 1000, worst / 1000, 100 * sum(cpus) / max(len(cpus), 1),
    machine, health, finished, 8 * m, "" if bad == 0 else " (%d servers failed)" % bad))
EOF
)
  echo "$row"
  table="$table
$row"
done
echo
echo "$table"
if [ -n "$out" ]; then printf '%s\n' "$table" >"$out"; fi
