# Sourced by the test scripts: `stop_processes SECONDS PID...` asks the processes to stop
# (SIGTERM), waits up to SECONDS for each to exit, and kills what is left (SIGKILL). Only the
# given process ids are touched.
stop_processes() {
    local seconds=$1 pid
    shift
    for pid in "$@"; do
        kill -TERM "$pid" 2>/dev/null || true
    done
    for pid in "$@"; do
        timeout "$seconds" tail --pid="$pid" -f /dev/null 2>/dev/null || kill -KILL "$pid" 2>/dev/null || true
    done
}
