#!/usr/bin/env bash
# Stop the single-node SLURM started by start.sh: cancel jobs, then slurmd, slurmctld, slurmdbd, MariaDB, munged.
# Each daemon is stopped through its own pid file; missing ones are skipped, so running it twice is fine.
set -uo pipefail

RUN_DIR=/run/slurm
TIMEOUT="${SLURM_CI_TIMEOUT:-60}"

# Send TERM to the process named in a pid file and wait until it is gone.
stop_pidfile() {
    local name="$1" pidfile="$2" pid
    [ -s "$pidfile" ] || return 0
    pid="$(cat "$pidfile")"
    if kill -0 "$pid" 2>/dev/null; then
        kill -TERM "$pid"
        for _ in $(seq "$TIMEOUT"); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 1
        done
        kill -0 "$pid" 2>/dev/null && { echo "slurm: $name ($pid) did not stop, killing"; kill -KILL "$pid"; }
        echo "slurm: stopped $name"
    fi
    rm -f "$pidfile"
}

if command -v scancel >/dev/null && scontrol ping >/dev/null 2>&1; then
    scancel --user=root --full 2>/dev/null || true
fi
stop_pidfile slurmd "$RUN_DIR/slurmd.pid"
stop_pidfile slurmctld "$RUN_DIR/slurmctld.pid"
stop_pidfile slurmdbd "$RUN_DIR/slurmdbd.pid"
if command -v mariadb-admin >/dev/null && mariadb-admin ping >/dev/null 2>&1; then
    /etc/init.d/mariadb stop >/dev/null && echo "slurm: stopped mariadb"
fi
stop_pidfile munged /run/munge/munged.pid
exit 0
