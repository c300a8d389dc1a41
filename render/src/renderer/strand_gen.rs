//! GPU strand generation (`shaders/strand_gen.wgsl`): every styled strand vertex computed from
//! the five runtime textures, never stored between frames. Strands are generated in batches
//! of [`BATCH_STRANDS`] into one bounded scratch buffer, which the preview draws from right
//! away; tests and benchmarks read it back or time it.
//!
//! CPU mirror: `hairloom_core::runtime::strand_gen` (`StrandGen::main` for one batch).

use hairloom_core::io::ktx2::TexelFormat;
use hairloom_core::runtime::frame_plan::{BundleBounds, FramePlan};
use hairloom_core::runtime::gpu_types::{
    BundleGpu, BundleLodGpu, FILTERING_EXACT, FILTERING_HARDWARE, StrandGenParams, StrandRun,
    StylingGpu, styling_array,
};
use hairloom_core::runtime::hair::RuntimeHair;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::{Precision, RuntimeTextures, Texture3d};
use wgpu::util::DeviceExt;

use crate::device::{GpuContext, read_buffer};
use crate::renderer::scene_lighting::RibbonInput;
use crate::resources::Tracked;

/// The WGSL source: `shaders/shared/strand_run.wgsl`, `shaders/shared/strand_vertex.wgsl`,
/// then `shaders/strand_gen.wgsl` (validated by naga in `cargo test`).
pub const SHADER_SOURCE: &str = concat!(
    include_str!("../../../shaders/shared/strand_run.wgsl"),
    include_str!("../../../shaders/shared/strand_vertex.wgsl"),
    include_str!("../../../shaders/strand_gen.wgsl")
);

/// Where the ribbon vertex shader binds strand_gen's resources: their compute bindings plus
/// this (`shaders/shared/ribbon_generated.wgsl`).
pub const GENERATED_BINDING_OFFSET: u32 = 16;

/// strand_gen's bindings other than its output (4) and runs (10).
const SOURCE_BINDINGS: [u32; 10] = [0, 1, 2, 3, 5, 6, 7, 8, 9, 11];

/// The layout entries of strand_gen's resources other than its output and runs (params,
/// bundles, the five textures and their sampler, styling, samples) at their compute bindings
/// plus `offset`: the compute layout's (offset 0) and the generating ribbons'
/// ([`GENERATED_BINDING_OFFSET`]). 32-bit float textures are only filterable with
/// `FLOAT32_FILTERABLE`; without it the layout declares them unfilterable and hardware
/// filtering is refused ([`StrandGenRenderer::check_filtering`]).
pub fn source_layout_entries(
    device: &wgpu::Device,
    offset: u32,
    visibility: wgpu::ShaderStages,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let float32_filterable = device
        .features()
        .contains(wgpu::Features::FLOAT32_FILTERABLE);
    let storage = |size: u64| wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: wgpu::BufferSize::new(size),
    };
    let texture = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float {
            filterable: float32_filterable,
        },
        view_dimension: wgpu::TextureViewDimension::D3,
        multisampled: false,
    };
    SOURCE_BINDINGS
        .iter()
        .map(|&binding| wgpu::BindGroupLayoutEntry {
            binding: binding + offset,
            visibility,
            ty: match binding {
                0 => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(size_of::<StrandGenParams>() as u64),
                },
                1 => storage(size_of::<BundleGpu>() as u64),
                3 => wgpu::BindingType::Sampler(if float32_filterable {
                    wgpu::SamplerBindingType::Filtering
                } else {
                    wgpu::SamplerBindingType::NonFiltering
                }),
                9 => storage(size_of::<StylingGpu>() as u64),
                11 => storage(8),
                _ => texture,
            },
            count: None,
        })
        .collect()
}

/// Why generation failed.
#[derive(Debug, thiserror::Error)]
pub enum StrandGenError {
    #[error(
        "{adapter} cannot filter 32-bit float textures in hardware; use exact filtering or f16 textures"
    )]
    NoFloat32Filtering { adapter: String },
    #[error(
        "{adapter} has no mesh shaders (wgpu's EXPERIMENTAL_MESH_SHADER, Vulkan VK_EXT_mesh_shader); choose another generation path"
    )]
    NoMeshShaders { adapter: String },
    #[error("reading generated positions back failed: {0}")]
    Readback(String),
    /// A resource would exceed what the adapter allows; nothing was created.
    #[error("{what} is {value}, above this adapter's {limit_name} of {limit}{hint}")]
    AdapterLimit {
        what: String,
        value: u64,
        limit_name: &'static str,
        limit: u64,
        hint: String,
    },
}

