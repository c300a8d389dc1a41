//! One hair asset: a document's runtime data ([`RuntimeHair`]) and its GPU side together,
//! changed one way. What changed in the document comes as a [`ChangeKind`], worked out in
//! core from the undo history's diff; the CPU side of the change is built off the UI thread
//! ([`AssetBuilder`]), then [`HairAsset::apply`] takes it to the GPU: a restyle rewrites the
//! styling buffers, a reshape the textures in place (where their layout allows), a rebuild
//! uploads afresh. The editor's viewport, the CLI's renders, the game runtime and the benches
//! all hold their hair this way.
//!
//! A curl tick thus walks editor → document → change kind → asset change → GPU buffer →
//! shader, one way.

use std::sync::{Arc, Condvar, Mutex};

use glam::Vec3;
use hairloom_core::fur::base::FurBase;
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::document::Document;
use hairloom_core::model::root_maps::RootMaps;
use hairloom_core::model::scene::FurShells;
use hairloom_core::model::styling::StylingSet;
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;

use crate::device::GpuContext;
use crate::frame::HairSource;
use crate::preview::default_strand_width_m;
use crate::renderer::fur::{FurStrands, GpuFur};
use crate::renderer::preview_body::GpuBody;
use crate::renderer::strand_gen::{GpuFarHair, GpuHair, StrandGenError, StrandGenRenderer};
use hairloom_core::runtime::thick_hair::{FarHair, ThickHairError};

