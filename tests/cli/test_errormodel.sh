#!/usr/bin/env bash
# odomctl errormodel validate|fit: exit codes, JSON on stdout, progress on stderr, SVG, bad input.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget

# validate --json: one object with the documented keys; progress on stderr; an SVG; a run CSV.
run "$ODOMCTL" errormodel validate --runs 300 --path arc --k-left 0.0004 --k-right 0.00058 \
  --wheelbase 0.34 --seed 3 --plot "$tmp/e.svg" --csv "$tmp/runs.csv" --json >"$tmp/out" 2>"$tmp/err"
check "validate exit 0" $?
python3 - "$tmp/out" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
assert text.count("\n") == 1, text
j = json.loads(text)
for k in ("runs", "wheelbase", "k_left", "k_right", "predicted", "sample", "max_rel_error_diag"):
    assert k in j, k
assert j["runs"] == 300 and j["wheelbase"] == 0.34 and j["k_left"] == 0.0004, j
for m in (j["predicted"], j["sample"]):
    assert len(m) == 3 and all(len(r) == 3 for r in m), m
    assert all(m[i][i] > 0 for i in range(3)), m
    assert all(m[i][k] == m[k][i] for i in range(3) for k in range(3)), m
# 300 runs: sample variances within ~3 standard errors (sqrt(2/299) = 8%) of the prediction.
assert j["max_rel_error_diag"] < 0.3, j
PY
check "validate json content" $?
grep -q "^errormodel validate: 300 runs driven$" "$tmp/err" && ! grep -q "300/300" "$tmp/err"
check "validate off a terminal: a summary, no progress lines" $?
python3 -c "import sys, xml.dom.minidom as m; d = m.parse(sys.argv[1]); \
assert len(d.getElementsByTagName('polyline')) == 6" "$tmp/e.svg"
check "validate svg: 3 panels x 2 ellipses" $?
[ "$(wc -l <"$tmp/runs.csv")" = 301 ]; check "validate csv rows" $?

# The run CSV feeds the fit.
run "$ODOMCTL" errormodel validate --runs 400 --seed 11 --csv "$tmp/ob.csv" --plot "$tmp/ob.svg" \
  >/dev/null 2>&1
check "validate outback exit 0" $?
python3 -c "import sys, xml.dom.minidom as m; m.parse(sys.argv[1])" "$tmp/ob.svg"
check "validate outback svg is well-formed XML" $?
run "$ODOMCTL" errormodel fit "$tmp/ob.csv" --distance 10 --wheelbase 0.34 --json >"$tmp/out" 2>"$tmp/err"
check "fit exit 0" $?
python3 - "$tmp/out" <<'PY'
import json, sys
j = json.loads(open(sys.argv[1]).read())
assert j["runs"] == 400, j
# 400 runs: k is known to about 4% (1 standard error); allow 15%.
assert abs(j["k_left"] / 0.0004 - 1) < 0.15 and abs(j["k_right"] / 0.00058 - 1) < 0.15, j
PY
check "fit json content" $?

# Bad input: exit 2, file:line:field on stderr, nothing on stdout.
printf 'run,ex,ey,etheta\n1,0.001,0.002,0.0001\n2,0.001,zz,0.0001\n' >"$tmp/bad.csv"
run "$ODOMCTL" errormodel fit "$tmp/bad.csv" --json >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "fit bad field exit 2 (got $rc)" $?
[ ! -s "$tmp/out" ]; check "fit bad field: empty stdout" $?
grep -q "bad.csv:3: field 'ey'" "$tmp/err"; check "fit bad field: file:line:field named" $?
run "$ODOMCTL" errormodel fit "$tmp/missing.csv" >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && [ ! -s "$tmp/out" ]; check "fit missing file exit 2 (got $rc)" $?
run "$ODOMCTL" errormodel fit "$tmp/ob.csv" --wheelbase 34 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q "wheelbase = 34" "$tmp/err"; check "fit bad wheelbase exit 2" $?
for bad in "--runs 1" "--path square" "--k-left -1" "--k-right 0.5" "--wheelbase 0" "--runs x"; do
  # shellcheck disable=SC2086
  run "$ODOMCTL" errormodel validate $bad --json >"$tmp/out" 2>"$tmp/err"
  rc=$?; [ $rc = 2 ] && [ ! -s "$tmp/out" ] && [ -s "$tmp/err" ]
  check "validate $bad: exit 2, message, empty stdout (got $rc)" $?
done

echo "errormodel cli: $pass passed, $fail failed"
[ "$fail" = 0 ]
