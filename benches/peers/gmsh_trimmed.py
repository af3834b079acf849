"""Peer for benches/trimmed.rs: gmsh meshing paper 002's interstage cone
(fixtures/valid/trimmed_interstage.xml) with its cut-outs made by
OpenCASCADE booleans: the cone's lateral face minus three rounded-rectangle
prisms (two boxes and four cylinders each) and three cylinders, all radial.

Usage: python3 gmsh_trimmed.py SIZE
Prints one JSON object: wall and CPU seconds of the boolean cut and of
mesh.generate(2), triangles, nodes and the smallest triangle angle. One thread.
"""

import json
import math
import sys
import time

import gmsh
import numpy as np

R1, R2, L = 2.0, 1.5, 3.0
# (angle, y0, width, height, corner radius, tilt) as in the fixture.
SRECTS = [(0.0, 1.0, 0.9, 0.7, 0.15, 0.0), (math.pi, 1.8, 0.6, 1.0, 0.2, 0.0),
          (2 * math.pi / 3, 2.0, 0.8, 0.5, 0.1, math.pi / 6)]
CYLS = [(math.pi / 2, 1.5, 0.3), (4 * math.pi / 3, 0.9, 0.25), (5 * math.pi / 3, 2.2, 0.2)]
DEPTH = 3.0  # radial extent of the cutting prisms (from the axis outwards)


def radial(occ, tags, angle, y0, tilt):
    """Prisms built along +z around (0, y0): tilt about z, then turn the +z
    direction to the cut-out's radial direction (x cos a + z sin a)."""
    dims = [(3, t) for t in tags]
    if tilt:
        occ.rotate(dims, 0, y0, 0, 0, 0, 1, tilt)
    # +z to (cos a, 0, sin a): rotate about y by (pi/2 - a).
    occ.rotate(dims, 0, 0, 0, 0, 1, 0, math.pi / 2 - angle)
    return dims


def srect(occ, angle, y0, w, h, c, tilt):
    hw, hh = w / 2, h / 2
    tags = [occ.addBox(-hw, y0 - hh + c, 0, w, h - 2 * c, DEPTH),
            occ.addBox(-hw + c, y0 - hh, 0, w - 2 * c, h, DEPTH)]
    for sx in (1, -1):
        for sy in (1, -1):
            tags.append(occ.addCylinder(sx * (hw - c), y0 + sy * (hh - c), 0, 0, 0, DEPTH, c))
    return radial(occ, tags, angle, y0, tilt)


def main():
    size = float(sys.argv[1])
    gmsh.initialize(["gmsh", "-nopopup"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.model.add("interstage")
    occ = gmsh.model.occ
    cone = occ.addCone(0, 0, 0, 0, L, 0, R1, R2)
    occ.synchronize()
    faces = gmsh.model.getBoundary([(3, cone)], oriented=False)
    lateral = [f for f in faces if gmsh.model.getType(*f) != "Plane"]
    planes = [f for f in faces if gmsh.model.getType(*f) == "Plane"]
    # Keep the lateral surface alone.
    occ.remove([(3, cone)], recursive=False)
    occ.remove(planes, recursive=False)
    occ.synchronize()
    start, cpu_start = time.perf_counter(), time.process_time()
    tools = []
    for s in SRECTS:
        tools += srect(occ, *s)
    for (a, y0, r) in CYLS:
        tools += radial(occ, [occ.addCylinder(0, y0, 0, 0, 0, DEPTH, r)], a, y0, 0.0)
    occ.cut(lateral, tools, removeObject=True, removeTool=True)
    occ.synchronize()
    cut_seconds = time.perf_counter() - start
    cut_cpu = time.process_time() - cpu_start
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
        cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))

    smallest = np.minimum(np.minimum(angle(a, b, c), angle(b, c, a)), angle(c, a, b))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    print(json.dumps({
        "cut_seconds": cut_seconds, "cut_cpu_seconds": cut_cpu,
        "seconds": seconds, "cpu_seconds": cpu_seconds,
        "triangles": int(len(tri)), "nodes": int(len(node_tags)),
        "min_angle": float(smallest.min()), "area": float(area),
    }))
    gmsh.finalize()


if __name__ == "__main__":
    main()
