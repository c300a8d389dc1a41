//! Image comparison shared by the golden-image tests.
#![allow(
    dead_code,
    reason = "each test binary that includes this module uses a different part of it"
)]

/// Mean absolute channel difference of two same-sized images (0-255 scale).
pub fn mean_error(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let total: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y) as u64)
        .sum();
    total as f64 / a.as_raw().len() as f64
}

/// Pixels that differ from `background` by more than a faint tint.
pub fn drawn_pixels(image: &image::RgbaImage, background: [u8; 4]) -> usize {
    image
        .pixels()
        .filter(|p| {
            p.0.iter()
                .zip(&background)
                .any(|(a, b)| a.abs_diff(*b) > 12)
        })
        .count()
}
