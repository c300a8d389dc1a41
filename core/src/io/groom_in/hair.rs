//! cyHair `.hair` (Cem Yuksel's format): a 128-byte header (`HAIR`, strand count, point
//! count, array bits, default segment count, default thickness, transparency and colour,
//! 88 bytes of text), then the arrays the bits name, in order: segments (u16 per strand),
//! points (3 × f32), thickness (f32), transparency (f32), colour (3 × f32).

use std::ops::ControlFlow;
use std::path::Path;

use super::{GroomBuilder, GroomLimits, GroomReadError, InputGroom};

const HEADER_BYTES: usize = 128;
const HAS_SEGMENTS: u32 = 1;
const HAS_POINTS: u32 = 2;
const HAS_THICKNESS: u32 = 4;

/// Parses `.hair` bytes (`path` only names the file in errors).
pub fn parse(
    path: &Path,
    bytes: &[u8],
    limits: GroomLimits,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<InputGroom, GroomReadError> {
    let mut builder = GroomBuilder::new(path, limits, progress);
    if bytes.len() < HEADER_BYTES || &bytes[..4] != b"HAIR" {
        return Err(builder.format_error("not a cyHair file (no 128-byte header starting HAIR)"));
    }
    let u32_at =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let strands = u32_at(4) as u64;
    let points = u32_at(8) as u64;
    let arrays = u32_at(12);
    let default_segments = u32_at(16) as u64;
    let default_thickness = f32::from_le_bytes([bytes[20], bytes[21], bytes[22], bytes[23]]);
    if arrays & HAS_POINTS == 0 {
        return Err(builder.format_error("the file has no points array"));
    }
    builder.expect(strands, points)?;
    // Every array's size is known from the header; the file must hold them all.
    let segments_bytes = if arrays & HAS_SEGMENTS != 0 {
        strands * 2
    } else {
        0
    };
    let points_bytes = points * 12;
    let thickness_bytes = if arrays & HAS_THICKNESS != 0 {
        points * 4
    } else {
        0
    };
    let needed = HEADER_BYTES as u64 + segments_bytes + points_bytes + thickness_bytes;
    if (bytes.len() as u64) < needed {
        return Err(builder.format_error(format!(
            "the header promises {strands} strands and {points} points ({needed} bytes with its arrays) but the file has {} bytes",
            bytes.len()
        )));
    }
    let segments_at = HEADER_BYTES;
    let points_at = segments_at + segments_bytes as usize;
    let thickness_at = points_at + points_bytes as usize;
    let f32_at =
        |at: usize| f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let mut first_point = 0u64;
    let mut widths = Vec::new();
    for strand in 0..strands as usize {
        let segments = if arrays & HAS_SEGMENTS != 0 {
            u16::from_le_bytes([
                bytes[segments_at + 2 * strand],
                bytes[segments_at + 2 * strand + 1],
            ]) as u64
        } else {
            default_segments
        };
        let count = segments + 1;
        if first_point + count > points {
            return Err(builder.format_error(format!(
                "strand {strand} runs past the {points} points the header promises"
            )));
        }
        let first = first_point as usize;
        let curve = (first..first + count as usize).map(|k| {
            let at = points_at + 12 * k;
            [f32_at(at), f32_at(at + 4), f32_at(at + 8)]
        });
        widths.clear();
        if arrays & HAS_THICKNESS != 0 {
            widths.extend((first..first + count as usize).map(|k| f32_at(thickness_at + 4 * k)));
        } else {
            widths.resize(count as usize, default_thickness);
        }
        builder.push(curve, Some(&widths), None, None)?;
        first_point += count;
    }
    if first_point != points {
        let message =
            format!("the strands use {first_point} points but the header promises {points}");
        builder.note(message);
    }
    builder.note("cyHair .hair");
    builder.finish()
}
