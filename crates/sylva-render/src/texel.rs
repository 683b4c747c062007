//! Texture sampling for the renderer: [`sylva_mesh::texture`] pictures as linear-light mip chains,
//! made once per id and kept by the [`Renderer`](super::Renderer).
//!
//! Each triangle picks a level of detail from how many texels cover one sample (its texture
//! area over its screen area), and every sample blends bilinear lookups in the two nearest
//! levels (trilinear filtering), so distant bark shades to its average instead of shimmering.
//! `u` wraps but for cut-outs; `v` wraps for bark and is clamped for leaf and petal
//! textures, as the exporters' samplers do. Cut-outs (leaf atlases, petals) also carry their
//! coverage, filtered down so that each level passes the alpha test over as much of its area
//! as the full picture does.
//!
//! ```ignore
//! let tex = cache.get(id);
//! let lod = tex.lod(uv_area / screen_area);
//! let factor = tex.sample(lod, u, v); // linear, 0..=1
//! ```

use std::collections::HashMap;
use sylva_core::glam::Vec3;
use sylva_mesh::picture::Picture;

use super::shade::{floor_i64, to_linear_table};

/// One level of a mip chain: `size` × `size` linear grey texels, and their coverage when
/// the picture cuts a shape out.
#[derive(Clone, Debug)]
struct Level {
    size: usize,
    texels: Vec<f32>,
    alpha: Vec<f32>,
    /// Linear colour per texel, for colour pictures (an impostor's); empty for grey ones.
    color: Vec<Vec3>,
}

/// A texture ready to sample.
#[derive(Clone, Debug)]
pub(crate) struct MipTexture {
    /// From full size down to 1 × 1.
    levels: Vec<Level>,
    repeat_u: bool,
    repeat_v: bool,
}

/// What a texel holds: a grey level or a colour, averaged and blended alike.
pub(crate) trait Texel:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<f32, Output = Self>
{
}

impl Texel for f32 {}
impl Texel for Vec3 {}

/// Half of each 2 × 2 block's mean: the next level down.
fn halve<T: Texel>(texels: &[T], size: usize) -> Vec<T> {
    let half = size / 2;
    let at = |x: usize, y: usize| texels[y * size + x];
    (0..half * half)
        .map(|k| {
            let (x, y) = (2 * (k % half), 2 * (k / half));
            (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1)) * 0.25
        })
        .collect()
}

/// The share of `alpha` at or above one half once scaled by `scale`.
fn coverage(alpha: &[f32], scale: f32) -> f32 {
    alpha.iter().filter(|&&a| a * scale >= 0.5).count() as f32 / alpha.len().max(1) as f32
}

