//! Where strands are generated: compute per strand, in the ribbon vertex shader, or in task
//! and mesh shaders.

use super::*;
use crate::renderer::shader_composer::RibbonInput;

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
