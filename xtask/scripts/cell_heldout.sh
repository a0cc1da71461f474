#!/bin/bash
# Issue 26: the held-out estimate a fit keeps in the model file against the error measured on the
# odd rows, each UR10 series' even rows fitted. Usage (from the worktree root, release build):
#   xtask/scripts/cell_heldout.sh [DATA=/work/data]
C=${CALIB:-target/release/calib}; R=fixtures/robots/ur10.ron; D=${1:-/work/data}; T=$(mktemp -d)
ev() { $C eval --model $1 --data $2 --json 2>/dev/null | python3 -c "import json,sys; print('%.4f' % json.load(sys.stdin)['mean_position_error_mm'])"; }
for S in C B D; do for m in "poe" "poe-gp" "poe --effects auto"; do
  $C fit --robot $R --data $D/ur10_${S}_full_even.csv --method $m --out $T/m.ron >/dev/null 2>&1 || { echo "$S | $m | fit failed"; continue; }
  stored=$(python3 -c "import re,sys; t=open('$T/m.ron').read(); m=re.search(r'heldout: Some\(\(\s*mean_position_error_mm: ([0-9.e-]+),\s*source: (\w+)', t); print('%.4f (%s)' % (float(m.group(1)), m.group(2)) if m else 'none')")
  echo "$S | $m | stored $stored | odd rows $(ev $T/m.ron $D/ur10_${S}_full_odd.csv)"
done; done
rm -rf $T
