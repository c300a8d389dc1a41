//! GPU-layout structs shared by the CPU mirrors (here) and the shaders (`shaders/`).
//! Fields are explicitly padded to WGSL alignment; `render`'s shader-validation test checks
//! that each size matches its WGSL struct.

use bytemuck::{Pod, Zeroable};

/// Uniform parameters of strand generation.
/// Keep in sync with `shaders/shared/strand_vertex.wgsl` (`StrandGenParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StrandGenParams {
    /// Added to every sampled position (xyz; w unused).
    pub position_offset: [f32; 4],
    /// Vertices this dispatch writes (the batch's runs together).
    pub vertex_total: u32,
    /// The batch's runs: `runs[first_run .. first_run + run_count]`.
    pub run_count: u32,
    /// 0: exact (manual) filtering, 1: hardware filtering.
    pub filtering: u32,
    pub first_run: u32,
    /// Roots per bundle: root `i` is sample `i % per_bundle` of bundle `i / per_bundle`.
    pub per_bundle: u32,
    /// Samples per domain in the samples buffer (quads first, then triangles).
    pub sample_set: u32,
    /// Strands this dispatch writes (the batch's runs together).
    pub strand_total: u32,
    pub _padding: u32,
}

/// One bundle's placement on the root slice: what the shader needs to turn a root sample into
/// texel coordinates (mirror: `runtime::strand_root`).
/// Keep in sync with `shaders/shared/strand_vertex.wgsl` (`BundleGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BundleGpu {
    /// Texel coordinates of block corner 0's centre (origin + 0.5).
    pub origin_texel: [f32; 2],
    pub layers: u32,
    /// Index into the styling array (0 = global, `g + 1` = group `g`).
    pub styling: u32,
    /// Quarter turns of quad samples (`corner_of_block[0]`); triangles are never rotated.
    pub rotation: u32,
    /// 1 for triangles (barycentric samples), 0 for quads.
    pub triangle: u32,
    pub _padding: [u32; 2],
}

impl BundleGpu {
    pub fn new(block: &crate::runtime::atlas::BundleBlock, styling: u32) -> Self {
        let triangle = crate::runtime::atlas::Atlas::is_triangle(block);
        Self {
            origin_texel: [block.origin[0] as f32 + 0.5, block.origin[1] as f32 + 0.5],
            layers: block.layers,
            styling,
            rotation: if triangle {
                0
            } else {
                block.corner_of_block[0] as u32 % 4
            },
            triangle: triangle as u32,
            _padding: [0; 2],
        }
    }
}

/// Consecutive strands of one bundle drawn at one vertex level of detail: the unit the
/// bundle-level work (culling, strand and vertex LOD) hands to the strand-level work.
/// Keep in sync with `shaders/shared/strand_run.wgsl` (`StrandRun`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StrandRun {
    /// Index of the run's first root (bundle × roots per bundle + sample).
    pub first_root: u32,
    pub strand_count: u32,
    /// Vertices per strand of this run (`2^e + 1`).
    pub vertex_count: u32,
    /// Offset of the run's first vertex in the batch's scratch buffer.
    pub vertex_offset: u32,
    /// Offset of the run's first segment among the batch's segments (for drawing).
    pub segment_offset: u32,
    /// Eq. 12 morph factor of odd vertices toward the coarser level.
    pub gamma: f32,
    /// Eq. 8 width factor compensating for dropped strands.
    pub thickness: f32,
    pub _padding: u32,
}

/// One thick hair of far hair's hierarchy (seed 001) as generation reads it: it is drawn
/// along the centre of its four corner strands, which the GPU generates as it generates any
/// strand, so it follows the hair mesh with no refit.
/// Keep in sync with `shaders/strand_gen.wgsl` (`ThickHairGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ThickHairGpu {
    /// Root indices (block × roots per bundle + sample) of the strands nearest the `+major`,
    /// `−major`, `+minor` and `−minor` ends of its cross-section.
    pub corners: [u32; 4],
    /// Strands it stands for.
    pub members: u32,
    /// Its bundle's atlas block.
    pub block: u32,
    /// Its level in the bundle's hierarchy (1: about four strands; the last: the whole bundle).
    pub level: u32,
    pub _padding: u32,
}

/// Uniform parameters of generating thick hairs `thick_hairs[first .. first + count]` at
/// `vertex_count` vertices each, written from `output_offset` on.
/// Keep in sync with `shaders/strand_gen.wgsl` (`ThickGenParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ThickGenParams {
    pub first: u32,
    pub count: u32,
    pub vertex_count: u32,
    pub output_offset: u32,
}

