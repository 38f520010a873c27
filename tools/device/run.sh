#!/usr/bin/env bash
# The one command of a device call that measures issue 45's 16-core targets (the
# device: 16 cores, Python 3.12 at python3, no network; docs/performance.md, "Measuring
# on a 16-core machine without network"). Run from the repository root, with .whl/
# (tools/device/fetch_wheels.sh) carried:
#
#   bash tools/device/run.sh            # the targets' sizes: about 9 minutes on 16 cores
#   KIT_SMALL=1 bash tools/device/run.sh   # small sizes: the kit proved on 2 cores
#
# It prints the machine, installs the carried wheels into /tmp/site, builds the
# solver's C kernel for this python3 (or takes the carried build) and stops unless
# minvar._lqg_kernel loads (without it planning is many times slower: every figure
# would be wrong), runs a smoke check, then each benchmark part (tools/device/parts.py)
# in its own process under its own time limit, never past KIT_BUDGET seconds in all
# (default 540: a run call's timeout_s of 600 leaves a minute). Logs go to $OUT
# (default /tmp/kit-out), 7 files: 0-setup.log (machine, install, kernel, smoke, each
# part's end), 1-scaling.log ... 5-study.log (each part's output) and tables.md (every
# part's tables, also printed at the end, so that the call's output tail holds them).
# Exit 0 when every part ran to its end; the figures say whether each target is met.
set -uo pipefail
cd "$(dirname "$0")/../.." || exit 2
OUT=${OUT:-/tmp/kit-out}
BUDGET=${KIT_BUDGET:-540}
mkdir -p "$OUT"
LOG=$OUT/0-setup.log
MD=$OUT/tables.md
: >"$LOG"
: >"$MD"
START=$(date +%s)
export PYTHONUNBUFFERED=1 MPLBACKEND=Agg

elapsed() { echo $(($(date +%s) - START)); }
say() { echo "[$(elapsed) s] $*" | tee -a "$LOG"; }

{
    echo "== machine"
    date -u
    echo "cores (nproc): $(nproc); CPUs online: $(getconf _NPROCESSORS_ONLN)"
    grep -m1 'model name' /proc/cpuinfo || true
    grep -E 'MemTotal|MemAvailable' /proc/meminfo || true
    echo "load: $(cat /proc/loadavg)"
    echo "python3: $(command -v python3) $(python3 --version 2>&1)"
    echo "C compiler: $(command -v cc || command -v gcc || echo none)"
    echo "git: $(git log -1 --format='%h %s' 2>/dev/null | cut -c1-100)"
} 2>&1 | tee -a "$LOG"

say "== wheels: $(ls .whl/*.whl 2>/dev/null | wc -l) into /tmp/site"
if ! python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl >>"$LOG" 2>&1; then
    say "FAILED: the wheels did not install (log above)"
    exit 3
fi
# the carried packages first (pydantic's typing_extensions over an older one there); the
# repository on the path of every process, dask's workers too (nothing is installed)
export PYTHONPATH=/tmp/site:$PWD

kernel_ok() {
    python3 -c 'from minvar import _kernel; assert _kernel.loaded(), _kernel._WHY' >>"$LOG" 2>&1
}
say "== the solver's C kernel (minvar._lqg_kernel) for this python3"
rm -f minvar/_lqg_kernel.cpython-312*.so
if timeout 120 python3 setup.py -q build_ext --inplace >>"$LOG" 2>&1 && kernel_ok; then
    say "kernel: built here by setup.py"
elif cp .whl/kernel/_lqg_kernel.cpython-312*.so minvar/ 2>>"$LOG" && kernel_ok; then
    say "kernel: the carried build (built by fetch_wheels.sh); setup.py failed here"
else
    say "FAILED: minvar._lqg_kernel does not load; every figure would be wrong: stopping"
    exit 4
fi

# as installed (make bytecode): no process times compiling our modules or the carried
# ones (pip installed them with --no-compile), nor do 16 workers compile them at once
python3 -m compileall -q -j 0 minvar perception hammer_mv tools /tmp/site >/dev/null 2>&1

