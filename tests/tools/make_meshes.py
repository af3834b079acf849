"""Writes meshes with other tools for tests/convert_external.rs and prints, as
JSON, what each file holds according to the tool that wrote it.

gmsh: a box whose face x=0 is physical surface `inlet`, the other faces
`walls`, the volume `solid`; saved as MSH 4.1 and 2.2, ASCII and binary.
meshio: that mesh as VTU (zlib-compressed binary, and ASCII).
trimesh 5.2.0: an icosphere and a box as binary and ASCII STL, OBJ and GLB.

Exit code 3 when a module is missing (the Rust test then prints the hint).
"""

import json
import os
import sys

try:
    import gmsh
    import meshio
    import numpy as np
    import trimesh
except ImportError as e:  # pragma: no cover
    print(f"missing module: {e}", file=sys.stderr)
    sys.exit(3)

out = sys.argv[1]
facts = {}

# ---- gmsh ----
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box")
box = gmsh.model.occ.addBox(0, 0, 0, 1, 2, 3)
gmsh.model.occ.synchronize()
surfaces = [tag for _, tag in gmsh.model.getBoundary([(3, box)], oriented=False)]
inlet = [s for s in surfaces if abs(gmsh.model.occ.getCenterOfMass(2, s)[0]) < 1e-9]
walls = [s for s in surfaces if s not in inlet]
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, inlet), "inlet")
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, walls), "walls")
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [box]), "solid")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
gmsh.model.mesh.generate(3)


def triangles_of(tags):
    n = 0
    for s in tags:
        types, elems, _ = gmsh.model.mesh.getElements(2, s)
        for t, e in zip(types, elems):
            if t == 2:
                n += len(e)
    return n


tets = 0
types, elems, _ = gmsh.model.mesh.getElements(3, box)
for t, e in zip(types, elems):
    if t == 4:
        tets += len(e)
gmsh_groups = {"inlet": triangles_of(inlet), "walls": triangles_of(walls)}
for version, binary, name in [
    (4.1, 0, "gmsh41.msh"),
    (4.1, 1, "gmsh41_bin.msh"),
    (2.2, 0, "gmsh22.msh"),
    (2.2, 1, "gmsh22_bin.msh"),
]:
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", binary)
    gmsh.write(os.path.join(out, name))
    facts[name] = {"groups": gmsh_groups, "tetrahedra": tets}
gmsh.finalize()

# ---- meshio: the gmsh mesh as VTU ----
m = meshio.read(os.path.join(out, "gmsh41.msh"))
meshio.write(os.path.join(out, "meshio.vtu"), m)
meshio.write(os.path.join(out, "meshio_ascii.vtu"), m, binary=False)
vtu_groups = {}
for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
    if block.type == "triangle":
        for tag in phys:
            vtu_groups[int(tag)] = vtu_groups.get(int(tag), 0) + 1
names = {int(v[0]): k for k, v in m.field_data.items() if int(v[1]) == 2}
for name in ["meshio.vtu", "meshio_ascii.vtu"]:
    facts[name] = {
        "triangles_by_tag": {str(k): v for k, v in vtu_groups.items()},
        "names": {str(k): v for k, v in names.items()},
        "points": len(m.points),
    }

# ---- trimesh ----
sphere = trimesh.creation.icosphere(subdivisions=2)
cube = trimesh.creation.box(extents=[1, 2, 3])
cube.apply_translation([3, 0, 0])
for name, kind in [("trimesh_bin.stl", "stl"), ("trimesh_ascii.stl", "stl_ascii"), ("trimesh.obj", "obj")]:
    data = sphere.export(file_type=kind)
    mode = "w" if isinstance(data, str) else "wb"
    with open(os.path.join(out, name), mode) as f:
        f.write(data)
    facts[name] = {"triangles": len(sphere.faces), "vertices": len(sphere.vertices),
                   "volume": float(sphere.volume)}
scene = trimesh.Scene()
scene.add_geometry(sphere, node_name="ball", geom_name="ball")
scene.add_geometry(cube, node_name="brick", geom_name="brick")
with open(os.path.join(out, "trimesh.glb"), "wb") as f:
    f.write(scene.export(file_type="glb"))
facts["trimesh.glb"] = {
    "groups": {"ball": len(sphere.faces), "brick": len(cube.faces)},
    "bounds": np.asarray(scene.bounds).tolist(),
}
print(json.dumps(facts))
