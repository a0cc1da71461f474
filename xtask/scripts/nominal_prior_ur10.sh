#!/usr/bin/env bash
# The prior toward the nominal geometry on the real UR10: fit times on C's even rows and
# held-out errors on C even -> odd, B even -> odd and B's elbow split (rows with q3 > 0 against
# q3 < 0, each way), beside the nominal geometry placed by `--method base-tool`.
# Usage: xtask/scripts/nominal_prior_ur10.sh CALIB DATA_DIR OUT_DIR
# DATA_DIR holds the SPEC CSVs of `cargo xtask convert-ur10` (B.csv, B_even.csv, B_odd.csv,
# C_even.csv, C_odd.csv); the data is never committed. Prints one line per case.
set -euo pipefail
calib=$1 data=$2 out=$3
robot=$(dirname "$0")/../../fixtures/robots/ur10.ron
mkdir -p "$out"
awk -F, -v pos="$out/B_q3pos.csv" -v neg="$out/B_q3neg.csv" \
    'NR == 1 { print > pos; print > neg; next } $3 > 0 { print >> pos } $3 < 0 { print >> neg }' "$data/B.csv"
# case: name train test method [extra args]
run() {
    local name=$1 train=$2 test=$3 method=$4
    shift 4
    local model="$out/$name.ron" start end
    start=$(date +%s.%N)
    "$calib" fit --robot "$robot" --data "$train" --method "$method" "$@" --out "$model" > "$out/$name.fit.txt" 2>&1
    end=$(date +%s.%N)
    local error
    error=$("$calib" eval --model "$model" --data "$test" --json 2> /dev/null |
        python3 -c 'import json, sys; print("%.4f" % json.load(sys.stdin)["mean_position_error_mm"])')
    local prior
    prior=$(grep -o 'prior toward the nominal geometry: .*' "$out/$name.fit.txt" | head -1 || true)
    printf '%-28s %8.1f s  %s mm  %s\n' "$name" "$(echo "$end - $start" | bc)" "$error" "$prior"
}
run C_poe "$data/C_even.csv" "$data/C_odd.csv" poe
run C_poe_auto "$data/C_even.csv" "$data/C_odd.csv" poe --effects auto
run B_poe "$data/B_even.csv" "$data/B_odd.csv" poe
run B_poe_auto "$data/B_even.csv" "$data/B_odd.csv" poe --effects auto
for way in "pos neg" "neg pos"; do
    set -- $way
    run "B_q3$1_base-tool" "$out/B_q3$1.csv" "$out/B_q3$2.csv" base-tool
    run "B_q3$1_poe" "$out/B_q3$1.csv" "$out/B_q3$2.csv" poe
    run "B_q3$1_poe_auto" "$out/B_q3$1.csv" "$out/B_q3$2.csv" poe --effects auto
done
