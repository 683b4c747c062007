//! A designer's picture read as a target outline: a PNG or JPEG file decoded and told apart
//! into ink and background, one bit per pixel ([`Bitmap`]), for
//! [`Outline::new`](sylva_fitness::silhouette::Outline::new) to normalise.
//!
//! Which pixels are ink:
//! - a picture with an alpha channel that is not opaque everywhere (a cut-out): the pixels at
//!   least half opaque, whatever their colour, so a white shape on a transparent background
//!   is a shape;
//! - any other picture: the pixels darker than a [`Threshold`], a tree drawn or photographed
//!   dark against a light background. [`Threshold::Otsu`] finds the level from the picture's
//!   own histogram ([`otsu`]), so a photo of a tree against the sky needs no tuning.
//!
//! The format comes from the content, not the file's name. Pictures are untrusted input:
//! files over [`MAX_FILE`] bytes are refused before they are read whole, and pictures wider
//! or taller than [`MAX_SIDE`] pixels, or that would decode into more than [`MAX_DECODED`]
//! bytes, are refused from their header before any pixel is decoded (a decompression bomb
//! is a small file with a huge header).

use std::io::Cursor;
use std::path::Path;

use image::error::LimitErrorKind;
use image::{DynamicImage, ImageBuffer, ImageDecoder, ImageError, ImageFormat, Limits, Pixel};
use serde::de;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_fitness::silhouette::Bitmap;

use crate::error::InputError;

/// Largest picture file read: 64 MiB.
pub const MAX_FILE: u64 = 64 << 20;

/// Widest and tallest picture read, in pixels: an outline is compared at a few hundred
/// rows, so larger pictures add nothing but memory.
pub const MAX_SIDE: u32 = 8192;

/// Most memory a decoded picture may take, in bytes: 256 MiB (8192 x 8192 pixels of 8-bit
/// RGBA).
pub const MAX_DECODED: u64 = 256 << 20;

/// How a picture's pixels are told apart into ink and background, when it has no
/// transparency to tell them apart by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Threshold {
    /// Otsu's level for the picture's histogram ([`otsu`]): the level that best splits it
    /// into a dark class and a light one.
    #[default]
    Otsu,
    /// A luminance level from 0 (black) to 1 (white): ink is darker than it.
    Level(f32),
}

// In configs: `"otsu"` or the level.
impl Serialize for Threshold {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Threshold::Otsu => s.serialize_str("otsu"),
            Threshold::Level(l) => s.serialize_f32(*l),
        }
    }
}

impl<'de> Deserialize<'de> for Threshold {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Name(String),
            Level(f64),
        }
        let expected = "`\"otsu\"` or a luminance from 0 to 1";
        match Raw::deserialize(d) {
            Ok(Raw::Name(name)) if name == "otsu" => Ok(Threshold::Otsu),
            Ok(Raw::Level(l)) if (0.0..=1.0).contains(&l) => Ok(Threshold::Level(l as f32)),
            Ok(Raw::Name(name)) => Err(de::Error::custom(format!(
                "unknown threshold `{name}`; expected {expected}"
            ))),
            Ok(Raw::Level(l)) => Err(de::Error::custom(format!(
                "threshold {l} is out of range; expected {expected}"
            ))),
            Err(_) => Err(de::Error::custom(format!("expected {expected}"))),
        }
    }
}

/// Reads a PNG or JPEG picture and returns its ink as a bitmap (one bit per pixel, same
/// size). A file that cannot be opened keeps the system's reason in [`InputError::io`].
pub fn load_target(path: &Path, threshold: Threshold) -> Result<Bitmap, InputError> {
    // A bad threshold is found before a large file is read for nothing.
    check_threshold(path, threshold)?;
    let bytes = crate::files::read_bytes(path, MAX_FILE)?;
    decode_target(path, &bytes, threshold)
}

