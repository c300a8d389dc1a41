//! Alembic's object and property layer (AbcCoreOgawa) over the [`ogawa`](super::ogawa)
//! container: objects with compound, scalar and array properties, their metadata and time
//! samples, laid out the way the reference C++ reader and `ogawa-rs` read them.
//!
//! What each reader needs, and why some choices look odd:
//! - The root group has six children: the core file version (`i32 0`), the library version
//!   (`i32`, the Alembic release whose layout we write), the top object, the archive
//!   metadata (never empty: `ogawa-rs` refuses an empty blob), the time samplings and the
//!   indexed-metadata table.
//! - Metadata (`key=value;…`, keys sorted) is stored once in the table and named by index in
//!   each header (inline past 253 entries or 255 bytes). The table ends with one empty entry,
//!   because `ogawa-rs` 0.4 reads the last entry as empty.
//! - Every sample starts with a 16-byte key (MurmurHash3 x64 128 of its bytes). Readers
//!   skip it, but tools use it to spot unchanged samples, so it is the real hash.
//! - Object and property hashes (32 bytes after an object's child headers) are left zero:
//!   no reader checks them, and Unreal, Unity and Blender do not use them.
//! - A property set more than once names its first and last changed sample explicitly,
//!   because `ogawa-rs` 0.4 assumes other defaults than the C++ library when they are left out.
//! - Every variable-length field is a u32 (size hint 2): always large enough, so no per-record choice.

use std::collections::HashMap;

use super::ogawa::Node;

/// The Alembic release whose file layout this writes (1.8.12 as `XXYYZZ`).
pub const LIBRARY_VERSION: i32 = 10812;

/// Plain data types, with Alembic's codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pod {
    U8 = 1,
    I16 = 4,
    I32 = 6,
    F32 = 10,
    F64 = 11,
    String = 12,
}

impl Pod {
    fn bytes(self) -> usize {
        match self {
            Pod::U8 => 1,
            Pod::I16 => 2,
            Pod::I32 | Pod::F32 => 4,
            Pod::F64 => 8,
            Pod::String => 1,
        }
    }

    /// The name geometry-parameter metadata uses (`podName`).
    pub fn name(self) -> &'static str {
        match self {
            Pod::U8 => "uint8_t",
            Pod::I16 => "int16_t",
            Pod::I32 => "int32_t",
            Pod::F32 => "float32_t",
            Pod::F64 => "float64_t",
            Pod::String => "string",
        }
    }
}

/// A property and, for compounds, the properties it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Property {
    pub name: String,
    pub metadata: Metadata,
    pub kind: PropertyKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum PropertyKind {
    Compound(Vec<Property>),
    /// One value per sample.
    Scalar(Samples),
    /// An array of values per sample.
    Array(Samples),
}

/// Values of a scalar or array property: each sample is raw little-endian values (strings:
/// each followed by a NUL byte), `extent` components per element.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    pub pod: Pod,
    pub extent: u8,
    pub samples: Vec<Vec<u8>>,
    /// Index into the archive's time samplings: 0 is the static default, 1 the animation.
    pub time_sampling: u32,
}

impl Samples {
    pub fn new<T: bytemuck::Pod, S: AsRef<[T]>>(pod: Pod, extent: u8, samples: &[S]) -> Self {
        Self {
            pod,
            extent,
            samples: samples
                .iter()
                .map(|s| bytemuck::cast_slice(s.as_ref()).to_vec())
                .collect(),
            time_sampling: if samples.len() > 1 { 1 } else { 0 },
        }
    }

    fn elements(&self, sample: &[u8]) -> usize {
        sample.len() / (self.pod.bytes() * self.extent as usize).max(1)
    }
}

impl Property {
    pub fn compound(name: &str, metadata: Metadata, children: Vec<Property>) -> Self {
        Self {
            name: name.into(),
            metadata,
            kind: PropertyKind::Compound(children),
        }
    }

    pub fn scalar(name: &str, metadata: Metadata, samples: Samples) -> Self {
        Self {
            name: name.into(),
            metadata,
            kind: PropertyKind::Scalar(samples),
        }
    }