/// Checks `hair` against the device's `limits` before any resource is made: every texture
/// extent against `max_texture_dimension_3d` (all five are 3D textures), and every storage
/// buffer against `max_storage_buffer_binding_size` and `max_buffer_size`. The error names
/// the texture, the limit and, for depth, the bundle with the most layers. (wgpu panics on
/// a descriptor above the limits, so this must come first.)
pub fn check_adapter_limits(
    limits: &wgpu::Limits,
    hair: &RuntimeHair,
) -> Result<(), StrandGenError> {
    let textures = &hair.textures;
    let tallest = textures
        .atlas
        .blocks
        .iter()
        .max_by_key(|b| b.layers)
        .map(|b| (b.bundle, b.layers));
    let max_3d = u64::from(limits.max_texture_dimension_3d);
    for (name, texture) in [
        ("hair_mesh", &textures.hair_mesh),
        ("uv", &textures.uv),
        ("w", &textures.w),
        ("u", &textures.u),
        ("v", &textures.v),
    ] {
        // Depth first: too many layers is the likelier cause, and its hint is the better one.
        for (axis, value) in [
            ("depth", texture.depth),
            ("width", texture.width),
            ("height", texture.height),
        ] {
            if u64::from(value) > max_3d {
                let hint = match (axis, tallest) {
                    ("depth", Some((bundle, layers))) => format!(
                        " (bundle {bundle} has {layers} layers; fewer layers per bundle fit)"
                    ),
                    _ => format!(
                        " ({} bundles need a {}x{} atlas; split the hair into smaller projects)",
                        textures.atlas.blocks.len(),
                        textures.atlas.width,
                        textures.atlas.height
                    ),
                };
                return Err(StrandGenError::AdapterLimit {
                    what: format!("the {name} texture's {axis}"),
                    value: value.into(),
                    limit_name: "max_texture_dimension_3d",
                    limit: max_3d,
                    hint,
                });
            }
        }
    }
    let blocks = textures.atlas.blocks.len() as u64;
    let per_bundle = u64::from(hair.strands_per_bundle);
    let sample_bytes = 2 * per_bundle.max(1) * 8;
    let bundle_bytes = blocks * std::mem::size_of::<BundleGpu>() as u64;
    for (what, bytes) in [
        ("the bundle placement buffer", bundle_bytes),
        ("the root sample buffer", sample_bytes),
    ] {
        for (limit_name, limit) in [
            (
                "max_storage_buffer_binding_size",
                limits.max_storage_buffer_binding_size,
            ),
            ("max_buffer_size", limits.max_buffer_size),
        ] {
            if bytes > limit {
                return Err(StrandGenError::AdapterLimit {
                    what: format!("{what} ({blocks} bundles, {per_bundle} strands each)"),
                    value: bytes,
                    limit_name,
                    limit,
                    hint: " bytes".into(),
                });
            }
        }
    }
    Ok(())
}

/// Where strands are generated, and how the work is spread (`hairloom bench gpu` measures
/// each side by side).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GenerationPath {
    /// `strand_gen.wgsl` `main` into a bounded scratch buffer the ribbons read: one
    /// invocation per strand computes the strand's set-up (root, root uv, length, the styling
    /// ops' random values) once and walks its vertices, morphing odd ones from the neighbours
    /// it has just computed.
    #[default]
    ComputePerStrand,
    /// `main_per_vertex`: one invocation per vertex, redoing the set-up at every vertex (and
    /// three vertices for a morphed one); adjacent invocations write adjacent vertices, which
    /// a GPU's memory system may prefer.
    ComputePerVertex,
    /// No compute pass and no scratch buffer: the ribbon vertex shader evaluates its own
    /// strand vertex from the textures (`shared/ribbon_generated.wgsl`), in every pass that
    /// draws the hair. Readbacks ([`StrandGenRenderer::generate_positions`],
    /// [`StrandGenRenderer::store`]) still use the per-strand compute entry.
    VertexShader,
    /// No compute pass and no scratch buffer: task shaders cull each run's bundle against the
    /// pass's view and launch mesh shaders that generate strand groups with each strand's
    /// set-up and every vertex computed once (`strand_mesh.wgsl`; seed 000 §4). Only where
    /// the device has [`wgpu::Features::EXPERIMENTAL_MESH_SHADER`]
    /// ([`GenerationPath::available`]).
    MeshShader,
}

impl GenerationPath {
    pub const ALL: [GenerationPath; 4] = [
        GenerationPath::ComputePerStrand,
        GenerationPath::ComputePerVertex,
        GenerationPath::VertexShader,
        GenerationPath::MeshShader,
    ];

    pub fn name(self) -> &'static str {
        match self {
            GenerationPath::ComputePerStrand => "compute per strand",
            GenerationPath::ComputePerVertex => "compute per vertex",
            GenerationPath::VertexShader => "vertex shader",
            GenerationPath::MeshShader => "mesh shader",
        }
    }

    /// Whether `device` can run this path (every path but mesh shaders runs anywhere).
    pub fn available(self, device: &wgpu::Device) -> bool {
        self != GenerationPath::MeshShader || mesh_shaders_available(device)
    }

    /// The fastest path `device` has: mesh shaders where it has them, else compute per strand
    /// (what `--generation auto` picks).
    pub fn preferred(device: &wgpu::Device) -> Self {
        if mesh_shaders_available(device) {
            GenerationPath::MeshShader
        } else {
            GenerationPath::ComputePerStrand
        }
    }

    /// Where the ribbons of this path take their vertices from: a buffer the compute pass
    /// fills, or their own generation (vertex shader, mesh shader: no compute pass, no
    /// scratch buffer).
    pub fn ribbon_input(self) -> RibbonInput {
        match self {
            GenerationPath::ComputePerStrand | GenerationPath::ComputePerVertex => {
                RibbonInput::Buffer
            }
            GenerationPath::VertexShader => RibbonInput::Generated,
            GenerationPath::MeshShader => RibbonInput::Mesh,
        }
    }
}

