//! Lights, colour conversion, the ground disc and the shadow map.
//!
//! Lighting is a hemisphere ambient (cool sky above, warm bounce below), a warm key light
//! from the upper front-left of the picture that casts shadows, and a cool unshadowed fill
//! from the right. Light directions follow the camera's yaw, so every view is lit the same
//! way relative to the picture, with the key always 50 degrees above the horizon.
//!
//! Colours are linear RGB while shading and 8-bit sRGB in the sample buffer; two lookup
//! tables convert between them without a `powf` per sample.
//!
//! ```ignore
//! let lights = Lights::for_camera(&camera);
//! let linear = albedo * lights.shade(normal, shadow.lit(light_pos, normal));
//! let packed = pack(to_srgb_table(), linear);
//! ```

use std::sync::LazyLock;

use sylva_core::{Aabb, glam::Vec3};

use super::camera::Camera;

/// Linear 0..=1 (in 4096 steps) to 8-bit sRGB.
static TO_SRGB: LazyLock<[u8; 4096]> = LazyLock::new(|| {
    std::array::from_fn(|i| (linear_to_srgb(i as f32 / 4095.0) * 255.0 + 0.5) as u8)
});

/// 8-bit sRGB to linear.
static TO_LINEAR: LazyLock<[f32; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)));

fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The linear-to-sRGB table (take it once per render: `LazyLock` derefs are not free).
pub(crate) fn to_srgb_table() -> &'static [u8; 4096] {
    &TO_SRGB
}

/// The sRGB-to-linear table.
pub(crate) fn to_linear_table() -> &'static [f32; 256] {
    &TO_LINEAR
}

/// Packs a linear colour as 8-bit sRGB `r | g << 8 | b << 16`.
#[inline]
pub(crate) fn pack(table: &[u8; 4096], c: Vec3) -> u32 {
    // `clamp` maps NaN to NaN and `as usize` maps NaN to 0: never out of range.
    let q = |v: f32| u32::from(table[(v.clamp(0.0, 1.0) * 4095.0 + 0.5) as usize]);
    q(c.x) | q(c.y) << 8 | q(c.z) << 16
}

/// Packs an sRGB triple.
pub(crate) fn pack_srgb(c: [u8; 3]) -> u32 {
    u32::from(c[0]) | u32::from(c[1]) << 8 | u32::from(c[2]) << 16
}

/// The linear colour of an sRGB triple.
pub(crate) fn srgb_to_linear3(c: [u8; 3]) -> Vec3 {
    let t = to_linear_table();
    Vec3::new(t[c[0] as usize], t[c[1] as usize], t[c[2] as usize])
}

/// A material colour made safe: NaN becomes mid grey, everything clamped to 0..=1.
pub(crate) fn albedo(c: [f32; 3]) -> Vec3 {
    let v = Vec3::from_array(c);
    if v.is_finite() {
        v.clamp(Vec3::ZERO, Vec3::ONE)
    } else {
        Vec3::splat(0.5)
    }
}

/// The scene's lights, in world space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lights {
    /// Unit direction towards the key light.
    pub key: Vec3,
    key_color: Vec3,
    fill: Vec3,
    fill_color: Vec3,
    sky: Vec3,
    bounce: Vec3,
}

impl Lights {
    /// Lights placed relative to the camera's horizontal right and towards-viewer axes.
    pub(crate) fn for_camera(camera: &Camera) -> Lights {
        let right = Vec3::new(camera.right.x, 0.0, camera.right.z).normalize_or(Vec3::X);
        // Horizontal direction from the scene towards the viewer (+Z in the front view; in
        // the top view the bottom of the picture).
        let toward = right.cross(Vec3::Y);
        Lights {
            key: (-0.55 * right + 0.6 * toward).normalize() * 50f32.to_radians().cos()
                + Vec3::Y * 50f32.to_radians().sin(),
            key_color: Vec3::new(1.0, 0.95, 0.85) * 1.05,
            fill: (0.85 * right + 0.25 * Vec3::Y + 0.45 * toward).normalize(),
            fill_color: Vec3::new(0.62, 0.70, 0.85) * 0.30,
            sky: Vec3::new(0.36, 0.42, 0.50) * 0.85,
            bounce: Vec3::new(0.24, 0.20, 0.15) * 0.85,
        }
    }