    pub fn array(name: &str, metadata: Metadata, samples: Samples) -> Self {
        Self {
            name: name.into(),
            metadata,
            kind: PropertyKind::Array(samples),
        }
    }
}

/// `key=value` pairs, written sorted by key with `;` between them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metadata(pub Vec<(String, String)>);

impl Metadata {
    pub fn new(pairs: &[(&str, &str)]) -> Self {
        Self(
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        )
    }

    /// The serialised form. Empty values are left out, as the C++ library does; `;` and `=`
    /// cannot appear in keys or values (they would break the format), so they become `_`.
    pub fn serialize(&self) -> String {
        let clean = |s: &str| s.replace([';', '='], "_");
        let mut pairs: Vec<(String, String)> = self
            .0
            .iter()
            .filter(|(_, v)| !v.is_empty())
            .map(|(k, v)| (clean(k), clean(v)))
            .collect();
        pairs.sort();
        pairs
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(";")
    }
}

/// An object: its properties and child objects.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub metadata: Metadata,
    pub properties: Vec<Property>,
    pub children: Vec<Object>,
}

/// A whole file: the top object's children, the archive metadata and, when any property
/// has several samples, the animation's frame rate (time sampling 1: sample `i` at
/// `i / frames_per_second` seconds).
#[derive(Clone, Debug, PartialEq)]
pub struct Archive {
    pub objects: Vec<Object>,
    pub metadata: Metadata,
    pub frames_per_second: f64,
}

impl Archive {
    /// The `.abc` file.
    pub fn write(&self) -> Vec<u8> {
        let mut table = MetadataTable::default();
        let top = object_node(
            &Object {
                name: "ABC".into(),
                metadata: Metadata::default(),
                properties: Vec::new(),
                children: self.objects.clone(),
            },
            &mut table,
        );
        let mut archive_metadata = self.metadata.serialize();
        if archive_metadata.is_empty() {
            archive_metadata = "_ai_Application=Hairloom".into();
        }
        let mut animated_samples = 0u32;
        let mut static_samples = 1u32;
        for object in &self.objects {
            visit_samples(object, &mut |s: &Samples| {
                let count = s.samples.len() as u32;
                if s.time_sampling == 0 {
                    static_samples = static_samples.max(count);
                } else {
                    animated_samples = animated_samples.max(count);
                }
            });
        }
        let mut time_samplings = Vec::new();
        push_time_sampling(&mut time_samplings, static_samples, 1.0);
        if animated_samples > 0 {
            push_time_sampling(
                &mut time_samplings,
                animated_samples,
                1.0 / self.frames_per_second,
            );
        }
        let root = Node::Group(vec![
            Node::data(0i32.to_le_bytes()),
            Node::data(LIBRARY_VERSION.to_le_bytes()),
            top,
            Node::data(archive_metadata.into_bytes()),
            Node::data(time_samplings),
            Node::data(table.bytes()),
        ]);
        super::ogawa::write(&root)
    }
}

/// A time-sampling record: the most samples any property has on it, the time between
/// samples, and one stored time (the start, 0 s).
fn push_time_sampling(out: &mut Vec<u8>, max_samples: u32, time_per_cycle_s: f64) {
    out.extend_from_slice(&max_samples.to_le_bytes());
    out.extend_from_slice(&time_per_cycle_s.to_le_bytes());
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&0f64.to_le_bytes());
}

fn visit_samples(object: &Object, f: &mut dyn FnMut(&Samples)) {
    fn visit_property(p: &Property, f: &mut dyn FnMut(&Samples)) {
        match &p.kind {
            PropertyKind::Compound(children) => children.iter().for_each(|c| visit_property(c, f)),
            PropertyKind::Scalar(s) | PropertyKind::Array(s) => f(s),
        }
    }
    object.properties.iter().for_each(|p| visit_property(p, f));
    object.children.iter().for_each(|c| visit_samples(c, f));
}

