#!/bin/bash
# The cost model's timings, each configuration timed in separate processes:
# the four lists of the fit (sweep.txt, layouts.txt, layouts_refit.txt,
# sweep_bracket.txt), once per run, as the layouts step times them (frame 1 after a history
# frame, each pass the median of 5 runs). A small build's time moves from
# one process to the next (on the H100 a 100K refit took 0.57 ms in one run,
# 0.24 in two others) while it repeats within a process; the fit takes each
# pass's median over the runs
# (bench/gpu/replicate_median.py). On the GPU machine after
# `bash bench/gpu/run.sh build`:
#   UNITS="1:sweep 1:layouts 1:layouts_refit 2:sweep ..." DEADLINE=480 bash bench/gpu/retime_fit.sh
# UNITS: run:list pairs (default: runs 1-3 of the four lists); a unit
# starts only before DEADLINE seconds (default: no limit). What finished
# comes back as $OUT/retimed.tar.gz (run<N>/<list>/<config>.timings.csv).
set -uo pipefail
O=${OUT:?OUT: the folder that comes back}
units=${UNITS:-$(for r in 1 2 3; do for l in sweep layouts layouts_refit sweep_bracket; do echo -n "$r:$l "; done; done)}
T=$O/retimed
start=$SECONDS
for u in $units; do
    rep=${u%%:*} list=${u#*:}
    if [ -n "${DEADLINE:-}" ] && [ $((SECONDS - start)) -ge "$DEADLINE" ]; then
        echo "run $rep: $list: not started (deadline)"
        continue
    fi
    OUT=$T/work LAYOUT_LIST=bench/gpu/$list.txt REPEAT=5 bash bench/gpu/run.sh layouts > "$T.log" 2>&1
    mkdir -p "$T/run$rep" "$T/x"
    tar xzf "$T/work/layouts.tar.gz" -C "$T/x" && rm -rf "$T/work"
    mv "$T/x/layouts" "$T/run$rep/$list"
    echo "run $rep: $list: $(ls "$T/run$rep/$list" | grep -c timings.csv) configurations, $((SECONDS - start)) s"
done
rm -rf "$T/x"
tar czf "$O/retimed.tar.gz" -C "$T" . && rm -rf "$T"
