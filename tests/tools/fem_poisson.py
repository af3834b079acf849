"""Solve -div(k grad u) = 1 with u = 0 on named boundary lines, on a 2D MSH
mesh written by geomc, with scikit-fem (P1, or P2 for 6-node triangles).

usage: fem_poisson.py MESH.msh CASE [BOUNDARY ...]
CASE: disk (unit disk, exact (1 - r^2)/4), annulus (radii 0.5 and 1),
      twomat (unit square, k = 1 for x < 0.5 and 10 beyond; reports the
      flux jump across the interface line named 'interface'),
      disks:X,Y,R;X,Y,R;... (disjoint or touching disks, k = 1, exact
      (R^2 - |x - c|^2)/4 in the disk holding the point),
      square (the unit square [0, 1]^2 however it is cut into subdomains,
      k = 1, exact: the double sine series over odd n, m < 400).
Prints one JSON object: triangles, nodes, max_u, max_error (nodal, against
the exact solution where there is one), flux_jump (twomat).
"""
import json
import sys

import meshio
import numpy as np
import skfem
from skfem.helpers import dot, grad


def main():
    path, case, *names = sys.argv[1:]
    m = meshio.read(path)
    quadratic = "triangle6" in m.cells_dict
    tri_type, line_type = ("triangle6", "line3") if quadratic else ("triangle", "line")
    points = m.points[:, :2]
    tris = m.cells_dict[tri_type]
    # Boundary nodes: every node of the named physical lines.
    fixed = set()
    for name in names:
        if name not in m.field_data:
            raise SystemExit(f"no physical group {name!r} in {path}: {sorted(m.field_data)}")
        tag = m.field_data[name][0]
        for block, data in zip(m.cells, m.cell_data["gmsh:physical"]):
            if block.type == line_type:
                for cell, t in zip(block.data, data):
                    if t == tag:
                        fixed.update(int(n) for n in cell)
    # Build the scikit-fem mesh from the corners; P2 dofs then sit at the
    # mid-edge nodes, which we compare by position.
    used = np.unique(tris[:, :3])
    index = -np.ones(len(points), dtype=int)
    index[used] = np.arange(len(used))
    if quadratic:
        # Isoparametric: the mid-edge nodes (on the curve) shape the elements.
        mesh = skfem.MeshTri2.load(path, force_meshio_type="triangle6")
    else:
        mesh = skfem.MeshTri(points[used].T, index[tris[:, :3]].T)
    element = skfem.ElementTriP2() if quadratic else skfem.ElementTriP1()
    basis = skfem.Basis(mesh, element, intorder=4)
    x = basis.doflocs
    if case == "twomat":
        k_of = lambda xs: np.where(xs[0] < 0.5, 1.0, 10.0)
    else:
        k_of = lambda xs: np.ones_like(xs[0])

    @skfem.BilinearForm
    def a(u, v, w):
        return k_of(w.x) * dot(grad(u), grad(v))

    @skfem.LinearForm
    def f(v, w):
        return 1.0 * v

    A = a.assemble(basis)
    b = f.assemble(basis)
    fixed_points = points[sorted(fixed)]
    # Dofs at fixed node positions (corner and mid-edge nodes alike).
    from scipy.spatial import cKDTree
    tree = cKDTree(fixed_points)
    dist, _ = tree.query(x.T)
    scale = np.ptp(points, axis=0).max()
    D = np.nonzero(dist < 1e-9 * scale)[0]
    u = skfem.solve(*skfem.condense(A, b, D=D))
    r = np.hypot(x[0], x[1])
    out = {"triangles": int(len(tris)), "nodes": int(len(points)), "max_u": float(u.max()),
           "fixed": int(len(D))}
    if case == "disk":
        out["max_error"] = float(np.abs(u - (1 - r**2) / 4).max())
    elif case == "annulus":
        a_, b_ = 0.5, 1.0
        c1 = (b_**2 - a_**2) / (4 * np.log(b_ / a_))
        exact = -r**2 / 4 + c1 * np.log(r) + b_**2 / 4 - c1 * np.log(b_)
        out["max_error"] = float(np.abs(u - exact).max())
    elif case.startswith("disks:"):
        disks = [[float(v) for v in d.split(",")] for d in case[len("disks:"):].split(";")]
        exact = np.max([(R**2 - (x[0] - cx)**2 - (x[1] - cy)**2) / 4 for cx, cy, R in disks],
                       axis=0)
        out["max_error"] = float(np.abs(u - np.maximum(exact, 0.0)).max())
    elif case == "square":
        n = np.arange(1, 400, 2, dtype=float)
        sx = np.sin(np.pi * np.outer(x[0], n)) / n
        sy = np.sin(np.pi * np.outer(x[1], n)) / n
        weight = 16.0 / np.pi**4 / (n[:, None] ** 2 + n[None, :] ** 2)
        exact = np.einsum("pi,ij,pj->p", sx, weight, sy)
        out["max_error"] = float(np.abs(u - exact).max())
    elif case == "twomat":
        # Normal flux k du/dx on each side of x = 0.5, from the elements that
        # touch the interface, integrated over it: equal for the exact solution.
        grads = {}
        ib = skfem.InteriorBasis(mesh, element)
        du = ib.interpolate(u).grad
        centre = mesh.p[:, mesh.t].mean(axis=1)
        touching = np.any(np.abs(mesh.p[0, mesh.t] - 0.5) < 1e-12, axis=0)
        for side, sel in (("left", centre[0] < 0.5), ("right", centre[0] > 0.5)):
            elems = np.nonzero(sel & touching)[0]
            k = 1.0 if side == "left" else 10.0
            # Mean over the element's quadrature points, weighted by the
            # element's share of the interface.
            flux = k * du[0][elems].mean(axis=1)
            ys = mesh.p[1, mesh.t[:, elems]]
            on = np.abs(mesh.p[0, mesh.t[:, elems]] - 0.5) < 1e-12
            length = np.array([np.ptp(ys[on[:, j], j]) if on[:, j].sum() == 2 else 0.0
                               for j in range(len(elems))])
            grads[side] = float((flux * length).sum())
        out["flux_left"] = grads["left"]
        out["flux_right"] = grads["right"]
        out["flux_jump"] = abs(grads["left"] - grads["right"]) / max(abs(grads["left"]), 1e-300)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
