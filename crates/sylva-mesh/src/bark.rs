//! Tiling bark Sylva draws itself: a grey colour texture and a normal map per [`BarkKind`].
//!
//! The colour texture ([`bark_color`]) is [`BARK_SIZE`]² grey, multiplied by the material's
//! colour as every texture of [`crate::texture`] is; it tiles both ways. The normal map
//! ([`bark_normal`]) is the same pattern read as a height field (light is high: ridges,
//! plates and lip of lenticels stand out, furrows and crevices sink), in tangent space as
//! glTF has it: red along `u` (around the stem), green up the picture, blue out of the bark.
//!
//! A tile spans [`BarkSpec`](sylva_core::species::BarkSpec)-independent [`tile_metres`] around
//! a stem: the mesher repeats it a whole number of times round each stem
//! ([`crate::mesher`]), so a furrow is as wide on a trunk as on a limb, as on a real tree.
//!
//! | kind | pattern |
//! | --- | --- |
//! | `smooth` | smooth grey with faint bands and fine speckles (beech, aspen, fir) |
//! | `birch` | white with dark horizontal lenticels and black fissured patches |
//! | `furrowed` | deep vertical furrows between ridges broken by cross cracks (oak, ash) |
//! | `plated` | flaky plates parted by dark crevices (pine, spruce) |

use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex};

use image::{GrayImage, RgbImage};
use sylva_core::species::BarkKind;

use crate::texture::{cells, fbm, furrowed_bark, lenticel_bark, plated_bark, smooth};

/// Side of a bark texture and of its normal map, pixels.
pub const BARK_SIZE: u32 = 512;

/// How far round a stem one tile of `kind` reaches, metres.
pub fn tile_metres(kind: BarkKind) -> f32 {
    match kind {
        BarkKind::Furrowed => 0.45,
        BarkKind::Plated => 0.6,
        BarkKind::Birch => 0.7,
        BarkKind::Smooth => 0.7,
    }
}

/// Smooth bark: light grey with faint horizontal bands, soft mottling and fine speckles.
fn smooth_bark(u: f32, v: f32, s: u32) -> f32 {
    let bands = fbm(u, v, 1, 14, 3, s) - 0.5;
    let mottle = fbm(u, v, 6, 6, 3, s ^ 0x21) - 0.5;
    let (f1, _, _) = cells(u, v, 40, 40, s ^ 0x31);
    let speck = 1.0 - smooth(0.05, 0.12, f1);
    0.86 + 0.14 * bands + 0.12 * mottle - 0.18 * speck
}

/// Birch: white lenticel bark with a few dark horizontal blotches, ragged at their edges.
fn birch_bark(u: f32, v: f32, s: u32) -> f32 {
    let base = lenticel_bark(u, v, s);
    // Cells wide around and short along: blotches stretched around the stem.
    let (f1, _, id) = cells(u, v, 2, 9, s ^ 0x41);
    let ragged = 0.12 * (fbm(u, v, 16, 16, 2, s ^ 0x51) - 0.5);
    let patch = if crate::texture::unit(id) < 0.3 {
        1.0 - smooth(0.18, 0.34, f1 + ragged)
    } else {
        0.0
    };
    let dark = patch * (0.75 + 0.25 * fbm(u, v, 24, 24, 2, s ^ 0x61));
    (0.1 + 0.95 * base) * (1.0 - 0.85 * dark)
}

/// The grey pattern of `kind` at `(u, v)`.
fn pattern(kind: BarkKind, u: f32, v: f32) -> f32 {
    // Seeds away from the designs' own ids, so these are other pictures than textures 0–2.
    match kind {
        BarkKind::Smooth => smooth_bark(u, v, 0x5b00),
        BarkKind::Birch => birch_bark(u, v, 0x5b01),
        BarkKind::Furrowed => furrowed_bark(u, v, 0x5b02),
        BarkKind::Plated => plated_bark(u, v, 0x5b03),
    }
}

/// How deep the pattern's relief reads in the normal map (1 for a texel-sized step of the
/// full grey range at 45 degrees).
fn relief(kind: BarkKind) -> f32 {
    match kind {
        BarkKind::Smooth => 5.0,
        BarkKind::Birch => 2.0,
        BarkKind::Furrowed => 7.0,
        BarkKind::Plated => 5.0,
    }
}

