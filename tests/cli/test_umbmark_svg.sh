#!/usr/bin/env bash
# The SVG plots (issue 20): ticks between the extremes on both axes, one legend line and one
# marker shape per pass, and, rendered to PNG by rsvg-convert, no text or mark outside the
# canvas. The rendering part is skipped (exit 77, after the other checks) without rsvg-convert.
# The self-calibration's convergence plot (issue 18): one marker per fit and parameter, filled
# for the applied ones, as many as --json counts; a bad --plot path refused before any work.
# Issue 35 item 5 (check_svg_axes.py on every plot): each panel has labelled ticks and a grid on
# both axes, equal scales where both axes are positions (ex-ey), every text inside the canvas;
# the UMBmark plot has the after-clusters in their own panel, the bump runs drawn and a marker
# of its own for every one of 10 passes.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp

run "$ODOMCTL" umbmark simulate --runs 3 --passes 3 --noise paper --plot "$tmp/u3.svg" >/dev/null 2>&1
check "simulate --passes 3 --plot exit 0" $?
run "$ODOMCTL" umbmark simulate --runs 2 --passes 1 --side 0.5 --plot "$tmp/u1.svg" >/dev/null 2>&1
check "simulate --side 0.5 --plot exit 0" $?
run "$ODOMCTL" umbmark simulate --runs 2 --passes 10 --bumps --noise paper --plot "$tmp/u10.svg" \
  >/dev/null 2>&1
check "simulate --passes 10 --bumps --plot exit 0" $?
run "$ODOMCTL" errormodel validate --runs 50 --plot "$tmp/e.svg" >/dev/null 2>&1
check "errormodel validate --plot exit 0" $?
run "$ODOMCTL" selfcal simulate --excursions 10 --min-fixes 3 --fit-every 1 --score-runs 5 \
  --json --plot "$tmp/s.svg" >"$tmp/s.json" 2>"$tmp/s.err"
check "selfcal simulate --plot exit 0" $?

python3 - "$tmp/s.svg" "$tmp/s.json" <<'PY'
import json, re, sys
import xml.etree.ElementTree as ET
s = open(sys.argv[1]).read()
j = json.load(open(sys.argv[2]))
root = ET.fromstring(s)  # well-formed XML
assert root.tag == "{http://www.w3.org/2000/svg}svg", root.tag
fits = j["fits"] - j["fit_errors"]
assert fits >= 5, j  # --fit-every 1 from the 3rd of the 11 fixes: several fits
for p in ("c_l", "c_r", "b"):
    marks = [e for e in root.iter() if e.get("class") == "fit " + p]
    assert len(marks) == fits, (p, len(marks), fits)
    filled = [e for e in marks if e.get("fill") != "white"]
    assert len(filled) == j["applied"], (p, len(filled), j["applied"])
xt = re.findall(r'text-anchor="middle">(-?[0-9.e+-]+)</text>', s)
yt = re.findall(r'text-anchor="end">(-?[0-9.e+-]+)</text>', s)
assert len(xt) >= 4 and len(yt) >= 4, (xt, yt)
for label in ("c_L", "c_R", "b (wheelbase)", "applied", "not applied", "[%]", "E_max,syst"):
    assert label in s, label
PY
check "selfcal plot: valid SVG, one marker per fit and parameter, applied ones filled, ticks" $?

# A bad --plot path: refused before the simulation (which at these sizes takes minutes), one
# line on stderr naming the path, nothing on stdout, exit 2.
timeout 20 ${CROSS_EMULATOR:-} "$ODOMCTL" selfcal simulate --excursions 1000 --score-runs 1000 \
  --plot "$tmp/no/such/dir/s.svg" >"$tmp/bad.out" 2>"$tmp/bad.err"
rc=$?
[ $rc = 2 ] && [ ! -s "$tmp/bad.out" ] && [ "$(wc -l <"$tmp/bad.err")" = 1 ] &&
  grep -q "^odomctl selfcal simulate: $tmp/no/such/dir/s.svg: cannot create" "$tmp/bad.err"
rc_=$?
check "selfcal simulate --plot bad path: exit 2 before any work, one line (rc $rc: $(cat "$tmp/bad.err"))" $rc_

python3 - "$tmp/u3.svg" <<'PY'
import re, sys
s = open(sys.argv[1]).read()
# Tick labels: text-anchor middle below the x axis, end left of the y axis; at least 4 each.
xt = re.findall(r'text-anchor="middle">(-?[0-9.e+-]+)</text>', s)
yt = re.findall(r'text-anchor="end">(-?[0-9.e+-]+)</text>', s)
assert len(xt) >= 4 and len(yt) >= 4, (xt, yt)
# Every pass has its legend line: before, after pass 1, 2, 3.
for label in ("before:", "after pass 1:", "after pass 2:", "after pass 3:"):
    assert label in s, label
# Four marker kinds: open circles, filled circles, squares, triangles.
assert 'fill="none" stroke=' in s and "<rect x=" in s and " Z\" fill=" in s, "markers"
PY
check "umbmark plot: ticks on both axes, every pass in the legend and with its own marker" $?

