//! A game's view of Hairloom: a plain winit window and wgpu device of the game's own, a
//! runtime bundle loaded through `hairloom_render::game`, drawn with an orbit camera into the
//! game's render pass each frame.
//!
//! ```sh
//! cargo run --release --example game                  # the bundled shoulder-length sample
//! cargo run --release --example game -- RUNTIME_DIR   # a bundle from `hairloom export --runtime`
//! cargo run --release --example game -- PROJECT.hairloom
//! ```
//! Drag with the left button to orbit, scroll to zoom, Esc to quit. `--frames N` quits after
//! N frames and prints what was drawn (a smoke test).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use glam::{Mat4, Vec3};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_render::game::{GameCamera, GameHair, HairTargets};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Yaw and pitch around the hair's centre, and the distance from it.
struct Orbit {
    yaw_rad: f32,
    pitch_rad: f32,
    distance_m: f32,
    centre: Vec3,
}

impl Orbit {
    fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw_rad.sin_cos();
        let (sp, cp) = self.pitch_rad.sin_cos();
        self.centre + self.distance_m * Vec3::new(cp * sy, sp, cp * cy)
    }

    fn camera(&self, width: u32, height: u32) -> GameCamera {
        let fov_y_rad = 35f32.to_radians();
        let eye = self.eye();
        let projection = Mat4::perspective_rh(
            fov_y_rad,
            width.max(1) as f32 / height.max(1) as f32,
            self.distance_m * 0.02,
            self.distance_m * 20.0,
        );
        GameCamera {
            view_projection: projection * Mat4::look_at_rh(eye, self.centre, Vec3::Y),
            eye,
            fov_y_rad,
            viewport_height_px: height,
        }
    }
}

struct Gpu {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    depth: wgpu::TextureView,
    hair: GameHair,
}

struct Game {
    bundle: RuntimeHair,
    gpu: Option<Gpu>,
    orbit: Option<Orbit>,
    dragging: bool,
    last_cursor: Option<(f64, f64)>,
    frames_left: Option<u64>,
    frames_drawn: u64,
    started: Instant,
    error: Option<String>,
}

fn depth_view(device: &wgpu::Device, width: u32, height: u32) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("game_depth"),
            size: wgpu::Extent3d {
                width: width.max(1),
                height: height.max(1),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl Game {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        let window = Arc::new(
            event_loop
                .create_window(Window::default_attributes().with_title("Hairloom: game runtime"))
                .map_err(|e| format!("opening a window: {e}"))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| format!("creating a surface: {e}"))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| format!("no GPU adapter for the window: {e}"))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("game"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| format!("creating the device: {e}"))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or("the surface does not work with this adapter")?;
        // Hair is shaded in linear light: draw into an sRGB view of the surface.
        let srgb = config.format.add_srgb_suffix();
        if srgb != config.format {
            config.view_formats.push(srgb);
        }
        surface.configure(&device, &config);
        let targets = HairTargets {
            color: srgb,
            depth: DEPTH_FORMAT,
            sample_count: 1,
        };
        let hair = GameHair::new(&adapter, &device, &queue, &self.bundle, targets)
            .map_err(|e| format!("loading the hair: {e}"))?;
        let (lo, hi) = hair.bounds();
        self.orbit.get_or_insert(Orbit {
            yaw_rad: 0.6,
            pitch_rad: 0.2,
            distance_m: (hi - lo).length() * 1.6,
            centre: (lo + hi) * 0.5,
        });
        println!(
            "adapter: {} ({:?}); {} × {} surface, {:?}",
            adapter.get_info().name,
            adapter.get_info().backend,
            config.width,
            config.height,
            srgb
        );
        self.gpu = Some(Gpu {
            depth: depth_view(&device, config.width, config.height),
            window,
            surface,
            device,
            queue,
            config,
            hair,
        });
        Ok(())
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let (Some(gpu), Some(orbit)) = (&mut self.gpu, &self.orbit) else {
            return;
        };
        let frame = match gpu.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame)
            | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gpu.surface.configure(&gpu.device, &gpu.config);
                return;
            }
            _ => return,
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(gpu.config.format.add_srgb_suffix()),
            ..Default::default()
        });
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("game"),
            });
        let camera = orbit.camera(gpu.config.width, gpu.config.height);
        let stats = gpu.hair.prepare(&mut encoder, &camera);
        {
            let [r, g, b] = gpu.hair.scene().background;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("game"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: r as f64,
                            g: g as f64,
                            b: b as f64,
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &gpu.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // A game draws its own scene here; the hair is depth-tested against it.
            gpu.hair.draw(&mut pass);
        }
        gpu.queue.submit([encoder.finish()]);
        gpu.window.pre_present_notify();
        gpu.queue.present(frame);
        self.frames_drawn += 1;
        if let Some(left) = &mut self.frames_left {
            *left = left.saturating_sub(1);
            if *left == 0 {
                println!(
                    "{} frames in {:.2} s; last frame: {} strands, {} vertices, {} bundles culled",
                    self.frames_drawn,
                    self.started.elapsed().as_secs_f64(),
                    stats.strands,
                    stats.vertices,
                    stats.culled_bundles
                );
                event_loop.exit();
            }
        }
    }
}