/// Indexed metadata: index 0 is the empty string, `k + 1` the table's entry `k`, 0xff
/// "written inline".
#[derive(Default)]
struct MetadataTable {
    entries: Vec<String>,
    index_of: HashMap<String, u8>,
}

const INLINE_METADATA: u8 = 0xff;

impl MetadataTable {
    fn index(&mut self, metadata: &str) -> u8 {
        if metadata.is_empty() {
            return 0;
        }
        if let Some(&i) = self.index_of.get(metadata) {
            return i;
        }
        // 254 entries at most, leaving room for the empty one `ogawa-rs` needs at the end.
        if metadata.len() > 255 || self.entries.len() >= 253 {
            return INLINE_METADATA;
        }
        self.entries.push(metadata.to_string());
        let i = self.entries.len() as u8;
        self.index_of.insert(metadata.to_string(), i);
        i
    }

    fn bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for e in &self.entries {
            out.push(e.len() as u8);
            out.extend_from_slice(e.as_bytes());
        }
        out.push(0); // see the module comment
        out
    }
}

fn push_string(out: &mut Vec<u8>, s: &str) {
    out.extend_from_slice(&(s.len() as u32).to_le_bytes());
    out.extend_from_slice(s.as_bytes());
}

/// An object group: `[properties, children…, child headers]`.
fn object_node(object: &Object, table: &mut MetadataTable) -> Node {
    let mut children = vec![compound_node(&object.properties, table)];
    let mut headers = Vec::new();
    for child in &object.children {
        children.push(object_node(child, table));
        push_string(&mut headers, &child.name);
        let metadata = child.metadata.serialize();
        let index = table.index(&metadata);
        headers.push(index);
        if index == INLINE_METADATA {
            push_string(&mut headers, &metadata);
        }
    }
    headers.extend_from_slice(&[0; 32]); // properties and children hashes, see the module comment
    children.push(Node::data(headers));
    Node::Group(children)
}

/// A compound's group: `[property groups…, property headers]`, or the empty group.
fn compound_node(properties: &[Property], table: &mut MetadataTable) -> Node {
    if properties.is_empty() {
        return Node::Group(Vec::new());
    }
    let mut children = Vec::new();
    let mut headers = Vec::new();
    for property in properties {
        let metadata = property.metadata.serialize();
        let index = table.index(&metadata);
        const SIZE_HINT_U32: u32 = 2 << 2;
        let mut info = SIZE_HINT_U32 | (u32::from(index) << 20);
        let mut fields = Vec::new();
        match &property.kind {
            PropertyKind::Compound(inner) => children.push(compound_node(inner, table)),
            PropertyKind::Scalar(s) | PropertyKind::Array(s) => {
                let is_array = matches!(property.kind, PropertyKind::Array(_));
                let count = s.samples.len() as u32;
                let all_same = s.samples.windows(2).all(|w| w[0] == w[1]);
                let single_elements = s.samples.iter().all(|v| s.elements(v) == 1);
                info |= if is_array { 2 } else { 1 };
                if is_array && single_elements {
                    info |= 1;
                }
                info |= (s.pod as u32) << 4;
                info |= u32::from(s.extent) << 12;
                info |= 0x400; // homogenous: informative only
                fields.extend_from_slice(&count.to_le_bytes());
                let stored: &[Vec<u8>] = if all_same {
                    info |= 0x800;
                    &s.samples[..count.min(1) as usize]
                } else {
                    info |= 0x200;
                    fields.extend_from_slice(&1u32.to_le_bytes());
                    fields.extend_from_slice(&(count - 1).to_le_bytes());
                    &s.samples
                };
                if s.time_sampling != 0 {
                    info |= 0x100;
                    fields.extend_from_slice(&s.time_sampling.to_le_bytes());
                }
                let mut sample_nodes = Vec::new();
                for sample in stored {
                    let mut data = murmur3_x64_128(sample).to_vec();
                    data.extend_from_slice(sample);
                    sample_nodes.push(Node::Data(data));
                    if is_array {
                        // Dimensions are worked out from the data size, except for strings.
                        sample_nodes.push(if s.pod == Pod::String {
                            let strings = sample.iter().filter(|&&b| b == 0).count() as u64;
                            Node::data(strings.to_le_bytes())
                        } else {
                            Node::data(Vec::new())
                        });
                    }
                }
                children.push(Node::Group(sample_nodes));
            }
        }
        headers.extend_from_slice(&info.to_le_bytes());
        headers.extend_from_slice(&fields);
        push_string(&mut headers, &property.name);
        if index == INLINE_METADATA {
            push_string(&mut headers, &metadata);
        }
    }
    children.push(Node::data(headers));
    Node::Group(children)
}

