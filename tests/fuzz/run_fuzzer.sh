#!/usr/bin/env bash
# run_fuzzer.sh EXE NAME SRCDIR BINDIR - one libFuzzer run of a target (ctest label `fuzz`).
# The seeds (SRCDIR/corpus/NAME) and past findings (SRCDIR/regressions/NAME) are read but never
# written: new inputs go to BINDIR/corpus/NAME, crash inputs to BINDIR/artifacts/.
# ODO_FUZZ_ARGS: libFuzzer options, default a short run (-max_total_time=10: CI's smoke run of
# every target from its seeds, each finding kept under regressions/; the search itself is the
# long run's, TESTING.md. 10 s rather than 20 s since stop 40: 60 s of CI's time);
# the long run: ODO_FUZZ_ARGS=-runs=1000000 ctest --preset fuzz (TESTING.md).
set -euo pipefail
exe=$1 name=$2 src=$3 bin=$4
work=$bin/corpus/$name
mkdir -p "$work" "$bin/artifacts"
dirs=("$work" "$src/corpus/$name")
if [[ -d $src/regressions/$name ]]; then dirs+=("$src/regressions/$name"); fi
opts=(-artifact_prefix="$bin/artifacts/$name-" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1)
if [[ -f $src/$name.dict ]]; then opts+=(-dict="$src/$name.dict"); fi
read -r -a extra <<<"${ODO_FUZZ_ARGS:--max_total_time=10}"
echo "run_fuzzer: $exe ${opts[*]} ${extra[*]} ${dirs[*]}"
exec "$exe" "${opts[@]}" "${extra[@]}" "${dirs[@]}"