/// One strand's root on the root slice.
/// Keep in sync with `shaders/shared/strand_vertex.wgsl` (`StrandRoot`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StrandRoot {
    /// Texel coordinates of the root: block origin + 0.5 + block coordinates.
    pub texel: [f32; 2],
    /// Texel coordinates of the bundle's centre strand (the axis twist turns about).
    pub centre_texel: [f32; 2],
    /// Layers of the strand's bundle.
    pub layers: u32,
    /// Index into the styling-parameter array: 0 = global, `g + 1` = styling group `g`.
    pub styling: u32,
    /// `(j + ½) / N`: sample `j`'s place among the bundle's `N` (strands per bundle), what
    /// the hairline op thins by (computed in f32 on both sides, so they agree exactly).
    pub rank: f32,
    pub _padding: u32,
}

/// One set of styling parameters in f32 (`crate::model::styling::StylingParams`), flattened.
/// Keep in sync with `shaders/shared/strand_vertex.wgsl` (`Styling`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StylingGpu {
    pub curl_radius_m: f32,
    pub curl_turns_per_m: f32,
    pub curl_ramp_in_m: f32,
    pub curl_radius_jitter: f32,
    pub twist_turns_per_m: f32,
    pub noise_amplitude_m: f32,
    pub noise_frequency_per_m: f32,
    pub noise_octaves: u32,
    pub clump_strength: f32,
    pub clump_clumps_per_uv: f32,
    pub clump_radius_m: f32,
    pub clump_tightening: f32,
    pub frizz_amplitude_m: f32,
    pub frizz_frequency_per_m: f32,
    pub frizz_fraction: f32,
    pub length_fraction: f32,
    pub wave_amplitude_m: f32,
    pub wave_frequency_per_m: f32,
    pub wave_direction_rad: f32,
    pub wave_phase_spread: f32,
    pub wave_ramp_in_m: f32,
    pub variation_per_uv: f32,
    pub seed: u32,
    pub curl_clump_coherence: f32,
    pub curl_radius_tip_scale: f32,
    pub curl_rate_tip_scale: f32,
    pub clump_sub_strength: f32,
    pub clump_sub_clumps_per_uv: f32,
    pub clump_sub_radius_m: f32,
    pub wave_clump_coherence: f32,
    pub stray_fraction: f32,
    pub stray_amplitude_m: f32,
    pub stray_frequency_per_m: f32,
    pub stray_length_min: f32,
    pub hairline_width_m: f32,
    pub hairline_edge_density: f32,
    pub hairline_edge_length: f32,
    pub wave_lock_phase_spread: f32,
    pub _padding: [u32; 2],
}

impl From<&crate::model::styling::StylingParams> for StylingGpu {
    fn from(p: &crate::model::styling::StylingParams) -> Self {
        Self {
            curl_radius_m: p.curl.radius_m as f32,
            curl_turns_per_m: p.curl.turns_per_m as f32,
            curl_ramp_in_m: p.curl.ramp_in_m as f32,
            curl_radius_jitter: p.curl.radius_jitter as f32,
            twist_turns_per_m: p.twist.turns_per_m as f32,
            noise_amplitude_m: p.noise.amplitude_m as f32,
            noise_frequency_per_m: p.noise.frequency_per_m as f32,
            noise_octaves: p.noise.octaves.clamp(1, 8),
            clump_strength: p.clump.strength as f32,
            clump_clumps_per_uv: p.clump.clumps_per_uv as f32,
            clump_radius_m: p.clump.radius_m as f32,
            clump_tightening: p.clump.tightening.max(0.0) as f32,
            frizz_amplitude_m: p.frizz.amplitude_m as f32,
            frizz_frequency_per_m: p.frizz.frequency_per_m as f32,
            frizz_fraction: p.frizz.fraction as f32,
            length_fraction: p.length.fraction.clamp(0.0, 1.0) as f32,
            wave_amplitude_m: p.wave.amplitude_m as f32,
            wave_frequency_per_m: p.wave.frequency_per_m as f32,
            wave_direction_rad: p.wave.direction_rad as f32,
            wave_phase_spread: p.wave.phase_spread as f32,
            wave_ramp_in_m: p.wave.ramp_in_m as f32,
            variation_per_uv: p.variation_per_uv as f32,
            seed: p.seed,
            curl_clump_coherence: p.curl.clump_coherence as f32,
            curl_radius_tip_scale: p.curl.radius_tip_scale as f32,
            curl_rate_tip_scale: p.curl.rate_tip_scale as f32,
            clump_sub_strength: p.clump.sub_strength as f32,
            clump_sub_clumps_per_uv: p.clump.sub_clumps_per_uv as f32,
            clump_sub_radius_m: p.clump.sub_radius_m as f32,
            wave_clump_coherence: p.wave.clump_coherence as f32,
            stray_fraction: p.stray.fraction as f32,
            stray_amplitude_m: p.stray.amplitude_m as f32,
            stray_frequency_per_m: p.stray.frequency_per_m as f32,
            stray_length_min: p.stray.length_min.clamp(0.0, 1.0) as f32,
            hairline_width_m: p.hairline.width_m.max(0.0) as f32,
            hairline_edge_density: p.hairline.edge_density.clamp(0.0, 1.0) as f32,
            hairline_edge_length: p.hairline.edge_length.clamp(0.0, 1.0) as f32,
            wave_lock_phase_spread: p.wave.lock_phase_spread.clamp(0.0, 1.0) as f32,
            _padding: [0; 2],
        }
    }
}

