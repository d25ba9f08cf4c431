//! Image error in 8-bit levels: what a viewer of the written PNG sees, so the tone-mapped,
//! rounded values are compared, not the HDR radiance.

/// Error of an 8-bit RGB image against a reference of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Root-mean-square difference over every channel value, in 8-bit levels.
    pub rmse: f64,
    /// Percentage of pixels with some channel more than 1 level away from the reference.
    pub pct_over_1lsb: f64,
    /// Largest difference of any channel value, in levels.
    pub max_error: u8,
    /// `20·log10(255 / rmse)` in dB; infinite for identical images.
    pub psnr_db: f64,
}

/// Compares two RGB8 buffers (3 bytes per pixel) of equal length.
pub fn compare_rgb8(image: &[u8], reference: &[u8]) -> ErrorStats {
    assert_eq!(
        image.len(),
        reference.len(),
        "images of different sizes cannot be compared"
    );
    let mut sum_sq = 0.0f64;
    let mut max_error = 0u8;
    let mut over = 0usize;
    for (p, q) in image.chunks_exact(3).zip(reference.chunks_exact(3)) {
        let mut worst = 0u8;
        for (&a, &b) in p.iter().zip(q) {
            let d = a.abs_diff(b);
            sum_sq += f64::from(d) * f64::from(d);
            worst = worst.max(d);
        }
        max_error = max_error.max(worst);
        if worst > 1 {
            over += 1;
        }
    }
    let pixels = image.len() / 3;
    let rmse = (sum_sq / image.len().max(1) as f64).sqrt();
    ErrorStats {
        rmse,
        pct_over_1lsb: 100.0 * over as f64 / pixels.max(1) as f64,
        max_error,
        psnr_db: psnr(rmse),
    }
}

/// Peak signal-to-noise ratio for 8-bit data.
pub fn psnr(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        20.0 * (255.0 / rmse).log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_no_error() {
        let a = [10, 20, 30, 40, 50, 60];
        let s = compare_rgb8(&a, &a);
        assert_eq!(s.rmse, 0.0);
        assert_eq!(s.pct_over_1lsb, 0.0);
        assert_eq!(s.max_error, 0);
        assert!(s.psnr_db.is_infinite());
    }

    #[test]
    fn hand_computed_values() {
        // Pixel 0 differs by (1, 0, 0): within 1 LSB. Pixel 1 by (0, 2, 0): over.
        // Pixel 2 by (3, 0, 4): over. Squares: 1 + 4 + 9 + 16 = 30 over 12 values.
        let reference = [100, 100, 100, 50, 50, 50, 0, 0, 0, 200, 200, 200];
        let image = [101, 100, 100, 50, 52, 50, 3, 0, 4, 200, 200, 200];
        let s = compare_rgb8(&image, &reference);
        assert!((s.rmse - (30.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!(s.pct_over_1lsb, 50.0);
        assert_eq!(s.max_error, 4);
        // 20·log10(255/√2.5) = 44.151…
        assert!((s.psnr_db - 44.1514).abs() < 1e-3, "{}", s.psnr_db);
    }

    #[test]
    fn psnr_of_one_level() {
        // 20·log10(255) = 48.1308…
        assert!((psnr(1.0) - 48.1308).abs() < 1e-3);
    }
}