axes="$(dirname "$0")/check_svg_axes.py"
python3 "$axes" "$tmp/u10.svg" --umbmark 10 bumps
check "u10.svg: two panels, before and bump runs left, 10 passes right, 12 distinct markers, axes" $?
python3 "$axes" "$tmp/u3.svg" --umbmark 3 && python3 "$axes" "$tmp/u1.svg"
check "u3.svg, u1.svg: ticks, grid, equal scales, text inside" $?
python3 "$axes" "$tmp/e.svg" && python3 - "$tmp/e.svg" <<'PY'
import sys
s = open(sys.argv[1]).read()
assert s.count('<g class="panel">') == 3 and 'class="axis-x" ' in s, "three panels"
PY
check "e.svg (errormodel validate --plot): three panels with ticks and grid, ex-ey equal scales" $?
python3 "$axes" "$tmp/s.svg"
check "s.svg (selfcal simulate --plot): ticks and grid on both axes, text inside" $?

# Without a renderer: every unrotated text's extent, estimated at 0.55 em a character (DejaVu
# Sans averages about 0.55 em; a renderer check follows below), lies inside the canvas.
for f in u3 u1 u10 e s; do
  python3 - "$tmp/$f.svg" <<'PY'
import re, sys
s = open(sys.argv[1]).read()
w, h = (float(v) for v in re.search(r'<svg[^>]* width="([0-9.]+)" height="([0-9.]+)"', s).groups())
base = float(re.search(r'<svg[^>]* font-size="([0-9.]+)"', s).group(1))
for m in re.finditer(r'<text x="([-0-9.e]+)" y="([-0-9.e]+)"([^>]*)>([^<]*)</text>', s):
    x, y, attrs = float(m.group(1)), float(m.group(2)), m.group(3)
    text = m.group(4).replace("&amp;", "&").replace("&lt;", "<").replace("&gt;", ">")
    fs = re.search(r'font-size="([0-9.]+)"', attrs)
    width = 0.55 * (float(fs.group(1)) if fs else base) * len(text)
    anchor = re.search(r'text-anchor="(\w+)"', attrs)
    left = x - {"middle": width / 2, "end": width}.get(anchor.group(1) if anchor else "", 0)
    assert left >= 0 and left + width <= w and 0 < y <= h, (text, left, left + width, w)
PY
  check "$f.svg: every text inside the canvas (estimated extents)" $?
done

if ! command -v rsvg-convert >/dev/null; then
  echo "cli_umbmark_svg: $pass passed, $fail failed"
  echo "SKIP: rsvg-convert is not installed (Debian: librsvg2-bin): the rendering check did not run"
  [ $fail = 0 ] || exit 1
  exit 77
fi
# inside FILE: renders FILE on a canvas 100 px larger on every side (its white background
# removed) and fails when any pixel outside the original canvas is not transparent.
inside() {
  python3 - "$1" "$tmp/pad.svg" <<'PY' && rsvg-convert "$tmp/pad.svg" -o "$tmp/pad.png" &&
import re, sys
s = open(sys.argv[1]).read()
w, h = (float(v) for v in re.search(r'<svg[^>]* width="([0-9.]+)" height="([0-9.]+)"', s).groups())
s = s.replace('<rect width="100%" height="100%" fill="white"/>', "", 1)
s = re.sub(r'<svg([^>]*) width="[0-9.]+" height="[0-9.]+"',
           r'<svg\1 width="%g" height="%g" viewBox="-100 -100 %g %g"' % (w + 200, h + 200, w + 200, h + 200), s, 1)
open(sys.argv[2], "w").write(s)
open(sys.argv[2] + ".size", "w").write("%d %d" % (round(w), round(h)))
PY
  python3 - "$tmp/pad.png" "$tmp/pad.svg.size" <<'PY'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
w0, h0 = (int(v) for v in open(sys.argv[2]).read().split())
pos, idat, W, H = 8, b"", 0, 0
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        W, H, depth, colour = struct.unpack(">IIBB", body[:10])
        assert depth == 8 and colour == 6, (depth, colour)  # RGBA, 8 bits
    elif kind == b"IDAT":
        idat += body
    pos += 12 + n
raw, bpp, stride = zlib.decompress(idat), 4, W * 4
rows, prev = [], bytearray(stride)
for y in range(H):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(line)
    prev = line
out = [(x, y) for y in range(H) for x in range(W)
       if rows[y][4 * x + 3] and not (100 <= x < 100 + w0 and 100 <= y < 100 + h0)]
assert not out, "%d pixels outside the canvas, e.g. %s" % (len(out), out[:5])
PY
}
for f in u3 u1 u10 e s; do
  inside "$tmp/$f.svg"
  check "$f.svg: nothing drawn outside the canvas" $?
done
echo "cli_umbmark_svg: $pass passed, $fail failed"
[ $fail = 0 ]
