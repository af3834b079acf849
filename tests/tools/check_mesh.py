#!/usr/bin/env python3
"""Reads mesh files written by geomc with independent readers and prints what
they found as one JSON object, for tests/writers_external.rs to assert.

Usage: check_mesh.py FILE.msh|FILE.vtu [--tetra]

For .msh: gmsh (its Python API) lists the physical groups with their element
counts and the entities; meshio lists its cell blocks and cell sets. With
--tetra, gmsh tetrahedralizes every volume: for each volume entity read from
the file a geo volume is declared over its boundary surfaces (a discrete
volume read from a file is otherwise left empty by mesh.generate(3)), then
the fragment groups are counted again on the boundary triangles.
For .vtu: meshio lists cell blocks and the distinct values of each cell field.

Exit 3 when gmsh or meshio is missing, so the Rust test can say how to install.
"""
import json
import sys

try:
    import gmsh
    import meshio
except ImportError as e:  # the test turns exit 3 into "run ./scripts/test.sh"
    print(f"missing Python module: {e}", file=sys.stderr)
    sys.exit(3)


def count_elements(dim, tag):
    """Elements of a physical group, by element type name."""
    counts = {}
    for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
        types, tags, _ = gmsh.model.mesh.getElements(dim, entity)
        for t, ts in zip(types, tags):
            name = gmsh.model.mesh.getElementProperties(t)[0].split()[0].lower()
            counts[name] = counts.get(name, 0) + len(ts)
    return counts


def gmsh_groups():
    groups = []
    for dim, tag in gmsh.model.getPhysicalGroups():
        groups.append({
            "dim": dim,
            "tag": tag,
            "name": gmsh.model.getPhysicalName(dim, tag),
            "entities": len(gmsh.model.getEntitiesForPhysicalGroup(dim, tag)),
            "elements": count_elements(dim, tag),
        })
    return groups


def check_msh(path, tetra):
    out = {}
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        node_tags, _, _ = gmsh.model.mesh.getNodes()
        out["gmsh"] = {
            "nodes": len(node_tags),
            "entities": {str(d): len(gmsh.model.getEntities(d)) for d in range(4)},
            "groups": gmsh_groups(),
            "volume_boundaries": {
                str(tag): sorted(t for _, t in gmsh.model.getBoundary([(3, tag)], oriented=True, combined=False))
                for _, tag in gmsh.model.getEntities(3)
            },
        }
        if tetra:
            out["tetra"] = tetrahedralize()
    finally:
        gmsh.finalize()

    m = meshio.read(path)
    out["meshio"] = {
        "points": int(len(m.points)),
        "cells": cell_counts(m),
        "cell_sets": {
            name: sum(int(len(block)) for block in blocks if block is not None)
            for name, blocks in m.cell_sets.items()
            if name != "gmsh:bounding_entities"
        },
    }
    # MSH 2.2 has no cell sets in meshio: its names are field data
    # (name -> [tag, dim]) and each cell's physical tag is cell data.
    out["meshio_physical"] = {
        "field_data": {name: [int(v) for v in vals] for name, vals in m.field_data.items()},
        "physical_cells": physical_cells(m),
    }
    return out


def physical_cells(m):
    """Cells per (dim:tag) of meshio's gmsh:physical cell data."""
    counts = {}
    dims = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "triangle6": 2, "quad": 2}
    for block, tags in zip(m.cells, m.cell_data.get("gmsh:physical", [])):
        dim = dims.get(block.type, 3)
        for t in tags:
            key = f"{dim}:{int(t)}"
            counts[key] = counts.get(key, 0) + 1
    return counts


def tetrahedralize():
    for _, tag in gmsh.model.getEntities(3):
        surfaces = [abs(t) for _, t in gmsh.model.getBoundary([(3, tag)], oriented=False, combined=False)]
        loop = gmsh.model.geo.addSurfaceLoop(surfaces)
        gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    try:
        gmsh.model.mesh.generate(3)
    except Exception as e:  # reported, and the test fails on ok = false
        return {"ok": False, "error": str(e)}
    groups = gmsh_groups()
    # Tetrahedra per subdomain, through its physical group: the groups read
    # from the file must hold the new volume elements.
    per_volume = {g["name"]: g["elements"].get("tetrahedron", 0) for g in groups if g["dim"] == 3}
    return {
        "ok": len(per_volume) > 0 and all(n > 0 for n in per_volume.values()),
        "tetrahedra": per_volume,
        "groups": groups,
    }


def cell_counts(m):
    counts = {}
    for block in m.cells:
        counts[block.type] = counts.get(block.type, 0) + int(len(block.data))
    return counts


def check_vtu(path):
    m = meshio.read(path)
    fields = {}
    for name, blocks in m.cell_data.items():
        values = set()
        for block in blocks:
            values.update(int(v) for v in block)
        fields[name] = sorted(values)
    return {"meshio": {"points": int(len(m.points)), "cells": cell_counts(m), "cell_data": fields}}


def main():
    args = sys.argv[1:]
    tetra = "--tetra" in args
    paths = [a for a in args if a != "--tetra"]
    if len(paths) != 1:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    path = paths[0]
    result = check_vtu(path) if path.endswith(".vtu") else check_msh(path, tetra)
    print(json.dumps(result, sort_keys=True))


if __name__ == "__main__":
    main()