    /// Light leaving a thin leaf or petal seen on the side whose unit normal is `n`: what
    /// [`Lights::shade`] gives, plus a third of the key light passing through when it
    /// shines on the other side (`lit` is the key light's reach on whichever side it hits).
    #[inline]
    pub(crate) fn shade_thin(&self, n: Vec3, lit: f32) -> Vec3 {
        let front = n.dot(self.key);
        let through = if front < 0.0 { -front * 0.35 } else { 0.0 };
        self.shade(n, lit) + self.key_color * (through * lit)
    }

    /// Light arriving at a surface with unit normal `n`; `lit` (0..=1) scales the key light.
    #[inline]
    pub(crate) fn shade(&self, n: Vec3, lit: f32) -> Vec3 {
        let ambient = self.bounce.lerp(self.sky, 0.5 + 0.5 * n.y);
        ambient
            + self.key_color * (n.dot(self.key).max(0.0) * lit)
            + self.fill_color * n.dot(self.fill).max(0.0)
    }
}

/// Segments of the ground disc's rim.
pub(crate) const GROUND_SEGMENTS: usize = 96;

/// A round ground at y = 0 under the plants: a soft checker (squares of a round size in
/// metres, so it doubles as a scale) fading into the background at its rim.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ground {
    /// Centre, on y = 0.
    pub centre: Vec3,
    /// Radius, metres.
    pub radius: f32,
    /// 1 / checker square side (metres).
    inv_cell: f32,
    tones: [Vec3; 2],
}

impl Ground {
    /// A disc sized to the plants: 1.2 times their wider horizontal extent across, and at
    /// least 0.6 times their height across, so a lone stem still stands on something.
    pub(crate) fn for_plants(plants: &Aabb) -> Ground {
        let (centre, radius) = if plants.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            let size = plants.size();
            let c = plants.center();
            let r = (0.6 * size.x.max(size.z)).max(0.3 * size.y).max(1e-3);
            (Vec3::new(c.x, 0.0, c.z), r)
        };
        Ground {
            centre,
            radius,
            inv_cell: 1.0 / nice_step(radius / 4.0),
            tones: [
                srgb_to_linear3([196, 201, 171]),
                srgb_to_linear3([184, 191, 159]),
            ],
        }
    }

    /// Bounds of the disc.
    pub(crate) fn bounds(&self) -> Aabb {
        let r = Vec3::new(self.radius, 0.0, self.radius);
        Aabb {
            min: self.centre - r,
            max: self.centre + r,
        }
    }

    /// Rim point `i` (counter-clockwise seen from above, so the fan faces up).
    pub(crate) fn rim(&self, i: usize) -> Vec3 {
        let a = (i % GROUND_SEGMENTS) as f32 * std::f32::consts::TAU / GROUND_SEGMENTS as f32;
        self.centre + Vec3::new(a.cos(), 0.0, -a.sin()) * self.radius
    }

    /// Albedo at a ground point, and how far it has faded into the background (0..=1).
    #[inline]
    pub(crate) fn albedo(&self, p: Vec3) -> (Vec3, f32) {
        let (i, k) = (
            floor_i64(p.x * self.inv_cell),
            floor_i64(p.z * self.inv_cell),
        );
        let parity = (i + k) & 1 == 1;
        let d = Vec3::new(p.x - self.centre.x, 0.0, p.z - self.centre.z).length() / self.radius;
        let t = ((d - 0.7) / 0.3).clamp(0.0, 1.0);
        (self.tones[usize::from(parity)], t * t * (3.0 - 2.0 * t))
    }
}

/// `x.floor()` as an integer, saturating (and 0 for NaN), without a call into libm: the
/// baseline x86-64 target has no floor instruction.
#[inline]
pub(crate) fn floor_i64(x: f32) -> i64 {
    let t = x as i64;
    if (t as f32) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The nearest 1, 2 or 5 times a power of ten below `x`.
fn nice_step(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let p = 10f32.powf(x.log10().floor());
    let m = x / p;
    p * if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    }
}