/// Strand vertices (invocations) of one mesh workgroup in `strand_mesh.wgsl` (these three
/// sizes are written into the shader from here). 96: 192 ribbon vertices of 8 attribute slots
/// is 24 KiB of outputs, and the group's workgroup memory stays under NVIDIA's 28 KiB.
pub const MESH_STRAND_VERTICES: u32 = 96;
/// Segments per chunk of a strand longer than a mesh workgroup (even: chunks start on even
/// vertices).
pub const MESH_CHUNK_SEGMENTS: u32 = 94;
/// Most whole strands in one mesh workgroup.
pub const MESH_MAX_STRANDS: u32 = 16;

/// Mesh workgroups a task shader launches for `strands` strands of `vertex_count` vertices
/// (mirror of `strand_mesh.wgsl` `mesh_work` and `ts_main`).
pub fn mesh_groups(strands: u32, vertex_count: u32) -> u64 {
    let n = vertex_count.max(2);
    let (per_group, chunks) = if n <= MESH_STRAND_VERTICES {
        ((MESH_STRAND_VERTICES / n).min(MESH_MAX_STRANDS), 1)
    } else {
        (1, (n - 1).div_ceil(MESH_CHUNK_SEGMENTS))
    };
    u64::from(strands.div_ceil(per_group)) * u64::from(chunks)
}

/// Refuses mesh-shader generation of `bundles` bundles of `per_bundle` strands at up to
/// `vertex_count` vertices when the task shaders would exceed the device's limits: one task
/// workgroup per bundle (`max_task_workgroup_total_count`), and one bundle's mesh workgroups
/// in one dimension (`max_mesh_workgroup_total_count`, `max_mesh_workgroups_per_dimension`,
/// which wgpu leaves to the driver).
pub fn check_mesh_groups(
    limits: &wgpu::Limits,
    bundles: usize,
    per_bundle: u32,
    vertex_count: u32,
) -> Result<(), StrandGenError> {
    let task_limit = u64::from(limits.max_task_workgroup_total_count);
    if bundles as u64 > task_limit {
        return Err(StrandGenError::AdapterLimit {
            what: "the task workgroups (one per bundle)".into(),
            value: bundles as u64,
            limit_name: "max_task_workgroup_total_count",
            limit: task_limit,
            hint: "; split the hair into smaller projects, or use another generation path".into(),
        });
    }
    let groups = mesh_groups(per_bundle, vertex_count);
    let (limit_name, limit) =
        if limits.max_mesh_workgroups_per_dimension < limits.max_mesh_workgroup_total_count {
            (
                "max_mesh_workgroups_per_dimension",
                limits.max_mesh_workgroups_per_dimension,
            )
        } else {
            (
                "max_mesh_workgroup_total_count",
                limits.max_mesh_workgroup_total_count,
            )
        };
    let limit = u64::from(limit);
    if groups > limit {
        return Err(StrandGenError::AdapterLimit {
            what: format!(
                "one bundle's mesh workgroups ({per_bundle} strands of {vertex_count} vertices)"
            ),
            value: groups,
            limit_name,
            limit,
            hint: "; use fewer strands per bundle or vertices, or another generation path".into(),
        });
    }
    Ok(())
}

/// Whether `device` was created with mesh shaders (wgpu's `EXPERIMENTAL_MESH_SHADER`, which
/// [`crate::device::GpuContext::new_headless`] requests where the adapter has it) and limits
/// that hold `strand_mesh.wgsl`'s groups: 96 invocations, 192 ribbon vertices and 192
/// triangles per mesh workgroup, and its task payload (what NVIDIA, AMD and DirectX 12
/// allow).
pub fn mesh_shaders_available(device: &wgpu::Device) -> bool {
    let limits = device.limits();
    device
        .features()
        .contains(wgpu::Features::EXPERIMENTAL_MESH_SHADER)
        && limits.max_mesh_invocations_per_workgroup >= 96
        && limits.max_mesh_invocations_per_dimension >= 96
        && limits.max_mesh_output_vertices >= 192
        && limits.max_mesh_output_primitives >= 192
        && limits.max_task_payload_size >= size_of::<StrandRun>() as u32
}

/// Pipeline and bind-group layout of `strand_gen` (one per device).
pub struct StrandGenRenderer {
    path: GenerationPath,
    pipeline: Tracked<wgpu::ComputePipeline>,
    bind_group_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    float32_filterable: bool,
}

/// Workgroup size of `main` in `strand_gen.wgsl`.
const WORKGROUP_SIZE: u32 = 64;

/// Strands generated per dispatch. The transient output buffer holds one batch, so scratch
/// memory is `BATCH_STRANDS × vertices × 16` bytes whatever the strand count (34 MB at 65
/// vertices, under the 64 MB bound).
pub const BATCH_STRANDS: usize = 32_768;

/// Vertices of one batch: [`BATCH_STRANDS`] strands at full detail.
pub fn batch_vertex_limit(max_vertex_count: u32) -> usize {
    BATCH_STRANDS * max_vertex_count as usize
}

/// Bytes of the scratch buffer `plan` needs: its largest batch (at most
/// [`batch_vertex_limit`] vertices), 16 bytes per vertex.
pub fn scratch_bytes(plan: &FramePlan) -> u64 {
    let vertices = plan
        .batches
        .iter()
        .map(|b| FramePlan::batch_vertices(b))
        .max()
        .unwrap_or(0);
    (vertices.max(1) * 16) as u64
}