/// Why an asset could not be put on the GPU.
#[derive(Debug, thiserror::Error)]
pub enum HairAssetError {
    #[error("no bundle grows hair")]
    NoHair,
    #[error(transparent)]
    Upload(#[from] StrandGenError),
    #[error(transparent)]
    Fur(#[from] crate::renderer::fur::FurError),
    #[error("{0}")]
    FurFailed(String),
    #[error("far hair's hierarchy: {0}")]
    FarHair(#[from] hairloom_core::runtime::thick_hair::ThickHairError),
    #[error("far hair's hierarchy: {0}")]
    FarHairFailed(String),
}

/// What a restyle carries: the styling parameters and the painted maps (both read per
/// strand; neither moves the hair mesh).
pub struct Restyling {
    pub styling: StylingSet,
    pub root_maps: RootMaps,
}

impl Restyling {
    pub fn of(document: &Document) -> Self {
        Self {
            styling: document.styling.clone(),
            root_maps: document.root_maps.clone(),
        }
    }
}

/// The CPU side of a change, ready for the GPU.
pub enum AssetChange {
    /// New styling and painted maps for the asset on the GPU.
    Restyle(Box<Restyling>),
    /// The runtime data made again: taken in place when only positions moved
    /// ([`ChangeKind::Reshape`]), uploaded afresh otherwise.
    Hair {
        hair: Box<RuntimeHair>,
        kind: ChangeKind,
    },
}

impl AssetChange {
    /// Builds what a change of `kind` to `document` needs (the runtime data for a reshape or
    /// a rebuild: the costly part, for a worker thread); `None` for a scene change, which
    /// leaves the asset alone.
    pub fn build(document: &Document, kind: ChangeKind, options: &RuntimeOptions) -> Option<Self> {
        match kind {
            ChangeKind::Scene => None,
            ChangeKind::Restyle => Some(AssetChange::Restyle(Box::new(Restyling::of(document)))),
            ChangeKind::Reshape | ChangeKind::Rebuild => Some(AssetChange::Hair {
                hair: Box::new(RuntimeHair::from_document(document, options)),
                kind,
            }),
        }
    }

    pub fn kind(&self) -> ChangeKind {
        match self {
            AssetChange::Restyle(_) => ChangeKind::Restyle,
            AssetChange::Hair { kind, .. } => *kind,
        }
    }

    /// This change followed by `later`, as one change.
    pub fn then(self, later: AssetChange) -> AssetChange {
        let kind = self.kind().and(later.kind());
        match (self, later) {
            (_, AssetChange::Hair { hair, .. }) => AssetChange::Hair { hair, kind },
            (AssetChange::Hair { mut hair, .. }, AssetChange::Restyle(styling)) => {
                hair.set_styling(&styling.styling);
                hair.textures.root_maps = styling.root_maps;
                AssetChange::Hair { hair, kind }
            }
            (AssetChange::Restyle(_), restyle) => restyle,
        }
    }
}

/// A runtime asset on the GPU: its textures, samples and styling, its body, and the box
/// around its hair.
pub struct HairAsset {
    hair: RuntimeHair,
    gpu: GpuHair,
    body: GpuBody,
    bounds: (Vec3, Vec3),
    /// Vertices per strand the styling's curls and waves need
    /// ([`RuntimeHair::strand_vertices_log2`]): it scans the w texture, so it is kept here,
    /// made again when the styling or the shape changes, not per frame.
    vertices_log2: u32,
    /// Far hair's hierarchy (seed 001), once a scene asked for it or a bundle carried it.
    /// Kept through a restyle or a reshape (its thick hairs are generated from the textures
    /// every frame, so they follow); made again after a rebuild.
    far: Option<GpuFarHair>,
    /// Far hair's hierarchy being built on a worker thread for the viewport
    /// ([`Self::prepare_far_hair`]): frames draw strands until it is ready. A rebuild makes a
    /// new asset, which drops the handle (the worker's result is then discarded).
    far_build: Option<FarBuild>,
    /// Why the last build failed: not tried again every frame.
    far_failure: Option<String>,
    /// Fur's textures and patches (seed 002), once a scene asked for them; made again when
    /// the hair's root faces or the scene's fur settings change.
    fur: Option<GpuFur>,
    /// The last fur that could not be made: what it was made from, and why.
    fur_failure: Option<(FurShells, FurStrands, FurBase, String)>,
}

impl HairAsset {
    /// Uploads `hair` with `generator`'s layouts.
    pub fn upload(
        context: &GpuContext,
        generator: &StrandGenRenderer,
        hair: RuntimeHair,
    ) -> Result<Self, HairAssetError> {
        let bounds = hair.textures.hair_bounds().ok_or(HairAssetError::NoHair)?;
        let gpu = generator.upload(context, &hair)?;
        Ok(Self {
            body: GpuBody::upload(context, &hair.body),
            vertices_log2: hair.strand_vertices_log2(),
            hair,
            gpu,
            bounds,
            far: None,
            far_build: None,
            far_failure: None,
            fur: None,
            fur_failure: None,
        })
    }

    /// Builds `document`'s runtime data with `options` and uploads it (the costly part: not
    /// on a UI thread).
    pub fn from_document(
        context: &GpuContext,
        generator: &StrandGenRenderer,
        document: &Document,
        options: &RuntimeOptions,
    ) -> Result<Self, HairAssetError> {
        Self::upload(
            context,
            generator,
            RuntimeHair::from_document(document, options),
        )
    }

    /// Takes `change` to the GPU; returns what was done: a reshape whose texture layout
    /// changed is uploaded afresh (a rebuild). On an error the asset is as it was.
    pub fn apply(
        &mut self,
        context: &GpuContext,
        generator: &StrandGenRenderer,
        change: AssetChange,
    ) -> Result<ChangeKind, HairAssetError> {
        match change {
            AssetChange::Restyle(styling) => {
                self.hair.set_styling(&styling.styling);
                self.hair.textures.root_maps = styling.root_maps;
                generator.update_styling(context, &mut self.gpu, &self.hair);
                self.vertices_log2 = self.hair.strand_vertices_log2();
                Ok(ChangeKind::Restyle)
            }
            AssetChange::Hair { hair, kind } => {
                if kind <= ChangeKind::Reshape
                    && let Some(bounds) = hair.textures.hair_bounds()
                    && generator.update_shape(context, &mut self.gpu, &hair)
                {
                    // A head animation moves the body with the hair.
                    if self.hair.body != hair.body {
                        self.body = GpuBody::upload(context, &hair.body);
                    }
                    self.hair = *hair;
                    self.bounds = bounds;
                    self.vertices_log2 = self.hair.strand_vertices_log2();
                    // Other hair: a build that failed may succeed now.
                    self.far_failure = None;
                    return Ok(ChangeKind::Reshape);
                }
                *self = HairAsset::upload(context, generator, *hair)?;
                Ok(ChangeKind::Rebuild)
            }
        }
    }

    /// [`Self::apply`] for a holder that may have no asset yet (made by the change); on an
    /// error the holder is left empty, so nothing stale is drawn. A restyle of an empty
    /// holder (its upload failed) changes nothing: [`ChangeKind::Scene`].
    pub fn apply_to(
        asset: &mut Option<HairAsset>,
        context: &GpuContext,
        generator: &StrandGenRenderer,
        change: AssetChange,
    ) -> Result<ChangeKind, HairAssetError> {
        let result = match (asset.as_mut(), change) {
            (Some(current), change) => current.apply(context, generator, change),
            (None, AssetChange::Hair { hair, .. }) => HairAsset::upload(context, generator, *hair)
                .map(|made| {
                    *asset = Some(made);
                    ChangeKind::Rebuild
                }),
            (None, AssetChange::Restyle(_)) => Ok(ChangeKind::Scene),
        };
        if result.is_err() {
            *asset = None;
        }
        result
    }

    pub fn hair(&self) -> &RuntimeHair {
        &self.hair
    }

    /// Vertices per strand (2^N + 1, as N) this hair's styling needs.
    pub fn strand_vertices_log2(&self) -> u32 {
        self.vertices_log2
    }

    /// Far hair's hierarchy as a bundle carries it (`LoadedBundle::far_hair`).
    pub fn set_far_hair(&mut self, context: &GpuContext, table: FarHair) {
        self.far = Some(GpuFarHair::upload(context, table));
        self.far_build = None;
    }

    /// Builds far hair's hierarchy from the strands at full detail where the asset has none
    /// yet (as an export does: the costly part, seconds on a large groom), and uploads it.
    /// Blocks: for renders, benches and games that need it in their first frame. The
    /// viewport uses [`Self::prepare_far_hair`].
    pub fn ensure_far_hair(&mut self, context: &GpuContext) -> Result<(), HairAssetError> {
        if self.far.is_none() {
            let table = match self.far_build.take() {
                // A build already under way: wait for it rather than start another.
                Some(build) => build.join()?,
                None => FarHair::build(&self.hair, far_vertex_count(&self.hair))?,
            };
            self.far = Some(GpuFarHair::upload(context, table));
        }
        Ok(())
    }

    /// Far hair's hierarchy without stalling the caller (the editor's paint callback, where a
    /// build of seconds froze the viewport when far hair was switched on): starts the build on
    /// a worker thread, and on a later call uploads what it made. `Ok(true)` once far hair
    /// is on the GPU; `Ok(false)` while it is building (draw strands meanwhile, and call
    /// again); a failed build's error, at once and without building again, until the hair is
    /// reshaped.
    pub fn prepare_far_hair(&mut self, context: &GpuContext) -> Result<bool, HairAssetError> {
        if self.far.is_some() {
            return Ok(true);
        }
        if let Some(message) = &self.far_failure {
            return Err(HairAssetError::FarHairFailed(message.clone()));
        }
        match self.far_build.take() {
            Some(build) if build.is_finished() => match build.join() {
                Ok(table) => {
                    self.far = Some(GpuFarHair::upload(context, table));
                    Ok(true)
                }
                Err(error) => {
                    self.far_failure = Some(error.to_string());
                    Err(error)
                }
            },
            Some(build) => {
                self.far_build = Some(build);
                Ok(false)
            }
            None => match FarBuild::start(&self.hair) {
                Some(build) => {
                    self.far_build = Some(build);
                    Ok(false)
                }
                // No thread to be had: build it here.
                None => self.ensure_far_hair(context).map(|()| true),
            },
        }
    }

    /// Whether far hair's hierarchy is being built on a worker.
    pub fn far_hair_building(&self) -> bool {
        self.far_build.is_some()
    }

    /// Makes fur's textures and patches for `settings` where they are missing or were made
    /// from other settings or another hair mesh (the costly part: not per frame).
    pub fn ensure_fur(
        &mut self,
        context: &GpuContext,
        settings: &FurShells,
    ) -> Result<(), HairAssetError> {
        let base = &self.hair.fur_base;
        let grown: f64 = self
            .hair
            .block_density
            .iter()
            .map(|&d| d.clamp(0.0, 1.0) as f64 * self.hair.strands_per_bundle as f64)
            .sum();
        let strands = FurStrands {
            per_m2: grown / base.area_m2().max(1e-12),
            radius_m: 0.5 * default_strand_width_m(self.bounds.0, self.bounds.1) as f64,
        };
        if self
            .fur
            .as_ref()
            .is_some_and(|f| f.fits(base, settings, strands))
        {
            return Ok(());
        }
        // A fur that could not be made is not tried again every frame for the same hair and
        // settings: the same error comes back at once.
        if let Some((failed_settings, failed_strands, failed_base, message)) = &self.fur_failure
            && failed_settings == settings
            && *failed_strands == strands
            && failed_base == base
        {
            return Err(HairAssetError::FurFailed(message.clone()));
        }
        self.fur = None;
        match GpuFur::build(context, base, settings, strands) {
            Ok(fur) => {
                self.fur = Some(fur);
                self.fur_failure = None;
                Ok(())
            }
            Err(error) => {
                self.fur_failure =
                    Some((settings.clone(), strands, base.clone(), error.to_string()));
                Err(error.into())
            }
        }
    }

    /// Fur on the GPU, where made.
    pub fn fur(&self) -> Option<&GpuFur> {
        self.fur.as_ref()
    }

    /// Far hair's hierarchy on the GPU, where made.
    pub fn far_hair(&self) -> Option<&GpuFarHair> {
        self.far.as_ref()
    }

    pub fn gpu(&self) -> &GpuHair {
        &self.gpu
    }

    pub fn body(&self) -> &GpuBody {
        &self.body
    }

    /// The box around the hair.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The asset as a frame's hair, generated by `generator`.
    pub fn source<'a>(
        &'a self,
        generator: &'a StrandGenRenderer,
        filtering: Filtering,
        lod: LodSettings,
    ) -> HairSource<'a> {
        HairSource::Generated {
            generator,
            hair: &self.gpu,
            filtering,
            lod,
            far: self.far.as_ref(),
            fur: self.fur.as_ref(),
        }
    }
}

/// Strand vertices far hair's hierarchy is fitted to.
fn far_vertex_count(hair: &RuntimeHair) -> usize {
    (1usize << hair.lod.max_vertices_log2.min(8)) + 1
}

/// Far hair's hierarchy being built on a worker thread from a copy of the runtime data.
struct FarBuild(std::thread::JoinHandle<Result<FarHair, ThickHairError>>);

impl FarBuild {
    /// `None` when no thread could be started.
    fn start(hair: &RuntimeHair) -> Option<Self> {
        let hair = hair.clone();
        std::thread::Builder::new()
            .name("far hair hierarchy".into())
            .spawn(move || FarHair::build(&hair, far_vertex_count(&hair)))
            .ok()
            .map(Self)
    }