/// The same from bytes already read (`path` names them in errors).
pub fn decode_target(
    path: &Path,
    bytes: &[u8],
    threshold: Threshold,
) -> Result<Bitmap, InputError> {
    check_threshold(path, threshold)?;
    let image = decode(path, bytes)?;
    let translucent = image.color().has_alpha() && {
        let mut any = false;
        each_pixel(&image, |_, _, _, alpha| any |= alpha < 1.0);
        any
    };
    let mut ink = Bitmap::new(image.width(), image.height());
    if translucent {
        each_pixel(&image, |x, y, _, alpha| {
            if alpha >= 0.5 {
                ink.set(x, y);
            }
        });
        return Ok(ink);
    }
    let level = match threshold {
        Threshold::Level(level) => level,
        Threshold::Otsu => {
            let mut histogram = [0u64; 256];
            each_pixel(&image, |_, _, luma, _| histogram[usize::from(luma)] += 1);
            otsu(&histogram)
        }
    };
    // Pixels are compared as the 8-bit luminance the histogram counts, so Otsu's split and
    // the ink agree exactly.
    let dark: [bool; 256] = std::array::from_fn(|bin| (bin as f32 / 255.0) < level);
    each_pixel(&image, |x, y, luma, _| {
        if dark[usize::from(luma)] {
            ink.set(x, y);
        }
    });
    Ok(ink)
}

/// A picture held in memory (8-bit pixels, `channels` to a pixel: 1 grey, 3 RGB, 4 RGBA;
/// rows top first) as PNG bytes, for what reads targets from files: a front end's picture
/// in memory (Python's numpy mask) becomes the file a config can name. `name` names it in
/// errors.
pub fn encode_png(
    name: &str,
    width: u32,
    height: u32,
    channels: u8,
    pixels: Vec<u8>,
) -> Result<Vec<u8>, InputError> {
    let bad = |message: String| InputError::new(name, message);
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(bad(format!(
            "{width} x {height} pixels; expected 1 to {MAX_SIDE} on each side"
        )));
    }
    let wrong = || bad("the pixels do not fill the picture".to_owned());
    let image = match channels {
        1 => DynamicImage::ImageLuma8(
            ImageBuffer::from_raw(width, height, pixels).ok_or_else(wrong)?,
        ),
        3 => {
            DynamicImage::ImageRgb8(ImageBuffer::from_raw(width, height, pixels).ok_or_else(wrong)?)
        }
        4 => DynamicImage::ImageRgba8(
            ImageBuffer::from_raw(width, height, pixels).ok_or_else(wrong)?,
        ),
        n => return Err(bad(format!("{n} channels; expected 1, 3 or 4"))),
    };
    let mut png = Cursor::new(Vec::new());
    image
        .write_to(&mut png, ImageFormat::Png)
        .map_err(|e| bad(e.to_string()))?;
    Ok(png.into_inner())
}

/// Otsu's threshold of a 256-bin luminance histogram, as a level 0..=1: the split into a dark
/// class (the bins below the level) and a light one with the greatest variance between
/// their means. When a run of empty bins separates the classes, the level is in the middle
/// of the run, halfway between them rather than hugging the dark one. A histogram of fewer
/// than two distinct bins has no split: 0.5, so a uniform dark picture is all ink and a
/// uniform light one none.
pub fn otsu(histogram: &[u64; 256]) -> f32 {
    let total: f64 = histogram.iter().map(|&n| n as f64).sum();
    let total_sum: f64 = histogram
        .iter()
        .enumerate()
        .map(|(bin, &n)| bin as f64 * n as f64)
        .sum();
    let (mut dark, mut dark_sum) = (0.0f64, 0.0f64);
    // The best split so far, and the run of splits after it (through empty bins) that score
    // the same.
    let mut best: Option<(f64, usize, usize)> = None;
    for (bin, &n) in histogram.iter().enumerate() {
        dark += n as f64;
        dark_sum += bin as f64 * n as f64;
        let light = total - dark;
        if dark == 0.0 {
            continue;
        }
        if light == 0.0 {
            break;
        }
        let gap = dark_sum / dark - (total_sum - dark_sum) / light;
        let between = dark * light * gap * gap;
        best = match best {
            Some((score, first, last)) if between == score && last + 1 == bin => {
                Some((score, first, bin))
            }
            Some((score, ..)) if between <= score => best,
            _ => Some((between, bin, bin)),
        };
    }
    match best {
        // Splitting after any bin of `first..=last` gives the same classes (the bins between
        // are empty): the level is halfway across, between bin `first` and bin `last + 1`.
        Some((_, first, last)) => (first + last + 1) as f32 / 2.0 / 255.0,
        None => 0.5,
    }
}