/// Every root at `vertex_count` vertices, no LOD, split into batches of [`BATCH_STRANDS`]
/// strands: what generation without a camera does.
pub fn full_detail_plan(root_count: usize, vertex_count: u32) -> FramePlan {
    let mut plan = FramePlan::default();
    for start in (0..root_count).step_by(BATCH_STRANDS) {
        let strands = BATCH_STRANDS.min(root_count - start);
        let mut runs = hairloom_core::runtime::strand_gen::full_detail_runs(strands, vertex_count);
        for run in &mut runs {
            run.first_root += start as u32;
        }
        plan.batches.push(runs);
        plan.strands += strands;
        plan.vertices += strands * vertex_count as usize;
    }
    plan
}

impl GpuHair {
    /// Each bundle's bounds and LOD sizes (block order): what the mesh path's task shaders
    /// cull and plan with.
    pub fn bundle_lods(&self) -> &wgpu::Buffer {
        &self.bundle_lods
    }
}

/// Measured cost of generating a set of strands.
#[derive(Clone, Copy, Debug)]
pub struct GenerationTiming {
    /// Sum of the compute passes' GPU time (timestamp queries); `None` without
    /// `TIMESTAMP_QUERY`.
    pub gpu_ms: Option<f64>,
    /// Wall time from the first submit to the GPU going idle.
    pub wall_ms: f64,
    /// Bytes of the transient output buffer.
    pub scratch_bytes: u64,
    pub batches: usize,
}

/// Everything generation reads, uploaded once (the game's per-asset data): the five
/// textures, one placement per bundle, the root sample sets and the styling array. Nothing
/// is stored per strand.
pub struct GpuHair {
    pub position_offset: [f32; 3],
    /// The five textures (hair_mesh, uv, w, u, v): kept so the registry lists them while
    /// the hair lives, and rewritten in place by [`StrandGenRenderer::update_shape`].
    textures: Vec<Tracked<wgpu::Texture>>,
    hair_mesh: wgpu::TextureView,
    uv: wgpu::TextureView,
    w: wgpu::TextureView,
    u: wgpu::TextureView,
    v: wgpu::TextureView,
    bundle_buffer: Tracked<wgpu::Buffer>,
    /// Each bundle's bounds and sizes for LOD, for the mesh path's task shaders.
    bundle_lods: Tracked<wgpu::Buffer>,
    samples: Tracked<wgpu::Buffer>,
    sample_set: u32,
    /// Strands at full detail: bundles × `per_bundle`.
    pub root_count: usize,
    styling: Tracked<wgpu::Buffer>,
    /// Bounds of every bundle (block order) for LOD and culling.
    pub bundles: Vec<BundleBounds>,
    /// Roots per bundle (roots are bundle-major).
    pub per_bundle: u32,
    /// Bytes of the textures, roots and styling on the GPU.
    pub bytes: u64,
    layout: TextureLayout,
}

fn upload_texture(
    context: &GpuContext,
    label: &str,
    texture: &Texture3d,
    precision: Precision,
    channels: usize,
) -> (Tracked<wgpu::Texture>, wgpu::TextureView, u64) {
    let export_format = TexelFormat::for_precision(precision, channels);
    let format = match export_format {
        TexelFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        TexelFormat::Rg32Float => wgpu::TextureFormat::Rg32Float,
        TexelFormat::R32Float => wgpu::TextureFormat::R32Float,
        TexelFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        TexelFormat::Rg16Float => wgpu::TextureFormat::Rg16Float,
        TexelFormat::R16Float => wgpu::TextureFormat::R16Float,
    };
    let bytes = hairloom_core::io::ktx2::texel_bytes(&texture.texels, export_format);
    let size = wgpu::Extent3d {
        width: texture.width,
        height: texture.height,
        depth_or_array_layers: texture.depth,
    };
    let gpu_texture = context.resources.texture(
        &context.device,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
    );
    write_texels(
        context,
        &gpu_texture,
        texture,
        &bytes,
        channels,
        export_format,
    );
    let view = gpu_texture.create_view(&wgpu::TextureViewDescriptor::default());
    (gpu_texture, view, bytes.len() as u64)
}

/// Writes `bytes` (the texels of `texture` in `format`) into all of `gpu_texture`.
fn write_texels(
    context: &GpuContext,
    gpu_texture: &wgpu::Texture,
    texture: &Texture3d,
    bytes: &[u8],
    channels: usize,
    format: TexelFormat,
) {
    let texel_size = (channels * format.bytes_per_channel()) as u32;
    context.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: gpu_texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(texture.width * texel_size),
            rows_per_image: Some(texture.height),
        },
        wgpu::Extent3d {
            width: texture.width,
            height: texture.height,
            depth_or_array_layers: texture.depth,
        },
    );
}

/// What the GPU textures and placements of a [`GpuHair`] were laid out for: a reshaped hair
/// mesh with the same layout can be written into them in place.
#[derive(Clone, Debug, PartialEq)]
struct TextureLayout {
    precision: Precision,
    /// `[width, height, depth]` of hair_mesh, uv, w, u, v.
    sizes: [[u32; 3]; 5],
    blocks: Vec<hairloom_core::runtime::atlas::BundleBlock>,
    per_bundle: u32,
}

