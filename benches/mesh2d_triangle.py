"""The 2D meshing peer of benches/mesh2d.rs: Shewchuk's Triangle (PyPI
`triangle`) on the same boundary (a PSLG of geomc's boundary nodes) at the
same minimum angle and area limit. Prints {"seconds": best of RUNS × REPS
single runs (as geomc's), "cpu_seconds": CPU time per run, the best of RUNS samples of REPS
back-to-back runs (process CPU time: every thread), "threads": threads in
the process, "triangles": n}.

Run with OPENBLAS_NUM_THREADS=1 (the bench sets it): numpy's OpenBLAS
worker thread spins for about 0.1 s after import, and on an idle machine
that spinning was counted in `process_time` (above the wall time on the
50-hole disk). Triangle itself is single-threaded.

usage: mesh2d_triangle.py PSLG.json RUNS [REPS]
"""
import json
import os
import sys
import time

import numpy as np
import triangle


def main():
    path, runs = sys.argv[1], int(sys.argv[2])
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 1
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
    for _ in range(runs * reps):
        start, cpu = time.perf_counter(), time.process_time()
        out = triangle.triangulate(pslg, opts)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - cpu)
        count = len(out["triangles"])
    if reps > 1:
        best_cpu = float("inf")
        for _ in range(runs):
            cpu = time.process_time()
            for _ in range(reps):
                triangle.triangulate(pslg, opts)
            best_cpu = min(best_cpu, (time.process_time() - cpu) / reps)
    threads = len(os.listdir("/proc/self/task")) if os.path.isdir("/proc/self/task") else 1
    print(json.dumps({"seconds": best, "cpu_seconds": best_cpu, "threads": threads,
                      "triangles": count}))


if __name__ == "__main__":
    main()