/// Refuses a level outside 0..=1 (or NaN).
fn check_threshold(path: &Path, threshold: Threshold) -> Result<(), InputError> {
    match threshold {
        Threshold::Level(level) if !(0.0..=1.0).contains(&level) => Err(InputError::file(
            path,
            format!("`threshold` must be a luminance level from 0 to 1, not {level}"),
        )),
        _ => Ok(()),
    }
}

/// Decodes a PNG or JPEG picture within the limits.
fn decode(path: &Path, bytes: &[u8]) -> Result<DynamicImage, InputError> {
    if bytes.is_empty() {
        return Err(InputError::file(
            path,
            "the file is empty: not a PNG or JPEG picture",
        ));
    }
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| damaged(path, &e))?;
    match reader.format() {
        Some(ImageFormat::Png | ImageFormat::Jpeg) => {}
        Some(other) => {
            let name = other.extensions_str().first().unwrap_or(&"other");
            return Err(InputError::file(
                path,
                format!(
                    "not a PNG or JPEG picture (a {} picture)",
                    name.to_uppercase()
                ),
            ));
        }
        None => return Err(InputError::file(path, "not a PNG or JPEG picture")),
    }
    reader.limits(limits());
    // The decoder reads the header only; the PNG decoder checks the size right after IHDR.
    let decoder = reader.into_decoder().map_err(|e| match e {
        ImageError::Limits(limit) => too_large(path, header_size(bytes), &limit.kind()),
        e => image_error(path, e),
    })?;
    let (width, height) = decoder.dimensions();
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(too_large(
            path,
            Some((width, height)),
            &LimitErrorKind::DimensionError,
        ));
    }
    // The decoder checks only the sizes of its own buffers: the picture's is checked here,
    // as `ImageReader::decode` does.
    let decoded = decoder.total_bytes();
    if decoded > MAX_DECODED {
        return Err(InputError::file(
            path,
            format!(
                "the picture is {width} x {height} pixels at {} bytes a pixel, {} MiB decoded; \
                 pictures up to {} MiB decoded are read",
                decoder.color_type().bytes_per_pixel(),
                decoded.div_ceil(1 << 20),
                MAX_DECODED >> 20
            ),
        ));
    }
    DynamicImage::from_decoder(decoder).map_err(|e| image_error(path, e))
}

/// The limits every picture is decoded within.
fn limits() -> Limits {
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(MAX_DECODED);
    limits
}

/// A refusal of a picture over the limits, with its size when known.
fn too_large(path: &Path, size: Option<(u32, u32)>, kind: &LimitErrorKind) -> InputError {
    let message = match (size, kind) {
        (Some((w, h)), _) if w > MAX_SIDE || h > MAX_SIDE => format!(
            "the picture is {w} x {h} pixels; pictures up to {MAX_SIDE} x {MAX_SIDE} are read"
        ),
        (_, LimitErrorKind::DimensionError) => {
            format!("the picture is larger than {MAX_SIDE} x {MAX_SIDE} pixels, the largest read")
        }
        (Some((w, h)), _) => format!(
            "the picture ({w} x {h} pixels) needs more than {} MiB to decode, the most used",
            MAX_DECODED >> 20
        ),
        (None, _) => format!(
            "the picture needs more than {} MiB to decode, the most used",
            MAX_DECODED >> 20
        ),
    };
    InputError::file(path, message)
}

