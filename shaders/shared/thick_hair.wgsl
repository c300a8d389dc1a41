// One thick hair of far hair's hierarchy (seed 001): its four corner strands' roots, the
// strands it stands for, its bundle and level. Shared by strand_gen.wgsl (`thick_main`) and
// far_lod.wgsl. Keep in sync with core/src/runtime/gpu_types.rs (`ThickHairGpu`).
struct ThickHairGpu {
    corners: vec4<u32>,
    members: u32,
    block: u32,
    level: u32,
    padding: u32,
}
