"""Draws the held-out target outlines of `sylva match`: shapes never used to tune Sylva.

Each is a tree outline a designer might sketch (black on white, 200 x 240 PNG), drawn from
circles, ellipses and polygons, unlike the examples in `examples/match`. Sylva's figures
on outline matching are reported on these, and nothing is tuned on them. Run
`python3 tests/held-out/draw.py`; it needs only the standard library.
"""

import math
import struct
import zlib
from pathlib import Path

WIDTH, HEIGHT = 200, 240


def png(path, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", WIDTH, HEIGHT, 8, 0, 0, 0, 0)
    Path(path).write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


def disc(x, y, cx, cy, r):
    return (x - cx) ** 2 + (y - cy) ** 2 <= r * r


def stem(x, y, cx, width, top, bottom=230):
    return abs(x - cx) <= width / 2 and top <= y <= bottom


SHAPES = {
    # An oak: a lumpy crown of overlapping lobes, wider than tall.
    "oak": lambda x, y: stem(x, y, 100, 16, 140)
    or any(disc(x, y, cx, cy, r) for cx, cy, r in
           [(100, 80, 55), (55, 105, 38), (145, 105, 38), (75, 60, 35), (128, 58, 35)]),
    # A weeping willow: a dome whose sides hang down almost to the ground.
    "willow": lambda x, y: stem(x, y, 100, 12, 120)
    or (y <= 200 and ((x - 100) / 85) ** 2 + ((y - 110) / 100) ** 2 <= 1 and y >= 10),
    # A spruce: a narrow spire, stepped.
    "spruce": lambda x, y: stem(x, y, 100, 8, 205)
    or (15 <= y <= 210 and abs(x - 100) <= (y - 15) * 0.33 * (1.0 - 0.25 * ((y - 15) % 40) / 40)),
    # A young tree: a small round crown on a long bare stem.
    "sapling": lambda x, y: stem(x, y, 100, 8, 90) or disc(x, y, 100, 65, 45),
    # A shrub: a low, wide mound from the ground.
    "shrub": lambda x, y: y <= 230 and ((x - 100) / 90) ** 2 + ((y - 230) / 110) ** 2 <= 1,
}

if __name__ == "__main__":
    here = Path(__file__).parent
    for name, inside in SHAPES.items():
        rows = [[0 if inside(x, y) else 255 for x in range(WIDTH)] for y in range(HEIGHT)]
        png(here / f"{name}.png", rows)
