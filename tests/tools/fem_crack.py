"""Laplace's equation across a crack, on a 2D MSH mesh written by geomc, with
scikit-fem (P1): u = value on named boundary lines, natural (insulated)
boundaries elsewhere, including both sides of the crack.

usage: fem_crack.py MESH.msh LEFT_GROUP RIGHT_GROUP NAME=VALUE [NAME=VALUE ...]
Prints one JSON object: the solution's range, and over the node pairs of the
two crack sides that share a position (the opened crack's duplicated nodes)
the largest jump |u_left - u_right|, the jump and both values at the pair
nearest the crack's middle, and there |u_left + u_right - 1| (0 at the
centre of the antisymmetric test case).
"""
import json
import sys

import meshio
import numpy as np
import skfem
from skfem.helpers import dot, grad


def group_nodes(m, name):
    if name not in m.field_data:
        raise SystemExit(f"no physical group {name!r}: {sorted(m.field_data)}")
    tag = m.field_data[name][0]
    nodes = set()
    for block, data in zip(m.cells, m.cell_data["gmsh:physical"]):
        if block.type == "line":
            for cell, t in zip(block.data, data):
                if t == tag:
                    nodes.update(int(n) for n in cell)
    return sorted(nodes)


def main():
    path, left, right, *fixed_specs = sys.argv[1:]
    m = meshio.read(path)
    points = m.points[:, :2]
    tris = m.cells_dict["triangle"]
    used = np.unique(tris)
    index = -np.ones(len(points), dtype=int)
    index[used] = np.arange(len(used))
    mesh = skfem.MeshTri(points[used].T, index[tris].T)
    basis = skfem.Basis(mesh, skfem.ElementTriP1())

    @skfem.BilinearForm
    def a(u, v, w):
        return dot(grad(u), grad(v))

    A = a.assemble(basis)
    u = np.zeros(basis.N)
    dofs = []
    for spec in fixed_specs:
        name, value = spec.split("=")
        ids = index[group_nodes(m, name)]
        u[ids] = float(value)
        dofs.extend(ids.tolist())
    dofs = np.array(sorted(set(dofs)))
    u = skfem.solve(*skfem.condense(A, np.zeros(basis.N), x=u, D=dofs))

    lnodes, rnodes = group_nodes(m, left), group_nodes(m, right)
    pairs = []
    for i in lnodes:
        for j in rnodes:
            if i != j and np.allclose(points[i], points[j], atol=1e-12):
                pairs.append((i, j))
    jumps = [abs(u[index[i]] - u[index[j]]) for i, j in pairs]
    centre = (points[lnodes].min(axis=0) + points[lnodes].max(axis=0)) / 2
    mid = min(pairs, key=lambda p: np.linalg.norm(points[p[0]] - centre))
    print(json.dumps({
        "nodes": int(len(points)),
        "triangles": int(len(tris)),
        "u_min": float(u.min()),
        "u_max": float(u.max()),
        "pairs": len(pairs),
        "max_jump": float(max(jumps)),
        "mid_left": float(u[index[mid[0]]]),
        "mid_right": float(u[index[mid[1]]]),
        "mid_jump": float(abs(u[index[mid[0]]] - u[index[mid[1]]])),
        "mid_antisymmetry_error": float(abs(u[index[mid[0]]] + u[index[mid[1]]] - 1.0)),
    }))


if __name__ == "__main__":
    main()
