#!/usr/bin/env bash
# Starts a real single-node Slurm cluster (slurmctld + slurmd + munge, configured in a
# temporary directory through SLURM_CONF), renders the orbit animation as a 3-task job array
# through scripts/slurm-render.sbatch, and checks that every frame was rendered exactly once
# and by the right task. Then resubmits the array and checks that nothing is rendered again.
# Needs root; installs Slurm and munge with apt when they are missing. The daemons are
# stopped by the PIDs in their pid files when the script exits, however it exits.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

if [ "$(id -u)" -ne 0 ]; then
  echo "error: run as root: this starts slurmctld, slurmd and munged" >&2
  exit 1
fi
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
  ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  echo "==> installing slurmd slurmctld slurm-client munge"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    slurmd slurmctld slurm-client munge >/dev/null
fi

tmp=$(mktemp -d /tmp/anim-slurm.XXXXXX)
export SLURM_CONF=$tmp/slurm.conf
started_munged=""
ok=""

stop_pidfile() {
  local file=$1 pid
  [ -f "$file" ] || return 0
  pid=$(cat "$file")
  [ -n "$pid" ] || return 0
  kill "$pid" 2>/dev/null || return 0
  for _ in $(seq 50); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.2
  done
  echo "warning: process $pid ($file) did not stop; killing it" >&2
  kill -9 "$pid" 2>/dev/null || true
}

cleanup() {
  stop_pidfile "$tmp/slurmd.pid"
  stop_pidfile "$tmp/slurmctld.pid"
  if [ -n "$started_munged" ]; then
    stop_pidfile /run/munge/munged.pid
  fi
  if [ -n "$ok" ]; then
    rm -rf "$tmp"
  else
    echo "logs kept in $tmp" >&2
    for f in "$tmp"/log/*.log; do
      [ -f "$f" ] && { echo "--- $f (last lines)" >&2; tail -n 20 "$f" >&2; }
    done
  fi
}
trap cleanup EXIT

echo "==> building anim (release)"
cargo build --release --quiet
target_dir=$(cargo metadata --format-version 1 --no-deps |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
export ANIM="${target_dir:-$root/target}/release/anim"

echo "==> munge"
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  if [ ! -s /etc/munge/munge.key ]; then
    mungekey --create --force
  fi
  chown munge:munge /etc/munge/munge.key
  chmod 400 /etc/munge/munge.key
  install -d -o munge -g munge -m 755 /run/munge
  runuser -u munge -- /usr/sbin/munged
  started_munged=yes
  for _ in $(seq 50); do
    munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break
    sleep 0.1
  done
  munge -n | unmunge >/dev/null
fi

echo "==> slurm (config in $tmp)"
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/out"
node=$(hostname -s)
cat >"$SLURM_CONF" <<CONF
ClusterName=ci
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 Sockets=1 CoresPerSocket=2 ThreadsPerCore=1 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -i
slurmd
state=""
for _ in $(seq 120); do
  state=$(sinfo -h -o %T 2>/dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.5
done
if [ "$state" != idle ]; then
  echo "error: the node did not become idle (state: '${state:-none}')" >&2
  exit 1
fi

echo "==> generating the orbit animation"
frames=$tmp/frames
"$ANIM" generate animations/orbit.ron -o "$frames" --quiet
total=$(find "$frames" -maxdepth 1 -name '*.sdf' | wc -l)

submit() {
  local tag=$1
  sbatch --wait --array=1-3 --output="$tmp/out/$tag-%a.out" \
    scripts/slurm-render.sbatch "$frames" --width 64 --height 36 --spp 1 >/dev/null
}

echo "==> sbatch --wait --array=1-3 (rendering $total frames at 64x36)"
start=$(date +%s%N)
submit first
ms=$((($(date +%s%N) - start) / 1000000))
printf '    done in %d.%03d s\n' $((ms / 1000)) $((ms % 1000))

# Every task logs one line per frame it rendered: "[ n/N] rendered frame_0003.sdf in ...".
failed=0
all=$tmp/rendered.txt
: >"$all"
for k in 1 2 3; do
  log=$tmp/out/first-$k.out
  grep -o 'rendered frame_[0-9]*\.sdf' "$log" | sed 's/^rendered //' >"$tmp/task-$k.txt" || true
  cat "$tmp/task-$k.txt" >>"$all"
  # Task k must have rendered exactly the k-th of 3 contiguous runs: frames i of n with
  # floor(i*3/n) = k-1.
  expected=$(find "$frames" -maxdepth 1 -name 'frame_*.sdf' -printf '%f\n' | sort |
    awk -v k="$k" -v n="$total" 'int((NR - 1) * 3 / n) == k - 1')
  if [ "$(sort "$tmp/task-$k.txt")" != "$expected" ]; then
    echo "error: task $k did not render exactly its shard" >&2
    failed=1
  fi
  echo "    task $k rendered $(wc -l <"$tmp/task-$k.txt") frames"
done
dups=$(sort "$all" | uniq -d)
if [ -n "$dups" ]; then
  echo "error: frames rendered more than once: $dups" >&2
  failed=1
fi
if [ "$(sort -u "$all" | wc -l)" -ne "$total" ]; then
  echo "error: $(sort -u "$all" | wc -l) distinct frames rendered, expected $total" >&2
  failed=1
fi
pngs=$(find "$frames" -maxdepth 1 -name 'frame_*.png' | wc -l)
if [ "$pngs" -ne "$total" ]; then
  echo "error: $pngs images for $total frames" >&2
  failed=1
fi
[ "$failed" -eq 0 ] || exit 1

echo "==> resubmitting: every frame is unchanged, nothing may render"
submit second
again=$(cat "$tmp"/out/second-*.out | grep -c 'rendered frame_' || true)
if [ "$again" -ne 0 ]; then
  echo "error: the second run rendered $again frames" >&2
  exit 1
fi

ok=yes
echo "slurm test passed: $total frames rendered exactly once across 3 array tasks; a rerun rendered none"