impl ApplicationHandler for Game {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_none()
            && let Err(error) = self.start(event_loop)
        {
            self.error = Some(error);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::KeyboardInput { event, .. }
                if event.logical_key == Key::Named(NamedKey::Escape) =>
            {
                event_loop.exit()
            }
            WindowEvent::Resized(size) => {
                if let Some(gpu) = &mut self.gpu {
                    gpu.config.width = size.width.max(1);
                    gpu.config.height = size.height.max(1);
                    gpu.surface.configure(&gpu.device, &gpu.config);
                    gpu.depth = depth_view(&gpu.device, gpu.config.width, gpu.config.height);
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y)), Some(orbit)) =
                    (self.dragging, self.last_cursor, &mut self.orbit)
                {
                    orbit.yaw_rad -= (position.x - x) as f32 * 0.01;
                    orbit.pitch_rad =
                        (orbit.pitch_rad + (position.y - y) as f32 * 0.01).clamp(-1.5, 1.5);
                }
                self.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                if let Some(orbit) = &mut self.orbit {
                    orbit.distance_m *= (1.0 - 0.1 * lines).clamp(0.5, 1.5);
                }
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(gpu) = &self.gpu {
            gpu.window.request_redraw();
        }
    }
}

/// A runtime bundle folder, or a project turned into one in memory.
fn load(path: &Path) -> Result<RuntimeHair, String> {
    if path.is_dir() {
        hairloom_core::io::runtime_bundle::load_runtime_bundle(path)
            .map_err(|e| format!("{}: {e}", path.display()))
    } else {
        let project = hairloom_core::io::project::load(path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(RuntimeHair::from_document(
            &project.document,
            &RuntimeOptions::default(),
        ))
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut path = None;
    let mut frames_left = None;
    while let Some(arg) = args.next() {
        if arg == "--frames" {
            frames_left = args.next().and_then(|n| n.parse::<u64>().ok());
            if frames_left.is_none() {
                eprintln!("--frames needs a number");
                std::process::exit(2);
            }
        } else {
            path = Some(PathBuf::from(arg));
        }
    }
    let path = path.unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples/head_long_wavy.hairloom")
    });
    let bundle = match load(&path) {
        Ok(bundle) => bundle,
        Err(error) => {
            eprintln!("{error}");
            std::process::exit(2);
        }
    };
    let event_loop = match EventLoop::new() {
        Ok(event_loop) => event_loop,
        Err(error) => {
            eprintln!("no window system: {error}");
            std::process::exit(1);
        }
    };
    let mut game = Game {
        bundle,
        gpu: None,
        orbit: None,
        dragging: false,
        last_cursor: None,
        frames_left,
        frames_drawn: 0,
        started: Instant::now(),
        error: None,
    };
    if let Err(error) = event_loop.run_app(&mut game) {
        eprintln!("{error}");
        std::process::exit(1);
    }
    if let Some(error) = game.error {
        eprintln!("{error}");
        std::process::exit(1);
    }
}