/// Scales a level's coverage so that as large a share of it passes the alpha test as of
/// the full-size picture (Castaño's coverage-preserving mipmaps): without it, thin needles
/// and leaf tips fade away with distance as averaging pulls their alpha under one half.
fn keep_coverage(alpha: &mut [f32], target: f32) {
    let (mut lo, mut hi) = (1.0f32, 8.0f32);
    if coverage(alpha, lo) >= target {
        return;
    }
    for _ in 0..16 {
        let mid = 0.5 * (lo + hi);
        if coverage(alpha, mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    for a in alpha {
        *a = (*a * hi).min(1.0);
    }
}

impl MipTexture {
    /// `picture`, decoded from sRGB to linear light and box-filtered down level by level
    /// (its coverage kept, for cut-outs). A normal map reads as flat grey (the renderer
    /// does not use them).
    pub(crate) fn new(picture: Picture) -> MipTexture {
        let image = picture.image();
        let linear = to_linear_table();
        let size = image.width() as usize;
        let (texels, alpha): (Vec<f32>, Vec<f32>) = match &image {
            image::DynamicImage::ImageLuma8(g) => (
                g.as_raw().iter().map(|&g| linear[g as usize]).collect(),
                Vec::new(),
            ),
            image::DynamicImage::ImageLumaA8(ga) => ga
                .pixels()
                .map(|p| (linear[p.0[0] as usize], f32::from(p.0[1]) / 255.0))
                .unzip(),
            _ => (vec![1.0; size * size], Vec::new()),
        };
        MipTexture::of_levels(
            Level {
                size,
                texels,
                alpha,
                color: Vec::new(),
            },
            picture.repeats_u(),
            picture.repeats_v(),
        )
    }

    /// A colour picture with alpha (an impostor's, decoded from its PNG), clamped both ways;
    /// a picture that does not decode, or is not square of a power of two, reads as clear.
    pub(crate) fn of_png(png: &[u8]) -> MipTexture {
        let linear = to_linear_table();
        let image = image::load_from_memory_with_format(png, image::ImageFormat::Png)
            .map(|i| i.to_rgba8())
            .ok()
            .filter(|i| i.width() == i.height() && i.width().is_power_of_two());
        let Some(image) = image else {
            return MipTexture::of_levels(
                Level {
                    size: 1,
                    texels: vec![1.0],
                    alpha: vec![0.0],
                    color: vec![Vec3::ONE],
                },
                false,
                false,
            );
        };
        let size = image.width() as usize;
        let mut color = Vec::with_capacity(size * size);
        let mut alpha = Vec::with_capacity(size * size);
        for p in image.pixels() {
            let [r, g, b, a] = p.0;
            color.push(Vec3::new(
                linear[r as usize],
                linear[g as usize],
                linear[b as usize],
            ));
            alpha.push(f32::from(a) / 255.0);
        }
        MipTexture::of_levels(
            Level {
                size,
                texels: vec![1.0; size * size],
                alpha,
                color,
            },
            false,
            false,
        )
    }

    /// The mip chain down from `first`, keeping its alpha's coverage level by level.
    fn of_levels(first: Level, repeat_u: bool, repeat_v: bool) -> MipTexture {
        let target = coverage(&first.alpha, 1.0);
        let mut levels = vec![first];
        while let Some(last) = levels.last().filter(|l| l.size > 1) {
            let texels = halve(&last.texels, last.size);
            let mut alpha = if last.alpha.is_empty() {
                Vec::new()
            } else {
                halve(&last.alpha, last.size)
            };
            keep_coverage(&mut alpha, target);
            let color = if last.color.is_empty() {
                Vec::new()
            } else {
                halve(&last.color, last.size)
            };
            levels.push(Level {
                size: last.size / 2,
                texels,
                alpha,
                color,
            });
        }
        MipTexture {
            levels,
            repeat_u,
            repeat_v,
        }
    }

    /// Whether it has coverage to test ([`MipTexture::alpha`]).
    pub(crate) fn cuts_out(&self) -> bool {
        !self.levels[0].alpha.is_empty()
    }

    /// The level of detail for a triangle whose texture area (in `uv` units²) covers
    /// `uv_per_sample` of that area per screen sample: 0 when texels are no smaller than
    /// samples, one more for every halving.
    pub(crate) fn lod(&self, uv_per_sample: f32) -> f32 {
        let size = self.levels[0].size as f32;
        let texels = uv_per_sample * size * size;
        if !(texels > 1.0 && texels.is_finite()) {
            return 0.0;
        }
        (0.5 * texels.log2()).min((self.levels.len() - 1) as f32)
    }

    /// The linear grey at `(u, v)`, blended between the two levels around `lod`.
    #[inline]
    pub(crate) fn sample(&self, lod: f32, u: f32, v: f32) -> f32 {
        self.trilinear(lod, u, v, |l| &l.texels)
    }

    /// The linear colour at `(u, v)`: a colour picture's colour, a grey one's grey.
    #[inline]
    pub(crate) fn sample_color(&self, lod: f32, u: f32, v: f32) -> Vec3 {
        if self.levels[0].color.is_empty() {
            return Vec3::splat(self.sample(lod, u, v));
        }
        self.trilinear(lod, u, v, |l| &l.color)
    }

    /// The coverage at `(u, v)` (1 for a picture without alpha), as [`MipTexture::sample`].
    #[inline]
    pub(crate) fn alpha(&self, lod: f32, u: f32, v: f32) -> f32 {
        if !self.cuts_out() {
            return 1.0;
        }
        self.trilinear(lod, u, v, |l| &l.alpha)
    }

    #[inline]
    fn trilinear<T: Texel>(&self, lod: f32, u: f32, v: f32, channel: impl Fn(&Level) -> &[T]) -> T {
        let level = lod as usize;
        let t = lod - level as f32;
        let fine = self.bilinear(level, u, v, &channel);
        if t > 0.0 && level + 1 < self.levels.len() {
            fine + (self.bilinear(level + 1, u, v, &channel) - fine) * t
        } else {
            fine
        }
    }

    #[inline]
    fn bilinear<T: Texel>(
        &self,
        level: usize,
        u: f32,
        v: f32,
        channel: impl Fn(&Level) -> &[T],
    ) -> T {
        let l = &self.levels[level];
        let texels = channel(l);
        let n = l.size as i64;
        // Texel centres sit at half-integers.
        let (x, y) = (u * l.size as f32 - 0.5, v * l.size as f32 - 0.5);
        let (x0, y0) = (floor_i64(x), floor_i64(y));
        let (tx, ty) = (x - x0 as f32, y - y0 as f32);
        let wrap = |i: i64, repeats: bool| {
            if repeats {
                i.rem_euclid(n) as usize
            } else {
                i.clamp(0, n - 1) as usize
            }
        };
        let (c0, c1) = (wrap(x0, self.repeat_u), wrap(x0 + 1, self.repeat_u));
        let (r0, r1) = (
            wrap(y0, self.repeat_v) * l.size,
            wrap(y0 + 1, self.repeat_v) * l.size,
        );
        let top = texels[r0 + c0] + (texels[r0 + c1] - texels[r0 + c0]) * tx;
        let bottom = texels[r1 + c0] + (texels[r1 + c1] - texels[r1 + c0]) * tx;
        top + (bottom - top) * ty
    }
}

/// Mip chains by picture, made on first use, and impostors' by their pictures' hashes.
#[derive(Clone, Debug, Default)]
pub(crate) struct TextureCache {
    textures: HashMap<Picture, MipTexture>,
    impostors: HashMap<u64, MipTexture>,
}

impl TextureCache {
    /// The texture of `picture`, made the first time.
    pub(crate) fn get(&mut self, picture: Picture) -> &MipTexture {
        self.textures
            .entry(picture)
            .or_insert_with(|| MipTexture::new(picture))
    }

    /// The texture of an impostor's picture (a PNG), made the first time it is seen; the
    /// few most recent are kept.
    pub(crate) fn impostor(&mut self, png: &[u8]) -> &MipTexture {
        let key = sylva_core::hash::stable_hash(png);
        if !self.impostors.contains_key(&key) && self.impostors.len() >= 16 {
            self.impostors.clear();
        }
        self.impostors
            .entry(key)
            .or_insert_with(|| MipTexture::of_png(png))
    }

    /// Pictures held.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.textures.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_down_to_one_texel_and_keep_the_mean() {
        let t = MipTexture::new(Picture::Design(0));
        let sizes: Vec<usize> = t.levels.iter().map(|l| l.size).collect();
        assert_eq!(
            sizes.first(),
            Some(&(sylva_mesh::texture::TEXTURE_SIZE as usize))
        );
        assert_eq!(sizes.last(), Some(&1));
        let mean = |l: &Level| l.texels.iter().sum::<f32>() / l.texels.len() as f32;
        let m0 = mean(&t.levels[0]);
        for l in &t.levels {
            assert!((mean(l) - m0).abs() < 1e-3);
        }
    }

    #[test]
    fn sampling_wraps_u_and_clamps_leaf_v() {
        let bark = MipTexture::new(Picture::Design(0));
        for &(u, v) in &[(0.3, 0.7), (0.0, 0.0), (0.999, 0.5)] {
            let a = bark.sample(0.0, u, v);
            assert!((a - bark.sample(0.0, u + 1.0, v)).abs() < 1e-4);
            assert!((a - bark.sample(0.0, u - 3.0, v + 2.0)).abs() < 1e-4);
        }
        let petal = MipTexture::new(Picture::Design(6));
        // Clamped: far past the tip reads the last row, not the dark base again.
        assert!((petal.sample(0.0, 0.5, 1.0) - petal.sample(0.0, 0.5, 7.0)).abs() < 1e-6);
        assert!(petal.sample(0.0, 0.5, 1.0) > petal.sample(0.0, 0.5, 0.0) + 0.2);
        // Exactly at a texel centre, bilinear filtering returns that texel.
        let l = &bark.levels[0];
        let (x, y) = (10, 20);
        let (u, v) = (
            (x as f32 + 0.5) / l.size as f32,
            (y as f32 + 0.5) / l.size as f32,
        );
        assert_eq!(bark.sample(0.0, u, v), l.texels[y * l.size + x]);
    }

    #[test]
    fn far_away_means_blurrier() {
        let t = MipTexture::new(Picture::Design(0));
        assert_eq!(t.lod(0.0), 0.0);
        assert_eq!(t.lod(f32::NAN), 0.0);
        let size = sylva_mesh::texture::TEXTURE_SIZE as f32;
        // Four texels per sample: one level down.
        assert!((t.lod(4.0 / (size * size)) - 1.0).abs() < 1e-5);
        assert_eq!(t.lod(1e9), (t.levels.len() - 1) as f32);
    }
}
