//! Bitmap text for captions and titles, from the public-domain `font8x8` glyphs.
//!
//! Each character is an 8x8 cell (optionally scaled up by an integer factor). Characters
//! outside printable ASCII are drawn as `?`; text wider than the room it has is cut and
//! ends in `..`. Drawing is clipped to the image, so any position is safe.
//!
//! ```ignore
//! let mut img = image::RgbImage::new(100, 20);
//! draw_text(&mut img, 4, 6, &fit_text("#12  fit 3.41", 92, 1), 1, [30, 30, 30]);
//! ```

use font8x8::legacy::BASIC_LEGACY;
use image::RgbImage;

/// Glyph side in pixels at scale 1.
pub(crate) const GLYPH: u32 = 8;

/// The glyph rows of a character (bit 0 is the leftmost pixel).
fn glyph(c: char) -> [u8; 8] {
    let code = c as u32;
    let printable = (0x20..0x7f).contains(&code);
    BASIC_LEGACY[if printable {
        code as usize
    } else {
        '?' as usize
    }]
}

/// `text` cut to at most `width` pixels at `scale`, ending in `..` when cut.
pub(crate) fn fit_text(text: &str, width: u32, scale: u32) -> String {
    let room = (width / (GLYPH * scale.max(1))) as usize;
    let count = text.chars().count();
    if count <= room {
        return text.to_owned();
    }
    if room < 3 {
        return ".".repeat(room);
    }
    let mut cut: String = text.chars().take(room - 2).collect();
    cut.push_str("..");
    cut
}

/// Width in pixels of `text` at `scale`.
pub(crate) fn text_width(text: &str, scale: u32) -> u32 {
    (text.chars().count() as u32).saturating_mul(GLYPH * scale)
}

/// Draws `text` with its top-left corner at (`x`, `y`), clipped to the image.
pub(crate) fn draw_text(img: &mut RgbImage, x: u32, y: u32, text: &str, scale: u32, rgb: [u8; 3]) {
    let scale = scale.max(1);
    let (w, h) = img.dimensions();
    for (i, c) in text.chars().enumerate() {
        let gx = u64::from(x) + i as u64 * u64::from(GLYPH * scale);
        if gx >= u64::from(w) {
            break;
        }
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..GLYPH {
                if bits >> col & 1 == 0 {
                    continue;
                }
                for sy in 0..scale {
                    for sx in 0..scale {
                        let px = gx + u64::from(col * scale + sx);
                        let py = u64::from(y) + u64::from(row as u32 * scale + sy);
                        if px < u64::from(w) && py < u64::from(h) {
                            img.put_pixel(px as u32, py as u32, image::Rgb(rgb));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_long_text() {
        assert_eq!(fit_text("hello", 40, 1), "hello");
        assert_eq!(fit_text("hello world", 40, 1), "hel..");
        assert_eq!(fit_text("hello", 16, 1), "..");
        assert_eq!(
            fit_text("héllo", 40, 1),
            "héllo",
            "counts characters, not bytes"
        );
    }

    #[test]
    fn draws_dark_pixels_and_clips() {
        let mut img = RgbImage::from_pixel(20, 10, image::Rgb([255, 255, 255]));
        draw_text(&mut img, 1, 1, "A\u{e9}", 1, [0, 0, 0]);
        let dark = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
        assert!(dark > 20);
        // The unknown character is drawn as '?', the same pixels as a literal '?'.
        let mut a = RgbImage::from_pixel(20, 10, image::Rgb([255, 255, 255]));
        draw_text(&mut a, 1, 1, "A?", 1, [0, 0, 0]);
        assert_eq!(a, img);
        draw_text(&mut img, 15, 5, "WWW", 3, [0, 0, 0]);
        draw_text(&mut img, u32::MAX, u32::MAX, "W", 2, [0, 0, 0]);
    }
}
