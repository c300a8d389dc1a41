//! IEEE binary16 conversions of the runtime textures: what an f16 texture stores, as bits
//! (for KTX2 files and GPU uploads) and as the f32 value the GPU reads back. One policy for
//! all three, on the `half` crate's round-to-nearest-even: values past the half range clamp
//! to ±65504 (a texture never holds ±∞) and NaN becomes 0 (a texture never holds NaN).

use half::f16;

/// The largest finite half.
const F16_MAX: f32 = 65504.0;

/// IEEE binary16 bits of `value` (round to nearest even, overflow clamped to ±65504, NaN 0).
pub(crate) fn f16_bits(value: f32) -> u16 {
    let value = if value.is_nan() {
        0.0
    } else {
        value.clamp(-F16_MAX, F16_MAX)
    };
    f16::from_f32(value).to_bits()
}

/// The f32 value of half-precision `bits`.
pub(crate) fn f16_to_f32(bits: u16) -> f32 {
    f16::from_bits(bits).to_f32()
}

/// `value` as an f16 texture stores it: [`f16_bits`] and back.
pub(crate) fn round_to_f16(value: f32) -> f32 {
    f16_to_f32(f16_bits(value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_rounding_matches_ieee() {
        assert_eq!(round_to_f16(1.0), 1.0);
        assert_eq!(round_to_f16(1.0 + 1.0 / 2048.0), 1.0, "tie rounds to even");
        assert_eq!(round_to_f16(1.0 + 3.0 / 2048.0), 1.0 + 2.0 / 1024.0);
        assert_eq!(round_to_f16(0.1), 0.099_975_586);
        assert_eq!(round_to_f16(1e6), 65504.0);
        assert_eq!(round_to_f16(-2.0e-8), -0.0);
        assert_eq!(
            round_to_f16(3.0e-8),
            2f32.powi(-24),
            "rounds up to the smallest subnormal"
        );
        assert_eq!(round_to_f16(f32::NAN), 0.0);
    }

    #[test]
    fn half_bits_match_ieee() {
        assert_eq!(f16_bits(1.0), 0x3C00);
        assert_eq!(f16_bits(-2.0), 0xC000);
        assert_eq!(f16_bits(0.1), 0x2E66);
        assert_eq!(f16_bits(65504.0), 0x7BFF);
        assert_eq!(f16_bits(1e9), 0x7BFF);
        assert_eq!(f16_bits(2f32.powi(-24)), 0x0001);
        assert_eq!(f16_bits(0.5), 0x3800);
        assert_eq!(f16_bits(0.0), 0);
    }

    #[test]
    fn every_finite_half_round_trips_and_infinities_clamp() {
        for bits in 0..=u16::MAX {
            let value = f16_to_f32(bits);
            if value.is_finite() {
                assert_eq!(
                    f16_bits(value).to_ne_bytes(),
                    bits.to_ne_bytes(),
                    "{bits:#06x}"
                );
                assert_eq!(round_to_f16(value), value);
            }
        }
        assert_eq!(round_to_f16(f32::INFINITY), F16_MAX);
        assert_eq!(round_to_f16(f32::NEG_INFINITY), -F16_MAX);
    }
}
