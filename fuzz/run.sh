#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each (default 60), seeded with the fixtures.
# Needs cargo-fuzz (`cargo install cargo-fuzz`); the stable toolchain is used
# in nightly mode through RUSTC_BOOTSTRAP, as cargo-fuzz needs sanitizer flags.
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-60}"
export RUSTC_BOOTSTRAP=1
mkdir -p corpus/xml_front_end
cp ../fixtures/valid/*.xml ../fixtures/invalid/*.xml corpus/xml_front_end/ 2>/dev/null || true
# The mesh readers start from files geomc writes (examples compiled to each format).
for fmt in stl obj gltf msh vtu; do
    mkdir -p "corpus/read_$fmt"
done
if command -v geomc >/dev/null 2>&1 || [ -x ../target/debug/geomc ]; then
    g="$(command -v geomc || echo ../target/debug/geomc)"
    for ex in ../examples/*.xml; do
        b="$(basename "$ex" .xml)"
        "$g" compile "$ex" -o "corpus/read_stl/$b.stl" -o "corpus/read_obj/$b.obj" \
            -o "corpus/read_gltf/$b.glb" -o "corpus/read_msh/$b.msh" -o "corpus/read_vtu/$b.vtu" \
            >/dev/null 2>&1 || true
    done
fi
for target in $(cargo fuzz list); do
    echo "== $target for ${seconds}s"
    cargo fuzz run "$target" -- -max_total_time="$seconds" -rss_limit_mb=2048
done
