"""Peers of benches/convert.rs, measured in the same run as geomc: each
conversion runs as its own process, timed by wall clock, with its peak
resident memory from os.wait4.

Usage: convert_peers.py GEOMC DIR  (DIR holds big.stl and mid.msh)
Prints one JSON object: case -> {tool: {"seconds": s, "peak_bytes": b, ...}},
and "environment": the versions of the pinned packages
(benches/peers/requirements.txt) as installed, with "pinned": whether they
are the pinned ones (the peers' times depend on them: most of the MSH -> GLB
peer's time is importing numpy, scipy and networkx).

convert_peers.py --check-pins exits 1, naming them, when an installed
version differs from its pin (scripts/test.sh then installs the pins).

Each conversion runs several times (geomc 5, peers 3) and "seconds" is the
median, "first_seconds" the first run alone (what this script reported
before it repeated runs): geomc's MSH -> GLB takes about 0.1 s, where one
run varies by 20% or more.

Peers: meshio 5.3.5 (`meshio.read` + `meshio.write`, as `meshio convert`
does) for STL -> MSH 4.1 binary; meshio cannot write glTF, so the GLB cases
use trimesh 5.2.0 (STL -> GLB) and meshio's MSH reader + trimesh's GLB
export (MSH -> GLB).
"""
import importlib.metadata
import json
import os
import subprocess
import sys
import time

PINS_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "requirements.txt")


def pins():
    """name -> pinned version, from requirements.txt's `name==version` lines."""
    out = {}
    with open(PINS_FILE) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                name, version = line.split("==")
                out[name.strip()] = version.strip()
    return out


def installed(name):
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def environment():
    """name -> installed version of each pinned package, and the mismatches."""
    pinned = pins()
    versions = {name: installed(name) for name in pinned}
    wrong = [f"{n} {versions[n] or 'missing'} (pinned {v})" for n, v in pinned.items() if versions[n] != v]
    return versions, wrong


if sys.argv[1:] == ["--check-pins"]:
    _, wrong = environment()
    if wrong:
        raise SystemExit("the peer set-up differs from its pins: " + ", ".join(wrong))
    sys.exit(0)

geomc, d = sys.argv[1], sys.argv[2]
j = lambda name: os.path.join(d, name)


def run(argv):
    start = time.perf_counter()
    p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    seconds = time.perf_counter() - start
    err = p.stderr.read().decode(errors="replace")
    if status != 0:
        raise SystemExit(f"{argv} failed ({status}): {err}")
    # CPU seconds too: on a loaded machine wall time is mostly waiting for a core.
    return {"seconds": seconds, "cpu_seconds": usage.ru_utime + usage.ru_stime,
            "peak_bytes": usage.ru_maxrss * 1024}


py = sys.executable
cases = {
    "stl_to_glb": {
        "geomc": [geomc, "convert", j("big.stl"), j("g.glb")],
        "trimesh": [py, "-c", f"import trimesh; trimesh.load({j('big.stl')!r}).export({j('p.glb')!r})"],
    },
    "stl_to_msh41_binary": {
        "geomc": [geomc, "convert", "--binary", j("big.stl"), j("g.msh")],
        "meshio": [py, "-c", f"import meshio; meshio.write({j('p.msh')!r}, meshio.read({j('big.stl')!r}), file_format='gmsh', binary=True)"],
    },
    "msh_to_glb": {
        "geomc": [geomc, "convert", j("mid.msh"), j("g2.glb")],
        "meshio+trimesh": [py, "-c", "import meshio, trimesh; m = meshio.read(%r); "
                           "trimesh.Trimesh(m.points, m.cells_dict['triangle'], process=False).export(%r)"
                           % (j("mid.msh"), j("p2.glb"))],
    },
}
REPEATS = {"geomc": 5}
PEER_REPEATS = 3


def repeated(tool, argv):
    runs = [run(argv) for _ in range(REPEATS.get(tool, PEER_REPEATS))]
    seconds = sorted(r["seconds"] for r in runs)
    cpu = sorted(r["cpu_seconds"] for r in runs)
    return {"seconds": seconds[len(seconds) // 2], "first_seconds": runs[0]["seconds"],
            "all_seconds": [r["seconds"] for r in runs],
            "cpu_seconds": cpu[len(cpu) // 2],
            "peak_bytes": max(r["peak_bytes"] for r in runs)}


versions, wrong = environment()
out = {"environment": {"versions": versions, "pinned": not wrong, "differs": wrong,
                       "python": sys.version.split()[0]}}
for case, tools in cases.items():
    out[case] = {tool: repeated(tool, argv) for tool, argv in tools.items()}
print(json.dumps(out))
