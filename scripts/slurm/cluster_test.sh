#!/usr/bin/env bash
# A one-node Slurm cluster on this machine (Debian's slurm-wlm daemons and
# munge, installed here if missing, as root), then:
#  1. the job array of scripts/slurm/reference.sbatch (4 shards of a small
#     scene), merged, must equal a single run bit for bit;
#  2. a task signalled with `scancel --signal=TERM` mid-run checkpoints,
#     `scontrol requeue` runs it again, it resumes from the checkpoint (its
#     log says so) and its image equals an uninterrupted run bit for bit.
# Usage: bash scripts/slurm/cluster_test.sh [BUILD_DIR]   (from the repository root)
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
BIN=$ROOT/${1:-build}/accretion
[[ -x $BIN ]] || { echo "slurm test: no $BIN (build first)" >&2; exit 2; }
say() { echo "slurm test: $*" >&2; }
fail() { echo "slurm test: FAILED: $*" >&2; exit 1; }

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
    say "installing slurmctld, slurmd, slurm-client and munge (Debian packages)"
    [[ $(id -u) == 0 ]] || fail "installing Slurm needs root"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge >/dev/null
fi

WORK=$(mktemp -d /tmp/accretion-slurm.XXXXXX)
NODE=$(hostname -s)
CPUS=$(nproc)
PIDS=()
cleanup() {
    for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
    [[ ${KEEP:-0} == 1 ]] || rm -rf "$WORK"
}
trap cleanup EXIT

# munge: a key of our own and a daemon on a private socket.
mkdir -p "$WORK/munge" "$WORK/state" "$WORK/spool" "$WORK/out"
chmod 700 "$WORK/munge"
dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$WORK/munge/munge.key"
SOCKET=$WORK/munge/munge.socket
munged --force --key-file="$WORK/munge/munge.key" --socket="$SOCKET" --pid-file="$WORK/munge/munged.pid" \
       --log-file="$WORK/munge/munged.log" --seed-file="$WORK/munge/munged.seed" || fail "munged did not start ($(cat "$WORK/munge/munged.log" 2>/dev/null))"
PIDS+=("$(cat "$WORK/munge/munged.pid")")

cat > "$WORK/slurm.conf" <<CONF
ClusterName=accretion-test
SlurmctldHost=$NODE
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCKET
CredType=cred/munge
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
JobRequeue=1
KillWait=30
NodeName=$NODE CPUs=$CPUS State=UNKNOWN
PartitionName=test Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$WORK/slurm.conf
slurmctld -D -f "$SLURM_CONF" >"$WORK/slurmctld.stdout" 2>&1 & PIDS+=($!)
slurmd -D -f "$SLURM_CONF" >"$WORK/slurmd.stdout" 2>&1 & PIDS+=($!)
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -q idle && break
    sleep 1
done
sinfo -h -o %T 2>/dev/null | grep -q idle || fail "the node never became idle: $(tail -n 3 "$WORK/slurmctld.log" "$WORK/slurmd.log" 2>&1)"
say "one-node cluster up ($NODE, $CPUS CPUs)"

# Wait for job $1 (all its array tasks) to leave the queue.
wait_job() {
    for _ in $(seq 600); do
        [[ -z $(squeue -h -j "$1" 2>/dev/null) ]] && return 0
        sleep 1
    done
    fail "job $1 still queued after 10 minutes"
}
# One field of job $1's record in slurmctld ("" once slurmctld has forgotten it).
job_field() {
    scontrol -o show job "$1" 2>/dev/null | head -1 | grep -o " $2=[^ ]*" | cut -d= -f2
}
# The pixels of two EXRs are bit-identical (every channel, float compare at 0 tolerance).
same_pixels() {
    idiff -q -fail 0 -failpercent 0 -warn 0 -warnpercent 0 "$1" "$2" >/dev/null || fail "$1 and $2 differ: $(idiff -fail 0 "$1" "$2" | tail -3)"
}

SCENE_ARGS=(-D particles.count=3000 -D camera.width=96 -D camera.height=54)
export ACCRETION=$BIN SCENE=$ROOT/scenes/quickstart.toml ESTIMATOR=tree SPP=256 FRAME=0 SHARDS=4 OUT=$WORK/out/array
# docs/batches.md's job array, scaled down: 4 tasks of one CPU each; the scene
# is shrunk through the same render flags for every task.
sed "s|render \"\$SCENE\"|render \"\$SCENE\" ${SCENE_ARGS[*]}|" scripts/slurm/reference.sbatch > "$WORK/reference.sbatch"
cd "$WORK"
JOB=$(sbatch --parsable --array=0-3 --cpus-per-task=1 --time=10 "$WORK/reference.sbatch")
say "job array $JOB submitted"
wait_job "$JOB"
for t in 0 1 2 3; do
    grep -q "^stats:" "slurm-${JOB}_$t.out" || fail "task $t did not finish: $(tail -n 5 "slurm-${JOB}_$t.out")"
