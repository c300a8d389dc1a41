//! wgpu device setup for the editor and headless tools.
//!
//! Adapter choice: a real GPU when there is one (discrete before integrated before virtual),
//! Mesa's lavapipe software rasteriser otherwise. `HAIRLOOM_ADAPTER` overrides it: `cpu`
//! (software only), `gpu` (hardware only) or any other text, matched case-insensitively
//! against adapter names (for example `llvmpipe` or `h100`).

/// Environment variable that overrides the adapter choice.
pub const ADAPTER_ENV: &str = "HAIRLOOM_ADAPTER";

/// Why no device could be created.
#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    #[error(
        "no GPU adapter found; on Debian install mesa-vulkan-drivers and libvulkan1 for the lavapipe software adapter (`make test` does this)"
    )]
    NoAdapter,
    /// Only OpenGL adapters were found: their GLSL back end has no storage buffers in the
    /// vertex stage and cannot load from depth textures, which every frame uses.
    #[error(
        "only OpenGL adapters found ({available}); hairloom needs Vulkan, Metal or DX12: on Debian install mesa-vulkan-drivers and libvulkan1 (`make test` does this)"
    )]
    OnlyOpenGl { available: String },
    #[error("no adapter matches {ADAPTER_ENV}={wanted:?}; available: {available}")]
    NoMatch { wanted: String, available: String },
    #[error("{adapter}: cannot create a device: {source}")]
    RequestDevice {
        adapter: String,
        source: wgpu::RequestDeviceError,
    },
}

/// An adapter, device and queue ready for headless work. Cloning shares the same device
/// (wgpu handles are reference-counted), so a worker thread can measure on it.
#[derive(Clone)]
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub adapter_info: wgpu::AdapterInfo,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Every labelled resource the renderers keep on this device (see [`crate::resources`]).
    pub resources: std::sync::Arc<crate::resources::ResourceRegistry>,
}

impl GpuContext {
    /// Wraps a device someone else created (the editor's window, through eframe).
    pub fn from_parts(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        Self {
            adapter_info: adapter.get_info(),
            adapter,
            device,
            queue,
            resources: Default::default(),
        }
    }

    /// Whether the adapter is a software rasteriser running on the CPU (lavapipe).
    pub fn is_cpu(&self) -> bool {
        self.adapter_info.device_type == wgpu::DeviceType::Cpu
    }
}

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Preference rank of a device type: lower is better.
fn rank(device_type: wgpu::DeviceType) -> u8 {
    match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Picks an adapter index from `infos` according to `wanted` (the value of
/// [`ADAPTER_ENV`], if set). Pure, so the policy is testable without a GPU.
pub fn choose_adapter(
    infos: &[wgpu::AdapterInfo],
    wanted: Option<&str>,
) -> Result<usize, DeviceError> {
    if infos.is_empty() {
        return Err(DeviceError::NoAdapter);
    }
    let names = |infos: &mut dyn Iterator<Item = &wgpu::AdapterInfo>| {
        infos
            .map(|i| format!("{} ({:?})", i.name, i.backend))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if infos.iter().all(|i| i.backend == wgpu::Backend::Gl) {
        return Err(DeviceError::OnlyOpenGl {
            available: names(&mut infos.iter()),
        });
    }
    let filter: Box<dyn Fn(&wgpu::AdapterInfo) -> bool> = match wanted.map(str::trim) {
        None | Some("") => Box::new(|_| true),
        Some(w) if w.eq_ignore_ascii_case("cpu") => {
            Box::new(|i| i.device_type == wgpu::DeviceType::Cpu)
        }
        Some(w) if w.eq_ignore_ascii_case("gpu") => {
            Box::new(|i| i.device_type != wgpu::DeviceType::Cpu)
        }
        Some(w) => {
            let needle = w.to_lowercase();
            Box::new(move |i| i.name.to_lowercase().contains(&needle))
        }
    };
    (0..infos.len())
        // Never GL (see `DeviceError::OnlyOpenGl`): the renderer's shaders do not run there.
        .filter(|&i| infos[i].backend != wgpu::Backend::Gl && filter(&infos[i]))
        .min_by_key(|&i| rank(infos[i].device_type))
        .ok_or_else(|| DeviceError::NoMatch {
            wanted: wanted.unwrap_or_default().to_string(),
            available: names(&mut infos.iter().filter(|i| i.backend != wgpu::Backend::Gl)),
        })
}

/// Every adapter wgpu can see.
pub fn list_adapters() -> Vec<wgpu::AdapterInfo> {
    pollster::block_on(instance().enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(|a| a.get_info())
        .collect()
}

/// One line describing an adapter, for logs and benchmark headers.
pub fn describe(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?}, {:?}, driver {} {})",
        info.name, info.backend, info.device_type, info.driver, info.driver_info
    )
}

/// The adapter features the renderer uses when the adapter has them: timestamps (measured
/// GPU time), f32 texture filtering (the hardware-filtering switch), f16, and the
/// adapter-specific format features (8× MSAA where the adapter has it: see
/// [`crate::view::sample_count`]). Requested by the headless device and the editor's window.
pub const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::TIMESTAMP_QUERY
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::SHADER_F16)
    .union(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);

