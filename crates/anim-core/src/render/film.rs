//! From HDR radiance to files: `c/(c+1)` tone mapping, `round(255·c)`, PNG/PPM encoding, the
//! linear radiance itself as PFM (`--hdr`), and atomic writes (a reader never sees a
//! half-written image).

use glam::{Vec3, Vec3A};
use std::io::{self, Write};
use std::path::Path;

/// Linear (HDR) radiance per pixel, row 0 at the top: what the samplers fill.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major, `width × height`, linear radiance per channel.
    pub pixels: Vec<Vec3>,
}

/// The tone map of one channel (docs/shading.md §4): `c_ldr = c_hdr / (c_hdr + 1)`, in
/// [0, 1]. Negative or NaN input (which the renderer never produces) maps to 0, infinity to 1.
/// Adaptive sampling judges a pixel's error in these units too, times 255.
#[inline]
pub fn tone(c: f32) -> f32 {
    if c > 0.0 {
        if c == f32::INFINITY {
            1.0
        } else {
            c / (c + 1.0)
        }
    } else {
        0.0
    }
}

/// [`tone`] of each channel.
#[inline]
pub fn tone3(c: Vec3A) -> Vec3A {
    Vec3A::new(tone(c.x), tone(c.y), tone(c.z))
}

/// One channel as stored in an 8-bit image: `round(255·tone(c))`.
#[inline]
pub fn tone_map_u8(c: f32) -> u8 {
    // The ends without the rounding (much of many images is black background), and so that
    // the division in `tone` is all that is left for the rest.
    if c.is_nan() || c <= 0.0 {
        return 0;
    }
    if c == f32::INFINITY {
        return 255;
    }
    round_level(255.0 * tone(c))
}

/// `v.round() as u8` for `v` in [0, 255], without the library call `f32::round` is on CPUs the
/// build does not assume to round in hardware (three calls a pixel). Exact: `v` minus its whole part is a float subtraction without
/// rounding (the two are within a factor two of each other, or the whole part is 0).
#[inline]
fn round_level(v: f32) -> u8 {
    let whole = v as u8;
    whole + (v - whole as f32 >= 0.5) as u8
}

/// 8-bit RGB, row-major from the top row.
pub fn to_rgb8(img: &HdrImage) -> Vec<u8> {
    // Filled in place: collected from a flat map, each byte took a capacity check and a push.
    let mut rgb = vec![0u8; img.pixels.len() * 3];
    for (p, out) in img.pixels.iter().zip(rgb.chunks_exact_mut(3)) {
        out.copy_from_slice(&[tone_map_u8(p.x), tone_map_u8(p.y), tone_map_u8(p.z)]);
    }
    rgb
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
/// How an image file is encoded, from its extension.
pub enum ImageFormat {
    /// PNG, fast compression.
    Png,
    /// Binary PPM (P6).
    PpmBinary,
    /// ASCII PPM (P3, `--ppm-ascii`).
    PpmAscii,
    /// Another format the `image` crate writes (BMP, JPEG, TGA).
    Other(image::ImageFormat),
}

impl ImageFormat {
    /// The format for a file name, by its extension (case-insensitive).
    pub fn for_path(path: &Path, ppm_ascii: bool) -> Option<ImageFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        if !crate::limits::is_image_extension(&ext) {
            return None;
        }
        match ext.as_str() {
            "png" => Some(ImageFormat::Png),
            "ppm" if ppm_ascii => Some(ImageFormat::PpmAscii),
            "ppm" => Some(ImageFormat::PpmBinary),
            _ => image::ImageFormat::from_extension(&ext)
                .filter(|f| f.writing_enabled())
                .map(ImageFormat::Other),
        }
    }
}

fn encode(
    out: &mut impl Write,
    rgb: &[u8],
    width: u32,
    height: u32,
    format: ImageFormat,
) -> io::Result<()> {
    use image::ImageEncoder;
    let to_io = |e: image::ImageError| io::Error::other(e.to_string());
    match format {
        ImageFormat::Png => {
            // Fast compression: at 120 frames, deflate effort is a real share of the run.
            let enc = image::codecs::png::PngEncoder::new_with_quality(
                out,
                image::codecs::png::CompressionType::Fast,
                image::codecs::png::FilterType::Adaptive,
            );
            enc.write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
                .map_err(to_io)
        }
        ImageFormat::PpmBinary => {
            write!(out, "P6\n{width} {height}\n255\n")?;
            out.write_all(rgb)
        }
        ImageFormat::PpmAscii => {
            write!(out, "P3\n{width} {height}\n255\n")?;
            for row in rgb.chunks(width as usize * 3) {
                let line: Vec<String> = row.iter().map(u8::to_string).collect();
                writeln!(out, "{}", line.join(" "))?;
            }
            Ok(())
        }
        ImageFormat::Other(f) => {
            let img = image::RgbImage::from_raw(width, height, rgb.to_vec())
                .ok_or_else(|| io::Error::other("image buffer has the wrong size"))?;
            let mut buf = io::Cursor::new(Vec::new());
            img.write_to(&mut buf, f).map_err(to_io)?;
            out.write_all(buf.get_ref())
        }
    }
}

/// What was written to an image file: its length and a fingerprint of its exact bytes, so
/// that a later run can tell the file is still the one this run wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageBytes {
    /// Its length in bytes.
    pub len: u64,
    /// The FNV-1a hash of its bytes.
    pub hash: u64,
}

