#!/usr/bin/env bash
# A newcomer's cold build and first study, or a fresh-clone CI run, at a revision:
#
#   xtask/scripts/cold_build.sh study REV OUT_DIR   # fresh clone, empty target, `cargo fetch`
#                                                   # (not timed), then `cargo run --timings -p
#                                                   # xtask -- reproduce-sim`, wall time
#   xtask/scripts/cold_build.sh ci REV OUT_DIR      # fresh clone, `cargo fetch`, `bash .ci/run`
#   xtask/scripts/cold_build.sh build REV OUT_DIR   # fresh clone, `cargo fetch`, then only
#                                                   # `cargo build --timings -p xtask` (what the
#                                                   # study's first run compiles), wall and CPU
#                                                   # seconds: CPU is what to compare on a machine
#                                                   # that other work shares
#
# Run two revisions back to back on an idle machine: the wall times of one machine drift by tens
# of per cent between days. OUT_DIR gets the log, the `--timings` report and a line in times.txt.
set -eu
mode=$1
rev=$2
out=$(realpath -m "$3")
repo=$(realpath "$(dirname "$0")/../..")
mkdir -p "$out"
clone=$(mktemp -d)/clone
git clone -q "$repo" "$clone"
cd "$clone"
git checkout -q "$rev"
cargo fetch -q
load=$(cut -d' ' -f1-3 /proc/loadavg)
started=$(date +%s.%N)
case $mode in
    build)
        /usr/bin/time -f "%e s wall, %U s user, %S s system" -o "$out/cpu-$rev.txt" \
            cargo build --timings -p xtask >"$out/$mode-$rev.log" 2>&1
        cp target/cargo-timings/cargo-timing.html "$out/timings-$rev.html"
        echo "build $rev: $(cat "$out/cpu-$rev.txt"), load average before: $load" | tee -a "$out/times.txt"
        ;;
    study)
        cargo run --timings -p xtask -- reproduce-sim --out "$out/reproduce-sim-$rev" >"$out/$mode-$rev.log" 2>&1
        cp target/cargo-timings/cargo-timing.html "$out/timings-$rev.html"
        ;;
    ci) bash .ci/run >"$out/$mode-$rev.log" 2>&1 ;;
    *) echo "mode: build, study or ci" >&2; exit 2 ;;
esac
ended=$(date +%s.%N)
build=$(grep -m1 'Finished' "$out/$mode-$rev.log" || true)
echo "$mode $rev: $(echo "$ended - $started" | bc) s wall; first build: $build" | tee -a "$out/times.txt"
rm -rf "$clone"
