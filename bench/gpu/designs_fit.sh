#!/usr/bin/env bash
# The cost model with the designs in its data: the sweep's counters and
# H100 timings (results/sweep_*.csv) and the designs' (designs_cost.sh's
# cost CSVs of the 100K and cluster_150k configurations, results/designs.csv's
# H100 rows),
# fitted per pass on half the configurations and predicting the other half
# (`calibrate --holdout 0.5`, split seeds 1-12); each run's report in OUT,
# summary.txt per configuration (designs_holdout.py: its frame and its
# iterated spatial reuse in every split that held it out), and
# coefficients_h100.json, the fit of them all. The sweep's timings are
# SWEEP_TIMINGS (results/sweep_timings_d37668c.csv: the twin at d37668c149,
# whose spatial pass costs 0.69x of results/sweep_timings.csv's).
# SWEEP_COUNTERS: the sweep's counters (results/sweep_counters.csv by
# default; results/sweep_counters_feb5ed5.csv holds the timed 70 counted
# again with the traversal model's node_visits).
# DROP: counters set to 0 in every CSV before fitting (bench/gpu/zero_counters.py:
# the same counts without them, the control of a new counter).
# GPU, MEASURED_AT: what the coefficients file records of the timings (calibrate
# --gpu, --measured-at; by default the H100 and the files fitted).
# SIZES: the designs' sizes fitted ("100k cluster" by default; "100k cluster
# 1m" adds the 1M configurations, results/designs_fit_all: a fit of 100K and
# the cluster alone extrapolates badly to 1M, docs/designs.md).
#   bash bench/gpu/designs_fit.sh COST_DIR [OUT]   (OUT: bench/gpu/results/designs_fit)
set -euo pipefail
cd "$(dirname "$0")/../.."
costs=$1 out=${2:-bench/gpu/results/designs_fit}
A=${ACCRETION:-build/accretion}
read -ra sizes <<< "${SIZES:-100k cluster}"
mkdir -p "$out"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
{ cat "${SWEEP_TIMINGS:-bench/gpu/results/sweep_timings_d37668c.csv}"
  python3 bench/gpu/designs_timings.py "_($(IFS='|'; echo "${sizes[*]}"))\$"
} > "$T/timings.csv"
counters=("${SWEEP_COUNTERS:-bench/gpu/results/sweep_counters.csv}")
for s in "${sizes[@]}"; do counters+=("$costs"/cost_*_"$s".csv); done
if [ -n "${DROP:-}" ]; then
    python3 bench/gpu/zero_counters.py "$DROP" "$T/counters" "${counters[@]}"
    mapfile -t counters < <(for c in "${counters[@]}"; do echo "$T/counters/$(basename "$c")"; done)
fi
for seed in $(seq 1 12); do
    "$A" calibrate "${counters[@]}" "$T/timings.csv" --form per_pass --holdout 0.5 \
        --split-seed $seed -o "$T/c$seed.json" | sed -n '/^held out/,$p' | grep -v '^coefficients:' > "$out/holdout_seed$seed.txt"
done
python3 bench/gpu/designs_holdout.py "$T"/c*.json > "$out/summary.txt"
# The fit of every configuration (no hold-out): coefficients calibrate writes, for `-D gpu.coefficients=`.
"$A" calibrate "${counters[@]}" "$T/timings.csv" --form per_pass -o "$out/coefficients_h100.json" \
    --gpu "${GPU:-NVIDIA H100 80GB HBM3 (no RT cores: software traversal)}" \
    --measured-at "${MEASURED_AT:-timings: ${SWEEP_TIMINGS:-bench/gpu/results/sweep_timings_d37668c.csv} and the H100 rows of bench/gpu/results/designs.csv (each with its commit); counters: ${counters[0]} and $costs}" > /dev/null
cat "$out"/holdout_seed*.txt "$out/summary.txt"
