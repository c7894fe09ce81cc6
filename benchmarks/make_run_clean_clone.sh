#!/bin/bash
# `make run` as a new user meets it: a clean clone of this checkout's HEAD in a temporary
# folder, then `make setup`, `make run` with an empty Numba cache (the clone's own), and
# `make run` again with the cache warm (results removed first). Prints the wall time of
# each, the reproduce command's own time lines, and the machine's load average sampled
# every 10 s meanwhile (other work on the machine slows everything; say it with the
# numbers). Needs network access or a local wheel cache for `make setup`.
#
#   benchmarks/make_run_clean_clone.sh            # the clone is left in /tmp (printed)
set -euo pipefail
here=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
clone=$(mktemp -d "${TMPDIR:-/tmp}/quadimpact-clone-XXXX")
git clone -q "$here" "$clone"
cd "$clone"
echo "clone  $clone at $(git log --oneline -1 | cut -c1-60)"
(while true; do echo "$(date +%T) $(cut -d' ' -f1-3 /proc/loadavg)"; sleep 10; done) > load.txt &
sampler=$!
trap 'kill $sampler 2>/dev/null || true' EXIT

timed() {  # timed NAME LOG COMMAND...: the command's wall time, s
    local name=$1 log=$2 start end
    shift 2
    start=$(date +%s.%N)
    "$@" > "$log" 2>&1
    end=$(date +%s.%N)
    printf '%-22s %6.1f s\n' "$name" "$(echo "$end - $start" | bc)"
}

timed "make setup" setup.log make setup
timed "make run, cold cache" cold.log make run
rm -rf results
timed "make run, warm cache" warm.log make run
kill $sampler
grep -h '^time' cold.log warm.log | sed 's/^/reproduce /'
awk '{print $2}' load.txt | sort -n | awk '{v[NR]=$1} END {printf \
    "load   1-min load average over %d samples: min %s, median %s, max %s (make run itself: about 2)\n", \
    NR, v[1], v[int((NR + 1) / 2)], v[NR]}'