impl TextureLayout {
    fn of(hair: &RuntimeHair, per_bundle: u32) -> Self {
        let t = &hair.textures;
        Self {
            precision: t.precision,
            sizes: [&t.hair_mesh, &t.uv, &t.w, &t.u, &t.v].map(|x| [x.width, x.height, x.depth]),
            blocks: t.atlas.blocks.clone(),
            per_bundle,
        }
    }
}

/// One placement per atlas block with its styling index (never empty: a storage buffer
/// cannot be).
fn bundle_placements(textures: &RuntimeTextures, block_styling: &[u32]) -> Vec<BundleGpu> {
    let mut bundles: Vec<BundleGpu> = textures
        .atlas
        .blocks
        .iter()
        .enumerate()
        .map(|(i, block)| BundleGpu::new(block, block_styling.get(i).copied().unwrap_or(0)))
        .collect();
    if bundles.is_empty() {
        bundles.push(BundleGpu::default());
    }
    bundles
}

/// Each bundle's bounds and sizes for the mesh path's LOD (never empty: a storage buffer
/// cannot be).
fn bundle_lods(bounds: &[BundleBounds], per_bundle: u32) -> Vec<BundleLodGpu> {
    let mut bundles: Vec<BundleLodGpu> = bounds
        .iter()
        .map(|b| BundleLodGpu::new(b, per_bundle))
        .collect();
    if bundles.is_empty() {
        bundles.push(BundleLodGpu::default());
    }
    bundles
}

/// The styling array, or the default parameters when it is empty.
fn styling_or_default(styling: Vec<StylingGpu>) -> Vec<StylingGpu> {
    if styling.is_empty() {
        vec![StylingGpu::from(
            &hairloom_core::model::styling::StylingParams::default(),
        )]
    } else {
        styling
    }
}

impl StrandGenRenderer {
    /// Generation by compute, one invocation per strand ([`GenerationPath::ComputePerStrand`]).
    pub fn new(context: &GpuContext) -> Self {
        Self::with_path(context, GenerationPath::default())
    }