/// The pattern sampled at pixel centres, grey 0 to 1.
fn heights(kind: BarkKind) -> Vec<f32> {
    let n = BARK_SIZE as usize;
    let inv = 1.0 / n as f32;
    (0..n * n)
        .map(|k| {
            let (x, y) = (k % n, k / n);
            pattern(kind, (x as f32 + 0.5) * inv, (y as f32 + 0.5) * inv).clamp(0.0, 1.0)
        })
        .collect()
}

/// A bark's colour texture and normal map.
type BarkPair = (Arc<GrayImage>, Arc<RgbImage>);

static MADE: LazyLock<Mutex<HashMap<BarkKind, BarkPair>>> = LazyLock::new(Mutex::default);

/// Both pictures of `kind`, made once per process.
fn made(kind: BarkKind) -> BarkPair {
    if let Some(p) = MADE.lock().unwrap_or_else(|p| p.into_inner()).get(&kind) {
        return p.clone();
    }
    let n = BARK_SIZE as usize;
    let h = heights(kind);
    let to8 = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    let color = GrayImage::from_fn(BARK_SIZE, BARK_SIZE, |x, y| {
        image::Luma([to8(h[y as usize * n + x as usize])])
    });
    let k = relief(kind);
    let at = |x: usize, y: usize| h[(y % n) * n + (x % n)];
    let normal = RgbImage::from_fn(BARK_SIZE, BARK_SIZE, |x, y| {
        let (x, y) = (x as usize, y as usize);
        // Central differences, wrapping: the map tiles as the pattern does.
        let dx = 0.5 * (at(x + 1, y) - at(x + n - 1, y)) * k;
        let drow = 0.5 * (at(x, y + 1) - at(x, y + n - 1)) * k;
        // Up the picture is -row: the slope there is +drow.
        let (nx, ny, nz) = (-dx, drow, 1.0f32);
        let len = (nx * nx + ny * ny + nz * nz).sqrt();
        let enc = |c: f32| to8(0.5 + 0.5 * c / len);
        image::Rgb([enc(nx), enc(ny), enc(nz)])
    });
    let pair = (Arc::new(color), Arc::new(normal));
    MADE.lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert(kind, pair.clone());
    pair
}

/// The colour texture of `kind` (grey, to multiply its colour by).
pub fn bark_color(kind: BarkKind) -> Arc<GrayImage> {
    made(kind).0
}

/// The normal map of `kind`.
pub fn bark_normal(kind: BarkKind) -> Arc<RgbImage> {
    made(kind).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barks_tile_both_ways_and_differ() {
        let mut seen = Vec::new();
        for kind in BarkKind::ALL {
            let c = bark_color(kind);
            assert_eq!(c.dimensions(), (BARK_SIZE, BARK_SIZE));
            // Opposite edges are as alike as neighbouring rows inside.
            let n = BARK_SIZE;
            let row_gap = |a: u32, b: u32| {
                (0..n)
                    .map(|x| (c.get_pixel(x, a).0[0] as i32 - c.get_pixel(x, b).0[0] as i32).abs())
                    .sum::<i32>()
            };
            let col_gap = |a: u32, b: u32| {
                (0..n)
                    .map(|y| (c.get_pixel(a, y).0[0] as i32 - c.get_pixel(b, y).0[0] as i32).abs())
                    .sum::<i32>()
            };
            let rows = (0..n - 1).map(|y| row_gap(y, y + 1)).sum::<i32>() / (n - 1) as i32;
            let cols = (0..n - 1).map(|x| col_gap(x, x + 1)).sum::<i32>() / (n - 1) as i32;
            assert!(
                row_gap(0, n - 1) < 2 * rows + n as i32,
                "{kind}: {} vs {rows}",
                row_gap(0, n - 1)
            );
            assert!(
                col_gap(0, n - 1) < 2 * cols + n as i32,
                "{kind}: {} vs {cols}",
                col_gap(0, n - 1)
            );
            seen.push(c.as_raw().clone());
        }
        seen.dedup();
        assert_eq!(seen.len(), 4);
    }

    #[test]
    fn normal_maps_are_unit_and_face_out() {
        for kind in BarkKind::ALL {
            let m = bark_normal(kind);
            let mut tilted = 0;
            for p in m.pixels() {
                let v = p.0.map(|c| c as f32 / 127.5 - 1.0);
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                assert!((len - 1.0).abs() < 0.02, "{kind}: {len}");
                assert!(v[2] > 0.0);
                tilted += usize::from(v[2] < 0.98);
            }
            assert!(tilted > 1000, "{kind} has relief");
        }
    }
}
