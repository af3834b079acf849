#!/usr/bin/env bash
# The whole test suite, on a fresh machine: installs the external checkers the
# tests run (xmllint for the XSDs; gmsh + meshio and the Khronos glTF validator
# for the mesh writers' tests), then runs every Rust test. Each install is
# skipped when already present, so a second run starts testing at once.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

# gmsh's wheel links against these X11/OpenGL libraries even when run headless.
GMSH_LIBS=(libglu1-mesa libxrender1 libxcursor1 libxft2 libxinerama1 libgl1 libgomp1)

need_apt=()
command -v xmllint >/dev/null 2>&1 || need_apt+=(libxml2-utils)
for pkg in "${GMSH_LIBS[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need_apt+=("$pkg")
done
command -v python3 >/dev/null 2>&1 || need_apt+=(python3 python3-pip)
command -v npm >/dev/null 2>&1 || need_apt+=(nodejs npm)
if [ ${#need_apt[@]} -gt 0 ]; then
    echo "installing: ${need_apt[*]}" >&2
    $SUDO apt-get update -qq >/dev/null
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

# Every pip install below takes the convert bench's peer set-up as constraints
# (numpy, scipy, networkx, meshio, trimesh at fixed versions), so the peers'
# times can be compared from one machine to the next.
PINS=(-c benches/peers/requirements.txt)
if ! python3 benches/peers/convert_peers.py --check-pins >/dev/null 2>&1; then
    echo "installing: the convert bench's pinned peer set-up (pip)" >&2
    python3 -m pip install -q -r benches/peers/requirements.txt \
        || python3 -m pip install -q --break-system-packages -r benches/peers/requirements.txt
fi

# tests/tools/check_mesh.py (tests/writers_external.rs).
if ! python3 -c "import gmsh, meshio" >/dev/null 2>&1; then
    echo "installing: gmsh meshio (pip)" >&2
    # Debian's own python3 refuses system-wide pip installs without this flag.
    python3 -m pip install -q "${PINS[@]}" gmsh==4.15.2 meshio==5.3.5 \
        || python3 -m pip install -q "${PINS[@]}" --break-system-packages gmsh==4.15.2 meshio==5.3.5
fi

# tests/tools/make_meshes.py (tests/convert_external.rs): meshes made by trimesh.
if ! python3 -c "import trimesh" >/dev/null 2>&1; then
    echo "installing: trimesh (pip)" >&2
    python3 -m pip install -q "${PINS[@]}" trimesh==5.2.0 \
        || python3 -m pip install -q "${PINS[@]}" --break-system-packages trimesh==5.2.0
fi

# tests/tools/fem_poisson.py (tests/fem_2d.rs, tests/region_2d.rs), fem_crack.py
# (tests/crack_2d.rs, tests/edge_crack_2d.rs) and benches/mesh2d.rs' peer
# (benches/mesh2d_triangle.py): scikit-fem solves on geomc's meshes, Triangle
# is the 2D meshing peer.
if ! python3 -c "import skfem, triangle" >/dev/null 2>&1; then
    echo "installing: scikit-fem triangle (pip)" >&2
    python3 -m pip install -q "${PINS[@]}" scikit-fem==10.0.2 triangle==20250106 \
        || python3 -m pip install -q "${PINS[@]}" --break-system-packages scikit-fem==10.0.2 triangle==20250106
fi

# tests/tools/validate_gltf.js: the validator pinned by tests/tools/package-lock.json.
if [ ! -f tests/tools/node_modules/gltf-validator/package.json ]; then
    echo "installing: gltf-validator (npm, tests/tools/node_modules)" >&2
    (cd tests/tools && npm ci --no-audit --no-fund --silent)
fi

cargo test --all-targets --quiet
