// StrandRun: a run of strands of one bundle at one detail level, as the frame plan hands
// them to strand_gen and preview_hair (core/src/runtime/frame_plan.rs), and the run lookup
// both use (each shader declares its `runs`). WGSL has no #include: render/src/ prepends this
// file to each shader that uses it.
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

// Units a batch's items are counted in, for `find_run`.
const RUN_BY_VERTEX: u32 = 0u;
const RUN_BY_SEGMENT: u32 = 1u;
const RUN_BY_STRAND: u32 = 2u;

// The batch index of a run's first item in `unit`s; strands before the run each have one
// more vertex than segments.
fn run_start(run: StrandRun, unit: u32) -> u32 {
    if unit == RUN_BY_VERTEX {
        return run.vertex_offset;
    }
    if unit == RUN_BY_SEGMENT {
        return run.segment_offset;
    }
    return run.vertex_offset - run.segment_offset;
}

// The run among runs[first .. first + count] (count ≥ 1) holding the batch's item `index`,
// counted in `unit`s (binary search over the shader's `runs`).
fn find_run(first: u32, count: u32, index: u32, unit: u32) -> u32 {
    var low = first;
    var high = first + max(count, 1u) - 1u;
    while low < high {
        let middle = (low + high + 1u) / 2u;
        if run_start(runs[middle], unit) <= index {
            low = middle;
        } else {
            high = middle - 1u;
        }
    }
    return low;
}
