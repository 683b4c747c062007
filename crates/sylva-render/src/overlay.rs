//! Two outlines over each other, in two colours, with a caption: how a plant's silhouette
//! sits on the target it was evolved towards (`sylva match` writes it as `overlay.png`).

use image::RgbImage;

use crate::text::{draw_text, fit_text};

/// Pixels of the target alone.
pub const TARGET: [u8; 3] = [120, 170, 230];
/// Pixels of the plant alone.
pub const PLANT: [u8; 3] = [235, 140, 50];
/// Pixels of both.
pub const BOTH: [u8; 3] = [40, 110, 60];

/// A `width` x `height` picture of the two outlines (`target(x, y)`, `plant(x, y)`, rows
/// downwards), each pixel enlarged `scale` times, with `caption` in a band above them.
pub fn overlay(
    width: u32,
    height: u32,
    scale: u32,
    target: impl Fn(u32, u32) -> bool,
    plant: impl Fn(u32, u32) -> bool,
    caption: &str,
) -> RgbImage {
    let scale = scale.clamp(1, 16);
    let band = 24;
    let (w, h) = (width * scale, height * scale + band);
    let mut img = RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    for y in 0..height {
        for x in 0..width {
            let rgb = match (target(x, y), plant(x, y)) {
                (true, true) => BOTH,
                (true, false) => TARGET,
                (false, true) => PLANT,
                (false, false) => continue,
            };
            for sy in 0..scale {
                for sx in 0..scale {
                    img.put_pixel(x * scale + sx, band + y * scale + sy, image::Rgb(rgb));
                }
            }
        }
    }
    draw_text(
        &mut img,
        6,
        8,
        &fit_text(caption, w.saturating_sub(12), 1),
        1,
        [30, 30, 30],
    );
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_outline_has_its_colour() {
        let img = overlay(
            16,
            2,
            4,
            |x, _| x < 2,
            |x, _| (1..3).contains(&x),
            "IoU 0.33",
        );
        assert_eq!(img.dimensions(), (64, 32));
        let at = |x: u32| img.get_pixel(x * 4 + 1, 24 + 1).0;
        assert_eq!(
            [at(0), at(1), at(2), at(3)],
            [TARGET, BOTH, PLANT, [255; 3]]
        );
        // The caption is drawn in the band.
        assert!((0..64).any(|x| (0..24).any(|y| img.get_pixel(x, y).0 == [30, 30, 30])));
    }
}
