#!/usr/bin/env bash
# Bulk replay verification on a real scheduler, on this one machine: records a few hundred replays
# of a 2-player arena match (plus one desync, one corrupt and one truncated replay), writes their
# manifest, starts a one-node Slurm cluster on localhost (munged, slurmctld, slurmd), submits
# deploy/slurm/verify-array.sbatch as an array job of K shards, waits for it, stops the daemons it
# started, merges the shards' JSON lines (scripts/verify_shards.py) and checks that every manifest
# entry has exactly one result and that the results equal, byte for byte apart from the timing
# keys, those of one `detsim verify --manifest LIST --jobs 1` process. Prints what it did, the
# times, and the throughput. docs/SCALE.md shows a run.
#
# Usage: scripts/cluster-verify.sh [OPTIONS]
#   --replays N     replays to record (default 500)
#   --frames F      frames of each (default 3600: one minute at 60 fps)
#   --shards K      array tasks (default 4)
#   --plain         run the K shards as plain processes (SLURM_ARRAY_TASK_ID=0..K-1 set, the same
#                   sbatch script) instead of through Slurm: for CI, or a machine without Slurm
#   --detsim PATH   the detsim binary (default: build it as scripts/run.sh does, in build/release)
#   --work DIR      keep the replays, manifest, shard outputs and Slurm logs in DIR (default: a
#                   temporary folder, removed at the end)
#   --timeout S     seconds to wait for the array job (default 1800)
#   -h, --help      this text
#
# The Slurm mode needs root (it starts the daemons) and installs slurm-wlm and munge if missing
# (scripts/install-deps.sh). Its configuration lives in the work folder (SLURM_CONF), not in
# /etc/slurm; an already running munged is used, one it starts is stopped at the end. It refuses
# to run beside a Slurm controller that is already running.
#
# Exit status: 0 every check passed (the desync and the bad replays are expected and reported);
# 1 a check failed; 2 bad usage or a step that could not run (the message says which).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

replays=500
frames=3600
shards=4
mode=slurm
detsim=""
work=""
timeout=1800

usage() { sed -n '2,/^set -euo pipefail/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"; }
die() { echo "cluster-verify: $*" >&2; exit 2; }
say() { printf 'cluster-verify: %s\n' "$*"; }
number() { if ! [[ $2 =~ ^[0-9]+$ ]] || (($2 < $3)); then die "$1 needs a whole number >= $3, got '$2'"; fi; }

while (($#)); do
  case $1 in
    --replays) number "$1" "${2-}" 1; replays=$2; shift 2 ;;
    --frames) number "$1" "${2-}" 2; frames=$2; shift 2 ;;
    --shards) number "$1" "${2-}" 1; shards=$2; shift 2 ;;
    --plain) mode=plain; shift ;;
    --detsim) detsim=${2:?--detsim needs a path}; shift 2 ;;
    --work) work=${2:?--work needs a folder}; shift 2 ;;
    --timeout) number "$1" "${2-}" 1; timeout=$2; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    *) die "unknown argument '$1' (--help lists the options)" ;;
  esac
done

clock() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(clock)" 'BEGIN { printf "%.1f", b - a }'; }
started=$(clock)

# --- what it needs ----------------------------------------------------------------------------
if [ "$mode" = slurm ]; then
  [ "$(id -u)" -eq 0 ] || die "the Slurm mode starts slurmctld, slurmd and munged: run it as root, or use --plain"
  bash scripts/install-deps.sh slurm-wlm munge
elif [ -z "$detsim" ]; then
  bash scripts/install-deps.sh
fi
if [ -z "$detsim" ]; then
  say "building detsim (build/release, as scripts/run.sh does)"
  cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DDETSIM_BUILD_TESTS=OFF >/dev/null
  cmake --build build/release --target detsim -j "$(nproc)" >/dev/null
  detsim=build/release/tools/detsim
fi
[ -x "$detsim" ] || die "no detsim binary at '$detsim'"
detsim=$(realpath "$detsim")
verify_help=$("$detsim" verify --help) || die "$detsim verify --help failed"
grep -q -- --manifest <<<"$verify_help" || die "$detsim has no bulk verify (verify --manifest): rebuild it"

keep_work=1
if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/detsim-cluster.XXXXXX")
  keep_work=0
