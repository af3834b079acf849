"""Writes volume meshes with gmsh for tests/convert_volume.rs and prints, as
JSON, what gmsh says each holds.

tets*.msh: two unit boxes side by side ([0,1] and [1,2] in x), fragmented so
they share their interface, tetrahedralized; physical volumes `left` and
`right`, physical surfaces `outer` (the boundary) and `interface`. Saved as
MSH 4.1 and 2.2, ASCII and binary.
layers.msh: two unit squares extruded by one in z over 4 layers: one
recombined (hexahedra, volume `hex`), one triangulated (prisms, volume
`prism`), plus a discrete volume `pyramid` holding one pyramid (base the unit
square at z = 2, apex (0.5, 0.5, 3)); MSH 4.1 ASCII.

Exit code 3 when a module is missing (the Rust test then prints the hint).
"""

import json
import os
import sys

try:
    import gmsh
except ImportError as e:  # pragma: no cover
    print(f"missing module: {e}", file=sys.stderr)
    sys.exit(3)

out = sys.argv[1]
facts = {}


def element_counts(dim, tag):
    counts = {}
    for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
        types, elems, _ = gmsh.model.mesh.getElements(dim, entity)
        for t, e in zip(types, elems):
            name = gmsh.model.mesh.getElementProperties(t)[0].split()[0].lower()
            counts[name] = counts.get(name, 0) + len(e)
    return counts


def groups():
    return {
        gmsh.model.getPhysicalName(dim, tag): {"dim": dim, "elements": element_counts(dim, tag)}
        for dim, tag in gmsh.model.getPhysicalGroups()
    }


gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)

# ---- two tetrahedralized boxes ----
gmsh.model.add("tets")
a = gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
b = gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
gmsh.model.occ.fragment([(3, a)], [(3, b)])
gmsh.model.occ.synchronize()
vols = sorted(t for _, t in gmsh.model.getEntities(3))
left = [v for v in vols if gmsh.model.occ.getCenterOfMass(3, v)[0] < 1]
right = [v for v in vols if v not in left]
faces_left = {abs(t) for _, t in gmsh.model.getBoundary([(3, v) for v in left], combined=False, oriented=False)}
faces_right = {abs(t) for _, t in gmsh.model.getBoundary([(3, v) for v in right], combined=False, oriented=False)}
shared = sorted(faces_left & faces_right)
outer = sorted((faces_left | faces_right) - set(shared))
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, left), "left")
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, right), "right")
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, outer), "outer")
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, shared), "interface")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
gmsh.model.mesh.generate(3)
node_tags, _, _ = gmsh.model.mesh.getNodes()
tet_facts = {"groups": groups(), "nodes": len(node_tags)}
for version, binary, name in [
    (4.1, 0, "tets41.msh"),
    (4.1, 1, "tets41_bin.msh"),
    (2.2, 0, "tets22.msh"),
    (2.2, 1, "tets22_bin.msh"),
]:
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", binary)
    gmsh.write(os.path.join(out, name))
    facts[name] = tet_facts
gmsh.model.remove()

# ---- hexahedra, prisms and a pyramid ----
gmsh.model.add("layers")
s1 = gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
s2 = gmsh.model.occ.addRectangle(2, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
for c in gmsh.model.getBoundary([(2, s1)], oriented=False):
    gmsh.model.mesh.setTransfiniteCurve(abs(c[1]), 4)
gmsh.model.mesh.setTransfiniteSurface(s1)
gmsh.model.mesh.setRecombine(2, s1)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
hex_out = gmsh.model.occ.extrude([(2, s1)], 0, 0, 1, numElements=[4], recombine=True)
prism_out = gmsh.model.occ.extrude([(2, s2)], 0, 0, 1, numElements=[4], recombine=True)
gmsh.model.occ.synchronize()
hex_vol = [t for d, t in hex_out if d == 3]
prism_vol = [t for d, t in prism_out if d == 3]
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, hex_vol), "hex")
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, prism_vol), "prism")
gmsh.model.mesh.generate(3)
pyr = gmsh.model.addDiscreteEntity(3)
first = int(max(gmsh.model.mesh.getNodes()[0])) + 1
coords = [0, 0, 2, 1, 0, 2, 1, 1, 2, 0, 1, 2, 0.5, 0.5, 3]
gmsh.model.mesh.addNodes(3, pyr, list(range(first, first + 5)), coords)
gmsh.model.mesh.addElementsByType(pyr, 7, [], list(range(first, first + 5)))
gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [pyr]), "pyramid")
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write(os.path.join(out, "layers.msh"))
facts["layers.msh"] = {"groups": groups()}
gmsh.finalize()
print(json.dumps(facts, sort_keys=True))
