#!/usr/bin/env bash
# A distributed run killed mid-run (issue 43 item 7): runs COMMAND (mpiexec ... a long run that
# writes ARCHIVE) in a session of its own, waits until ARCHIVE's index lists at least
# MIN_STEPS committed steps, sends SIGKILL to mpiexec alone, makes sure no rank outlives it (the
# ranks are given GRACE_S seconds to notice; any left are killed and named: the test leaves no
# orphans), then checks that `insitu-view verify` finds the archive clean and that `insitu-view
# info` lists every step committed before the kill. With KILL=all, SIGKILL goes to every process
# of the run at once instead, as a batch system ends a job at its time limit: the ranks die
# wherever they are, rank 0's writer thread mid-file as likely as not.
#
#   [KILL=all] [PYTHON=python3] kill_test.sh INSITU_VIEW ARCHIVE MIN_STEPS -- COMMAND...
#
# Every wait is bounded (WAIT_S for the steps, GRACE_S for the ranks) and says what it waited
# for when it gives up, so that a loaded machine makes the test slow, not wrong.
set -uo pipefail

if [[ $# -lt 5 || $4 != "--" ]]; then
    echo "usage: kill_test.sh INSITU_VIEW ARCHIVE MIN_STEPS -- COMMAND..." >&2
    exit 2
fi
insitu_view=$1
archive=$2
min_steps=$3
shift 4
wait_s=${WAIT_S:-200}
grace_s=${GRACE_S:-30}
python=${PYTHON:-python3}
log="${archive}.log"

rm -rf "$archive" "$log" "$archive".step*.png

# The steps committed in ARCHIVE, one a line: those of manifest.json's "steps" and of each whole
# line of manifest.journal (the writer's commit point: a step is in the archive once its line is
# there; a torn last line is not). Read in that order, a compaction in between can only hide
# steps, never invent one. Empty while the archive has no index yet.
committed_steps() {
    "$python" - "$1" <<'PYTHON'
import json, os, sys
steps = set()
try:
    with open(os.path.join(sys.argv[1], "manifest.json")) as manifest:
        steps.update(entry["step"] for entry in json.load(manifest).get("steps", []))
except (OSError, ValueError):
    pass
try:
    with open(os.path.join(sys.argv[1], "manifest.journal")) as journal:
        for line in journal:
            if line.endswith("\n"):
                steps.add(json.loads(line)["step"])
except (OSError, ValueError):
    pass
print("\n".join(str(step) for step in sorted(steps)))
PYTHON
}

# The processes of session $1 (ps lists the session id of each), zombies aside.
session_processes() {
    ps -e -o pid=,sid=,stat=,args= | awk -v sid="$1" '$2 == sid && $3 !~ /^Z/ {print}'
}

session=""
cleanup() {
    # Whatever went wrong, nothing of the run outlives the test.
    if [[ -n $session ]]; then
        session_processes "$session" | awk '{print $1}' | xargs -r kill -KILL 2>/dev/null
    fi
}
trap cleanup EXIT
trap "exit 1" INT TERM

# setsid without --fork execs COMMAND in place: $! is mpiexec, and its pid is the session's id,
# which the ranks (children of mpiexec, whatever process group they get) keep.
setsid "$@" >"$log" 2>&1 &
launcher=$!
session=$launcher

committed=""
deadline=$((SECONDS + wait_s))
while :; do
    if ! kill -0 "$launcher" 2>/dev/null; then
        wait "$launcher"
        echo "FAIL: the run ended (exit $?) before its archive listed $min_steps steps;" \
            "its output:" >&2
        tail -n 20 "$log" >&2
        exit 1
    fi
    if [[ -e $archive ]]; then
        committed=$(committed_steps "$archive")
        count=$(grep -c . <<<"$committed")
        if ((count >= min_steps)); then break; fi
    fi
    if ((SECONDS >= deadline)); then
        echo "FAIL: after ${wait_s} s the archive lists ${count:-0} of the $min_steps steps" \
            "waited for; the run's output:" >&2
        tail -n 20 "$log" >&2
        exit 1
    fi
    sleep 0.2
done
echo "committed before the kill: $(tr '\n' ' ' <<<"$committed")"

if [[ ${KILL:-launcher} == all ]]; then
    session_processes "$session" | awk '{print $1}' | xargs -r kill -KILL 2>/dev/null
else
    kill -KILL "$launcher"
fi
wait "$launcher" 2>/dev/null
# The processes of the run still alive after waiting up to $1 seconds for them to end.
survivors_after() {
    local until=$((SECONDS + $1))
    while [[ -n $(session_processes "$session") ]] && ((SECONDS < until)); do
        sleep 0.2
    done
    session_processes "$session"
}

# Open MPI's ranks notice that mpiexec is gone and end; give them a bounded time to.
left=$(survivors_after "$grace_s")
if [[ -n $left ]]; then
    echo "note: these outlived mpiexec by ${grace_s} s and are killed now:" >&2
    echo "$left" >&2
    echo "$left" | awk '{print $1}' | xargs -r kill -KILL 2>/dev/null
    left=$(survivors_after 10)
    if [[ -n $left ]]; then
        echo "FAIL: processes of the run survive SIGKILL:" >&2
        echo "$left" >&2
        exit 1
    fi
fi
session=""
echo "no process of the run is left"

# The archive as the kill left it: every byte against its index, then its steps.
if ! "$insitu_view" verify "$archive"; then
    echo "FAIL: insitu-view verify does not find the killed run's archive clean" >&2
    exit 1
fi
# Every step committed before the kill is still in the index, and renders.
listed=$(committed_steps "$archive")
missing=$(comm -23 <(sort <<<"$committed") <(sort <<<"$listed"))
if [[ -n $missing ]]; then
    echo "FAIL: steps committed before the kill are no longer listed:" \
        "$(tr '\n' ' ' <<<"$missing")" >&2
    exit 1
fi
for step in $committed; do
    if ! "$insitu_view" render "$archive" --step "$step" --out "${archive}.step${step}.png" \
        >/dev/null; then
        echo "FAIL: step $step, committed before the kill, does not render" >&2
        exit 1
    fi
done
echo "PASS: the archive verifies and lists $(grep -c . <<<"$listed") steps; each of the" \
    "$(grep -c . <<<"$committed") committed before the kill renders"