/// `img` tone-mapped and encoded as `format`, in memory: the bytes of its image file.
pub fn encode_image(img: &HdrImage, format: ImageFormat) -> io::Result<Vec<u8>> {
    let rgb = to_rgb8(img);
    let mut encoded = Vec::new();
    encode(&mut encoded, &rgb, img.width, img.height, format)?;
    Ok(encoded)
}

/// Writes the bytes of an encoded image to `path` atomically.
pub fn write_encoded(path: &Path, encoded: &[u8]) -> io::Result<ImageBytes> {
    crate::util::write_atomically(path, |w| w.write_all(encoded))?;
    Ok(ImageBytes {
        len: encoded.len() as u64,
        hash: crate::util::Fnv64::of(encoded),
    })
}

/// Encodes `img` and writes it to `path` atomically.
pub fn write_image(path: &Path, img: &HdrImage, format: ImageFormat) -> io::Result<ImageBytes> {
    write_encoded(path, &encode_image(img, format)?)
}

/// Where `--hdr` writes the linear radiance of the image written to `image`: beside it, with
/// the extension `.pfm`.
pub fn hdr_path(image: &Path) -> std::path::PathBuf {
    image.with_extension("pfm")
}

/// Portable float map of the radiance before tone mapping: `PF`, the size, then a scale whose
/// negative sign declares little-endian floats, then RGB `f32` triples with the bottom row
/// first, as the format defines (readers such as POV-Ray, pfstools and OpenCV expect it).
pub fn encode_pfm(img: &HdrImage) -> Vec<u8> {
    let header = format!("PF\n{} {}\n-1.0\n", img.width, img.height);
    let mut out = Vec::with_capacity(header.len() + img.pixels.len() * 12);
    out.extend_from_slice(header.as_bytes());
    let width = img.width.max(1) as usize;
    for row in img.pixels.chunks(width).rev() {
        for p in row {
            for c in [p.x, p.y, p.z] {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

/// Writes `img`'s radiance to `path` as PFM, atomically.
pub fn write_pfm(path: &Path, img: &HdrImage) -> io::Result<ImageBytes> {
    write_encoded(path, &encode_pfm(img))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn tone_mapping_values() {
        assert_eq!(tone_map_u8(0.0), 0);
        assert_eq!(tone_map_u8(1.0), 128); // 127.5 rounds away from zero
        assert_eq!(tone_map_u8(3.0), 191); // 255·0.75 = 191.25
        assert_eq!(tone_map_u8(f32::INFINITY), 255);
        assert_eq!(tone_map_u8(f32::NAN), 0);
        assert_eq!(tone_map_u8(-1.0), 0);
    }

    #[test]
    fn formats_by_extension() {
        assert_eq!(
            ImageFormat::for_path(Path::new("a.PNG"), false),
            Some(ImageFormat::Png)
        );
        assert_eq!(
            ImageFormat::for_path(Path::new("a.ppm"), false),
            Some(ImageFormat::PpmBinary)
        );
        assert_eq!(
            ImageFormat::for_path(Path::new("a.ppm"), true),
            Some(ImageFormat::PpmAscii)
        );
        assert_eq!(ImageFormat::for_path(Path::new("a"), false), None);
        assert_eq!(ImageFormat::for_path(Path::new("a.xyz"), false), None);
    }

    #[test]
    fn ppm_round_trip_and_no_temp_left() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.ppm");
        let img = HdrImage {
            width: 2,
            height: 1,
            pixels: vec![Vec3::new(1.0, 0.0, 3.0), Vec3::ZERO],
        };
        let written = write_image(&path, &img, ImageFormat::PpmBinary).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(written.len, bytes.len() as u64);
        assert_eq!(written.hash, crate::util::Fnv64::of(&bytes));
        assert_eq!(&bytes[..11], b"P6\n2 1\n255\n");
        assert_eq!(&bytes[11..], &[128, 0, 191, 0, 0, 0]);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn pfm_is_little_endian_with_the_bottom_row_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = hdr_path(&dir.path().join("x.png"));
        assert_eq!(path, dir.path().join("x.pfm"));
        // Two rows: the top one (written last) holds 1.5 and 0.25, the bottom one 3 and 0.
        let img = HdrImage {
            width: 2,
            height: 2,
            pixels: vec![
                Vec3::new(1.5, 0.0, 0.25),
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::ZERO,
            ],
        };
        let written = write_pfm(&path, &img).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(written.len, bytes.len() as u64);
        assert_eq!(written.hash, crate::util::Fnv64::of(&bytes));
        let header = b"PF\n2 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(
            floats,
            [3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.25, 0.0, 2.0, 0.0]
        );
        // 1.5 is 0x3FC00000: the low byte comes first.
        let first_top = header.len() + 2 * 3 * 4;
        assert_eq!(&bytes[first_top..first_top + 4], &[0x00, 0x00, 0xC0, 0x3F]);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn round_level_is_the_library_round_at_every_half_and_between() {
        let mut values = Vec::new();
        for k in 0..=255u32 {
            let half = k as f32 + 0.5;
            values.extend([k as f32, half, half.next_up(), half.next_down()]);
        }
        // And a spread of all floats in [0, 255].
        values.extend((0..255f32.to_bits()).step_by(997).map(f32::from_bits));
        for v in values.into_iter().filter(|v| (0.0..=255.0).contains(v)) {
            assert_eq!(round_level(v), v.round() as u8, "{v}");
        }
    }
}
