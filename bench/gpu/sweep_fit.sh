#!/bin/bash
# The cost model against the sweep: `accretion calibrate --holdout 0.5` over
# split seeds 1-5 (half the configurations fitted, the other half predicted),
# every model form (shared, per_pass, selected; and per_pass without the
# working-set term, per_pass_no_ws), per pass the median and worst relative error; and the
# per_pass and selected coefficients fitted on every configuration.
#   bash bench/gpu/sweep_fit.sh COUNTERS.csv TIMINGS.csv OUT_DIR
set -euo pipefail
counters=$1 timings=$2 out=$3
A=${ACCRETION:-build/accretion}
mkdir -p "$out"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# The same counters without the working set (cold_work 0: the per-pass form
# before the working-set term), as the form "per_pass_no_ws".
python3 - "$counters" "$T/no_ws.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
names = [n for n in rows[0] if n != "working_set_bytes"]
w = csv.DictWriter(open(sys.argv[2], "w", newline=""), fieldnames=names, extrasaction="ignore")
w.writeheader()
w.writerows(rows)
PY
echo "split_seed,form,pass,rows,median_relative_error,worst_relative_error,worst_config" > "$out/holdout.csv"
for seed in 1 2 3 4 5; do
    $A calibrate "$counters" "$timings" --holdout 0.5 --split-seed $seed -o "$T/c$seed.json" > /dev/null
    $A calibrate "$T/no_ws.csv" "$timings" --holdout 0.5 --split-seed $seed -o "$T/n$seed.json" > /dev/null
    for form in shared per_pass selected; do
        jq -r --arg s $seed --arg f $form '.holdout[$f].passes[] |
            [$s, $f, .pass, .rows, .median_relative_error, .worst_relative_error, .worst_config] | @csv' "$T/c$seed.json" |
            tr -d '"' >> "$out/holdout.csv"
    done
    jq -r --arg s $seed '.holdout.per_pass.passes[] |
        [$s, "per_pass_no_ws", .pass, .rows, .median_relative_error, .worst_relative_error, .worst_config] | @csv' "$T/n$seed.json" |
        tr -d '"' >> "$out/holdout.csv"
done
$A calibrate "$counters" "$timings" --form per_pass -o "$out/coefficients_per_pass.json" > "$out/calibrate_per_pass.txt"
$A calibrate "$counters" "$timings" --form shared -o "$out/coefficients_shared.json" > "$out/calibrate_shared.txt"
$A calibrate "$counters" "$timings" --form selected -o "$out/coefficients_selected.json" > "$out/calibrate_selected.txt"
# Per pass over the five splits: the median of the medians and the worst of the worsts.
python3 - "$out/holdout.csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
passes = sorted({r["pass"] for r in rows}, key=lambda p: (p == "all passes", p))
forms = ("shared", "per_pass_no_ws", "per_pass", "selected")
print(f"{'pass':<20}" + "".join(f" {f + ' median':>22} {f + ' worst':>21}" for f in forms))
for p in passes:
    cells = []
    for f in forms:
        sel = [r for r in rows if r["pass"] == p and r["form"] == f]
        cells += [100 * statistics.median(float(r["median_relative_error"]) for r in sel),
                  100 * max(float(r["worst_relative_error"]) for r in sel)]
    print(f"{p:<20}" + "".join(f" {c:>21.1f}%" for c in cells))
PY
