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

/// Pixels of one range of adaptive sampling's error estimate, with the error measured there.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationBin {
    /// The range of estimates, in 8-bit levels (`None`: pixels that kept their centre sample,
    /// for which nothing was estimated).
    pub estimate: Option<(f32, f32)>,
    pub pixels: usize,
    /// Mean estimate of the bin's pixels (NaN for the unestimated).
    pub mean_estimate: f64,
    /// Root-mean-square of the measured per-pixel error against the reference, in levels.
    pub measured_rms: f64,
}

/// Upper ends of the estimate ranges (levels); the last range is open.
const CALIBRATION_EDGES: [f32; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, f32::INFINITY];

/// How well the per-pixel error estimate predicts the error measured against the reference:
/// pixels binned by estimate, each bin with its mean estimate and measured RMS error (a pixel's
/// error is the RMS over its three channels). Bins without pixels are left out.
pub fn calibration(image: &[u8], reference: &[u8], estimates: &[f32]) -> Vec<CalibrationBin> {
    assert_eq!(image.len(), reference.len());
    assert_eq!(image.len(), estimates.len() * 3);
    // (pixels, sum of estimates, sum of squared errors) per bin; bin 0: not estimated.
    let mut sums = [(0usize, 0.0f64, 0.0f64); CALIBRATION_EDGES.len() + 1];
    let pixels = image.chunks_exact(3).zip(reference.chunks_exact(3));
    for ((p, q), &e) in pixels.zip(estimates) {
        let sq: f64 = p
            .iter()
            .zip(q)
            .map(|(&a, &b)| f64::from(a.abs_diff(b)).powi(2))
            .sum::<f64>()
            / 3.0;
        let bin = if e.is_nan() {
            0
        } else {
            1 + CALIBRATION_EDGES
                .iter()
                .position(|&hi| e < hi)
                .unwrap_or(CALIBRATION_EDGES.len() - 1)
        };
        let s = &mut sums[bin];
        s.0 += 1;
        s.1 += if e.is_finite() { f64::from(e) } else { 0.0 };
        s.2 += sq;
    }
    sums.iter()
        .enumerate()
        .filter(|(_, s)| s.0 > 0)
        .map(|(bin, &(n, est, sq))| CalibrationBin {
            estimate: (bin > 0).then(|| {
                let lo = if bin == 1 {
                    0.0
                } else {
                    CALIBRATION_EDGES[bin - 2]
                };
                (lo, CALIBRATION_EDGES[bin - 1])
            }),
            pixels: n,
            mean_estimate: if bin == 0 { f64::NAN } else { est / n as f64 },
            measured_rms: (sq / n as f64).sqrt(),
        })
        .collect()
}

/// The calibration as one line: `kept n: rms; est lo–hi n: mean → rms; …`.
pub fn calibration_line(bins: &[CalibrationBin]) -> String {
    bins.iter()
        .map(|b| match b.estimate {
            None => format!(
                "kept centre ({} px): measured {:.2}",
                b.pixels, b.measured_rms
            ),
            Some((lo, hi)) => format!(
                "est {lo}–{hi} ({} px, mean {:.2}): measured {:.2}",
                b.pixels, b.mean_estimate, b.measured_rms
            ),
        })
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod calibration_tests {
    use super::*;

    #[test]
    fn pixels_fall_in_the_bins_of_their_estimates() {
        // Three pixels: kept (off by 3 in every channel), estimated 0.7 (off by 0), estimated
        // 5 (off by 6 in one channel: RMS over channels √(36/3) = √12).
        let image = [3, 3, 3, 10, 10, 10, 6, 0, 0];
        let reference = [0, 0, 0, 10, 10, 10, 0, 0, 0];
        let bins = calibration(&image, &reference, &[f32::NAN, 0.7, 5.0]);
        assert_eq!(bins.len(), 3);
        assert_eq!((bins[0].estimate, bins[0].pixels), (None, 1));
        assert!((bins[0].measured_rms - 3.0).abs() < 1e-12);
        assert_eq!(bins[1].estimate, Some((0.5, 1.0)));
        assert_eq!(bins[1].measured_rms, 0.0);
        assert_eq!(bins[2].estimate, Some((4.0, 8.0)));
        assert!((bins[2].measured_rms - 12f64.sqrt()).abs() < 1e-12);
        assert!((bins[2].mean_estimate - 5.0).abs() < 1e-12);
    }
}