    fn is_finished(&self) -> bool {
        self.0.is_finished()
    }

    /// Waits for the build; a worker that panicked (a bug) is an error that says so.
    fn join(self) -> Result<FarHair, HairAssetError> {
        match self.0.join() {
            Ok(built) => Ok(built?),
            Err(_) => Err(HairAssetError::FarHairFailed(
                "the worker building it stopped (a bug); switch far hair off and on to try again"
                    .into(),
            )),
        }
    }
}

/// Builds asset changes on a worker thread, in the order asked: requests that arrive while
/// one is being built are folded into one ([`ChangeKind::and`], the newest document), and
/// finished changes wait, folded likewise ([`AssetChange::then`]), until [`Self::poll`] takes
/// them with the serial of the newest request they hold. A build that panics (a bug) is
/// reported by [`Self::take_failure`] and the builder goes on with the next request.
pub struct AssetBuilder {
    shared: Arc<(Mutex<BuilderState>, Condvar)>,
    worker: Option<std::thread::JoinHandle<()>>,
}

struct Request {
    document: Arc<Document>,
    kind: ChangeKind,
    options: RuntimeOptions,
    serial: u64,
}

/// A finished change and the serial of the newest request it holds ([`AssetBuilder::request`]).
pub struct Built {
    pub change: AssetChange,
    pub serial: u64,
}

#[derive(Default)]
struct BuilderState {
    last_serial: u64,
    request: Option<Request>,
    building: bool,
    done: Option<Built>,
    failure: Option<String>,
    shutdown: bool,
}

impl Default for AssetBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl AssetBuilder {
    pub fn new() -> Self {
        let shared = Arc::new((Mutex::new(BuilderState::default()), Condvar::new()));
        let worker_shared = Arc::clone(&shared);
        let worker = std::thread::Builder::new()
            .name("hair-asset-builder".into())
            .spawn(move || build_loop(&worker_shared))
            .expect("spawning the asset builder thread");
        Self {
            shared,
            worker: Some(worker),
        }
    }

