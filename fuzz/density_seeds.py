"""Seeds for the density_volume fuzz target (see shared/density_case.rs):
every NRRD file under the fixtures as it is; every raw file with the
attributes of the fixture XML that names it as its first line; and a few
valid volumes of each sample type, attached, detached and raw.
Usage: density_seeds.py FIXTURES_DIR OUT_DIR"""
import pathlib
import re
import struct
import sys

fixtures, out = map(pathlib.Path, sys.argv[1:3])
out.mkdir(parents=True, exist_ok=True)
n = 0


def seed(data: bytes):
    global n
    (out / f"seed-{n:03}").write_bytes(data)
    n += 1


for nrrd in sorted(fixtures.rglob("*.nrrd")):
    seed(nrrd.read_bytes())
for xml in sorted(fixtures.rglob("*.xml")):
    for m in re.finditer(r"<density_volume\b([^>]*)/>", xml.read_text(errors="replace")):
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(1)))
        raw = xml.parent / attrs.pop("file", "")
        if raw.suffix != ".raw" or not raw.is_file():
            continue
        line = " ".join(f'{k}="{v}"' for k, v in attrs.items() if k not in ("name", "level"))
        seed(line.encode() + b"\n" + raw.read_bytes())

# A ball of radius 1.5 sampled on 4 x 4 x 4 points: 2 - distance from the centre.
ball = [2.0 - ((x - 1.5) ** 2 + (y - 1.5) ** 2 + (z - 1.5) ** 2) ** 0.5
        for z in range(4) for y in range(4) for x in range(4)]
u8 = bytes(max(0, min(255, int(v * 100))) for v in ball)
seed(b'type="u8" dims="4 4 4" spacing="0.5 0.5 0.5" origin="-1 -1 -1"\n' + u8)
seed(b'type="u16" dims="4 4 4" endian="big"\n' + b"".join(struct.pack(">H", max(0, int(v * 1000))) for v in ball))
seed(b'type="i16" dims="4 4 4"\n' + b"".join(struct.pack("<h", int(v * 1000)) for v in ball))
seed(b'type="f32" dims="4 4 4"\n' + b"".join(struct.pack("<f", v) for v in ball))
header = b"NRRD0004\ntype: float\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: raw\n"
seed(header + b"spacings: 0.5 0.5 0.5\n\n" + b"".join(struct.pack("<f", v) for v in ball))
seed(header + b"space directions: (1,0,0) (0,2,0) (0,0,1)\nspace origin: (1,2,3)\n\n"
     + b"".join(struct.pack("<f", v) for v in ball))
seed(b"NRRD0005\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: data.raw\n\n" + u8)
seed(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 4 4 4\nendian: big\nencoding: raw\n# a comment\nkey:=value\n\n"
     + b"".join(struct.pack(">h", int(v * 1000)) for v in ball))
print(f"{n} density_volume seeds in {out}")
