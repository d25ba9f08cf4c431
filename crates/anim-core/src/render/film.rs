//! From HDR radiance to files: `c/(c+1)` tone mapping, `round(255·c)` (or 16 bits), the
//! image formats (PNG, PPM, BMP, JPEG, TGA, OpenEXR), the alpha channel of `--alpha` from
//! each pixel's coverage, the linear radiance itself as PFM (`--hdr`), and atomic writes (a
//! reader never sees a half-written image).
//!
//! The alpha model (README, "Image formats, alpha and video codecs"): a camera sample that hits no surface
//! is transparent, so a pixel's alpha is its coverage, the fraction of its samples that hit
//! one. The background colour is not in an image with alpha: the samplers' mean counts what
//! the missed samples saw, the background, which is one colour, and the film takes it out
//! again. The colour left is the radiance of the covered samples: premultiplied by alpha in
//! OpenEXR (its convention, linear), straight in PNG and TGA (theirs, tone-mapped).

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
    /// OpenEXR: linear half or float channels, ZIP-compressed scan lines.
    Exr,
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
            "exr" => Some(ImageFormat::Exr),
            _ => image::ImageFormat::from_extension(&ext)
                .filter(|f| f.writing_enabled())
                .map(ImageFormat::Other),
        }
    }

    /// The format's name, for messages.
    fn name(self) -> String {
        match self {
            ImageFormat::Png => "PNG".to_string(),
            ImageFormat::PpmBinary | ImageFormat::PpmAscii => "PPM".to_string(),
            ImageFormat::Exr => "OpenEXR".to_string(),
            ImageFormat::Other(f) => f
                .extensions_str()
                .first()
                .map_or_else(|| format!("{f:?}"), |e| e.to_ascii_uppercase()),
        }
    }

    /// The bits of a channel the format holds, its default first.
    fn depths(self) -> &'static [u8] {
        match self {
            ImageFormat::Png => &[8, 16],
            ImageFormat::Exr => &[16, 32],
            _ => &[8],
        }
    }

    /// Whether the format has an alpha channel anim writes.
    fn holds_alpha(self) -> bool {
        matches!(
            self,
            ImageFormat::Png | ImageFormat::Exr | ImageFormat::Other(image::ImageFormat::Tga)
        )
    }
}

/// How an image file stores its pixels: the format, the bits of a channel (16 and 32 are
/// half and float in OpenEXR), whether the values are linear radiance or tone-mapped, and
/// whether there is an alpha channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Encoding {
    /// The file format.
    pub format: ImageFormat,
    /// Bits per channel.
    pub bits: u8,
    /// Linear radiance (clipped to [0, 1] in a PNG, whose gAMA chunk says 1.0) rather than
    /// the tone map's values.
    pub linear: bool,
    /// An alpha channel: each pixel's coverage.
    pub alpha: bool,
}

impl Encoding {
    /// The format's default: 8-bit tone-mapped, half-float linear for OpenEXR, no alpha.
    pub fn plain(format: ImageFormat) -> Encoding {
        Encoding {
            format,
            bits: format.depths()[0],
            linear: format == ImageFormat::Exr,
            alpha: false,
        }
    }

    /// What `--depth` (`None`: the format's default), `--linear` and `--alpha` ask of an
    /// image in `format`, or why the format cannot hold it.
    pub fn new(
        format: ImageFormat,
        depth: Option<u8>,
        linear: bool,
        alpha: bool,
    ) -> Result<Encoding, String> {
        let name = format.name();
        let plain = Encoding::plain(format);
        let bits = depth.unwrap_or(plain.bits);
        let depths = format.depths();
        if !depths.contains(&bits) {
            return Err(match (format, depths) {
                (ImageFormat::Exr, _) => format!(
                    "an OpenEXR image holds 16-bit (half) or 32-bit floats, not {bits} bits"
                ),
                (_, [8]) => format!(
                    "a {name} image holds 8 bits per channel; --depth {bits} needs a .png or .exr name"
                ),
                _ => format!("a {name} image holds 8 or 16 bits per channel, not {bits}"),
            });
        }
        if linear && !plain.linear && bits != 16 {
            return Err(if format == ImageFormat::Png {
                "--linear needs --depth 16 for a PNG image: 8 linear bits band in the shadows"
                    .to_string()
            } else {
                format!("a {name} image holds tone-mapped values; --linear needs a .png (with --depth 16) or .exr name")
            });
        }
        if alpha && !format.holds_alpha() {
            return Err(format!(
                "a {name} image has no alpha channel; --alpha needs a .png, .tga or .exr name"
            ));
        }
        Ok(Encoding {
            bits,
            linear: linear || plain.linear,
            alpha,
            ..plain
        })
    }
}