    fn state(&self) -> std::sync::MutexGuard<'_, BuilderState> {
        self.shared.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Asks for the change of `kind` that made `document` (relative to the last request);
    /// returns the request's serial (`None` for a scene change: nothing to build).
    pub fn request(
        &self,
        document: Arc<Document>,
        kind: ChangeKind,
        options: RuntimeOptions,
    ) -> Option<u64> {
        if kind == ChangeKind::Scene {
            return None;
        }
        let mut state = self.state();
        let kind = state
            .request
            .as_ref()
            .map_or(kind, |pending| pending.kind.and(kind));
        state.last_serial += 1;
        let serial = state.last_serial;
        state.request = Some(Request {
            document,
            kind,
            options,
            serial,
        });
        self.shared.1.notify_all();
        Some(serial)
    }

    /// The changes finished since the last poll, as one.
    pub fn poll(&self) -> Option<Built> {
        self.state().done.take()
    }

    /// Why the last build failed, once (a panic in the runtime data's construction).
    pub fn take_failure(&self) -> Option<String> {
        self.state().failure.take()
    }

    /// Whether a change is requested, being built, or waiting to be polled.
    pub fn busy(&self) -> bool {
        let state = self.state();
        state.request.is_some() || state.building || state.done.is_some()
    }

    /// Blocks until every requested change is built (tests and one-shot renders).
    pub fn wait(&self) {
        let mut state = self.state();
        while state.request.is_some() || state.building {
            state = self.shared.1.wait(state).unwrap_or_else(|e| e.into_inner());
        }
    }
}

impl Drop for AssetBuilder {
    fn drop(&mut self) {
        self.state().shutdown = true;
        self.shared.1.notify_all();
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

fn build_loop(shared: &(Mutex<BuilderState>, Condvar)) {
    let (lock, wake) = shared;
    let mut state = lock.lock().unwrap_or_else(|e| e.into_inner());
    loop {
        if state.shutdown {
            return;
        }
        let Some(request) = state.request.take() else {
            state = wake.wait(state).unwrap_or_else(|e| e.into_inner());
            continue;
        };
        state.building = true;
        drop(state);
        // A panic here is a bug in building the runtime data: say so and keep serving, so
        // neither the UI nor a waiting caller hangs on it.
        let built = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            AssetChange::build(&request.document, request.kind, &request.options)
        }));
        state = lock.lock().unwrap_or_else(|e| e.into_inner());
        state.building = false;
        match built {
            Ok(Some(change)) => {
                let change = match state.done.take() {
                    Some(earlier) => earlier.change.then(change),
                    None => change,
                };
                state.done = Some(Built {
                    change,
                    serial: request.serial,
                });
            }
            Ok(None) => {}
            Err(panic) => {
                let message = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic without a message".into());
                state.failure = Some(format!("building the hair failed: {message}"));
            }
        }
        wake.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hairloom_core::samples::{grid_scalp, straight_layers};