/// An error of the decoder, as what is wrong with the picture.
fn image_error(path: &Path, e: ImageError) -> InputError {
    match e {
        ImageError::Limits(limit) => too_large(path, None, &limit.kind()),
        ImageError::Unsupported(e) => InputError::file(
            path,
            format!("the picture uses a kind of PNG or JPEG that is not read: {e}"),
        ),
        e => damaged(path, &e),
    }
}

/// A picture that ends early or whose data does not decode.
fn damaged(path: &Path, e: &dyn std::error::Error) -> InputError {
    InputError::file(
        path,
        format!(
            "the picture is truncated or damaged: {}",
            crate::error::chain(e)
        ),
    )
}

/// Width and height as a PNG's IHDR or a JPEG's frame header says, read by hand for the
/// message when the decoder refuses a picture over the limits without saying its size.
fn header_size(bytes: &[u8]) -> Option<(u32, u32)> {
    let be16 = |at: usize| Some(u16::from_be_bytes(bytes.get(at..at + 2)?.try_into().ok()?));
    let be32 = |at: usize| Some(u32::from_be_bytes(bytes.get(at..at + 4)?.try_into().ok()?));
    if bytes.get(12..16) == Some(b"IHDR") {
        return Some((be32(16)?, be32(20)?));
    }
    // JPEG: segments after the start-of-image marker, up to a start-of-frame one (SOF0 to
    // SOF15 but DHT, JPG and DAC).
    let mut at = 2;
    while bytes.get(at) == Some(&0xff) {
        let marker = *bytes.get(at + 1)?;
        if marker == 0xff {
            at += 1;
            continue;
        }
        if (0xc0..=0xcf).contains(&marker) && !matches!(marker, 0xc4 | 0xc8 | 0xcc) {
            return Some((u32::from(be16(at + 7)?), u32::from(be16(at + 5)?)));
        }
        at += 2 + usize::from(be16(at + 2)?);
    }
    None
}

/// Calls `f(x, y, luminance, alpha)` for every pixel of `image`, without converting it: the
/// luminance as 8-bit (0 to 255) and the alpha from 0 to 1 (1 without an alpha channel).
fn each_pixel(image: &DynamicImage, f: impl FnMut(u32, u32, u8, f32)) {
    match image {
        DynamicImage::ImageLuma8(b) => each_in(b, f),
        DynamicImage::ImageLumaA8(b) => each_in(b, f),
        DynamicImage::ImageRgb8(b) => each_in(b, f),
        DynamicImage::ImageRgba8(b) => each_in(b, f),
        DynamicImage::ImageLuma16(b) => each_in(b, f),
        DynamicImage::ImageLumaA16(b) => each_in(b, f),
        DynamicImage::ImageRgb16(b) => each_in(b, f),
        DynamicImage::ImageRgba16(b) => each_in(b, f),
        DynamicImage::ImageRgb32F(b) => each_in(b, f),
        DynamicImage::ImageRgba32F(b) => each_in(b, f),
        // PNG and JPEG decode to the kinds above; any other is converted.
        other => each_in(&other.to_rgba32f(), f),
    }
}

/// [`each_pixel`] for one kind of pixel. The luminance is Rec. 709's luma of the sRGB
/// (gamma-encoded) values, `0.2126 R' + 0.7152 G' + 0.0722 B'`: lightness as it looks, not
/// linear light, as a designer judges dark against light.
fn each_in<P>(buffer: &ImageBuffer<P, Vec<P::Subpixel>>, mut f: impl FnMut(u32, u32, u8, f32))
where
    P: Pixel,
    P::Subpixel: Into<f32>,
{
    let max: f32 = <P::Subpixel as image::Primitive>::DEFAULT_MAX_VALUE.into();
    for (x, y, pixel) in buffer.enumerate_pixels() {
        let [r, g, b, a] = pixel.to_rgba().0.map(|c| c.into() / max);
        let luma = (0.2126 * r + 0.7152 * g + 0.0722 * b) * 255.0;
        f(x, y, luma.round().clamp(0.0, 255.0) as u8, a);
    }
}