say "== smoke check"
smoke() {
    python3 - <<'PY' || return 1
import importlib, time
t0 = time.perf_counter()
names = ("numpy scipy pandas matplotlib cv2 statsmodels h5py psutil threadpoolctl tqdm "
         "pydantic pydantic_core typing_extensions lazy_loader dask distributed tornado")
for name in names.split():
    mod = importlib.import_module(name)
    print(f"  {name} {getattr(mod, '__version__', '?')}  {mod.__file__}")
import dask.distributed  # noqa: F401
import perception, minvar  # noqa: F401
from minvar import _kernel
from perception.pipeline import RecognitionSettings  # pydantic-declared settings
RecognitionSettings()
assert _kernel.loaded()
print(f"  imports {time.perf_counter() - t0:.1f} s; compiled kernel loaded")
# dask's scheduler and workers talk over TCP on 127.0.0.1: the loopback must be up
import socket
try:
    with socket.create_server(("127.0.0.1", 0)) as server:
        socket.create_connection(server.getsockname(), timeout=5).close()
    print("  TCP on 127.0.0.1: yes (dask can start)")
except OSError as exc:  # the local parts can still run: the scaling part says so
    print(f"  TCP on 127.0.0.1: NO ({exc}): the dask rows will fail")
PY
    python3 tools/bench.py --only solver -o /tmp/kit-solver.md || return 1
    rm -rf /tmp/kit-smoke
    python3 -m hammer_mv recognize tests/data/mocap/optotrak-trials.tsv --rate 85 \
        -o /tmp/kit-smoke --quiet || return 1
    echo "  recognize of 4 Optotrak trials with figures: $(ls /tmp/kit-smoke | wc -l) files"
}
if ! timeout 90 bash -c "$(declare -f smoke); smoke" >>"$LOG" 2>&1; then
    tail -30 "$LOG"
    say "FAILED: the smoke check (log above): stopping"
    exit 5
fi
grep -E '^  |compiled passes' "$LOG" | tail -25
say "smoke check passed"

# part: file number, name, its time limit on 16 cores in s ("rest": what the budget
# has left), its options at the targets' sizes, then with KIT_SMALL=1 (a 2-core proof
# in minutes; limits doubled). No part starts with under 30 s of the budget left.
FAILED=0
part() {
    local n=$1 name=$2 limit=$3 full=$4 small=$5 args left rc t0
    left=$((BUDGET - $(elapsed)))
    [ "$limit" = rest ] && limit=$left
    if [ -n "${KIT_SMALL:-}" ]; then args=$small; limit=$((limit * 2)); else args=$full; fi
    if [ "$left" -lt 30 ]; then
        say "part $name: SKIPPED, ${left} s of the budget left"
        FAILED=1
        return
    fi
    [ "$limit" -gt "$left" ] && limit=$left
    say "part $name (limit ${limit} s): parts.py $name $args"
    t0=$(date +%s)
    # shellcheck disable=SC2086 # the options are words
    timeout -k 10 "$limit" python3 tools/device/parts.py "$name" $args --markdown "$MD" \
        >"$OUT/$n-$name.log" 2>&1
    rc=$?
    [ "$rc" -eq 0 ] || FAILED=1
    case $rc in
        0) say "part $name: done in $(($(date +%s) - t0)) s" ;;
        124|137) say "part $name: STOPPED at its limit (${limit} s); what it printed: $n-$name.log" ;;
        *) say "part $name: FAILED (exit $rc) after $(($(date +%s) - t0)) s; its log:"
           tail -15 "$OUT/$n-$name.log" | tee -a "$LOG" ;;
    esac
}

# Bounded parts first, in order of importance (issue 45's "Done when"), each limited to
# about 1.5 x its estimate on 16 cores (docs/performance.md); the study, the longest and
# least certain, last with the rest of the budget (about 200 s when the others keep to
# their estimates; its smaller run's figures are printed as soon as it ends).
part 1 scaling 200 "--clips 120" "--clips 6"
part 2 phases 100 "--trials 600 --base-trials 60 --counts 8,16" \
    "--trials 24 --base-trials 12 --counts 2"
part 3 online 60 "" "--videos 2 --stream 12"
part 4 mocap 75 "" ""
part 5 study rest "--participants 100 --study-trials 100" "--participants 6 --study-trials 20"

cat "$MD"
echo
grep -E '^\[[0-9]+ s\] (part|kernel|smoke|FAILED)' "$LOG"
say "== all parts in $(elapsed) s (budget ${BUDGET} s)"
exit "$FAILED"
