#!/bin/sh
# Profile SUMO's step on a kept run configuration, function by function.
#
#   benchmarks/sumo_profile/profile.sh RUN_DIR [END_S] [OUT_DIR]
#
# RUN_DIR is a directory `arzsumo run` kept (run.sumocfg and sumo/); END_S the simulated span
# (default 400 s); OUT_DIR where the profile and its reports go (default RUN_DIR/profile).
# Writes OUT_DIR/self.txt (functions by their own share of the samples) and
# OUT_DIR/inclusive.txt (functions by the share of samples with them on the stack), and
# OUT_DIR/callers.txt (the call chains into the hottest function, getBackPositionOnLane).
#
# The sumo binary of the eclipse-sumo wheel is stripped; libsumo's shared library keeps its
# symbols, so the profile runs the same configuration through libsumo (libsumo_run.py, one
# simulationStep to the end: the binary's loop, at the binary's cost within a few per cent).
#
# Tools: perf (Debian: apt-get install linux-perf). Where perf cannot sample (a container's
# perf_event_paranoid), valgrind's callgrind (apt-get install valgrind) profiles instead, on
# at most 100 s simulated (about 50 times slower than a plain run); its report is
# callgrind_annotate's, inclusive and self.
set -eu
RUN_DIR=$(cd "$1" && pwd)
END=${2:-400}
OUT=${3:-$RUN_DIR/profile}
HERE=$(cd "$(dirname "$0")" && pwd)
PY=${PYTHON:-$HERE/../../.venv/bin/python}
mkdir -p "$OUT"
cd "$RUN_DIR"

if perf record -q -o "$OUT/probe.data" -- true >/dev/null 2>&1; then
    rm -f "$OUT/probe.data"
    # 300 samples/s with DWARF unwinding: the call chains give inclusive shares without
    # frame pointers.
    perf record -F 300 --call-graph dwarf,32768 -o "$OUT/perf.data" -- \
        "$PY" "$HERE/libsumo_run.py" run.sumocfg --end "$END"
    perf report -i "$OUT/perf.data" --no-children --sort sym --stdio -g none \
        --percent-limit 0.3 --no-inline > "$OUT/self.txt" 2>/dev/null
    perf report -i "$OUT/perf.data" --children --sort sym --stdio -g none \
        --percent-limit 0.5 --no-inline > "$OUT/inclusive.txt" 2>/dev/null
    # who calls the hottest function (slow: perf resolves inlined frames with addr2line)
    perf report -i "$OUT/perf.data" --no-children --sort sym --stdio -G \
        -S MSVehicle::getBackPositionOnLane --percent-limit 1 > "$OUT/callers.txt" 2>/dev/null
    echo "perf: $OUT/self.txt $OUT/inclusive.txt $OUT/callers.txt"
else
    [ "$END" -gt 100 ] && END=100
    valgrind --tool=callgrind --callgrind-out-file="$OUT/callgrind.out" \
        "$PY" "$HERE/libsumo_run.py" run.sumocfg --end "$END"
    callgrind_annotate --inclusive=no "$OUT/callgrind.out" | head -60 > "$OUT/self.txt"
    callgrind_annotate --inclusive=yes "$OUT/callgrind.out" | head -80 > "$OUT/inclusive.txt"
    echo "callgrind ($END s simulated): $OUT/self.txt $OUT/inclusive.txt"
fi
