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
for target in $(cargo fuzz list); do
    echo "== $target for ${seconds}s"
    cargo fuzz run "$target" -- -max_total_time="$seconds" -rss_limit_mb=2048
done
