//! Mutations that reach deep into structured inputs: a few byte-level edits (flips,
//! interesting integers, inserted and deleted ranges, splices from another seed), and for
//! JSON text edits that keep it JSON-shaped (a number replaced by an extreme one, a string
//! replaced by a hostile path).

/// Numbers that break careless arithmetic: zero, negatives, the edges of u32 / i32 / u64,
/// huge and tiny floats, and texture-limit neighbours.
const NUMBERS: [&str; 16] = [
    "0",
    "-1",
    "1",
    "255",
    "4096",
    "4097",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "1e308",
    "-1e308",
    "1e-320",
    "0.5",
];

/// Strings a file reference could be turned into.
const STRINGS: [&str; 10] = [
    "../outside.bin",
    "/etc/passwd",
    "/dev/zero",
    "/proc/self/environ",
    "file:///etc/passwd",
    "C:\\\\x",
    "",
    "a/../../b",
    "data:application/octet-stream;base64,AAAA",
    "%2e%2e/x",
];

/// Little-endian integers for binary fields (sizes, offsets, counts).
const WORDS: [u32; 8] = [0, 1, 0x7f, 0xff, 0xffff, 0x7fff_ffff, 0x8000_0000, u32::MAX];

/// One mutated input from `seeds` (which must not be empty).
pub fn mutate(rng: &mut fastrand::Rng, seeds: &[Vec<u8>]) -> Vec<u8> {
    let mut input = seeds[rng.usize(..seeds.len())].clone();
    let rounds = 1 + rng.usize(..4);
    for _ in 0..rounds {
        let json = looks_like_json(&input);
        match rng.u32(..if json { 10 } else { 7 }) {
            0 | 1 => flip_bit(rng, &mut input),
            2 => set_byte(rng, &mut input),
            3 => set_word(rng, &mut input),
            4 => delete_range(rng, &mut input),
            5 => duplicate_range(rng, &mut input),
            6 => splice(rng, &mut input, seeds),
            7 | 8 => replace_number(rng, &mut input),
            _ => replace_string(rng, &mut input),
        }
    }
    input
}

fn looks_like_json(input: &[u8]) -> bool {
    input.first() == Some(&b'{') || input.windows(4).take(64).any(|w| w == b"\"asset")
}

fn flip_bit(rng: &mut fastrand::Rng, input: &mut [u8]) {
    if !input.is_empty() {
        let at = rng.usize(..input.len());
        input[at] ^= 1 << rng.u32(..8);
    }
}

fn set_byte(rng: &mut fastrand::Rng, input: &mut [u8]) {
    if !input.is_empty() {
        let at = rng.usize(..input.len());
        input[at] = [0, 1, 0x7f, 0x80, 0xff][rng.usize(..5)];
    }
}

fn set_word(rng: &mut fastrand::Rng, input: &mut [u8]) {
    if input.len() >= 4 {
        // Aligned positions hit binary header fields far more often.
        let at = rng.usize(..input.len() / 4) * 4;
        let word = WORDS[rng.usize(..WORDS.len())];
        input[at..at + 4].copy_from_slice(&word.to_le_bytes());
    }
}

fn delete_range(rng: &mut fastrand::Rng, input: &mut Vec<u8>) {
    if !input.is_empty() {
        let start = rng.usize(..input.len());
        let length = rng.usize(1..=(input.len() - start).min(64));
        input.drain(start..start + length);
    }
}

fn duplicate_range(rng: &mut fastrand::Rng, input: &mut Vec<u8>) {
    if !input.is_empty() && input.len() < 1 << 22 {
        let start = rng.usize(..input.len());
        let length = rng.usize(1..=(input.len() - start).min(256));
        let chunk = input[start..start + length].to_vec();
        let at = rng.usize(..=input.len());
        input.splice(at..at, chunk);
    }
}

fn splice(rng: &mut fastrand::Rng, input: &mut Vec<u8>, seeds: &[Vec<u8>]) {
    let other = &seeds[rng.usize(..seeds.len())];
    if input.is_empty() || other.is_empty() {
        return;
    }
    let cut = rng.usize(..input.len());
    let from = rng.usize(..other.len());
    input.truncate(cut);
    input.extend_from_slice(&other[from..]);
}

/// Replaces one run of digits (with its sign, fraction and exponent) by an extreme number.
fn replace_number(rng: &mut fastrand::Rng, input: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..input.len())
        .filter(|&i| input[i].is_ascii_digit() && (i == 0 || !input[i - 1].is_ascii_alphanumeric()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let start = starts[rng.usize(..starts.len())];
    let start = if start > 0 && input[start - 1] == b'-' {
        start - 1
    } else {
        start
    };
    let mut end = start + 1;
    while end < input.len() && matches!(input[end], b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-')
    {
        end += 1;
    }
    let number = NUMBERS[rng.usize(..NUMBERS.len())];
    input.splice(start..end, number.bytes());
}

/// Replaces the contents of one JSON string by a hostile path or URI.
fn replace_string(rng: &mut fastrand::Rng, input: &mut Vec<u8>) {
    let quotes: Vec<usize> = (0..input.len()).filter(|&i| input[i] == b'"').collect();
    if quotes.len() < 2 {
        return;
    }
    let pair = rng.usize(..quotes.len() / 2) * 2;
    let (open, close) = (quotes[pair], quotes[pair + 1]);
    let text = STRINGS[rng.usize(..STRINGS.len())];
    input.splice(open + 1..close, text.bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_change_inputs_and_stay_bounded() {
        let seeds = vec![
            br#"{"a": [1, 2.5e3, -4], "b": "x.bin"}"#.to_vec(),
            vec![7; 64],
        ];
        let mut rng = fastrand::Rng::with_seed(1);
        let mut changed = 0;
        for _ in 0..1000 {
            let input = mutate(&mut rng, &seeds);
            assert!(input.len() < 4096);
            changed += usize::from(!seeds.contains(&input));
        }
        assert!(changed > 900, "{changed} of 1000 inputs changed");
    }
}
