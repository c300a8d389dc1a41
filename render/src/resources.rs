//! The registry of the renderer's labelled GPU resources: every pipeline, texture and buffer a
//! renderer keeps is made through it, so tests (and `hairloom bench effects`) can list exactly
//! what exists for a scene and how many bytes it holds. An entry lives as long as the resource
//! it was made with: dropping the resource drops its token, and the registry forgets it.
//!
//! This is how the mission's "compute only what the scene calls for" is checked: a scene
//! without shadows has no `shadow` texture or pipeline alive, and turning shadows on and off
//! again frees them (`render/tests/effect_resources.rs`).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, Weak};

use wgpu::util::DeviceExt;

/// What kind of GPU object an entry is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ResourceKind {
    Texture,
    Buffer,
    Pipeline,
}

/// A GPU object made through the registry, listed there while it lives.
#[derive(Debug)]
pub struct Tracked<T> {
    resource: T,
    _alive: Arc<()>,
}

impl<T> std::ops::Deref for Tracked<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.resource
    }
}

#[derive(Debug)]
struct Entry {
    label: String,
    kind: ResourceKind,
    bytes: u64,
    alive: Weak<()>,
}

/// One live resource, as listed by [`ResourceRegistry::live`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LiveResource {
    pub label: String,
    pub kind: ResourceKind,
    pub bytes: u64,
}

#[derive(Debug, Default)]
pub struct ResourceRegistry {
    entries: Mutex<Vec<Entry>>,
}

impl ResourceRegistry {
    fn track<T>(&self, resource: T, label: &str, kind: ResourceKind, bytes: u64) -> Tracked<T> {
        let alive = Arc::new(());
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        // Forget the dead ones now and then, so a long session does not grow the list.
        entries.retain(|e| e.alive.strong_count() > 0);
        entries.push(Entry {
            label: label.to_string(),
            kind,
            bytes,
            alive: Arc::downgrade(&alive),
        });
        Tracked {
            resource,
            _alive: alive,
        }
    }

    pub fn texture(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::TextureDescriptor,
    ) -> Tracked<wgpu::Texture> {
        let texture = device.create_texture(descriptor);
        let size = descriptor.size;
        let block = descriptor
            .format
            .block_copy_size(Some(wgpu::TextureAspect::All))
            .or_else(|| {
                descriptor
                    .format
                    .block_copy_size(Some(wgpu::TextureAspect::DepthOnly))
            })
            .unwrap_or(4) as u64;
        let bytes = size.width as u64
            * size.height as u64
            * size.depth_or_array_layers as u64
            * block
            * descriptor.sample_count as u64;
        self.track(
            texture,
            descriptor.label.unwrap_or("unlabelled texture"),
            ResourceKind::Texture,
            bytes,
        )
    }

    pub fn buffer(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::BufferDescriptor,
    ) -> Tracked<wgpu::Buffer> {
        let buffer = device.create_buffer(descriptor);
        self.track(
            buffer,
            descriptor.label.unwrap_or("unlabelled buffer"),
            ResourceKind::Buffer,
            descriptor.size,
        )
    }

    pub fn buffer_init(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::util::BufferInitDescriptor,
    ) -> Tracked<wgpu::Buffer> {
        let buffer = device.create_buffer_init(descriptor);
        self.track(
            buffer,
            descriptor.label.unwrap_or("unlabelled buffer"),
            ResourceKind::Buffer,
            descriptor.contents.len() as u64,
        )
    }

    pub fn render_pipeline(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::RenderPipelineDescriptor,
    ) -> Tracked<wgpu::RenderPipeline> {
        let pipeline = device.create_render_pipeline(descriptor);
        self.track(
            pipeline,
            descriptor.label.unwrap_or("unlabelled pipeline"),
            ResourceKind::Pipeline,
            0,
        )
    }

    pub fn mesh_pipeline(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::MeshPipelineDescriptor,
    ) -> Tracked<wgpu::RenderPipeline> {
        let pipeline = device.create_mesh_pipeline(descriptor);
        self.track(
            pipeline,
            descriptor.label.unwrap_or("unlabelled pipeline"),
            ResourceKind::Pipeline,
            0,
        )
    }

    pub fn compute_pipeline(
        &self,
        device: &wgpu::Device,
        descriptor: &wgpu::ComputePipelineDescriptor,
    ) -> Tracked<wgpu::ComputePipeline> {
        let pipeline = device.create_compute_pipeline(descriptor);
        self.track(
            pipeline,
            descriptor.label.unwrap_or("unlabelled pipeline"),
            ResourceKind::Pipeline,
            0,
        )
    }

    /// Every resource alive now, sorted by kind and label.
    pub fn live(&self) -> Vec<LiveResource> {
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries.retain(|e| e.alive.strong_count() > 0);
        let mut live: Vec<LiveResource> = entries
            .iter()
            .map(|e| LiveResource {
                label: e.label.clone(),
                kind: e.kind,
                bytes: e.bytes,
            })
            .collect();
        live.sort_by(|a, b| (a.kind, &a.label).cmp(&(b.kind, &b.label)));
        live
    }

    /// The labels alive now, each with how many resources carry it.
    pub fn live_labels(&self) -> BTreeMap<String, usize> {
        let mut labels = BTreeMap::new();
        for resource in self.live() {
            *labels.entry(resource.label).or_insert(0) += 1;
        }
        labels
    }

    /// Bytes held by live textures and buffers.
    pub fn live_bytes(&self) -> u64 {
        self.live().iter().map(|r| r.bytes).sum()
    }

    /// Bytes held by live resources whose label starts with `prefix`.
    pub fn live_bytes_with_prefix(&self, prefix: &str) -> u64 {
        self.live()
            .iter()
            .filter(|r| r.label.starts_with(prefix))
            .map(|r| r.bytes)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_live_as_long_as_their_resources() {
        let registry = ResourceRegistry::default();
        let a = registry.track(1u32, "a", ResourceKind::Buffer, 10);
        let b = registry.track(2u32, "b", ResourceKind::Texture, 20);
        assert_eq!(registry.live_bytes(), 30);
        assert_eq!(*a, 1);
        drop(b);
        assert_eq!(
            registry.live(),
            vec![LiveResource {
                label: "a".into(),
                kind: ResourceKind::Buffer,
                bytes: 10
            }]
        );
        drop(a);
        assert!(registry.live().is_empty());
    }
}
