//! Ogawa, Alembic's container: a tree of groups whose leaves are byte blobs ("data").
//!
//! The file is a 16-byte header (`Ogawa`, a frozen flag that is `0xff` once the file is
//! complete, format version 1 as big-endian u16, then the root group's offset as u64) and then
//! blobs and groups anywhere after it. A data blob is its byte count (u64) then its bytes; a
//! group is its child count (u64) then one u64 per child: the child's offset, with the top
//! bit set when the child is data. An empty group is offset 0, empty data is the top bit
//! alone, and neither takes space. Every integer is little-endian.
//!
//! We build the whole tree in memory and write it children first, so every offset is known
//! when its parent is written: one pass, no seeking back (the C++ writer seeks, because it
//! streams). Readers only follow offsets, so the order is free.

/// Offsets with this bit set point at data, not at a group.
const DATA_BIT: u64 = 1 << 63;

/// A node of the tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Group(Vec<Node>),
    Data(Vec<u8>),
}

impl Node {
    pub fn data(bytes: impl Into<Vec<u8>>) -> Self {
        Node::Data(bytes.into())
    }
}

/// The file holding `root`.
pub fn write(root: &Node) -> Vec<u8> {
    let mut out = Vec::with_capacity(1 << 16);
    out.extend_from_slice(b"Ogawa");
    out.push(0xff); // frozen: the file is complete
    out.extend_from_slice(&1u16.to_be_bytes());
    out.extend_from_slice(&0u64.to_le_bytes()); // patched below
    let root_offset = match root {
        Node::Group(_) => write_node(&mut out, root),
        // The root is a group by definition; a lone blob gets one around it.
        Node::Data(_) => write_node(&mut out, &Node::Group(vec![root.clone()])),
    };
    out[8..16].copy_from_slice(&root_offset.to_le_bytes());
    out
}

/// Writes `node` (children first) and returns the offset its parent records.
fn write_node(out: &mut Vec<u8>, node: &Node) -> u64 {
    match node {
        Node::Data(bytes) if bytes.is_empty() => DATA_BIT,
        Node::Data(bytes) => {
            let offset = out.len() as u64;
            out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
            out.extend_from_slice(bytes);
            offset | DATA_BIT
        }
        Node::Group(children) if children.is_empty() => 0,
        Node::Group(children) => {
            let offsets: Vec<u64> = children.iter().map(|c| write_node(out, c)).collect();
            let offset = out.len() as u64;
            out.extend_from_slice(&(offsets.len() as u64).to_le_bytes());
            for o in offsets {
                out.extend_from_slice(&o.to_le_bytes());
            }
            offset
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn u64_at(bytes: &[u8], at: usize) -> u64 {
        u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
    }

    /// The layout the module comment describes, read back by hand: header, root group,
    /// data offsets with the top bit, empty children taking no space.
    #[test]
    fn groups_and_data_are_laid_out_as_ogawa_readers_expect() {
        let tree = Node::Group(vec![
            Node::data(vec![1u8, 2, 3]),
            Node::Group(vec![Node::data(b"ab".to_vec())]),
            Node::Group(vec![]),
            Node::data(Vec::new()),
        ]);
        let file = write(&tree);
        assert_eq!(&file[..8], b"Ogawa\xff\x00\x01");
        let root = u64_at(&file, 8) as usize;
        assert_eq!(u64_at(&file, root), 4);
        let child = |k: usize| u64_at(&file, root + 8 + 8 * k);
        let first = child(0);
        assert_ne!(first & DATA_BIT, 0);
        let at = (first & !DATA_BIT) as usize;
        assert_eq!(u64_at(&file, at), 3);
        assert_eq!(&file[at + 8..at + 11], &[1, 2, 3]);
        let group = child(1) as usize;
        assert_eq!(child(1) & DATA_BIT, 0);
        assert_eq!(u64_at(&file, group), 1);
        let inner = (u64_at(&file, group + 8) & !DATA_BIT) as usize;
        assert_eq!(&file[inner + 8..inner + 10], b"ab");
        assert_eq!(child(2), 0);
        assert_eq!(child(3), DATA_BIT);
        assert_eq!(file.len(), root + 8 + 4 * 8);
    }
}
