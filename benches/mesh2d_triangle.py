"""The 2D meshing peer of benches/mesh2d.rs: Shewchuk's Triangle (PyPI
`triangle`) on the same boundary (a PSLG of geomc's boundary nodes) at the
same minimum angle and area limit. Prints {"seconds": best of N, "cpu_seconds":
best process CPU time of N, "triangles": n}.

usage: mesh2d_triangle.py PSLG.json RUNS
"""
import json
import sys
import time

import numpy as np
import triangle


def main():
    path, runs = sys.argv[1], int(sys.argv[2])
    with open(path) as f:
        d = json.load(f)
    pslg = {"vertices": np.array(d["vertices"], dtype=float),
            "segments": np.array(d["segments"], dtype=np.int32)}
    if d["holes"]:
        pslg["holes"] = np.array(d["holes"], dtype=float)
    opts = "pq%gQ" % d["min_angle"]
    if d.get("max_area"):
        opts += "a%s" % np.format_float_positional(d["max_area"], trim="-")  # Triangle reads no exponents
    best, best_cpu, count = float("inf"), float("inf"), 0
    for _ in range(runs):
        start, cpu = time.perf_counter(), time.process_time()
        out = triangle.triangulate(pslg, opts)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - cpu)
        count = len(out["triangles"])
    print(json.dumps({"seconds": best, "cpu_seconds": best_cpu, "triangles": count}))


if __name__ == "__main__":
    main()
