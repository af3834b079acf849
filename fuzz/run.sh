#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each (default 60), one after the other,
# each seeded from the fixtures. Needs cargo-fuzz (`cargo install cargo-fuzz`);
# the stable toolchain is used in nightly mode through RUSTC_BOOTSTRAP, as
# cargo-fuzz needs sanitizer flags. `fuzz/run.sh SECONDS TARGET…` runs only
# the targets named.
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-60}"
shift || true
export RUSTC_BOOTSTRAP=1

# The XML front end: every fixture, valid and invalid.
mkdir -p corpus/xml_front_end
cp ../fixtures/valid/*.xml ../fixtures/invalid/*.xml corpus/xml_front_end/ 2>/dev/null || true
# The .rfs language: its fixtures.
mkdir -p corpus/rfs_language
cp ../fixtures/rfs/*.rfs corpus/rfs_language/ 2>/dev/null || true
# The triangulator: the 2D fixtures' polygons in the target's byte encoding.
python3 triangulate_seeds.py ../fixtures/valid corpus/triangulate
# The density-volume reader: the fixtures' raw and NRRD files in the
# target's encoding (see shared/density_case.rs), and a few written here.
python3 density_seeds.py ../fixtures corpus/density_volume
# The mesh readers start from files geomc writes (the examples and the valid
# fixtures compiled to each format); read_frag from the .frag.xml written with
# each, its mesh files kept in frag_meshes/ where the target looks for them.
for fmt in stl obj gltf msh vtu frag; do
    mkdir -p "corpus/read_$fmt"
done
mkdir -p frag_meshes
cargo build --quiet --manifest-path ../Cargo.toml --bin geomc
g=../target/debug/geomc
for ex in ../examples/*.xml ../fixtures/valid/*.xml; do
    b="$(basename "$ex" .xml)"
    "$g" compile "$ex" -o "corpus/read_stl/$b.stl" -o "corpus/read_obj/$b.obj" \
        -o "corpus/read_gltf/$b.glb" -o "corpus/read_msh/$b.msh" -o "corpus/read_vtu/$b.vtu" \
        >/dev/null 2>&1 || true
done
for ex in ../examples/*.xml; do
    b="$(basename "$ex" .xml)"
    for fmt in msh vtu stl obj glb; do
        "$g" compile "$ex" -o "frag_meshes/$b.$fmt" -o "frag_meshes/${b}_$fmt.frag.xml" \
            >/dev/null 2>&1 || true
        cp "frag_meshes/${b}_$fmt.frag.xml" corpus/read_frag/ 2>/dev/null || true
    done
done

targets=("$@")
[ ${#targets[@]} -gt 0 ] || mapfile -t targets < <(cargo fuzz list)
for target in "${targets[@]}"; do
    echo "== $target for ${seconds}s (load: $(cut -d' ' -f1-3 /proc/loadavg))"
    cargo fuzz run "$target" "corpus/$target" -- -max_total_time="$seconds" -rss_limit_mb=2048 \
        -print_final_stats=1
done