/// What an image's alpha channel is made of: each pixel's coverage (`Rendered::coverage`)
/// and the background colour that the samples that missed saw.
#[derive(Clone, Copy, Debug)]
pub struct Coverage<'a> {
    /// Per pixel, row-major, the fraction of its camera samples that hit a surface.
    pub fraction: &'a [f32],
    /// The scene's background colour (linear).
    pub background: Vec3,
}

impl Coverage<'_> {
    /// Pixel `i`'s colour without the background, and its alpha: premultiplied by alpha
    /// (the radiance of its covered samples over all its samples) or straight (over its
    /// covered samples). A pixel nothing covers is transparent black.
    fn pixel(&self, mean: Vec3, i: usize, premultiplied: bool) -> (Vec3, f32) {
        let a = self.fraction[i];
        if a <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        if a >= 1.0 {
            return (mean, 1.0);
        }
        let covered = (mean - (1.0 - a) * self.background).max(Vec3::ZERO);
        (if premultiplied { covered } else { covered / a }, a)
    }
}

/// `img` encoded as `encoding` says, in memory: the bytes of its image file. An alpha channel
/// takes its values from `coverage`, which it needs.
pub fn encode_image(
    img: &HdrImage,
    coverage: Option<&Coverage>,
    encoding: Encoding,
) -> io::Result<Vec<u8>> {
    let plain = Encoding::plain(encoding.format);
    let mut encoded = Vec::new();
    if encoding == plain && encoding.format != ImageFormat::Exr {
        let rgb = to_rgb8(img);
        encode(&mut encoded, &rgb, img.width, img.height, encoding.format)?;
        return Ok(encoded);
    }
    let coverage = match (encoding.alpha, coverage) {
        (true, None) => {
            return Err(io::Error::other(
                "an alpha channel needs each pixel's coverage",
            ))
        }
        (true, Some(c)) if c.fraction.len() != img.pixels.len() => {
            return Err(io::Error::other("the coverage has the wrong size"))
        }
        (alpha, c) => c.filter(|_| alpha),
    };
    // Premultiplied where the format's convention is (OpenEXR), straight elsewhere.
    let premultiplied = encoding.format == ImageFormat::Exr;
    let pixels = img
        .pixels
        .iter()
        .enumerate()
        .map(|(i, &mean)| match coverage {
            Some(c) => c.pixel(mean, i, premultiplied),
            None => (mean, 1.0),
        });
    match encoding.format {
        ImageFormat::Exr => encode_exr(&mut encoded, img, pixels, encoding)?,
        ImageFormat::Png => encode_png(&mut encoded, img, pixels, encoding)?,
        ImageFormat::Other(f) => {
            let rgba: Vec<u8> = pixels.flat_map(|(c, a)| channels8(c, a)).collect();
            let img = image::RgbaImage::from_raw(img.width, img.height, rgba)
                .ok_or_else(|| io::Error::other("image buffer has the wrong size"))?;
            let mut buf = io::Cursor::new(Vec::new());
            img.write_to(&mut buf, f)
                .map_err(|e| io::Error::other(e.to_string()))?;
            encoded = buf.into_inner();
        }
        ImageFormat::PpmBinary | ImageFormat::PpmAscii => {
            return Err(io::Error::other("PPM holds 8-bit RGB only"))
        }
    }
    Ok(encoded)
}

/// A pixel's four 8-bit channels: tone-mapped colour and alpha.
fn channels8(c: Vec3, a: f32) -> [u8; 4] {
    [
        tone_map_u8(c.x),
        tone_map_u8(c.y),
        tone_map_u8(c.z),
        round_level(255.0 * a.clamp(0.0, 1.0)),
    ]
}

/// One channel in 16 bits: `v` in [0, 1] (NaN as 0) scaled to 65535 and rounded.
fn level16(v: f32) -> u16 {
    if v > 0.0 {
        (65535.0 * v.min(1.0)).round() as u16
    } else {
        0
    }
}