done
"$BIN" merge "$OUT"/quickstart.0000.shard*of4.exr -o "$WORK/out/merged.exr" >/dev/null
"$BIN" render "$SCENE" "${SCENE_ARGS[@]}" --quiet --estimator tree --spp 256 --frames 0 -o "$WORK/out/single.exr" >/dev/null
same_pixels "$WORK/out/merged.exr" "$WORK/out/single.exr"
say "PASS: the merged job array equals a single run bit for bit"

# Signal, requeue, resume: one task with enough samples to be stopped mid-frame
# (65536 a pixel: 9.6 s alone on 2 cores, signalled about 3 s after its
# first frame line; it resumed at row 27 of 54 in the suite's runs).
export SPP=65536 SHARDS=1 OUT=$WORK/out/requeue
JOB=$(sbatch --parsable --requeue --array=0-0 --cpus-per-task=$CPUS --time=10 "$WORK/reference.sbatch")
LOG=slurm-${JOB}_0.out
for _ in $(seq 120); do grep -q "accretion: frame 0" "$LOG" 2>/dev/null && break; sleep 0.5; done
grep -q "accretion: frame 0" "$LOG" || fail "the task never started: $(tail -n 3 "$LOG" 2>&1)"
sleep 3
scancel --signal=TERM "$JOB" || fail "the task ended before it could be signalled: $(tail -n 3 "$LOG")"
# The first run must be over (a final state, not COMPLETING) before the requeue.
for _ in $(seq 240); do
    [[ $(job_field "$JOB" JobState) =~ ^(FAILED|COMPLETED|CANCELLED|)$ ]] && break
    sleep 0.5
done
grep -q "checkpoint" "$LOG" || fail "no checkpoint after SIGTERM: $(tail -n 5 "$LOG")"
cp "$LOG" "$WORK/first_run.log"
# Requeue, and again while the job sits in a final state without having
# resumed: a requeue within the second of the kill can be allocated at once and
# refused by slurmd ("Job credential revoked"), which ends the job again. A
# requeued job otherwise waits a few minutes before it is eligible, so its
# start time is moved to now (the array task takes the update under either id).
sleep 2
for k in $(seq 480); do
    grep -q "resuming" "$LOG" 2>/dev/null && break
    if (( k % 10 == 1 )); then
        if [[ $(job_field "$JOB" JobState) =~ ^(FAILED|COMPLETED|CANCELLED|)$ ]]; then
            scontrol requeue "$JOB" 2>/dev/null || scontrol requeue "${JOB}_0" 2>/dev/null || true
        fi
        scontrol update JobId="$JOB" StartTime=now 2>/dev/null || true
        scontrol update JobId="${JOB}_0" StartTime=now 2>/dev/null || true
    fi
    sleep 0.5
done
grep -q "resuming" "$LOG" || fail "the requeued task never started: $(scontrol -o show job "$JOB" 2>&1 | grep -o 'JobState=[^ ]* Reason=[^ ]*\|Restarts=[^ ]*' | tr '\n' ' ')
$(grep -i "JobId=${JOB}" "$WORK/slurmctld.log" | tail -8)"
wait_job "$JOB"
# Band-major sweeps: part-way down the frame (rows done) or past its first chunk.
grep -qE "resuming .* at frame 0, chunk ([1-9]|0, pixels before row [0-9]+ column [0-9]+ done)" "$LOG" || fail "the requeued task did not resume from its checkpoint: $(grep -i resum "$LOG" || tail -n 5 "$LOG")"
grep -q "^stats:" "$LOG" || fail "the requeued task did not finish: $(tail -n 5 "$LOG")"
"$BIN" render "$SCENE" "${SCENE_ARGS[@]}" --quiet --estimator tree --spp 65536 --frames 0 -o "$WORK/out/uninterrupted.exr" >/dev/null
same_pixels "$OUT/quickstart.0000.exr" "$WORK/out/uninterrupted.exr"
say "PASS: scancel --signal=TERM, requeue, resume: $(grep -o 'resuming .*' "$LOG" | head -1); image equals an uninterrupted run bit for bit"