fi
mkdir -p "$work"
work=$(realpath "$work")
rm -rf "${work:?}/replays" "${work:?}/shards" "${work:?}/slurm" "${work:?}/all-cores" "${work:?}/bin"
mkdir -p "$work/replays" "$work/shards" "$work/slurm" "$work/bin"
# A copy, so that every step runs the same binary even if a build replaces the original meanwhile.
cp "$detsim" "$work/bin/detsim"
detsim=$work/bin/detsim

# --- the daemons this script starts, stopped whatever happens ---------------------------------
slurm_pids=()
munged_pid=""
job=""
# shellcheck disable=SC2317  # (run by the EXIT trap)
cleanup() {
  local status=$?
  if ((${#slurm_pids[@]})); then
    if [ -n "$job" ]; then  # cancel the array if still running (interrupted); else a no-op
      scancel "$job" 2>/dev/null || true
      for _ in $(seq 100); do [ -z "$(squeue -h -j "$job" -o %i 2>/dev/null)" ] && break; sleep 0.1; done
    fi
    scontrol shutdown >/dev/null 2>&1 || true
    for pid in "${slurm_pids[@]}"; do
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill "$pid" 2>/dev/null || true
    done
    # Step daemons left by a task that did not end: those of this cluster carry its SLURM_CONF.
    for pid in $(pgrep -x slurmstepd || true); do
      if { tr '\0' '\n' <"/proc/$pid/environ"; } 2>/dev/null | grep -qxF "SLURM_CONF=$SLURM_CONF"; then
        kill -KILL "$pid" 2>/dev/null || true  # slurmstepd blocks SIGTERM
      fi
    done
  fi
  if [ -n "$munged_pid" ]; then kill "$munged_pid" 2>/dev/null || true; fi
  if [ "$keep_work" -eq 0 ]; then rm -rf "$work"; fi
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# --- the replays and their manifest -----------------------------------------------------------
cores=$(nproc)
say "recording $replays replays of arena (2 players, $frames frames, seeds 1..$replays) on $cores cores"
t=$(clock)
seq 1 "$replays" | xargs -P "$cores" -I{} "$detsim" run --scenario arena --players 2 --seed {} \
  --frames "$frames" --record "$work/replays/arena-{}.replay" >/dev/null
# A replay whose recorded hashes a perturbed run wrote: verify finds a desync at frame frames/2.
"$detsim" run --scenario arena --players 2 --seed $((replays + 1)) --frames "$frames" \
  --inject "$((frames / 2)):1:position.y:0.001" --record "$work/replays/desync.replay" >/dev/null
# A replay with 16 bytes flipped in the middle, and one cut at 60 % of its length.
python3 - "$work/replays/arena-1.replay" "$work/replays/corrupt.replay" "$work/replays/truncated.replay" <<'EOF'
import sys
data = bytearray(open(sys.argv[1], "rb").read())
middle = len(data) // 2
for i in range(middle, middle + 16):
    data[i] ^= 0xFF
open(sys.argv[2], "wb").write(data)
open(sys.argv[3], "wb").write(open(sys.argv[1], "rb").read()[: len(data) * 6 // 10])
EOF
record_seconds=$(since "$t")
manifest=$work/replays/manifest.txt
{
  echo "# detsim verify --manifest: one replay a line, relative to this file; '#' lines and blank lines skipped"
  echo "desync.replay"
  echo "corrupt.replay"
  echo "truncated.replay"
  echo
  for i in $(seq 1 "$replays"); do echo "arena-$i.replay"; done
} >"$manifest"
entries=$((replays + 3))
bytes=$(du -sb "$work/replays" | cut -f1)
say "  $entries manifest entries ($((bytes / 1048576)) MiB) in $record_seconds s"

# --- the reference: one process, one thread -----------------------------------------------------
run_single() {  # JOBS OUTPUT -> sets single_status, single_seconds
  local t status=0
  t=$(clock)
  "$detsim" verify --manifest "$manifest" --jobs "$1" --json >"$2" || status=$?
  single_seconds=$(since "$t")
  single_status=$status
  case $status in 0 | 1 | 2) ;; *) die "detsim verify --jobs $1 exited $status (a crash?)" ;; esac
}
say "one process, --jobs 1, over the whole manifest"
run_single 1 "$work/single.jsonl"
reference_status=$single_status
jobs1_seconds=$single_seconds
say "  exit status $single_status in $single_seconds s"
say "one process, --jobs $cores, for comparison"
run_single "$cores" "$work/single-all-cores.jsonl"
all_cores_seconds=$single_seconds
say "  exit status $single_status in $single_seconds s"
[ "$single_status" -eq "$reference_status" ] || say "  (--jobs 1 exited $reference_status: they differ)"

# --- the shards -------------------------------------------------------------------------------
script=$root/deploy/slurm/verify-array.sbatch
if [ "$mode" = plain ]; then
  say "$shards shards as plain processes (SLURM_ARRAY_TASK_ID=0..$((shards - 1)), $script)"
  t=$(clock)
  pids=()
  for ((i = 0; i < shards; i++)); do
    SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$shards DETSIM=$detsim \
      bash "$script" "$manifest" "$work/shards" 2>"$work/shards/shard-$i.log" &
    pids+=($!)
  done
  for ((i = 0; i < shards; i++)); do wait "${pids[$i]}" || true; done
  shard_seconds=$(since "$t")
  for ((i = 0; i < shards; i++)); do
    [ -f "$work/shards/shard-$i.status" ] || die "shard $i wrote no status: $(cat "$work/shards/shard-$i.log")"
  done
  say "  done in $shard_seconds s; exit statuses: $(cat "$work"/shards/shard-*.status | tr '\n' ' ')"
else
  if pgrep -x slurmctld >/dev/null || pgrep -x slurmd >/dev/null; then
    die "a Slurm daemon is already running here; stop it, or use --plain"
  fi
  say "starting a one-node Slurm cluster on localhost ($(slurmctld -V))"
  if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    say "  munged: already running"
  else
    if [ ! -s /etc/munge/munge.key ]; then
      if command -v mungekey >/dev/null; then mungekey --create --keyfile=/etc/munge/munge.key; else
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
      fi
      chown munge:munge /etc/munge/munge.key
      chmod 0400 /etc/munge/munge.key
    fi
    mkdir -p /run/munge /var/lib/munge /var/log/munge
    chown munge:munge /run/munge /var/lib/munge /var/log/munge
    runuser -u munge -- /usr/sbin/munged
    munged_pid=$(cat /run/munge/munged.pid)
    munge -n | unmunge >/dev/null || die "munged started but does not answer (see /var/log/munge/munged.log)"
    say "  munged: started (pid $munged_pid)"
  fi
  sd=$work/slurm
  mkdir -p "$sd/state" "$sd/spool" "$sd/log"
  # The node as slurmd sees it (CPUs, sockets, cores, threads, memory), named localhost.
  node=$(slurmd -C | head -1 | sed 's/^NodeName=[^ ]* //')
  cat >"$sd/slurm.conf" <<EOF
# One node on localhost, written by scripts/cluster-verify.sh. No cgroups, no accounting database:
# processes are tracked by parent id, jobs' results read from slurmctld (scontrol show job).
ClusterName=detsim
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$sd/state
SlurmdSpoolDir=$sd/spool
SlurmctldPidFile=$sd/slurmctld.pid
SlurmdPidFile=$sd/slurmd.pid
SlurmctldLogFile=$sd/log/slurmctld.log
SlurmdLogFile=$sd/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=3600
NodeName=localhost NodeAddr=127.0.0.1 $node State=UNKNOWN
PartitionName=verify Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF=$sd/slurm.conf
  slurmctld -D >"$sd/log/slurmctld.out" 2>&1 &
  slurm_pids+=($!)
  slurmd -D -N localhost >"$sd/log/slurmd.out" 2>&1 &
  slurm_pids+=($!)
  for _ in $(seq 60); do
    state=$(sinfo -h -n localhost -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
  done
  if [ "$state" != idle ]; then
    tail -n 20 "$sd"/log/*.log "$sd"/log/*.out >&2 || true
    die "the node did not become idle within 30 s (state '${state:-none}'); logs above"
  fi
  say "  slurmctld (pid ${slurm_pids[0]}) and slurmd (pid ${slurm_pids[1]}) up; node localhost: $node"

  say "sbatch --array=0-$((shards - 1)) $script (1 CPU per task)"
  t=$(clock)
  job=$(DETSIM=$detsim sbatch --parsable --array="0-$((shards - 1))" --cpus-per-task=1 \
    --chdir="$work" --output="$sd/log/task-%A_%a.log" "$script" "$manifest" "$work/shards")
  job=${job%%;*}
  deadline=$((SECONDS + timeout))
  while [ -n "$(squeue -h -j "$job" -o %i 2>/dev/null)" ]; do
    ((SECONDS < deadline)) || { scancel "$job" || true; die "array job $job still running after $timeout s: cancelled"; }
    sleep 0.5
  done
  shard_seconds=$(since "$t")
  # Each array task's state and exit status, from the controller (no accounting database here).
  tasks=$(scontrol show job -o "$job" | awk '{
      for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = substr($i, length(kv[1]) + 2) }
      printf "%s %s %s\n", v["ArrayTaskId"], v["JobState"], v["ExitCode"] }' | sort -n)
  say "  array job $job done in $shard_seconds s (submission to last task's end):"
  while read -r id state code; do say "    task $id: $state, exit code $code"; done <<<"$tasks"
  for ((i = 0; i < shards; i++)); do
    [ -f "$work/shards/shard-$i.status" ] || die "array task $i wrote no output: $(cat "$sd"/log/task-*_"$i".log 2>/dev/null)"
  done
fi

# --- merge and check ----------------------------------------------------------------------------
say "merging the $shards shards and comparing them with the --jobs 1 run"
check=0
python3 scripts/verify_shards.py --manifest "$manifest" --of "$shards" "$work/shards" \
  --single "$work/single.jsonl" --single-status "$reference_status" --output "$work/merged.jsonl" || check=$?
# The --jobs N run against the --jobs 1 run: the same check, as one shard of one.
mkdir -p "$work/all-cores"
cp "$work/single-all-cores.jsonl" "$work/all-cores/shard-0.jsonl"
all_cores_same=yes
python3 scripts/verify_shards.py --manifest "$manifest" --of 1 "$work/all-cores" \
  --single "$work/single.jsonl" >/dev/null || all_cores_same=no
if [ "$all_cores_same" = no ] || [ "$single_status" -ne "$reference_status" ]; then
  all_cores_same=no
  check=1
fi

# --- report -----------------------------------------------------------------------------------
read -r n ok desync invalid incomplete total_frames < <(python3 -c 'import json, sys
s = json.loads(open(sys.argv[1]).read().splitlines()[-1])["summary"]
print(s["replays"], s["ok"], s["desync"], s["invalid"], s["incomplete"], s["frames"])' "$work/merged.jsonl")
rate() { awk -v n="$1" -v s="$2" 'BEGIN { printf "%.1f", (s > 0 ? n / s : 0) }'; }
realtime() { awk -v f="$1" -v s="$2" 'BEGIN { printf "%.0f", (s > 0 ? f / 60 / s : 0) }'; }
echo
say "summary"
say "  machine: $cores cores ($(lscpu | sed -n 's/^Model name: *//p' | head -1)), $(uname -sr)"
say "  replays: $n ($ok ok, $desync desync, $invalid invalid, $incomplete incomplete), $total_frames frames"
say "  recording: $record_seconds s"
say "  one process --jobs 1: $jobs1_seconds s, $(rate "$n" "$jobs1_seconds") replays/s, $(realtime "$total_frames" "$jobs1_seconds")x real time (60 fps)"
say "  one process --jobs $cores: $all_cores_seconds s, $(rate "$n" "$all_cores_seconds") replays/s, $(realtime "$total_frames" "$all_cores_seconds")x real time; same results: $all_cores_same"
if [ "$mode" = plain ]; then what="$shards plain processes"; else what="Slurm array job, $shards tasks"; fi
say "  $what: $shard_seconds s, $(rate "$n" "$shard_seconds") replays/s, $(realtime "$total_frames" "$shard_seconds")x real time"
say "  every entry exactly once, same results as --jobs 1 (apart from timing keys), exit statuses agree: $([ "$check" -eq 0 ] && echo yes || echo NO)"
say "  total: $(since "$started") s$([ "$keep_work" -eq 1 ] && echo "; files in $work")"
exit $((check == 0 ? 0 : 1))