/// A PNG of 8 or 16 bits, RGB or RGBA, tone-mapped or linear (then marked so by a gAMA
/// chunk of 1.0, which viewers and `scripts/encode.sh` read), compressed as the 8-bit one is.
fn encode_png(
    out: &mut Vec<u8>,
    img: &HdrImage,
    pixels: impl Iterator<Item = (Vec3, f32)>,
    encoding: Encoding,
) -> io::Result<()> {
    let channels = if encoding.alpha { 4 } else { 3 };
    let mut data = Vec::with_capacity(img.pixels.len() * channels * encoding.bits as usize / 8);
    for (c, a) in pixels {
        let colour = [c.x, c.y, c.z];
        if encoding.bits == 8 {
            let [r, g, b, a] = channels8(c, a);
            data.extend_from_slice(&[r, g, b, a][..channels]);
            continue;
        }
        let value = |v: f32| match encoding.linear {
            true => level16(v),
            false => level16(tone(v)),
        };
        let [r, g, b] = colour.map(value);
        for v in [r, g, b, level16(a)].into_iter().take(channels) {
            data.extend_from_slice(&v.to_be_bytes());
        }
    }
    let to_io = |e: png::EncodingError| io::Error::other(e.to_string());
    let mut encoder = png::Encoder::new(out, img.width, img.height);
    encoder.set_color(match encoding.alpha {
        true => png::ColorType::Rgba,
        false => png::ColorType::Rgb,
    });
    encoder.set_depth(match encoding.bits {
        8 => png::BitDepth::Eight,
        _ => png::BitDepth::Sixteen,
    });
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Adaptive);
    if encoding.linear {
        encoder.set_source_gamma(png::ScaledFloat::new(1.0));
    }
    let mut writer = encoder.write_header().map_err(to_io)?;
    writer.write_image_data(&data).map_err(to_io)?;
    writer.finish().map_err(to_io)
}

