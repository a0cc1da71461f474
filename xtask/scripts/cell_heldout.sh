#!/bin/bash
# The held-out estimate a fit keeps in the model file against the error measured on the
# odd rows, each UR10 series' even rows fitted; then series B split at random by configuration
# (even and odd rows together, a repeated configuration kept on one side, Python random.seed(1)),
# since B's even and odd rows are two arm configurations of each target. Usage (from the worktree
# root, release build):
#   xtask/scripts/cell_heldout.sh [DATA=/work/data]
C=${CALIB:-target/release/calib}; R=fixtures/robots/ur10.ron; D=${1:-/work/data}; T=$(mktemp -d)
ev() { $C eval --model $1 --data $2 --json 2>/dev/null | python3 -c "import json,sys; print('%.4f' % json.load(sys.stdin)['mean_position_error_mm'])"; }
row() { # SERIES TRAIN TEST METHOD...
  local S=$1 TR=$2 TE=$3; shift 3; local m="$*"
  $C fit --robot $R --data $TR --method $m --out $T/m.ron >/dev/null 2>&1 || { echo "$S | $m | fit failed"; return; }
  stored=$(python3 -c "import re,sys; t=open('$T/m.ron').read(); m=re.search(r'heldout: Some\(\(\s*mean_position_error_mm: ([0-9.e-]+),\s*source: (\w+)', t); print('%.4f (%s)' % (float(m.group(1)), m.group(2)) if m else 'none')")
  echo "$S | $m | stored $stored | measured $(ev $T/m.ron $TE)"
}
for S in C B D; do for m in "poe" "poe-gp" "poe --effects auto"; do
  row $S $D/ur10_${S}_full_even.csv $D/ur10_${S}_full_odd.csv $m
done; done
python3 - "$D" "$T" <<'PY'
import csv, random, sys
d, t = sys.argv[1:]
rows = []
for f in ['even', 'odd']:
    r = list(csv.reader(open(f'{d}/ur10_B_full_{f}.csv'))); head = r[0]; rows += r[1:]
q = [list(map(float, r[:6])) for r in rows]
par = list(range(len(q)))
def find(i):
    while par[i] != i: par[i] = par[par[i]]; i = par[i]
    return i
for i in range(len(q)):
    for j in range(i):
        if max(abs(a - b) for a, b in zip(q[i], q[j])) <= 1e-3: par[find(i)] = find(j)
gs = sorted(set(find(i) for i in range(len(q)))); random.seed(1); random.shuffle(gs); half = set(gs[:len(gs) // 2])
for name, keep in (('train', True), ('test', False)):
    w = csv.writer(open(f'{t}/B_{name}.csv', 'w')); w.writerow(head); w.writerows(r for i, r in enumerate(rows) if (find(i) in half) == keep)
PY
for m in "poe" "poe-gp" "poe --effects auto"; do row "B random" $T/B_train.csv $T/B_test.csv $m; done
rm -rf $T
