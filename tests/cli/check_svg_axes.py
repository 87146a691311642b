#!/usr/bin/env python3
"""Axes of an odomctl SVG plot (issue 35 item 5): usage check_svg_axes.py FILE.svg [--umbmark N [bumps]]

Every panel (<g class="panel">, or the whole plot when it has none) has at least 3 labelled
ticks on each axis and a grid line at each; the tick labels are numbers at positions linear in
their value; where both axis titles end in "[mm]" (positions) one mm is as many px on x as on y.
Every text, also the rotated axis titles, lies inside the canvas (extents estimated at 0.62 em a
character, the width the plots reserve; the rendered check in test_umbmark_svg.sh is exact).
--umbmark N: the UMBmark plot of N passes: two panels, the "before" runs (and with `bumps` the
bump runs) in the first, every pass's verification runs in the second, one marker shape a set and no two sets
alike."""
import re
import sys
import xml.etree.ElementTree as ET

NS = "{http://www.w3.org/2000/svg}"
path = sys.argv[1]
root = ET.parse(path).getroot()
W, H = float(root.get("width")), float(root.get("height"))
base_font = float(root.get("font-size"))


def cls(e):
    return (e.get("class") or "").split()


def linear_scale(ticks, coord):
    """px per unit from (value, px) pairs, asserting they lie on one line."""
    (v0, p0), (v1, p1) = ticks[0], ticks[-1]
    k = (p1 - p0) / (v1 - v0)
    for v, p in ticks:
        assert abs(p0 + k * (v - v0) - p) < 0.6, (path, coord, "tick off the line", v, p)
    return k


panels = [g for g in root.iter(NS + "g") if "panel" in cls(g)] or [root]
for n, g in enumerate(panels):
    ticks = {"x": [], "y": []}
    for t in g.iter(NS + "text"):
        for axis in ("x", "y"):
            if "tick-" + axis in cls(t):
                pos = float(t.get(axis)) - (4 if axis == "y" else 0)  # y labels sit 4 px low
                ticks[axis].append((float(t.text), pos))
    for axis in ("x", "y"):
        assert len(ticks[axis]) >= 3, (path, "panel", n, axis, "ticks", ticks[axis])
        ticks[axis].sort()
    grid = [ln for ln in g.iter(NS + "line") if "grid" in cls(ln)]
    assert len(grid) == len(ticks["x"]) + len(ticks["y"]), (path, n, len(grid))
    kx = linear_scale(ticks["x"], "x")
    ky = -linear_scale(ticks["y"], "y")  # the canvas's y grows downwards
    titles = {a: [t.text for t in g.iter(NS + "text") if "axis-" + a in cls(t)] for a in "xy"}
    assert len(titles["x"]) == 1 and len(titles["y"]) == 1, (path, n, titles)
    if titles["x"][0].endswith("[mm]") and titles["y"][0].endswith("[mm]"):
        assert abs(kx - ky) <= 0.005 * kx, (path, n, "unequal scales (px/mm)", kx, ky)

for t in root.iter(NS + "text"):
    text = "".join(t.itertext())
    fs = float(t.get("font-size") or base_font)
    w = 0.62 * fs * len(text)
    anchor = t.get("text-anchor", "start")
    m = re.match(r"translate\(([-0-9.e]+),([-0-9.e]+)\) rotate\(-90\)", t.get("transform") or "")
    if m:  # rotated a quarter turn: the text runs upwards along y, its glyphs left of x
        x, y = float(m.group(1)), float(m.group(2))
        lo = y - {"middle": w / 2, "end": 0}.get(anchor, w)
        assert x - fs >= 0 and x <= W and lo >= 0 and lo + w <= H, (path, text, x, lo, lo + w)
        continue
    x, y = float(t.get("x")), float(t.get("y"))
    left = x - {"middle": w / 2, "end": w}.get(anchor, 0)
    assert left >= 0 and left + w <= W and y - fs >= 0 and y <= H, (path, text, left, left + w, y)

if len(sys.argv) > 3 and sys.argv[2] == "--umbmark":
    passes = int(sys.argv[3])
    assert len(panels) == 2, (path, "panels", len(panels))

    def outline(e):
        """A marker's shape independent of where it sits: tag, open or filled, vertices around
        the first (coordinates are printed to 6 digits: equal within 0.05 px)."""
        if e.tag == NS + "circle":
            return ("circle", e.get("fill") == "none", ((float(e.get("r")), 0.0),))
        pts = [tuple(map(float, p)) for p in re.findall(r"([-0-9.e]+),([-0-9.e]+)", e.get("d"))]
        return ("path", e.get("fill") == "none",
                tuple((x - pts[0][0], y - pts[0][1]) for x, y in pts))

    def same(a, b):
        return a[:2] == b[:2] and len(a[2]) == len(b[2]) and all(
            abs(p - q) < 0.05 for u, v in zip(a[2], b[2]) for p, q in zip(u, v))

    shapes = {}
    for n, g in enumerate(panels):
        for e in g:
            c = cls(e)
            if "run" in c:
                name = c[1]
                assert (name in ("before", "bumps")) == (n == 0), (path, name, "in panel", n)
                shapes.setdefault(name, []).append(outline(e))
    want = {"before"} | {"after-%d" % k for k in range(1, passes + 1)}
    if sys.argv[4:] == ["bumps"]:
        want.add("bumps")
    assert set(shapes) == want, (path, sorted(shapes), sorted(want))
    for name, s in shapes.items():
        assert all(same(s[0], o) for o in s), (path, name, "markers of one set differ")
    names = sorted(shapes)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert not same(shapes[a][0], shapes[b][0]), (path, a, b, "share a marker")
print("%s: %d panel(s), ticks and grid on both axes, text inside %gx%g" % (path, len(panels), W, H))