impl GpuContext {
    /// Creates a device on the adapter chosen by [`choose_adapter`] with
    /// `HAIRLOOM_ADAPTER` from the environment. Requests the adapter's optional features
    /// that later stages use when it has them ([`OPTIONAL_FEATURES`]).
    pub fn new_headless() -> Result<Self, DeviceError> {
        let adapters = pollster::block_on(instance().enumerate_adapters(wgpu::Backends::all()));
        let infos: Vec<wgpu::AdapterInfo> = adapters.iter().map(|a| a.get_info()).collect();
        let wanted = std::env::var(ADAPTER_ENV).ok();
        let index = choose_adapter(&infos, wanted.as_deref())?;
        let adapter = adapters
            .into_iter()
            .nth(index)
            .ok_or(DeviceError::NoAdapter)?;
        let adapter_info = adapter.get_info();
        let mut descriptor = wgpu::DeviceDescriptor {
            label: Some("hairloom"),
            required_features: adapter.features() & OPTIONAL_FEATURES,
            required_limits: adapter.limits(),
            ..Default::default()
        };
        request_mesh_shaders(&adapter, &mut descriptor);
        let (device, queue) =
            pollster::block_on(adapter.request_device(&descriptor)).map_err(|source| {
                DeviceError::RequestDevice {
                    adapter: adapter_info.name.clone(),
                    source,
                }
            })?;
        Ok(Self {
            adapter,
            adapter_info,
            device,
            queue,
            resources: Default::default(),
        })
    }
}

/// Environment variable that keeps mesh shaders off (`0`, `off` or `false`) on an adapter
/// that has them: wgpu marks them experimental, so a driver that misbehaves can be avoided
/// without a rebuild.
pub const MESH_SHADERS_ENV: &str = "HAIRLOOM_MESH_SHADERS";

/// Whether [`MESH_SHADERS_ENV`] (its value, if set) lets the device use mesh shaders.
pub fn mesh_shaders_wanted(value: Option<&str>) -> bool {
    !matches!(
        value.map(|v| v.trim().to_ascii_lowercase()).as_deref(),
        Some("0" | "off" | "false" | "no")
    )
}

