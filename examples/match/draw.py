"""Draws the example target outlines of `sylva match` (black ink on white, 256 x 256 PNG).

Each is a shape a designer might sketch, made from circles, ellipses and polygons, not by
Sylva. Run `python3 examples/match/draw.py` to redraw them; it needs only the standard
library.
"""

import math
import struct
import zlib
from pathlib import Path

SIZE = 256


def png(path, rows):
    """Writes 8-bit grayscale rows as a PNG."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", SIZE, SIZE, 8, 0, 0, 0, 0)
    Path(path).write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


def trunk(x, y, width, top, bottom=240):
    return abs(x - 128) <= width / 2 and top <= y <= bottom


def ellipse(x, y, cx, cy, rx, ry):
    return ((x - cx) / rx) ** 2 + ((y - cy) / ry) ** 2 <= 1


def triangle(x, y, apex, base, half):
    """A triangle with its apex at (128, apex) and its base `half` wide each side at `base`."""
    if not apex <= y <= base:
        return False
    return abs(x - 128) <= half * (y - apex) / (base - apex)


SHAPES = {
    # A broadleaf: a round crown on a trunk.
    "round": lambda x, y: trunk(x, y, 14, 150) or ellipse(x, y, 128, 100, 80, 75),
    # A conifer: a tall narrow cone on a short trunk.
    "cone": lambda x, y: trunk(x, y, 10, 200) or triangle(x, y, 16, 210, 60),
    # An acacia: a flat, wide crown high on a bare trunk.
    "umbrella": lambda x, y: trunk(x, y, 10, 90)
    or ellipse(x, y, 128, 80, 110, 30),
    # A poplar: a narrow column.
    "column": lambda x, y: trunk(x, y, 10, 200) or ellipse(x, y, 128, 115, 32, 100),
    # A vase: a crown widening from a short trunk, like an elm.
    "vase": lambda x, y: trunk(x, y, 12, 170)
    or (60 <= y <= 175 and abs(x - 128) <= 20 + 85 * math.sqrt((175 - y) / 115))
    or ellipse(x, y, 128, 60, 105, 40),
}

if __name__ == "__main__":
    here = Path(__file__).parent
    for name, inside in SHAPES.items():
        rows = [[0 if inside(x, y) else 255 for x in range(SIZE)] for y in range(SIZE)]
        png(here / f"{name}.png", rows)