/// An OpenEXR file of linear radiance, half (16 bits) or float (32), with alpha
/// (premultiplied) when asked: ZIP-compressed scan lines, which every EXR reader takes.
fn encode_exr(
    out: &mut Vec<u8>,
    img: &HdrImage,
    pixels: impl Iterator<Item = (Vec3, f32)>,
    encoding: Encoding,
) -> io::Result<()> {
    use exr::prelude::{f16, Encoding as Compression, Image, Layer, LayerAttributes};
    use exr::prelude::{SpecificChannels, Vec2, WritableImage};
    let pixels: Vec<[f32; 4]> = pixels.map(|(c, a)| [c.x, c.y, c.z, a]).collect();
    let size = (img.width as usize, img.height as usize);
    let at = |p: Vec2<usize>| pixels[p.y() * size.0 + p.x()];
    let half = |v: f32| f16::from_f32(v);
    let mut cursor = io::Cursor::new(Vec::new());
    let attributes = LayerAttributes::default;
    let written = match (encoding.bits, encoding.alpha) {
        (16, false) => {
            let channels = SpecificChannels::rgb(|p| {
                let [r, g, b, _] = at(p);
                (half(r), half(g), half(b))
            });
            let layer = Layer::new(size, attributes(), Compression::SMALL_LOSSLESS, channels);
            Image::from_layer(layer)
                .write()
                .non_parallel()
                .to_buffered(&mut cursor)
        }
        (16, true) => {
            let channels = SpecificChannels::rgba(|p| {
                let [r, g, b, a] = at(p).map(half);
                (r, g, b, a)
            });
            let layer = Layer::new(size, attributes(), Compression::SMALL_LOSSLESS, channels);
            Image::from_layer(layer)
                .write()
                .non_parallel()
                .to_buffered(&mut cursor)
        }
        (_, false) => {
            let channels = SpecificChannels::rgb(|p| {
                let [r, g, b, _] = at(p);
                (r, g, b)
            });
            let layer = Layer::new(size, attributes(), Compression::SMALL_LOSSLESS, channels);
            Image::from_layer(layer)
                .write()
                .non_parallel()
                .to_buffered(&mut cursor)
        }
        (_, true) => {
            let channels = SpecificChannels::rgba(|p| {
                let [r, g, b, a] = at(p);
                (r, g, b, a)
            });
            let layer = Layer::new(size, attributes(), Compression::SMALL_LOSSLESS, channels);
            Image::from_layer(layer)
                .write()
                .non_parallel()
                .to_buffered(&mut cursor)
        }
    };
    written.map_err(|e| io::Error::other(e.to_string()))?;
    *out = cursor.into_inner();
    Ok(())
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
        ImageFormat::Exr => Err(io::Error::other("OpenEXR holds floats, not 8-bit levels")),
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

/// Writes the bytes of an encoded image to `path` atomically.
pub fn write_encoded(path: &Path, encoded: &[u8]) -> io::Result<ImageBytes> {
    crate::util::write_atomically(path, |w| w.write_all(encoded))?;
    Ok(ImageBytes {
        len: encoded.len() as u64,
        hash: crate::util::Fnv64::of(encoded),
    })
}

/// Encodes `img` in `format`'s default encoding and writes it to `path` atomically.
pub fn write_image(path: &Path, img: &HdrImage, format: ImageFormat) -> io::Result<ImageBytes> {
    write_encoded(path, &encode_image(img, None, Encoding::plain(format))?)
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

    fn format_of(path: &str) -> ImageFormat {
        ImageFormat::for_path(Path::new(path), false).unwrap()
    }

    #[test]
    fn each_format_takes_the_depths_alpha_and_linearity_it_can_hold() {
        let png = ImageFormat::Png;
        let exr = format_of("a.EXR");
        let tga = format_of("a.tga");
        let jpg = format_of("a.jpg");
        assert_eq!(exr, ImageFormat::Exr);
        let ok = |f, depth, linear, alpha| Encoding::new(f, depth, linear, alpha).is_ok();
        // PNG: 8 or 16 bits; linear only in 16; alpha in both.
        assert!(ok(png, None, false, true) && ok(png, Some(16), true, true));
        assert!(!ok(png, Some(32), false, false) && !ok(png, Some(8), true, false));
        // OpenEXR: half by default, float on request, always linear.
        let half = Encoding::new(exr, None, false, false).unwrap();
        assert_eq!((half.bits, half.linear), (16, true));
        assert!(ok(exr, Some(32), true, true) && !ok(exr, Some(8), false, false));
        // TGA: 8 bits, alpha; JPEG: 8 bits, neither alpha nor linear.
        assert!(ok(tga, None, false, true) && !ok(tga, Some(16), false, false));
        assert!(!ok(jpg, None, false, true) && !ok(jpg, None, true, false));
        let why = Encoding::new(jpg, Some(16), false, false).unwrap_err();
        assert!(
            why.contains("8 bits") && why.contains(".png or .exr"),
            "{why}"
        );
        assert_eq!(
            Encoding::plain(png),
            Encoding::new(png, None, false, false).unwrap()
        );
    }

    #[test]
    fn sixteen_bits_scaled_to_eight_are_the_eight_bit_levels_within_one() {
        let values = (0..20_000).map(|k| k as f32 * 1e-3).chain([1e-7, 1e3, 1e6]);
        for c in values {
            let deep = f64::from(level16(tone(c)));
            let shallow = f64::from(tone_map_u8(c));
            assert!(
                (deep / 257.0 - shallow).abs() <= 1.0,
                "{c}: {deep} {shallow}"
            );
            assert_eq!((deep / 257.0).round(), shallow, "{c}");
        }
    }

    /// A 2×1 image whose left pixel is a third covered by a surface of radiance `c` over the
    /// background `bg`, whose right pixel shows only the background.
    fn partly_covered(c: Vec3, bg: Vec3) -> (HdrImage, Vec<f32>) {
        let a = 1.0 / 3.0;
        let img = HdrImage {
            width: 2,
            height: 1,
            pixels: vec![a * c + (1.0 - a) * bg, bg],
        };
        (img, vec![a, 0.0])
    }

    #[test]
    fn alpha_leaves_the_background_out_straight_in_png_premultiplied_in_exr() {
        let (c, bg) = (Vec3::new(3.0, 1.0, 0.25), Vec3::new(0.5, 0.75, 2.0));
        let (img, fraction) = partly_covered(c, bg);
        let coverage = Coverage {
            fraction: &fraction,
            background: bg,
        };
        let straight = coverage.pixel(img.pixels[0], 0, false);
        let premultiplied = coverage.pixel(img.pixels[0], 0, true);
        assert!((straight.0 - c).abs().max_element() < 1e-5, "{straight:?}");
        assert!((premultiplied.0 - c / 3.0).abs().max_element() < 1e-5);
        assert_eq!(coverage.pixel(img.pixels[1], 1, false), (Vec3::ZERO, 0.0));
        let encoding = Encoding::new(ImageFormat::Png, None, false, true).unwrap();
        let png = encode_image(&img, Some(&coverage), encoding).unwrap();
        let decoded = image::load_from_memory(&png).unwrap().to_rgba8();
        let expected = [tone_map_u8(3.0), tone_map_u8(1.0), tone_map_u8(0.25), 85];
        assert_eq!(decoded.get_pixel(0, 0).0, expected);
        assert_eq!(decoded.get_pixel(1, 0).0, [0, 0, 0, 0]);
        // No coverage, no alpha channel to write.
        assert!(encode_image(&img, None, encoding).is_err());
    }

    /// The channels of the first layer of an OpenEXR file, by name, as f32.
    fn read_exr(bytes: &[u8]) -> Vec<(String, Vec<f32>)> {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_buffered(io::Cursor::new(bytes))
            .unwrap();
        let layer = &image.layer_data[0];
        layer
            .channel_data
            .list
            .iter()
            .map(|ch| {
                let values = ch.sample_data.values_as_f32().collect();
                (ch.name.to_string(), values)
            })
            .collect()
    }

    #[test]
    fn exr_holds_the_radiance_in_half_or_float_with_premultiplied_alpha() {
        let (c, bg) = (Vec3::new(3.0, 1.0, 0.25), Vec3::new(0.5, 0.75, 2.0));
        let (img, fraction) = partly_covered(c, bg);
        let coverage = Coverage {
            fraction: &fraction,
            background: bg,
        };
        for bits in [16, 32] {
            let plain = Encoding::new(ImageFormat::Exr, Some(bits), false, false).unwrap();
            let channels = read_exr(&encode_image(&img, None, plain).unwrap());
            let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(names, ["B", "G", "R"]);
            let tolerance = if bits == 16 { 1.0 / 2048.0 } else { 0.0 };
            for (k, (_, values)) in channels.iter().enumerate() {
                for (i, v) in values.iter().enumerate() {
                    let expected = img.pixels[i][2 - k];
                    assert!(
                        (v - expected).abs() <= expected * tolerance,
                        "{bits}: {v} {expected}"
                    );
                }
            }
            let alpha = Encoding::new(ImageFormat::Exr, Some(bits), false, true).unwrap();
            let channels = read_exr(&encode_image(&img, Some(&coverage), alpha).unwrap());
            let value = |name: &str, i: usize| {
                channels
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| v[i])
                    .unwrap()
            };
            assert!((value("A", 0) - 1.0 / 3.0).abs() <= 1e-3);
            assert!((value("R", 0) - 1.0).abs() <= 1e-3, "3 × ⅓");
            assert_eq!((value("R", 1), value("A", 1)), (0.0, 0.0));
        }
    }

    #[test]
    fn a_linear_png_says_so_in_its_gama_chunk() {
        let img = HdrImage {
            width: 1,
            height: 1,
            pixels: vec![Vec3::new(0.5, 2.0, 0.0)],
        };
        let linear = Encoding::new(ImageFormat::Png, Some(16), true, false).unwrap();
        let png = encode_image(&img, None, linear).unwrap();
        // IHDR (8 + 25 bytes after the 8-byte signature), then gAMA: 100000 is gamma 1.0.
        assert_eq!(&png[33 + 4..33 + 8], b"gAMA");
        assert_eq!(&png[33 + 8..33 + 12], &100_000u32.to_be_bytes());
        let decoded = image::load_from_memory(&png).unwrap().to_rgb16();
        assert_eq!(decoded.get_pixel(0, 0).0, [32768, 65535, 0]);
        let toned = Encoding::new(ImageFormat::Png, Some(16), false, false).unwrap();
        let png = encode_image(&img, None, toned).unwrap();
        assert_ne!(&png[33 + 4..33 + 8], b"gAMA");
        let decoded = image::load_from_memory(&png).unwrap().to_rgb16();
        assert_eq!(decoded.get_pixel(0, 0).0, [21845, 43690, 0]);
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