/// Adds mesh shaders to `descriptor` where `adapter` has them and [`MESH_SHADERS_ENV`] does
/// not turn them off: the feature, wgpu's opt-in to experimental features, and the adapter's
/// own mesh-shader limits (the generation path `strand_mesh.wgsl` needs them). Used by the
/// headless device and the editor's window.
#[expect(
    unsafe_code,
    reason = "wgpu gates EXPERIMENTAL_MESH_SHADER behind an unsafe opt-in token"
)]
pub fn request_mesh_shaders(adapter: &wgpu::Adapter, descriptor: &mut wgpu::DeviceDescriptor) {
    let wanted = mesh_shaders_wanted(std::env::var(MESH_SHADERS_ENV).ok().as_deref());
    if !wanted
        || !adapter
            .features()
            .contains(wgpu::Features::EXPERIMENTAL_MESH_SHADER)
    {
        return;
    }
    let available = adapter.limits();
    let limits = &mut descriptor.required_limits;
    limits.max_task_workgroup_total_count = available.max_task_workgroup_total_count;
    limits.max_task_workgroups_per_dimension = available.max_task_workgroups_per_dimension;
    limits.max_mesh_workgroup_total_count = available.max_mesh_workgroup_total_count;
    limits.max_mesh_workgroups_per_dimension = available.max_mesh_workgroups_per_dimension;
    limits.max_task_invocations_per_workgroup = available.max_task_invocations_per_workgroup;
    limits.max_task_invocations_per_dimension = available.max_task_invocations_per_dimension;
    limits.max_mesh_invocations_per_workgroup = available.max_mesh_invocations_per_workgroup;
    limits.max_mesh_invocations_per_dimension = available.max_mesh_invocations_per_dimension;
    limits.max_task_payload_size = available.max_task_payload_size;
    limits.max_mesh_output_vertices = available.max_mesh_output_vertices;
    limits.max_mesh_output_primitives = available.max_mesh_output_primitives;
    limits.max_mesh_output_layers = available.max_mesh_output_layers;
    descriptor.required_features |= wgpu::Features::EXPERIMENTAL_MESH_SHADER;
    // SAFETY: the opt-in only allows requesting `EXPERIMENTAL_*` features; the only one
    // requested is `EXPERIMENTAL_MESH_SHADER`, which the adapter reports, used by
    // `strand_mesh.wgsl`'s pipelines within the limits the device reports.
    descriptor.experimental_features = unsafe { wgpu::ExperimentalFeatures::enabled() };
}

/// Maps a `MAP_READ` buffer after the queue's work, and returns its bytes.
pub fn read_buffer(context: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>, String> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    context
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| e.to_string())?;
    receiver
        .recv()
        .map_err(|e| e.to_string())?
        .map_err(|e| e.to_string())?;
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| format!("{e:?}"))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// GPU timestamps around a known number of passes (one begin/end pair each), resolved after
/// submission. `None` from [`PassTimer::new`] when the adapter has no `TIMESTAMP_QUERY`.
pub struct PassTimer {
    query_set: wgpu::QuerySet,
    capacity: u32,
    next: std::cell::Cell<u32>,
}

impl PassTimer {
    pub fn new(context: &GpuContext, passes: usize) -> Option<Self> {
        if !context
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            return None;
        }
        let capacity = (2 * passes).max(2) as u32;
        Some(Self {
            query_set: context.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass_timer"),
                ty: wgpu::QueryType::Timestamp,
                count: capacity,
            }),
            capacity,
            next: std::cell::Cell::new(0),
        })
    }

    /// Begin and end query indices of the next pass (`None` once full).
    fn claim(&self) -> Option<(u32, u32)> {
        let first = self.next.get();
        (first + 2 <= self.capacity).then(|| {
            self.next.set(first + 2);
            (first, first + 1)
        })
    }

    pub fn compute_pass(&self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.claim()
            .map(|(begin, end)| wgpu::ComputePassTimestampWrites {
                query_set: &self.query_set,
                beginning_of_pass_write_index: Some(begin),
                end_of_pass_write_index: Some(end),
            })
    }

    pub fn render_pass(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.claim()
            .map(|(begin, end)| wgpu::RenderPassTimestampWrites {
                query_set: &self.query_set,
                beginning_of_pass_write_index: Some(begin),
                end_of_pass_write_index: Some(end),
            })
    }
}

/// Submits `encoder`, waits for the GPU, and returns (wall ms, summed GPU ms of the timed
/// passes, if timed).
pub fn submit_timed(
    context: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    timer: Option<PassTimer>,
) -> Result<(f64, Option<f64>), String> {
    let device = &context.device;
    let readback = timer.as_ref().map(|timer| {
        let used = timer.next.get().max(2);
        let size = used as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass_timer_resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass_timer_readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.resolve_query_set(&timer.query_set, 0..used, &resolve, 0);
        encoder.copy_buffer_to_buffer(&resolve, 0, &readback, 0, size);
        (readback, timer.next.get() / 2)
    });
    let start = std::time::Instant::now();
    context.queue.submit([encoder.finish()]);
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| e.to_string())?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let gpu_ms = match readback {
        Some((readback, passes)) => {
            let bytes = read_buffer(context, &readback)?;
            let ticks: &[u64] = bytemuck::cast_slice(&bytes);
            let period_ns = context.queue.get_timestamp_period() as f64;
            let total: u64 = (0..passes as usize)
                .map(|i| ticks[2 * i + 1].saturating_sub(ticks[2 * i]))
                .sum();
            Some(total as f64 * period_ns * 1e-6)
        }
        None => None,
    };
    Ok((wall_ms, gpu_ms))
}