/// MurmurHash3 x64 128 with seed 0, as two little-endian u64 (Alembic's sample key).
pub(crate) fn murmur3_x64_128(data: &[u8]) -> [u8; 16] {
    const C1: u64 = 0x87c3_7b91_1142_53d5;
    const C2: u64 = 0x4cf5_ad43_2745_937f;
    fn mix(mut k: u64) -> u64 {
        k ^= k >> 33;
        k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
        k ^= k >> 33;
        k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        k ^ (k >> 33)
    }
    let (mut h1, mut h2) = (0u64, 0u64);
    let blocks = data.chunks_exact(16);
    let tail = blocks.remainder();
    for block in blocks {
        let k1 = u64::from_le_bytes(block[..8].try_into().expect("8 bytes"));
        let k2 = u64::from_le_bytes(block[8..].try_into().expect("8 bytes"));
        h1 ^= k1.wrapping_mul(C1).rotate_left(31).wrapping_mul(C2);
        h1 = h1
            .rotate_left(27)
            .wrapping_add(h2)
            .wrapping_mul(5)
            .wrapping_add(0x52dc_e729);
        h2 ^= k2.wrapping_mul(C2).rotate_left(33).wrapping_mul(C1);
        h2 = h2
            .rotate_left(31)
            .wrapping_add(h1)
            .wrapping_mul(5)
            .wrapping_add(0x3849_5ab5);
    }
    let (mut k1, mut k2) = (0u64, 0u64);
    for (j, &b) in tail.iter().enumerate() {
        if j < 8 {
            k1 ^= u64::from(b) << (8 * j);
        } else {
            k2 ^= u64::from(b) << (8 * (j - 8));
        }
    }
    if tail.len() > 8 {
        h2 ^= k2.wrapping_mul(C2).rotate_left(33).wrapping_mul(C1);
    }
    if !tail.is_empty() {
        h1 ^= k1.wrapping_mul(C1).rotate_left(31).wrapping_mul(C2);
    }
    h1 ^= data.len() as u64;
    h2 ^= data.len() as u64;
    h1 = h1.wrapping_add(h2);
    h2 = h2.wrapping_add(h1);
    h1 = mix(h1);
    h2 = mix(h2);
    h1 = h1.wrapping_add(h2);
    h2 = h2.wrapping_add(h1);
    let mut out = [0u8; 16];
    out[..8].copy_from_slice(&h1.to_le_bytes());
    out[8..].copy_from_slice(&h2.to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keys the C++ library wrote for known samples (an `i32` 7 and the string "ref").
    #[test]
    fn sample_keys_match_the_cpp_library() {
        let hex = |b: [u8; 16]| b.iter().map(|x| format!("{x:02x}")).collect::<String>();
        assert_eq!(
            hex(murmur3_x64_128(&7i32.to_le_bytes())),
            "fb1d467eb669277fa55b582f5c2215d2"
        );
        assert_eq!(
            hex(murmur3_x64_128(b"ref\0")),
            "15adccc5d3cca8668555df10667d6599"
        );
        assert_eq!(murmur3_x64_128(&[]), [0; 16]);
    }

    #[test]
    fn metadata_is_sorted_and_cannot_break_its_format() {
        let m = Metadata::new(&[("b", "x;y"), ("a", "1"), ("c", "")]);
        assert_eq!(m.serialize(), "a=1;b=x_y");
    }
}
