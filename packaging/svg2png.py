#!/usr/bin/env python3
"""svg2png.py SVG SIZE OUT.png: renders the icon SVG to a SIZExSIZE RGBA PNG with Python alone.

Understands exactly what packaging/sceneviewer.svg uses: a viewBox, and <polygon> elements with
points and a #rrggbb fill (optional fill-opacity), drawn in order; <title>/<desc> are ignored.
Anything else is an error, so the PNG can never silently differ from the SVG.
Coverage: 16 sub-scanlines per pixel, exact horizontal coverage along each; the polygons are
composited with "over" on a transparent background. Deterministic output (no timestamps).
"""
import struct
import sys
import xml.etree.ElementTree as ET
import zlib

SUB = 16  # sub-scanlines per pixel row
NS = "{http://www.w3.org/2000/svg}"


def fail(msg):
    sys.exit(f"svg2png: {sys.argv[1]}: {msg}")


def parse(path):
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        fail(str(e))
    if root.tag != NS + "svg":
        fail("root element is not <svg>")
    try:
        vx, vy, vw, vh = (float(v) for v in root.get("viewBox", "").replace(",", " ").split())
    except ValueError:
        fail("needs a viewBox of four numbers")
    shapes = []
    for el in root:
        tag = el.tag.replace(NS, "")
        if tag in ("title", "desc"):
            continue
        if tag != "polygon" or set(el.attrib) - {"points", "fill", "fill-opacity"}:
            fail(f"unsupported element or attribute: <{tag} {' '.join(el.attrib)}>")
        fill = el.get("fill", "")
        if len(fill) != 7 or fill[0] != "#":
            fail(f"fill '{fill}' is not #rrggbb")
        rgb = tuple(int(fill[i:i + 2], 16) / 255.0 for i in (1, 3, 5))
        nums = [float(v) for v in el.get("points", "").replace(",", " ").split()]
        if len(nums) < 6 or len(nums) % 2:
            fail("polygon points must be at least three x,y pairs")
        pts = [((nums[i] - vx) / vw, (nums[i + 1] - vy) / vh) for i in range(0, len(nums), 2)]
        shapes.append((pts, rgb, float(el.get("fill-opacity", "1"))))
    return shapes


def coverage(pts, size):
    """Per-pixel coverage (0..1) of one polygon (nonzero rule), as a flat list."""
    cov = [0.0] * (size * size)
    p = [(x * size, y * size) for x, y in pts]
    edges = list(zip(p, p[1:] + p[:1]))
    ymin = max(0, int(min(y for _, y in p)))
    ymax = min(size - 1, int(max(y for _, y in p)))
    w = 1.0 / SUB
    for py in range(ymin, ymax + 1):
        row = py * size
        for k in range(SUB):
            ys = py + (k + 0.5) * w
            cross = []
            for (x0, y0), (x1, y1) in edges:
                if (y0 <= ys < y1) or (y1 <= ys < y0):
                    cross.append((x0 + (ys - y0) * (x1 - x0) / (y1 - y0), 1 if y1 > y0 else -1))
            cross.sort()
            wind = 0
            for i in range(len(cross) - 1):
                wind += cross[i][1]
                if wind == 0:
                    continue
                # Inside between this crossing and the next one.
                a, b = max(0.0, cross[i][0]), min(float(size), cross[i + 1][0])
                if b <= a:
                    continue
                ia, ib = int(a), int(b)
                if ia == ib:
                    cov[row + ia] += (b - a) * w
                    continue
                cov[row + ia] += (ia + 1 - a) * w
                for px in range(ia + 1, min(ib, size)):
                    cov[row + px] += w
                if ib < size:
                    cov[row + ib] += (b - ib) * w
    return cov


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: svg2png.py SVG SIZE OUT.png")
    size = int(sys.argv[2])
    shapes = parse(sys.argv[1])
    img = [[0.0, 0.0, 0.0, 0.0] for _ in range(size * size)]  # premultiplied RGBA
    for pts, rgb, opacity in shapes:
        for i, c in enumerate(coverage(pts, size)):
            a = min(c, 1.0) * opacity
            if a <= 0.0:
                continue
            px = img[i]
            for ch in range(3):
                px[ch] = rgb[ch] * a + px[ch] * (1.0 - a)
            px[3] = a + px[3] * (1.0 - a)
    raw = bytearray()
    for y in range(size):
        raw.append(0)  # filter: none
        for r, g, b, a in img[y * size:(y + 1) * size]:
            if a > 0.0:
                r, g, b = r / a, g / a, b / a
            raw += bytes(min(255, int(v * 255.0 + 0.5)) for v in (r, g, b, a))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(sys.argv[3], "wb") as f:
        f.write(png)


main()
