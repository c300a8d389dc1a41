#!/usr/bin/env bash
# The GPU comparison of BENCHMARKS.md ("GPU generation and frames") in one go, from a stripped
# release binary, so a short window on a machine with a real GPU is enough:
#
#   tools/gpu-bench.sh pack          # here: build, strip into .gpu/hairloom (~20 MB)
#   tools/gpu-bench.sh run [OUT]     # there: adapters, `bench gpu` side by side (with the LHS
#                                    # baseline), `bench switches`, `bench crowd`, `bench effects`
#
# `run` names the adapter first and writes adapters.txt, gpu.txt, switches.txt, crowd_default.txt,
# crowd_compute.txt, crowd_unique.txt, crowd_unique_no_lod.txt, teapots.txt and effects.txt into OUT (default $OUT when
# set, else out/gpu-bench). It unpacks carried Vulkan loaders (.gl/*.deb, see the device
# notes) when the machine has none, and points the loader at NVIDIA's ICD when it is there.
# Knobs: STRANDS (default 10000,100000,300000), RUNS (3), SIZE (1280x720), TEXTURES (f16,f32),
# CHARACTERS (1,10,100) and CROWD_STRANDS (100000) for the crowds, TEAPOTS (1,50,200),
# BIN (the binary; default .gpu/hairloom, else target/release/hairloom).
set -euo pipefail
cd "$(dirname "$0")/.."

case "${1:-run}" in
pack)
    cargo build --release -p hairloom-editor
    mkdir -p .gpu
    strip -o .gpu/hairloom target/release/hairloom
    grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >>.git/info/exclude
    ls -l .gpu/hairloom
    ;;
run)
    out=${2:-${OUT:-out/gpu-bench}}
    mkdir -p "$out"
    bin=${BIN:-}
    if [ -z "$bin" ]; then
        if [ -x .gpu/hairloom ]; then bin=.gpu/hairloom; else bin=target/release/hairloom; fi
    fi
    [ -x "$bin" ] || { echo "no binary at $bin: run '$0 pack' first" >&2; exit 2; }
    if ! ldconfig -p 2>/dev/null | grep -q libvulkan && compgen -G '.gl/*.deb' >/dev/null; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    fi
    icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$icd" ]; then export VK_DRIVER_FILES=$icd; fi
    export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/hairloom-runtime}
    mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
    "$bin" adapters | tee "$out/adapters.txt"
    "$bin" bench gpu --strands "${STRANDS:-10000,100000,300000}" --runs "${RUNS:-3}" \
        --size "${SIZE:-1280x720}" --textures "${TEXTURES:-f16,f32}" | tee "$out/gpu.txt"
    # Styling on vs off, MSAA 1× / 4× / 8×, exact vs hardware filtering and the game
    # runtime's measured choice (seed 000 §5's switch costs).
    "$bin" bench switches --strands "${STRANDS:-10000,100000,300000}" --runs "${RUNS:-3}" \
        --size "${SIZE:-1280x720}" | tee "$out/switches.txt"
    # The paper's Fig. 1 scene: up to 100 characters of 100K strands each, LOD on; the game
    # runtime's default path (mesh shaders where the adapter has them), then compute.
    for generation in default compute; do
        flag=(); [ "$generation" = default ] || flag=(--generation "$generation")
        "$bin" bench crowd --characters "${CHARACTERS:-1,10,100}" --strands "${CROWD_STRANDS:-100000}" \
            --runs "${RUNS:-3}" --size "${SIZE:-1280x720}" ${flag[@]+"${flag[@]}"} | tee "$out/crowd_$generation.txt"
    done
    # Fig. 1 as the paper ran it: every character its own hair model (varied from the five
    # head samples), with LOD and without; Fig. 9: 200 teapots of 50K strands, each its own.
    "$bin" bench crowd --unique --characters "${CHARACTERS:-1,10,100}" --strands "${CROWD_STRANDS:-100000}" \
        --runs "${RUNS:-3}" --size "${SIZE:-1280x720}" | tee "$out/crowd_unique.txt"
    "$bin" bench crowd --unique --no-lod --characters "${CHARACTERS:-1,10,100}" --strands "${CROWD_STRANDS:-100000}" \
        --runs 1 --size "${SIZE:-1280x720}" | tee "$out/crowd_unique_no_lod.txt"
    "$bin" bench crowd --unique --samples teapot_fur --characters "${TEAPOTS:-1,50,200}" --strands 50000 \
        --runs "${RUNS:-3}" --size "${SIZE:-1280x720}" | tee "$out/teapots.txt"
    # What each lighting effect costs on this adapter (about 25 s on an H200).
    "$bin" bench effects --size "${SIZE:-1280x720}" --runs "${RUNS:-3}" | tee "$out/effects.txt"
    ;;
*)
    echo "usage: $0 pack | run [OUT]" >&2
    exit 2
    ;;
esac