    fn document() -> Document {
        let scalp = grid_scalp(2, 2, |x, y| glam::DVec3::new(x, y, 0.0));
        Document::new("grid", straight_layers(scalp, 3, glam::DVec3::Z * 0.01))
    }

    #[test]
    fn requests_fold_into_the_newest_document_and_the_largest_kind() {
        let builder = AssetBuilder::new();
        let options = RuntimeOptions::default();
        let mut document = document();
        let first_serial = builder.request(
            Arc::new(document.clone()),
            ChangeKind::Rebuild,
            options.clone(),
        );
        builder.wait();
        let first = builder.poll().expect("built");
        assert_eq!(Some(first.serial), first_serial);
        assert_eq!(first.change.kind(), ChangeKind::Rebuild);
        assert!(builder.poll().is_none());
        // A drag, then a curl tick: one reshape carrying the new styling.
        document.hair_mesh.columns[1].positions[2].x += 0.01;
        builder.request(
            Arc::new(document.clone()),
            ChangeKind::Reshape,
            options.clone(),
        );
        document.styling.global.curl.radius_m = 0.004;
        let last_serial = builder.request(
            Arc::new(document.clone()),
            ChangeKind::Restyle,
            options.clone(),
        );
        builder.wait();
        let folded = builder.poll().expect("built");
        // It holds the newest request: a caller knows no older document is still to come.
        assert_eq!(Some(folded.serial), last_serial);
        assert!(last_serial > first_serial);
        assert_eq!(folded.change.kind(), ChangeKind::Reshape);
        assert!(builder.take_failure().is_none());
        let AssetChange::Hair { hair, .. } = folded.change else {
            panic!("a reshape carries the runtime data");
        };
        assert_eq!(hair.styling, document.styling);
        let moved = RuntimeHair::from_document(&document, &options);
        assert_eq!(
            hair.textures.hair_mesh.texels,
            moved.textures.hair_mesh.texels
        );
        // A scene change asks nothing.
        assert_eq!(
            builder.request(Arc::new(document), ChangeKind::Scene, options),
            None
        );
        assert!(!builder.busy());
    }
}