/// The styling array the shader indexes with [`StrandRoot::styling`]: the global
/// parameters, then every group in order.
pub fn styling_array(set: &crate::model::styling::StylingSet) -> Vec<StylingGpu> {
    std::iter::once(&set.global)
        .chain(set.groups.iter().map(|g| &g.params))
        .map(StylingGpu::from)
        .collect()
}

/// Filtering mode values of [`StrandGenParams::filtering`].
pub const FILTERING_EXACT: u32 = 0;
pub const FILTERING_HARDWARE: u32 = 1;

/// One bundle as the mesh path's task shader sees it: its bounding sphere (culling, distance)
/// and the sizes and density eq. 7-12 take (mirror: `runtime::frame_plan::BundleBounds`).
/// Keep in sync with `shaders/shared/strand_lod.wgsl` (`BundleLodGpu`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BundleLodGpu {
    pub centre: [f32; 3],
    pub radius_m: f32,
    pub root_size_m: f32,
    pub strand_length_m: f32,
    pub density: f32,
    /// The strands the bundle grows, `⌈density · N⌉` (`lod::density_count`, in f64 here so
    /// the GPU's count is the CPU's exactly).
    pub grown_strands: u32,
}

impl BundleLodGpu {
    pub fn new(bounds: &crate::runtime::frame_plan::BundleBounds, per_bundle: u32) -> Self {
        Self {
            centre: bounds.centre.to_array(),
            radius_m: bounds.radius_m,
            root_size_m: bounds.root_size_m,
            strand_length_m: bounds.strand_length_m,
            density: bounds.density,
            grown_strands: crate::strands::lod::density_count(bounds.density as f64, per_bundle),
        }
    }
}

/// The frame's LOD camera and settings for the mesh path's task shader (eq. 7-12 on the
/// GPU; mirror: `runtime::frame_plan::bundle_lod`).
/// Keep in sync with `shaders/shared/strand_lod.wgsl` (`LodParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LodParams {
    /// The camera's position (w unused).
    pub eye: [f32; 4],
    /// x: vertical resolution in pixels; y: tan of the vertical field of view; z: α of
    /// strand LOD; w: α of vertex LOD.
    pub detail: [f32; 4],
    /// x: λ (morph window); y: 1 when LOD is on; z: 1 when bundles outside the view are
    /// culled; w: the share of strands kept (`LodSettings::strand_keep`).
    pub switches: [f32; 4],
    /// x: strands per bundle; y: log2 of the full-detail segments; z: bundles; w: task
    /// workgroups per row of the draw (bundle = y × w + x).
    pub counts: [u32; 4],
}

impl LodParams {
    pub fn new(
        camera: &crate::runtime::frame_plan::LodCamera,
        settings: &crate::runtime::frame_plan::LodSettings,
        per_bundle: u32,
        max_vertices_log2: u32,
        bundles: u32,
        row: u32,
    ) -> Self {
        Self {
            eye: camera.eye.extend(1.0).to_array(),
            detail: [
                camera.resolution_px,
                // tan θ in f64, as eq. 7 on the CPU takes it.
                (camera.fov_y_rad as f64).tan() as f32,
                settings.alpha_strands as f32,
                settings.alpha_vertices as f32,
            ],
            switches: [
                settings.lambda as f32,
                settings.enabled as u32 as f32,
                settings.cull as u32 as f32,
                // NaN keeps every strand, as the CPU plan does.
                if settings.strand_keep.is_nan() {
                    1.0
                } else {
                    settings.strand_keep.clamp(0.0, 1.0) as f32
                },
            ],
            counts: [per_bundle, max_vertices_log2, bundles, row.max(1)],
        }
    }
}
