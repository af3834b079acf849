"""Peer for benches/implicit.rs: VTK flying edges on a field geomc already sampled.

Usage: python3 vtk_flying_edges.py FIELD.f32 NX NY NZ XMIN XMAX THREADS REPS
The field is little-endian f32, x fastest, on NX x NY x NZ points spanning
[XMIN, XMAX] on every axis; the iso level is 0. Prints one JSON line:
{"seconds": median contouring time, "triangles": n, "backend": ...}.
Only the contouring is timed (the field is given), as in PERF-ANCHORS.md.
"""
import json
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support


def main():
    path = sys.argv[1]
    nx, ny, nz = (int(v) for v in sys.argv[2:5])
    lo, hi = float(sys.argv[5]), float(sys.argv[6])
    threads, reps = int(sys.argv[7]), int(sys.argv[8])
    field = np.fromfile(path, dtype="<f4")
    assert field.size == nx * ny * nz, "field size"
    smp = vtk.vtkSMPTools()
    for backend in ("STDThread", "TBB"):
        if smp.SetBackend(backend):
            break
    smp.Initialize(threads)
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetOrigin(lo, lo, lo)
    image.SetSpacing(*((hi - lo) / (n - 1) for n in (nx, ny, nz)))
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(field, deep=True))
    times, triangles = [], 0
    for _ in range(reps):
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputData(image)
        fe.SetValue(0, 0.0)
        fe.ComputeNormalsOff()
        fe.ComputeGradientsOff()
        fe.ComputeScalarsOff()
        start = time.perf_counter()
        fe.Update()
        times.append(time.perf_counter() - start)
        triangles = fe.GetOutput().GetNumberOfCells()
    times.sort()
    print(json.dumps({
        "seconds": times[len(times) // 2],
        "triangles": triangles,
        "backend": smp.GetBackend(),
        "threads": smp.GetEstimatedNumberOfThreads(),
        "vtk": vtk.vtkVersion.GetVTKVersion(),
    }))


if __name__ == "__main__":
    main()
