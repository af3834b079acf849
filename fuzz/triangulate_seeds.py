#!/usr/bin/env python3
"""Seeds for the `triangulate` fuzz target from the 2D fixtures: every shape
given by literal <vertex> corners (polygon, triangle) becomes one input in the
target's byte encoding (flags, count, then x/y as little-endian i16 in 1/4096),
once alone and once with a poly_line segment between its first two corners."""
import re
import struct
import sys
from pathlib import Path

fixtures, out = Path(sys.argv[1]), Path(sys.argv[2])
out.mkdir(parents=True, exist_ok=True)
shape = re.compile(r"<(polygon|triangle)\b[^>]*>(.*?)</\1>", re.S)
vertex = re.compile(r'<vertex x="(-?[0-9.]+)" y="(-?[0-9.]+)"/>')


def coordinate(v):
    return struct.pack("<h", max(-32768, min(32767, round(float(v) * 4096))))


n = 0
for path in sorted(fixtures.glob("*.xml")):
    text = path.read_text(errors="replace")
    if 'dimension="2"' not in text:
        continue
    for m in shape.finditer(text):
        corners = vertex.findall(m.group(2))[:12]
        if len(corners) < 3:
            continue
        body = b"".join(coordinate(x) + coordinate(y) for x, y in corners)
        for flags, extra in [(0x07, b""), (0x47, body[:8])]:
            data = bytes([flags, len(corners) - 3]) + body + extra
            (out / f"{path.stem}_{n}").write_bytes(data)
            n += 1
print(f"{n} triangulate seeds", file=sys.stderr)
