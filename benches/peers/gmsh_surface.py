"""Peer for benches/compile.rs: gmsh's surface meshing of the same solids.

Usage: python3 gmsh_surface.py MODEL SIZE [--fuse]
  MODEL  sphere (unit sphere at the origin) or seven (paper 001's seven balls:
         radius 0.7 at the origin, radius 0.3 at (+-0.7, 0, 0), (0, +-0.7, 0),
         (0, 0, +-0.7))
  SIZE   the target element size (Mesh.MeshSizeMin = Mesh.MeshSizeMax)
  --fuse fuse the seven balls with OpenCASCADE first (the union's surface);
         without it each ball is meshed on its own, as geomc does with solids
         outside subdomains.
Prints one JSON object: wall and CPU seconds of mesh.generate(2) alone, triangles, nodes,
and the smallest triangle angle in degrees. One thread, default algorithm.
"""

import json
import sys
import time

import gmsh
import numpy as np

BALLS = [(0.0, 0.0, 0.0, 0.7)] + [
    (x * 0.7, y * 0.7, z * 0.7, 0.3)
    for (x, y, z) in [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
]


def main():
    model, size = sys.argv[1], float(sys.argv[2])
    fuse = "--fuse" in sys.argv[3:]
    gmsh.initialize(["gmsh", "-nopopup"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.model.add("peer")
    occ = gmsh.model.occ
    if model == "sphere":
        occ.addSphere(0, 0, 0, 1)
    elif model == "seven":
        tags = [occ.addSphere(x, y, z, r) for (x, y, z, r) in BALLS]
        if fuse:
            occ.fuse([(3, tags[0])], [(3, t) for t in tags[1:]])
    else:
        sys.exit(f"unknown model {model}")
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    start, cpu_start = time.perf_counter(), time.process_time()
    gmsh.model.mesh.generate(2)
    seconds = time.perf_counter() - start
    cpu_seconds = time.process_time() - cpu_start

    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    position = np.zeros((int(node_tags.max()) + 1, 3))
    position[node_tags.astype(np.int64)] = coords.reshape(-1, 3)
    triangles = []
    types, _, element_nodes = gmsh.model.mesh.getElements(2)
    for kind, nodes in zip(types, element_nodes):
        if kind == 2:
            triangles.append(nodes.reshape(-1, 3).astype(np.int64))
    tri = np.concatenate(triangles)
    a, b, c = position[tri[:, 0]], position[tri[:, 1]], position[tri[:, 2]]

    def angle(p, q, r):
        u, v = q - p, r - p
        cos = np.einsum("ij,ij->i", u, v) / (
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
        )
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))

    smallest = np.minimum(np.minimum(angle(a, b, c), angle(b, c, a)), angle(c, a, b))
    print(
        json.dumps(
            {
                "seconds": seconds,
                "cpu_seconds": cpu_seconds,
                "triangles": int(len(tri)),
                "nodes": int(len(node_tags)),
                "min_angle": float(smallest.min()),
            }
        )
    )
    gmsh.finalize()


if __name__ == "__main__":
    main()
