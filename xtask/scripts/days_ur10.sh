#!/bin/bash
# xtask/scripts/days_ur10.sh CALIB (docs/results/days.md): UR10 early -> late (first half of the rows
# against the second; the series have no time stamps) within B and C, and C -> B; poe-gp with and
# without --effects auto, evaluated as is and after registering the base on the first 30 test rows.
# Run in a scratch folder holding B_early/B_late/C_early/C_late, their _reg (first 30) and _test
# (the rest) halves, B_reg.csv and B_test.csv, cut from /work/data/{B,C}.csv.
C=$(realpath "$1"); R=$(realpath "$(dirname "$0")/../../fixtures/robots/ur10.ron")
ev() { $C eval --model $1 --data $2 --json 2>/dev/null | python3 -c 'import json,sys; d=json.load(sys.stdin); print("%.4f mm %.4f mrad" % (d["mean_position_error_mm"], d["mean_rotation_error_mrad"] or 0))'; }
for case in "B_early B_late" "C_early C_late" "C B"; do set -- $case; tr=$1; te=$2
  trf=$tr.csv; [ $tr = C ] && trf=/work/data/C.csv
  for e in none auto; do EF=""; [ $e = auto ] && EF="--effects auto"
    $C fit --robot $R --data $trf --method poe-gp $EF --out $tr.$e.ron > $tr.$e.fit.txt 2>&1
    if [ $te = B ]; then reg=B_reg.csv; test=B_test.csv; whole=/work/data/B.csv; else reg=${te}_reg.csv; test=${te}_test.csv; whole=$te.csv; fi
    $C register --model $tr.$e.ron --data $reg --out $tr.$e.$te.reg.ron > $tr.$e.$te.reg.txt 2>&1
    echo "$tr -> $te poe-gp $e: as is $(ev $tr.$e.ron $whole) | registered on 30, the rest: $(ev $tr.$e.$te.reg.ron $test)"
  done
done
