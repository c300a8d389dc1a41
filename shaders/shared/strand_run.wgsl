// StrandRun: a run of strands of one bundle at one detail level, as the frame plan hands
// them to strand_gen and preview_hair (core/src/runtime/frame_plan.rs). WGSL has no
// #include: render/src/ prepends this file to each shader that uses it.
// Keep in sync with core/src/runtime/gpu_types.rs (`StrandRun`).

struct StrandRun {
    first_root: u32,
    strand_count: u32,
    vertex_count: u32,
    vertex_offset: u32,
    segment_offset: u32,
    gamma: f32,
    thickness: f32,
    _padding: u32,
}
