//! Texture sampling for the renderer: [`sylva_mesh::texture`] pictures as linear-light mip chains,
//! made once per id and kept by the [`Renderer`](super::Renderer).
//!
//! Each triangle picks a level of detail from how many texels cover one sample (its texture
//! area over its screen area), and every sample blends bilinear lookups in the two nearest
//! levels (trilinear filtering), so distant bark shades to its average instead of shimmering.
//! `u` always wraps; `v` wraps for bark and is clamped for leaf and petal textures, as the
//! exporters' samplers do.
//!
//! ```ignore
//! let tex = cache.get(id);
//! let lod = tex.lod(uv_area / screen_area);
//! let factor = tex.sample(lod, u, v); // linear, 0..=1
//! ```

use std::collections::HashMap;
use sylva_mesh::texture::texture;

use super::shade::{floor_i64, to_linear_table};

/// One level of a mip chain: `size` × `size` linear grey texels.
#[derive(Clone, Debug)]
struct Level {
    size: usize,
    texels: Vec<f32>,
}

/// A texture ready to sample.
#[derive(Clone, Debug)]
pub(crate) struct MipTexture {
    /// From full size down to 1 × 1.
    levels: Vec<Level>,
    repeat_v: bool,
}

impl MipTexture {
    /// Texture `id`, decoded from sRGB to linear light and box-filtered down level by level.
    pub(crate) fn new(id: u16) -> MipTexture {
        let t = texture(id);
        let linear = to_linear_table();
        let size = t.image.width() as usize;
        let mut levels = vec![Level {
            size,
            texels: t
                .image
                .as_raw()
                .iter()
                .map(|&g| linear[g as usize])
                .collect(),
        }];
        while let Some(last) = levels.last().filter(|l| l.size > 1) {
            let (s, half) = (last.size, last.size / 2);
            let at = |x: usize, y: usize| last.texels[y * s + x];
            let texels = (0..half * half)
                .map(|k| {
                    let (x, y) = (2 * (k % half), 2 * (k / half));
                    0.25 * (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1))
                })
                .collect();
            levels.push(Level { size: half, texels });
        }
        MipTexture {
            levels,
            repeat_v: t.info().family.repeats_v(),
        }
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
        let level = lod as usize;
        let t = lod - level as f32;
        let fine = self.bilinear(level, u, v);
        if t > 0.0 && level + 1 < self.levels.len() {
            fine + (self.bilinear(level + 1, u, v) - fine) * t
        } else {
            fine
        }
    }

    #[inline]
    fn bilinear(&self, level: usize, u: f32, v: f32) -> f32 {
        let l = &self.levels[level];
        let n = l.size as i64;
        // Texel centres sit at half-integers.
        let (x, y) = (u * l.size as f32 - 0.5, v * l.size as f32 - 0.5);
        let (x0, y0) = (floor_i64(x), floor_i64(y));
        let (tx, ty) = (x - x0 as f32, y - y0 as f32);
        let col = |x: i64| x.rem_euclid(n) as usize;
        let row = |y: i64| {
            if self.repeat_v {
                y.rem_euclid(n) as usize
            } else {
                y.clamp(0, n - 1) as usize
            }
        };
        let (c0, c1, r0, r1) = (col(x0), col(x0 + 1), row(y0) * l.size, row(y0 + 1) * l.size);
        let top = l.texels[r0 + c0] + (l.texels[r0 + c1] - l.texels[r0 + c0]) * tx;
        let bottom = l.texels[r1 + c0] + (l.texels[r1 + c1] - l.texels[r1 + c0]) * tx;
        top + (bottom - top) * ty
    }
}

/// Mip chains by texture id, made on first use.
#[derive(Clone, Debug, Default)]
pub(crate) struct TextureCache {
    textures: HashMap<u16, MipTexture>,
}

impl TextureCache {
    /// The texture for `id`, generating it the first time.
    pub(crate) fn get(&mut self, id: u16) -> &MipTexture {
        self.textures
            .entry(id)
            .or_insert_with(|| MipTexture::new(id))
    }

    /// Ids held.
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
        let t = MipTexture::new(0);
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
        let bark = MipTexture::new(0);
        for &(u, v) in &[(0.3, 0.7), (0.0, 0.0), (0.999, 0.5)] {
            let a = bark.sample(0.0, u, v);
            assert!((a - bark.sample(0.0, u + 1.0, v)).abs() < 1e-4);
            assert!((a - bark.sample(0.0, u - 3.0, v + 2.0)).abs() < 1e-4);
        }
        let petal = MipTexture::new(6);
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
        let t = MipTexture::new(0);
        assert_eq!(t.lod(0.0), 0.0);
        assert_eq!(t.lod(f32::NAN), 0.0);
        let size = sylva_mesh::texture::TEXTURE_SIZE as f32;
        // Four texels per sample: one level down.
        assert!((t.lod(4.0 / (size * size)) - 1.0).abs() < 1e-5);
        assert_eq!(t.lod(1e9), (t.levels.len() - 1) as f32);
    }
}