    /// Generation where and as `path` says.
    pub fn with_path(context: &GpuContext, path: GenerationPath) -> Self {
        let device = &context.device;
        let float32_filterable = device
            .features()
            .contains(wgpu::Features::FLOAT32_FILTERABLE);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("strand_gen"),
            source: wgpu::ShaderSource::Wgsl(SHADER_SOURCE.into()),
        });
        let storage = |binding: u32, size: u64| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size),
            },
            count: None,
        };
        let mut entries = source_layout_entries(device, 0, wgpu::ShaderStages::COMPUTE);
        entries.push(storage(4, 16));
        entries.push(wgpu::BindGroupLayoutEntry {
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size_of::<StrandRun>() as u64),
            },
            ..storage(10, 0)
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("strand_gen"),
            entries: &entries,
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("strand_gen"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let pipeline = context.resources.compute_pipeline(
            device,
            &wgpu::ComputePipelineDescriptor {
                label: Some("strand_gen"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(match path {
                    GenerationPath::ComputePerVertex => "main_per_vertex",
                    _ => "main",
                }),
                compilation_options: Default::default(),
                cache: None,
            },
        );
        let filter = if float32_filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("strand_gen_linear_clamp"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        Self {
            path,
            pipeline,
            bind_group_layout,
            sampler,
            float32_filterable,
        }
    }

    /// Uploads a runtime asset: the five textures (f32 or f16 as built), every bundle's block
    /// placement with its styling index, the first `strands_per_bundle` root samples of each
    /// domain and the styling array. Root `i` is then sample `i % strands_per_bundle` of
    /// block `i / strands_per_bundle`, as [`RuntimeHair::strand_roots`] lays roots out on the
    /// CPU.
    ///
    /// Refused, with nothing created, when a resource would exceed the adapter's limits
    /// ([`check_adapter_limits`]).
    pub fn upload(
        &self,
        context: &GpuContext,
        hair: &RuntimeHair,
    ) -> Result<GpuHair, StrandGenError> {
        check_adapter_limits(&context.device.limits(), hair)?;
        let (textures, samples) = (&hair.textures, &hair.samples);
        let per_bundle = hair.strands_per_bundle as usize;
        let block_styling = &hair.block_styling;
        let precision = textures.precision;
        let (t0, hair_mesh, a) =
            upload_texture(context, "hair_mesh", &textures.hair_mesh, precision, 4);
        let (t1, uv, b) = upload_texture(context, "uv", &textures.uv, precision, 2);
        let (t2, w, c) = upload_texture(context, "w", &textures.w, precision, 1);
        let (t3, u, d) = upload_texture(context, "u", &textures.u, precision, 4);
        let (t4, v, e) = upload_texture(context, "v", &textures.v, precision, 4);
        let buffer = |label: &str, contents: &[u8]| {
            context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    // COPY_DST: styling edits rewrite the bundle and styling buffers in place.
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                },
            )
        };
        let per_bundle = per_bundle
            .min(samples.quad.len())
            .min(samples.triangle.len());
        let bundles = bundle_placements(textures, block_styling);
        let block_count = textures.atlas.blocks.len();
        let sample_set = per_bundle.max(1);
        let mut sample_data: Vec<[f32; 2]> = Vec::with_capacity(2 * sample_set);
        for set in [&samples.quad, &samples.triangle] {
            sample_data.extend(set.iter().take(sample_set));
            sample_data.resize(
                sample_data.len().div_ceil(sample_set) * sample_set,
                [0.0; 2],
            );
        }
        let styling = styling_or_default(styling_array(&hair.styling));
        let styling_bytes: &[u8] = bytemuck::cast_slice(&styling);
        let bundle_bytes: &[u8] = bytemuck::cast_slice(&bundles);
        let sample_bytes: &[u8] = bytemuck::cast_slice(&sample_data);
        let bounds = hair.bundle_bounds();
        let lods = bundle_lods(&bounds, per_bundle as u32);
        let lod_bytes: &[u8] = bytemuck::cast_slice(&lods);
        Ok(GpuHair {
            position_offset: textures.position_offset.to_array(),
            textures: vec![t0, t1, t2, t3, t4],
            hair_mesh,
            uv,
            w,
            u,
            v,
            bundle_buffer: buffer("strand_gen_bundles", bundle_bytes),
            bundle_lods: buffer("strand_mesh_bundle_lods", lod_bytes),
            samples: buffer("strand_gen_samples", sample_bytes),
            sample_set: sample_set as u32,
            root_count: block_count * per_bundle,
            styling: buffer("strand_gen_styling", styling_bytes),
            bundles: bounds,
            per_bundle: per_bundle as u32,
            layout: TextureLayout::of(hair, per_bundle as u32),
            bytes: a
                + b
                + c
                + d
                + e
                + (bundle_bytes.len() + lod_bytes.len() + sample_bytes.len() + styling_bytes.len())
                    as u64,
        })
    }

    /// Takes a reshaped `hair` (the hair mesh moved — motion, drape, a vertex drag — with the
    /// same atlas, texture sizes, precision and strands per bundle) into `gpu` by rewriting its five
    /// textures, placements and bounds in place: no allocation, no sample upload. Returns
    /// `false`, writing nothing, when the layout differs (then upload afresh).
    pub fn update_shape(
        &self,
        context: &GpuContext,
        gpu: &mut GpuHair,
        hair: &RuntimeHair,
    ) -> bool {
        let per_bundle = (hair.strands_per_bundle as usize)
            .min(hair.samples.quad.len())
            .min(hair.samples.triangle.len()) as u32;
        if TextureLayout::of(hair, per_bundle) != gpu.layout {
            return false;
        }
        let textures = &hair.textures;
        let precision = textures.precision;
        for (gpu_texture, (texture, channels)) in gpu.textures.iter().zip([
            (&textures.hair_mesh, 4),
            (&textures.uv, 2),
            (&textures.w, 1),
            (&textures.u, 4),
            (&textures.v, 4),
        ]) {
            let format = TexelFormat::for_precision(precision, channels);
            let bytes = hairloom_core::io::ktx2::texel_bytes(&texture.texels, format);
            write_texels(context, gpu_texture, texture, &bytes, channels, format);
        }
        gpu.position_offset = textures.position_offset.to_array();
        gpu.bundles = hair.bundle_bounds();
        context.queue.write_buffer(
            &gpu.bundle_lods,
            0,
            bytemuck::cast_slice(&bundle_lods(&gpu.bundles, gpu.per_bundle)),
        );
        self.update_styling(context, gpu, hair);
        true
    }

    /// Takes `hair`'s styling (parameters and group assignments) into `gpu` without touching
    /// its textures or samples: the bundle and styling buffers are rewritten in place (the
    /// styling buffer is replaced only when groups were added). What a styling-only edit
    /// costs; `hair` must be the asset `gpu` was uploaded from, restyled.
    pub fn update_styling(&self, context: &GpuContext, gpu: &mut GpuHair, hair: &RuntimeHair) {
        let bundles = bundle_placements(&hair.textures, &hair.block_styling);
        context
            .queue
            .write_buffer(&gpu.bundle_buffer, 0, bytemuck::cast_slice(&bundles));
        let styling = styling_or_default(styling_array(&hair.styling));
        let bytes: &[u8] = bytemuck::cast_slice(&styling);
        if bytes.len() as u64 <= gpu.styling.size() {
            context.queue.write_buffer(&gpu.styling, 0, bytes);
        } else {
            gpu.bytes += bytes.len() as u64 - gpu.styling.size();
            gpu.styling = context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("strand_gen_styling"),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                },
            );
        }
    }

    /// Refuses hardware filtering of f32 textures on adapters that cannot filter them.
    pub fn check_filtering(
        &self,
        context: &GpuContext,
        filtering: Filtering,
    ) -> Result<(), StrandGenError> {
        if filtering == Filtering::Hardware8Bit && !self.float32_filterable {
            return Err(StrandGenError::NoFloat32Filtering {
                adapter: context.adapter_info.name.clone(),
            });
        }
        Ok(())
    }

    /// Uploads the runs of every batch of `plan`, one after another.
    pub fn upload_runs(&self, context: &GpuContext, plan: &FramePlan) -> wgpu::Buffer {
        let mut runs: Vec<StrandRun> = plan.batches.iter().flatten().copied().collect();
        if runs.is_empty() {
            runs.push(StrandRun::default());
        }
        context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("strand_gen_runs"),
                contents: bytemuck::cast_slice(&runs),
                usage: wgpu::BufferUsages::STORAGE,
            })
    }

    /// Records the generation of one batch (`runs[first_run..][..batch.len()]` of the uploaded
    /// `runs` buffer, equal to `batch`) into `output` as one compute pass of `encoder`.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn encode(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hair: &GpuHair,
        runs: &wgpu::Buffer,
        first_run: usize,
        batch: &[StrandRun],
        filtering: Filtering,
        output: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let vertex_total = FramePlan::batch_vertices(batch) as u32;
        let strand_total: u32 = batch.iter().map(|run| run.strand_count).sum();
        let params = self.params_buffer(context, hair, filtering, first_run as u32, batch);
        let mut entries = self.source_entries(0, hair, &params);
        entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: output.as_entire_binding(),
        });
        entries.push(wgpu::BindGroupEntry {
            binding: 10,
            resource: runs.as_entire_binding(),
        });
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("strand_gen"),
                layout: &self.bind_group_layout,
                entries: &entries,
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strand_gen"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let invocations = match self.path {
            GenerationPath::ComputePerVertex => vertex_total,
            _ => strand_total,
        };
        pass.dispatch_workgroups(invocations.div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// Refuses a path the device cannot run (mesh shaders without
    /// `EXPERIMENTAL_MESH_SHADER`), naming the adapter.
    pub fn check_path(context: &GpuContext, path: GenerationPath) -> Result<(), StrandGenError> {
        if path.available(&context.device) {
            Ok(())
        } else {
            Err(StrandGenError::NoMeshShaders {
                adapter: crate::device::describe(&context.adapter_info),
            })
        }
    }

    /// Where strands are generated.
    pub fn path(&self) -> GenerationPath {
        self.path
    }

    /// The uniform parameters of generating `batch` (`runs[first_run..]` of the uploaded runs).
    pub fn params_buffer(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        filtering: Filtering,
        first_run: u32,
        batch: &[StrandRun],
    ) -> wgpu::Buffer {
        let params = StrandGenParams {
            position_offset: [
                hair.position_offset[0],
                hair.position_offset[1],
                hair.position_offset[2],
                0.0,
            ],
            vertex_total: FramePlan::batch_vertices(batch) as u32,
            run_count: batch.len() as u32,
            filtering: match filtering {
                Filtering::Exact => FILTERING_EXACT,
                Filtering::Hardware8Bit => FILTERING_HARDWARE,
            },
            first_run,
            per_bundle: hair.per_bundle.max(1),
            sample_set: hair.sample_set,
            strand_total: batch.iter().map(|run| run.strand_count).sum(),
            _padding: 0,
        };
        context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("strand_gen_params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            })
    }

    /// The bind-group entries of `hair` for [`source_layout_entries`] at `offset`.
    pub fn source_entries<'a>(
        &'a self,
        offset: u32,
        hair: &'a GpuHair,
        params: &'a wgpu::Buffer,
    ) -> Vec<wgpu::BindGroupEntry<'a>> {
        let view = |binding: u32, view: &'a wgpu::TextureView| wgpu::BindGroupEntry {
            binding: binding + offset,
            resource: wgpu::BindingResource::TextureView(view),
        };
        let buffer = |binding: u32, buffer: &'a wgpu::Buffer| wgpu::BindGroupEntry {
            binding: binding + offset,
            resource: buffer.as_entire_binding(),
        };
        vec![
            buffer(0, params),
            buffer(1, &hair.bundle_buffer),
            view(2, &hair.hair_mesh),
            wgpu::BindGroupEntry {
                binding: 3 + offset,
                resource: wgpu::BindingResource::Sampler(&self.sampler),
            },
            view(5, &hair.uv),
            view(6, &hair.w),
            view(7, &hair.u),
            view(8, &hair.v),
            buffer(9, &hair.styling),
            buffer(11, &hair.samples),
        ]
    }

    /// A scratch buffer for the largest batch of `plan`.
    pub fn scratch(&self, context: &GpuContext, plan: &FramePlan) -> Tracked<wgpu::Buffer> {
        context.resources.buffer(
            &context.device,
            &wgpu::BufferDescriptor {
                label: Some("strand_gen_scratch"),
                size: scratch_bytes(plan),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            },
        )
    }

    /// Generates every batch of `plan` into one reused scratch buffer and measures the GPU
    /// time (nothing is read back: this is the cost of generation).
    pub fn time_generation(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<GenerationTiming, StrandGenError> {
        self.check_filtering(context, filtering)?;
        let device = &context.device;
        let output = self.scratch(context, plan);
        let runs = self.upload_runs(context, plan);
        let timer = crate::device::PassTimer::new(context, plan.batches.len());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("strand_gen_timing"),
        });
        let mut first_run = 0;
        for batch in &plan.batches {
            let timestamp_writes = timer.as_ref().and_then(|t| t.compute_pass());
            self.encode(
                context,
                &mut encoder,
                hair,
                &runs,
                first_run,
                batch,
                filtering,
                &output,
                timestamp_writes,
            );
            first_run += batch.len();
        }
        let (wall_ms, gpu_ms) = crate::device::submit_timed(context, encoder, timer)
            .map_err(StrandGenError::Readback)?;
        Ok(GenerationTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes: output.size(),
            batches: plan.batches.len(),
        })
    }

    /// Generates `plan` batch after batch, one submission each: `finish` receives the
    /// batch's encoder (generation recorded), the scratch buffer and the batch's bytes, adds
    /// what it needs (copies) and submits.
    fn each_batch(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
        mut finish: impl FnMut(wgpu::CommandEncoder, &wgpu::Buffer, u64) -> Result<(), StrandGenError>,
    ) -> Result<(), StrandGenError> {
        self.check_filtering(context, filtering)?;
        let output = self.scratch(context, plan);
        let runs = self.upload_runs(context, plan);
        let mut first_run = 0;
        for batch in &plan.batches {
            let bytes = FramePlan::batch_vertices(batch) as u64 * 16;
            let mut encoder =
                context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("strand_gen"),
                    });
            self.encode(
                context,
                &mut encoder,
                hair,
                &runs,
                first_run,
                batch,
                filtering,
                &output,
                None,
            );
            first_run += batch.len();
            if bytes > 0 {
                finish(encoder, &output, bytes)?;
            }
        }
        Ok(())
    }

    /// Generates every batch of `plan` once into a persistent vertex buffer (batch after
    /// batch): the explicit-storage baseline, which a renderer then only draws.
    pub fn store(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<wgpu::Buffer, StrandGenError> {
        let stored = context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stored_strands"),
            size: (plan.vertices.max(1) * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut offset = 0u64;
        self.each_batch(
            context,
            hair,
            plan,
            filtering,
            |mut encoder, output, bytes| {
                encoder.copy_buffer_to_buffer(output, 0, &stored, offset, bytes);
                context.queue.submit([encoder.finish()]);
                offset += bytes;
                Ok(())
            },
        )?;
        context
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| StrandGenError::Readback(e.to_string()))?;
        Ok(stored)
    }

    /// Generates every batch of `plan` and reads the vertices back, batch after batch in
    /// scratch order: (position, fraction along the strand).
    pub fn generate_positions(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<Vec<[f32; 4]>, StrandGenError> {
        let mut positions = Vec::with_capacity(plan.vertices);
        self.each_batch(
            context,
            hair,
            plan,
            filtering,
            |mut encoder, output, bytes| {
                let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("strand_gen_readback"),
                    size: bytes,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(output, 0, &readback, 0, bytes);
                context.queue.submit([encoder.finish()]);
                let data = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
                positions.extend_from_slice(bytemuck::cast_slice(&data));
                Ok(())
            },
        )?;
        Ok(positions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mesh path's work distribution (as `strand_mesh.wgsl` `ms_main` maps groups and
    /// invocations): every segment of every strand is drawn exactly once, chunks start on
    /// even vertices, and no group exceeds its invocations or output arrays.
    #[test]
    fn mesh_groups_draw_every_segment_once() {
        for n in 2..=300u32 {
            for strands in [1u32, 3, 16, 17, 100] {
                let (per_group, chunks) = if n <= MESH_STRAND_VERTICES {
                    ((MESH_STRAND_VERTICES / n).min(MESH_MAX_STRANDS), 1)
                } else {
                    (1, (n - 1).div_ceil(MESH_CHUNK_SEGMENTS))
                };
                let chunk_vertices = if chunks == 1 {
                    n
                } else {
                    MESH_CHUNK_SEGMENTS + 1
                };
                let mut drawn = vec![0u32; (strands * (n - 1)) as usize];
                let groups = mesh_groups(strands, n);
                for group in 0..groups as u32 {
                    let first_strand = (group / chunks) * per_group;
                    let k0 = (group % chunks) * MESH_CHUNK_SEGMENTS;
                    assert!(first_strand < strands && k0 < n - 1, "n {n}, group {group}");
                    assert_eq!(k0 % 2, 0);
                    let in_group = per_group.min(strands - first_strand);
                    let chunk = chunk_vertices.min(n - k0);
                    assert!(in_group * chunk <= MESH_STRAND_VERTICES);
                    assert!(2 * in_group * (chunk - 1) <= 2 * MESH_STRAND_VERTICES);
                    for slot in 0..in_group {
                        for j in 0..chunk - 1 {
                            let strand = first_strand + slot;
                            drawn[(strand * (n - 1) + k0 + j) as usize] += 1;
                        }
                    }
                }
                assert!(
                    drawn.iter().all(|&d| d == 1),
                    "n {n}, {strands} strands: {:?}",
                    drawn.iter().position(|&d| d != 1)
                );
            }
        }
    }

    #[test]
    fn a_bundle_over_the_mesh_group_limit_is_refused_by_name() {
        let limits = wgpu::Limits {
            max_mesh_workgroup_total_count: 1024,
            max_mesh_workgroups_per_dimension: 65535,
            max_task_workgroup_total_count: 1000,
            ..wgpu::Limits::default()
        };
        assert!(check_mesh_groups(&limits, 500, 64, 33).is_ok());
        let error = check_mesh_groups(&limits, 1001, 64, 33).expect_err("too many bundles");
        assert!(error.to_string().contains("max_task_workgroup_total_count"));
        // 4,096 strands of 1,025 vertices: 11 chunks each.
        assert_eq!(mesh_groups(4096, 1025), 4096 * 11);
        let error = check_mesh_groups(&limits, 500, 4096, 1025).expect_err("over the limit");
        let message = error.to_string();
        assert!(
            message.contains("max_mesh_workgroup_total_count") && message.contains("45056"),
            "{message}"
        );
    }
}