/// A depth map seen from the key light (orthographic), for shadows on the ground and on
/// the plants themselves.
#[derive(Clone, Debug, Default)]
pub(crate) struct ShadowMap {
    /// Side, texels; 0 when shadows are off.
    pub size: usize,
    /// Depth along the light per texel, +inf where nothing is.
    pub depth: Vec<f32>,
    centre: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    radius: f32,
    texels_per_metre: f32,
}

impl ShadowMap {
    /// Clears to a `size` x `size` map covering the sphere (`centre`, `radius`) seen along
    /// `-towards_light`; `size` 0 switches shadows off.
    pub(crate) fn reset(&mut self, towards_light: Vec3, centre: Vec3, radius: f32, size: usize) {
        self.size = size;
        self.depth.clear();
        self.depth.resize(size * size, f32::INFINITY);
        self.forward = -towards_light;
        self.right = self.forward.cross(Vec3::Y).normalize_or(Vec3::X);
        self.up = self.right.cross(self.forward);
        self.centre = centre;
        self.radius = radius;
        self.texels_per_metre = size as f32 / (2.0 * radius);
    }

    /// Light-space coordinates of a point: texel x, texel y (down), depth along the light.
    #[inline]
    pub(crate) fn to_light(&self, p: Vec3) -> Vec3 {
        let d = p - self.centre;
        Vec3::new(
            (d.dot(self.right) + self.radius) * self.texels_per_metre,
            (self.radius - d.dot(self.up)) * self.texels_per_metre,
            d.dot(self.forward),
        )
    }

    /// How much key light reaches light-space point `l` on a surface with normal `n`
    /// (0 shadowed .. 1 lit), filtered over the four nearest texels.
    #[inline]
    pub(crate) fn lit(&self, l: Vec3, n: Vec3) -> f32 {
        if self.size == 0 {
            return 1.0;
        }
        // Offset along the normal and a small depth bias, both about a texel, keep surfaces
        // from shadowing themselves.
        const OFFSET: f32 = 1.5;
        let l = l + Vec3::new(
            n.dot(self.right) * OFFSET,
            -n.dot(self.up) * OFFSET,
            n.dot(self.forward) * OFFSET / self.texels_per_metre,
        );
        let depth = l.z - 1.5 / self.texels_per_metre;
        let (x, y) = (l.x - 0.5, l.y - 0.5);
        let (ix, iy) = (floor_i64(x), floor_i64(y));
        let (tx, ty) = (x - ix as f32, y - iy as f32);
        let tap = |dx: i64, dy: i64| -> f32 {
            let (x, y) = (ix + dx, iy + dy);
            let s = self.size as i64;
            if x < 0 || y < 0 || x >= s || y >= s {
                return 1.0;
            }
            if depth <= self.depth[(y * s + x) as usize] {
                1.0
            } else {
                0.0
            }
        };
        let top = tap(0, 0) * (1.0 - tx) + tap(1, 0) * tx;
        let bottom = tap(0, 1) * (1.0 - tx) + tap(1, 1) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_tables_round_trip() {
        for v in [0u8, 1, 10, 128, 200, 255] {
            let l = to_linear_table()[v as usize];
            assert_eq!(pack(to_srgb_table(), Vec3::splat(l)) & 0xff, u32::from(v));
        }
        assert_eq!(pack(to_srgb_table(), Vec3::splat(f32::NAN)), 0);
        assert_eq!(pack(to_srgb_table(), Vec3::splat(7.0)), 0xff_ffff);
    }

    #[test]
    fn fast_floor() {
        for x in [-2.5f32, -2.0, -0.1, 0.0, 0.1, 2.0, 2.9, 1e20, -1e20] {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}"); // both saturate
        }
        assert_eq!(floor_i64(f32::NAN), 0);
    }

    #[test]
    fn nice_steps() {
        assert!((nice_step(0.3) - 0.2).abs() < 1e-6);
        assert_eq!(nice_step(7.0), 5.0);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(f32::NAN), 1.0);
    }

    #[test]
    fn key_light_is_above_front_left() {
        use crate::{View, camera::Camera};
        let lights = Lights::for_camera(&Camera::looking(View::Front, Vec3::ZERO, 1.0));
        assert!(lights.key.x < 0.0 && lights.key.y > 0.5 && lights.key.z > 0.0);
        assert!((lights.key.length() - 1.0).abs() < 1e-5);
    }
}
