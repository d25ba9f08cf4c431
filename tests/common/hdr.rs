//! Reading what `anim render --hdr` writes (PFM radiance beside each image) and the 8-bit
//! images themselves, and measuring how far two images are apart.

use super::Rgb8;
use std::path::Path;

/// Linear radiance, row-major from the top row (as the 8-bit images are).
pub struct Pfm {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

/// Reads a colour PFM as anim writes it: `PF`, the size, a negative scale (little-endian), then
/// the rows from the bottom up. Anything else fails the test with the reason.
pub fn read_pfm(path: &Path) -> Pfm {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = bytes.splitn(4, |&b| b == b'\n');
    let mut field =
        || String::from_utf8_lossy(lines.next().expect("a PFM header line")).into_owned();
    let (magic, size, scale) = (field(), field(), field());
    assert_eq!(magic, "PF", "{}: not a colour PFM", path.display());
    let scale: f32 = scale.trim().parse().expect("a PFM scale");
    assert!(
        scale < 0.0,
        "{}: scale {scale} is not little-endian",
        path.display()
    );
    let mut dims = size
        .split_whitespace()
        .map(|n| n.parse::<usize>().expect("a PFM size"));
    let (width, height) = (dims.next().unwrap(), dims.next().unwrap());
    let data = lines.next().unwrap_or_default();
    assert_eq!(
        data.len(),
        width * height * 12,
        "{}: wrong data length",
        path.display()
    );
    let floats: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let mut pixels = Vec::with_capacity(width * height);
    for row in floats.chunks(width * 3).rev() {
        pixels.extend(row.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
    }
    Pfm {
        width,
        height,
        pixels,
    }
}

/// Reads a PNG as 8-bit RGB.
pub fn read_png(path: &Path) -> Rgb8 {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    Rgb8 {
        width: img.width() as usize,
        height: img.height() as usize,
        data: img.into_raw(),
    }
}

/// The per-pixel mean of several radiance images of one size.
pub fn mean(images: &[Pfm]) -> Pfm {
    let first = &images[0];
    let mut sum = vec![[0f64; 3]; first.pixels.len()];
    for img in images {
        assert_eq!((img.width, img.height), (first.width, first.height));
        for (s, p) in sum.iter_mut().zip(&img.pixels) {
            for c in 0..3 {
                s[c] += f64::from(p[c]);
            }
        }
    }
    let n = images.len() as f64;
    Pfm {
        width: first.width,
        height: first.height,
        pixels: sum
            .iter()
            .map(|s| [(s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32])
            .collect(),
    }
}

/// Root mean square difference of two 8-bit images over every channel, in levels.
pub fn rmse(a: &Rgb8, b: &Rgb8) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let sum: f64 = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum();
    (sum / a.data.len() as f64).sqrt()
}
