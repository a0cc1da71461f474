#!/usr/bin/env bash
# The prior toward the nominal geometry on simulated arms: a UR10 (`ur10.urdf`, its upper
# arm and forearm bent under the URDF's masses and payloads of 1-7.5 kg) and the column arm
# (`column_arm.urdf`, its column bent under the URDF's masses), each with `calib
# simulate`'s geometric errors (every local frame off by up to 1 mm and 1 mrad per component) and
# tracker noise, fitted on the even rows of two branch configurations (wrist not flipped, elbow
# either way), evaluated on their odd rows ("within") and on the third configuration (the wrist
# flipped, elbow up: "outside"), beside the nominal geometry placed by `--method base-tool`.
# Usage: xtask/scripts/nominal_prior_sim.sh CALIB OUT_DIR [SEEDS...]   (default seeds 1 2 3 4 5)
# Prints one line per robot, seed and method: the mean position error within and outside, mm.
set -euo pipefail
calib=$1 out=$2
shift 2
seeds=${*:-1 2 3 4 5}
fixtures=$(dirname "$0")/../../fixtures/robots
mkdir -p "$out"
echo '(deflection: (links: [(joint_index: 0, flexibility_per_nm2: (1e-6, 1e-6))]), tracker_noise: ())' > "$out/column.ron"
echo '(deflection: (links: [(joint_index: 1, flexibility_per_nm2: (5e-5, 5e-5)), (joint_index: 2, flexibility_per_nm2: (5e-5, 5e-5))]), tracker_noise: ())' > "$out/ur10.ron"
mean() {
    "$calib" eval --model "$1" --data "$2" --json 2> /dev/null |
        python3 -c 'import json, sys; print("%.4f" % json.load(sys.stdin)["mean_position_error_mm"])'
}
# robot name, file, effects file, elbow column, wrist column (1-based CSV fields), payloads
for spec in "ur10 $fixtures/ur10.urdf $out/ur10.ron 3 5 1,2.5,3.5,5,7.5" "column $fixtures/column_arm.urdf $out/column.ron 4 6 0"; do
    set -- $spec
    name=$1 robot=$2 effects=$3 elbow=$4 wrist=$5 payloads=$6
    for seed in $seeds; do
        dir="$out/$name-$seed"
        mkdir -p "$dir"
        "$calib" simulate --robot "$robot" --out "$dir/all.csv" --rows 1600 --seed "$seed" --effects "$effects" \
            --payloads "$payloads" > /dev/null
        awk -F, -v e="$elbow" -v w="$wrist" -v d="$dir" '
            NR == 1 { print > d "/train.csv"; print > d "/within.csv"; print > d "/outside.csv"; next }
            $w > 0 { if (NR % 2 == 0) print >> d "/train.csv"; else print >> d "/within.csv"; next }
            $w < 0 && $e > 0 { print >> d "/outside.csv" }' "$dir/all.csv"
        for method in base-tool poe poe-gp "poe --effects auto"; do
            model="$dir/$(echo "$method" | tr ' ' '_').ron"
            # shellcheck disable=SC2086
            "$calib" fit --robot "$robot" --data "$dir/train.csv" --method $method --out "$model" > "$model.txt" 2>&1
            printf '%-7s seed %s  %-20s within %s  outside %s\n' "$name" "$seed" "$method" \
                "$(mean "$model" "$dir/within.csv")" "$(mean "$model" "$dir/outside.csv")"
        done
    done
done