/// Whether a test must fail instead of skipping when no GPU adapter can be found: `make
/// test` sets `HAIRLOOM_REQUIRE_GPU=1` (it installs lavapipe); plain `cargo test` skips.
pub fn gpu_required() -> bool {
    std::env::var("HAIRLOOM_REQUIRE_GPU").as_deref() == Ok("1")
}

/// The one skip rule of every GPU test: prints `skipped: <test>: <why>` and returns `true`
/// (skip) where no GPU is required, panics with `why` where one is.
pub fn skip_test_without_gpu(test: &str, why: &str) -> bool {
    assert!(
        !gpu_required(),
        "{test}: {why} (HAIRLOOM_REQUIRE_GPU=1: make test installs lavapipe)"
    );
    eprintln!("skipped: {test}: {why} (set HAIRLOOM_REQUIRE_GPU=1 to make this a failure)");
    true
}

/// A headless device for a test, or `None` after [`skip_test_without_gpu`] said why not.
pub fn headless_for_test(test: &str) -> Option<GpuContext> {
    match GpuContext::new_headless() {
        Ok(context) => {
            eprintln!("{test}: adapter {}", describe(&context.adapter_info));
            Some(context)
        }
        Err(error) => {
            skip_test_without_gpu(test, &error.to_string());
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(
        name: &str,
        device_type: wgpu::DeviceType,
        backend: wgpu::Backend,
    ) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: name.into(),
            vendor: 0,
            device: 0,
            device_type,
            device_pci_bus_id: String::new(),
            driver: String::new(),
            driver_info: String::new(),
            backend,
            subgroup_min_size: 4,
            subgroup_max_size: 64,
            transient_saves_memory: None,
            limit_bucket: None,
        }
    }

    #[test]
    fn mesh_shaders_are_kept_off_only_when_asked() {
        for off in ["0", "off", "OFF", " false ", "no"] {
            assert!(!mesh_shaders_wanted(Some(off)), "{off:?}");
        }
        for on in [None, Some(""), Some("1"), Some("on"), Some("yes")] {
            assert!(mesh_shaders_wanted(on), "{on:?}");
        }
    }

    #[test]
    fn prefers_hardware_and_honours_the_override() {
        let infos = vec![
            info(
                "llvmpipe (LLVM 19)",
                wgpu::DeviceType::Cpu,
                wgpu::Backend::Vulkan,
            ),
            info(
                "NVIDIA H100",
                wgpu::DeviceType::DiscreteGpu,
                wgpu::Backend::Gl,
            ),
            info(
                "NVIDIA H100",
                wgpu::DeviceType::DiscreteGpu,
                wgpu::Backend::Vulkan,
            ),
        ];
        assert_eq!(choose_adapter(&infos, None).ok(), Some(2));
        assert_eq!(choose_adapter(&infos, Some("cpu")).ok(), Some(0));
        assert_eq!(choose_adapter(&infos, Some("LLVMPIPE")).ok(), Some(0));
        assert!(matches!(
            choose_adapter(&infos, Some("radeon")),
            Err(DeviceError::NoMatch { .. })
        ));
        assert!(matches!(
            choose_adapter(&[], None),
            Err(DeviceError::NoAdapter)
        ));
        // A GL adapter is never chosen, even when asked for by name.
        let gl_only = [info(
            "llvmpipe (LLVM 15)",
            wgpu::DeviceType::Cpu,
            wgpu::Backend::Gl,
        )];
        let error = choose_adapter(&gl_only, None).err().map(|e| e.to_string());
        assert!(
            error
                .as_deref()
                .is_some_and(|e| e.contains("only OpenGL") && e.contains("mesa-vulkan-drivers")),
            "{error:?}"
        );
        assert!(matches!(
            choose_adapter(&infos[..2], Some("h100")),
            Err(DeviceError::NoMatch { .. })
        ));
    }
}
