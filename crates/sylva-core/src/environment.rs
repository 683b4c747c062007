//! A voxel world of light and minerals that plants grow in (Bornhofen and Lattaud, §3.1).
//!
//! [`Environment`] is a box of sky and soil cut into cubic voxels. The ground is the plane
//! y = 0; the box is centred on the origin in x and z, the bottom
//! [`soil_layers`](EnvironmentSettings::soil_layers) layers are soil and the rest is sky.
//! With the defaults ([`EnvironmentSettings::default`]) it is 64 × 64 × 64 voxels of
//! 0.125 m: 8 m wide, 2 m of soil and 6 m of sky — a garden. Voxels should not be much
//! larger than a plant's leaves: a seedling inside one voxel column can never catch more
//! than that column's light, however many leaves it has.
//!
//! **Light (Figure 3).** Light arrives from one direction ([`LightSettings`]: vertical, or
//! lateral at any elevation and azimuth) with intensity `I₀`. Each step, plants
//! [`add_shade`](Environment::add_shade) the silhouette area of their above-ground modules
//! into the sky voxels they occupy; [`update_light`](Environment::update_light) then sweeps
//! the sky layer by layer along the light's dominant axis, from the side the light comes
//! from. A voxel holding shading area `A` lets through `T = exp(-k·A/s²)` of the light that
//! enters it (Beer–Lambert; `k` is the [`extinction`](LightSettings::extinction), `s` the
//! voxel size), and the light *entering* a voxel is the light leaving the point one layer
//! upstream along the ray, bilinearly interpolated between the four voxels around that point
//! (exact for vertical and axis-aligned light; at other angles shadows blur slightly with
//! distance). Light from outside the box arrives unshaded. So a module darkens the voxels
//! behind it along the light, never its own voxel or those in front of it. The sweep costs a
//! few reads per sky voxel downstream of the first shaded layer, nothing upstream of it,
//! and allocates nothing.
//!
//! **Capture.** A voxel absorbs `I·s²·(1 - T)` of light (`I` the light entering it); a module
//! gets the share of its own area in the voxel's shading area
//! ([`absorbed_light`](Environment::absorbed_light)). Light is thus conserved: what a voxel
//! absorbs is missing behind it, and stacking leaves in one voxel saturates.
//!
//! **Minerals (Figure 4).** Soil voxels hold minerals (grams). Each step
//! [`diffuse`](Environment::diffuse) moves, across every face shared by two soil voxels,
//! `r·(m_a - m_b)` from the richer to the poorer, with `r = D/s²` (`D` the
//! [`diffusion`](MineralSettings::diffusion) coefficient in m² per step). The explicit scheme
//! is stable and keeps every voxel non-negative when `r ≤ 1/6` (each voxel has at most six
//! neighbours); larger `r` is split into `⌈6r⌉` equal sub-steps, so the condition always
//! holds. Each face's flux is added to one side and taken from the other, so the total is
//! conserved up to rounding (grids are `f64`). The soil's outer faces and the ground are
//! closed. Roots take minerals through [`Uptake`], which serves all demands from the same
//! state and scales them down together where a voxel cannot satisfy them all, so no plant is
//! served first.
//!
//! **Litter.** A ground grid (one cell per column) collects the carbon plants shed
//! ([`deposit_litter`](Environment::deposit_litter)).
//!
//! Points outside the box are clamped to the nearest voxel; heights decide sky or soil.
//!
//! ```
//! use sylva_core::environment::{Environment, EnvironmentSettings};
//! use sylva_core::glam::Vec3;
//!
//! let mut env = Environment::new(EnvironmentSettings::default())?;
//! let leaf = Vec3::new(0.1, 2.0, 0.1);
//! env.clear_shade();
//! env.add_shade(leaf, 0.05);
//! env.update_light();
//! assert!(env.light_at(leaf - Vec3::Y) < env.light_at(leaf + Vec3::Y));
//! let before = env.total_minerals();
//! env.add_minerals(Vec3::new(0.0, -0.1, 0.0), 1.0);
//! env.diffuse();
//! assert!((env.total_minerals() - before - 1.0).abs() < 1e-9);
//! # Ok::<(), sylva_core::environment::EnvironmentError>(())
//! ```

use glam::Vec3;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Most voxels a world may hold (about 16.8 million).
pub const MAX_VOXELS: u64 = 1 << 24;

/// Where the light comes from and how the sky dims it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LightSettings {
    /// Height of the light above the horizon, 0 to 90 degrees; 90 shines straight down.
    /// Default 90.
    #[serde(deserialize_with = "elevation")]
    pub elevation: f64,
    /// The compass direction the light comes from, degrees about +Y: 0 from +X, 90 from +Z.
    /// Ignored when the light is vertical. Default 0.
    #[serde(deserialize_with = "azimuth")]
    pub azimuth: f64,
    /// Unshaded intensity, 0 to 100 (light units per m² per step). Default 1.
    #[serde(deserialize_with = "intensity")]
    pub intensity: f64,
    /// Beer–Lambert coefficient `k`: a voxel whose shading area is `A` lets through
    /// `exp(-k·A/s²)`. 0 to 50. Default 1.5.
    #[serde(deserialize_with = "extinction")]
    pub extinction: f64,
}

crate::ranged!(elevation: f64, "elevation", 0.0, 90.0, " degrees");
crate::ranged!(azimuth: f64, "azimuth", -360.0, 360.0, " degrees");
crate::ranged!(intensity: f64, "intensity", 0.0, 100.0, "");
crate::ranged!(extinction: f64, "extinction", 0.0, 50.0, "");

impl Default for LightSettings {
    fn default() -> Self {
        LightSettings {
            elevation: 90.0,
            azimuth: 0.0,
            intensity: 1.0,
            extinction: 1.5,
        }
    }
}

impl LightSettings {
    /// Unit vector pointing towards the light (from the world to the source).
    pub fn towards_source(&self) -> Vec3 {
        let (e, a) = (self.elevation.to_radians(), self.azimuth.to_radians());
        let v = Vec3::new(
            (e.cos() * a.cos()) as f32,
            e.sin() as f32,
            (e.cos() * a.sin()) as f32,
        );
        // Snap tiny components (cos 90° is 6e-17) so vertical light is exactly vertical.
        let snap = |c: f32| if c.abs() < 1e-6 { 0.0 } else { c };
        Vec3::new(snap(v.x), snap(v.y), snap(v.z)).normalize()
    }
}

/// Minerals in the soil.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MineralSettings {
    /// Starting concentration of every soil voxel, 0 to 1e6 g/m³. Default 40.
    #[serde(deserialize_with = "concentration")]
    pub concentration: f64,
    /// Diffusion coefficient `D`, 0 to 100 m² per step; each face exchanges
    /// `D/s²` of the difference per step (sub-stepped to stay at most 1/6). Default 0.001
    /// (0.064 per step with 0.125 m voxels).
    #[serde(deserialize_with = "diffusion")]
    pub diffusion: f64,
    /// Largest fraction of a voxel's minerals roots may take in one step, 0.01 to 1.
    /// Default 0.5.
    #[serde(deserialize_with = "max_uptake")]
    pub max_uptake: f64,
}

crate::ranged!(concentration: f64, "concentration", 0.0, 1e6, " g/m³");
crate::ranged!(diffusion: f64, "diffusion", 0.0, 100.0, " m² per step");
crate::ranged!(max_uptake: f64, "max_uptake", 0.01, 1.0, "");

impl Default for MineralSettings {
    fn default() -> Self {
        MineralSettings {
            concentration: 40.0,
            diffusion: 0.001,
            max_uptake: 0.5,
        }
    }
}

/// Size of the world, its voxels, its light and its soil.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvironmentSettings {
    /// Edge of a voxel, 0.01 to 10 m. Default 0.125.
    #[serde(deserialize_with = "voxel_size")]
    pub voxel_size: f64,
    /// Voxels along x, y (up) and z, each 2 to 1024, at most [`MAX_VOXELS`] in all.
    /// Default `[64, 64, 64]`.
    #[serde(deserialize_with = "grid_size")]
    pub size: [u32; 3],
    /// Layers of soil at the bottom; the rest is sky. At least 1 and fewer than `size[1]`.
    /// Default 16 (2 m of soil under 6 m of sky).
    #[serde(deserialize_with = "soil_layers")]
    pub soil_layers: u32,
    /// The light.
    pub light: LightSettings,
    /// The minerals.
    pub minerals: MineralSettings,
}

crate::ranged!(voxel_size: f64, "voxel_size", 0.01, 10.0, " m");

crate::ranged!(grid_size: [u32; 3], "size", 2, 1024);

crate::ranged!(soil_layers: u32, "soil_layers", 1, 1023);

impl Default for EnvironmentSettings {
    fn default() -> Self {
        EnvironmentSettings {
            voxel_size: 0.125,
            size: [64, 64, 64],
            soil_layers: 16,
            light: LightSettings::default(),
            minerals: MineralSettings::default(),
        }
    }
}

/// Why an environment could not be made.
#[derive(Debug, Error, PartialEq)]
pub enum EnvironmentError {
    /// A number is NaN, infinite or out of its range.
    #[error("`{field}` is {value}, expected {expected}")]
    OutOfRange {
        /// Which setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is allowed.
        expected: &'static str,
    },
    /// Too many voxels.
    #[error("{voxels} voxels is more than the {MAX_VOXELS} a world may hold")]
    TooLarge {
        /// Voxels asked for.
        voxels: u64,
    },
    /// The world would not fit in the memory budget.
    #[error("the world does not fit in memory")]
    OverBudget(#[from] crate::budget::OverBudget),
}

impl EnvironmentSettings {
    /// Bytes the world's voxels hold: shade, light and light leaving each sky voxel, minerals
    /// and their scratch in each soil voxel.
    pub fn memory_bytes(&self) -> u64 {
        let [x, y, z] = self.size.map(u64::from);
        let soil = u64::from(self.soil_layers).min(y);
        x * (y - soil) * z * 3 * 4 + x * soil * z * 2 * 8 + x * z * 8
    }

    /// Checks every range, including those serde cannot see (a struct built in code).
    pub fn validate(&self) -> Result<(), EnvironmentError> {
        let check = |field, value: f64, lo: f64, hi: f64, expected| {
            if value.is_finite() && (lo..=hi).contains(&value) {
                Ok(())
            } else {
                Err(EnvironmentError::OutOfRange {
                    field,
                    value,
                    expected,
                })
            }
        };
        check("voxel_size", self.voxel_size, 0.01, 10.0, "0.01 to 10 m")?;
        for s in self.size {
            check("size", f64::from(s), 2.0, 1024.0, "2 to 1024 voxels a side")?;
        }
        check(
            "soil_layers",
            f64::from(self.soil_layers),
            1.0,
            f64::from(self.size[1]) - 1.0,
            "at least 1 and fewer than the layers of the world",
        )?;
        let l = &self.light;
        check("elevation", l.elevation, 0.0, 90.0, "0 to 90 degrees")?;
        check("azimuth", l.azimuth, -360.0, 360.0, "-360 to 360 degrees")?;
        check("intensity", l.intensity, 0.0, 100.0, "0 to 100")?;
        check("extinction", l.extinction, 0.0, 50.0, "0 to 50")?;
        let m = &self.minerals;
        check("concentration", m.concentration, 0.0, 1e6, "0 to 1e6 g/m³")?;
        check("diffusion", m.diffusion, 0.0, 100.0, "0 to 100 m² per step")?;
        check("max_uptake", m.max_uptake, 0.01, 1.0, "0.01 to 1")?;
        let voxels = self.size.iter().map(|&s| u64::from(s)).product::<u64>();
        if voxels > MAX_VOXELS {
            return Err(EnvironmentError::TooLarge { voxels });
        }
        Ok(())
    }
}

/// Integer coordinates of a voxel: x, y (layer, 0 at the bottom of the soil), z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VoxelCoord {
    /// Column along x.
    pub x: u32,
    /// Layer, counted from the bottom of the soil.
    pub y: u32,
    /// Column along z.
    pub z: u32,
}

/// One tap of the light sweep: a linear offset to an upstream voxel, its coordinate offsets
/// along the two transverse axes, and its bilinear weight.
#[derive(Clone, Copy, Debug, Default)]
struct Tap {
    offset: isize,
    d1: i64,
    d2: i64,
    weight: f32,
}

/// The sweep order for the current light direction.
#[derive(Clone, Copy, Debug)]
struct Sweep {
    /// Dominant axis (0 x, 1 y, 2 z) and the two transverse axes, the one with the smallest
    /// stride last.
    axes: [usize; 3],
    /// +1 when the light comes from the high end of the dominant axis.
    upstream: i64,
    taps: [Tap; 4],
    tap_count: usize,
}

/// The voxel world. See the [module documentation](self).
#[derive(Clone, Debug)]
pub struct Environment {
    settings: EnvironmentSettings,
    /// Voxels along x, y, z.
    dims: [usize; 3],
    soil: usize,
    /// Minimum corner of the box, metres.
    origin: Vec3,
    size: f32,
    /// Sky grids, indexed `((y - soil)·nz + z)·nx + x`.
    shade: Vec<f32>,
    light: Vec<f32>,
    exit: Vec<f32>,
    /// Range of layers along the dominant axis holding shade, if any.
    shaded_layers: Option<(usize, usize)>,
    sweep: Sweep,
    /// Soil grids (grams), indexed `(y·nz + z)·nx + x`.
    minerals: Vec<f64>,
    scratch: Vec<f64>,
    /// Carbon on the ground, one cell per column, `z·nx + x`.
    litter: Vec<f64>,
}

impl Environment {
    /// A world with full light and uniform minerals.
    pub fn new(settings: EnvironmentSettings) -> Result<Environment, EnvironmentError> {
        settings.validate()?;
        crate::budget::check(
            settings.memory_bytes(),
            format_args!("a world of {:?} voxels (`size`)", settings.size),
            "use fewer or larger voxels",
        )?;
        let dims = settings.size.map(|s| s as usize);
        let soil = settings.soil_layers as usize;
        let size = settings.voxel_size as f32;
        let origin = Vec3::new(
            -(dims[0] as f32) * size * 0.5,
            -(soil as f32) * size,
            -(dims[2] as f32) * size * 0.5,
        );
        let sky_voxels = dims[0] * (dims[1] - soil) * dims[2];
        let soil_voxels = dims[0] * soil * dims[2];
        let voxel_volume = settings.voxel_size.powi(3);
        let mut env = Environment {
            settings,
            dims,
            soil,
            origin,
            size,
            shade: vec![0.0; sky_voxels],
            light: vec![settings.light.intensity as f32; sky_voxels],
            exit: vec![settings.light.intensity as f32; sky_voxels],
            shaded_layers: None,
            sweep: Sweep {
                axes: [1, 2, 0],
                upstream: 1,
                taps: [Tap::default(); 4],
                tap_count: 0,
            },
            minerals: vec![settings.minerals.concentration * voxel_volume; soil_voxels],
            scratch: vec![0.0; soil_voxels],
            litter: vec![0.0; dims[0] * dims[2]],
        };
        env.sweep = env.plan_sweep();
        Ok(env)
    }

    /// The settings it was made with.
    pub fn settings(&self) -> &EnvironmentSettings {
        &self.settings
    }

    /// Voxels along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Edge of a voxel, metres.
    pub fn voxel_size(&self) -> f32 {
        self.size
    }

    /// Minimum and maximum corners of the box, metres.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let extent = Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        ) * self.size;
        (self.origin, self.origin + extent)
    }

    /// Volume of one voxel, m³.
    pub fn voxel_volume(&self) -> f64 {
        self.settings.voxel_size.powi(3)
    }

    /// The voxel holding `point`, clamped into the box.
    pub fn voxel_at(&self, point: Vec3) -> VoxelCoord {
        let local = (point - self.origin) / self.size;
        let clamp = |v: f32, n: usize| {
            if v.is_nan() {
                0
            } else {
                (v.floor().max(0.0) as usize).min(n - 1) as u32
            }
        };
        VoxelCoord {
            x: clamp(local.x, self.dims[0]),
            y: clamp(local.y, self.dims[1]),
            z: clamp(local.z, self.dims[2]),
        }
    }

    /// Centre of a voxel, metres.
    pub fn center(&self, v: VoxelCoord) -> Vec3 {
        self.origin + (Vec3::new(v.x as f32, v.y as f32, v.z as f32) + 0.5) * self.size
    }

    /// True for soil voxels (below the ground).
    pub fn is_soil(&self, v: VoxelCoord) -> bool {
        (v.y as usize) < self.soil
    }

    /// Index in the sky grids, or `None` for a soil voxel.
    pub fn sky_index(&self, v: VoxelCoord) -> Option<usize> {
        let y = (v.y as usize).checked_sub(self.soil)?;
        Some((y * self.dims[2] + v.z as usize) * self.dims[0] + v.x as usize)
    }

    /// Index in the soil grids, or `None` for a sky voxel.
    pub fn soil_index(&self, v: VoxelCoord) -> Option<usize> {
        let y = v.y as usize;
        (y < self.soil).then(|| (y * self.dims[2] + v.z as usize) * self.dims[0] + v.x as usize)
    }

    /// Sky index of the voxel holding `point`, if that voxel is sky.
    #[inline]
    pub fn sky_index_at(&self, point: Vec3) -> Option<usize> {
        self.sky_index(self.voxel_at(point))
    }

    /// Soil index of the voxel holding `point`, if that voxel is soil.
    #[inline]
    pub fn soil_index_at(&self, point: Vec3) -> Option<usize> {
        self.soil_index(self.voxel_at(point))
    }

    /// Points spread along the segment `a`–`b`, at most half a voxel apart, each with its
    /// share of the segment (the shares sum to 1). Models use it to spread a module over
    /// the voxels it crosses.
    pub fn samples(&self, a: Vec3, b: Vec3) -> impl Iterator<Item = (Vec3, f32)> + use<> {
        let length = (b - a).length();
        let n = if length.is_finite() {
            ((length / (0.5 * self.size)).ceil() as usize).clamp(1, 4096)
        } else {
            1
        };
        let share = 1.0 / n as f32;
        (0..n).map(move |i| (a.lerp(b, (i as f32 + 0.5) * share), share))
    }

    // ----- light -----

    /// Removes all shade (call before plants add theirs for a step).
    pub fn clear_shade(&mut self) {
        if self.shaded_layers.take().is_some() {
            self.shade.fill(0.0);
        }
    }

    /// Adds `area` m² of silhouette to the voxel holding `point`; ignored below ground, for
    /// a non-positive or non-finite area.
    pub fn add_shade(&mut self, point: Vec3, area: f32) {
        if !area.is_finite() || area <= 0.0 {
            return;
        }
        let v = self.voxel_at(point);
        let Some(i) = self.sky_index(v) else {
            return;
        };
        self.shade[i] += area;
        let layer = [v.x, v.y, v.z][self.sweep.axes[0]] as usize;
        self.shaded_layers = Some(match self.shaded_layers {
            None => (layer, layer),
            Some((lo, hi)) => (lo.min(layer), hi.max(layer)),
        });
    }

    /// Shading area in the voxel at sky index `i`, m².
    pub fn shade(&self, i: usize) -> f32 {
        self.shade[i]
    }

    /// Changes the light direction and intensity (the extinction too); the light field is
    /// stale until the next [`update_light`](Self::update_light).
    pub fn set_light(&mut self, light: LightSettings) -> Result<(), EnvironmentError> {
        let mut settings = self.settings;
        settings.light = light;
        settings.validate()?;
        self.settings = settings;
        // Shaded layers were recorded along the old dominant axis: recompute them.
        let shaded = self.shaded_layers.take().is_some();
        self.sweep = self.plan_sweep();
        if shaded {
            self.recount_shaded_layers();
        }
        Ok(())
    }

    fn recount_shaded_layers(&mut self) {
        let [nx, _, nz] = self.dims;
        let axis = self.sweep.axes[0];
        for (i, &a) in self.shade.iter().enumerate() {
            if a > 0.0 {
                let coords = [i % nx, i / (nx * nz) + self.soil, (i / nx) % nz];
                let layer = coords[axis];
                self.shaded_layers = Some(match self.shaded_layers {
                    None => (layer, layer),
                    Some((lo, hi)) => (lo.min(layer), hi.max(layer)),
                });
            }
        }
    }

    fn strides(&self) -> [isize; 3] {
        let [nx, _, nz] = self.dims;
        [1, (nx * nz) as isize, nx as isize]
    }

    fn plan_sweep(&self) -> Sweep {
        let s = self.settings.light.towards_source();
        let c = [s.x, s.y, s.z];
        let abs = c.map(f32::abs);
        // Prefer y on ties, so 45° light still sweeps down from the sky.
        let dominant = if abs[1] >= abs[0] && abs[1] >= abs[2] {
            1
        } else if abs[0] >= abs[2] {
            0
        } else {
            2
        };
        let strides = self.strides();
        let mut transverse: Vec<usize> = (0..3).filter(|&a| a != dominant).collect();
        transverse.sort_by_key(|&a| std::cmp::Reverse(strides[a]));
        let (t1, t2) = (transverse[0], transverse[1]);
        let upstream = if c[dominant] >= 0.0 { 1 } else { -1 };
        let o1 = c[t1] / abs[dominant];
        let o2 = c[t2] / abs[dominant];
        let (f1, f2) = (o1.floor(), o2.floor());
        let (w1, w2) = (o1 - f1, o2 - f2);
        let mut taps = [Tap::default(); 4];
        let mut n = 0;
        for (a, wa) in [(0i64, 1.0 - w1), (1, w1)] {
            for (b, wb) in [(0i64, 1.0 - w2), (1, w2)] {
                let weight = wa * wb;
                if weight > 1e-6 {
                    let (d1, d2) = (f1 as i64 + a, f2 as i64 + b);
                    taps[n] = Tap {
                        offset: upstream as isize * strides[dominant]
                            + d1 as isize * strides[t1]
                            + d2 as isize * strides[t2],
                        d1,
                        d2,
                        weight,
                    };
                    n += 1;
                }
            }
        }
        let total: f32 = taps[..n].iter().map(|t| t.weight).sum();
        for t in &mut taps[..n] {
            t.weight /= total;
        }
        Sweep {
            axes: [dominant, t1, t2],
            upstream,
            taps,
            tap_count: n,
        }
    }

    /// Recomputes the light of every sky voxel from the shade added since
    /// [`clear_shade`](Self::clear_shade) (see the [module documentation](self)).
    pub fn update_light(&mut self) {
        let i0 = self.settings.light.intensity as f32;
        let Some((lo, hi)) = self.shaded_layers else {
            self.light.fill(i0);
            self.exit.fill(i0);
            return;
        };
        let k = self.settings.light.extinction as f32 / (self.size * self.size);
        let Sweep {
            axes: [d, t1, t2],
            upstream,
            taps,
            tap_count,
        } = self.sweep;
        let taps = &taps[..tap_count];
        let strides = self.strides();
        // Layer ranges along each axis, in world layers (sky starts at `soil` along y).
        let range = |axis: usize| {
            if axis == 1 {
                (self.soil, self.dims[1])
            } else {
                (0, self.dims[axis])
            }
        };
        let (d_lo, d_hi) = range(d);
        let (r1, r2) = (range(t1), range(t2));
        let n_layers = d_hi - d_lo;
        // Layers are visited from the light's side: the first shaded one (from that side)
        // still receives full light, everything before it is unshaded.
        let first = if upstream > 0 { hi } else { lo };
        let order = |step: usize| {
            if upstream > 0 {
                d_hi - 1 - step
            } else {
                d_lo + step
            }
        };
        let index = |coords: [usize; 3]| {
            let y = coords[1] - self.soil;
            (y * self.dims[2] + coords[2]) * self.dims[0] + coords[0]
        };
        for step in 0..n_layers {
            let layer = order(step);
            let before_first = if upstream > 0 {
                layer > first
            } else {
                layer < first
            };
            let mut coords = [0usize; 3];
            coords[d] = layer;
            if before_first {
                for i1 in r1.0..r1.1 {
                    coords[t1] = i1;
                    coords[t2] = r2.0;
                    let start = index(coords);
                    for j in 0..(r2.1 - r2.0) {
                        let v = start + j * strides[t2] as usize;
                        self.light[v] = i0;
                        self.exit[v] = i0;
                    }
                }
                continue;
            }
            let up_layer = layer as i64 + upstream;
            let up_inside = up_layer >= d_lo as i64 && up_layer < d_hi as i64;
            for i1 in r1.0..r1.1 {
                coords[t1] = i1;
                coords[t2] = r2.0;
                let start = index(coords);
                for (j, i2) in (r2.0..r2.1).enumerate() {
                    let v = start + j * strides[t2] as usize;
                    let mut incoming = 0.0f32;
                    for tap in taps {
                        let u1 = i1 as i64 + tap.d1;
                        let u2 = i2 as i64 + tap.d2;
                        let inside = up_inside
                            && u1 >= r1.0 as i64
                            && u1 < r1.1 as i64
                            && u2 >= r2.0 as i64
                            && u2 < r2.1 as i64;
                        let e = if inside {
                            self.exit[(v as isize + tap.offset) as usize]
                        } else if (t1 == 1 && u1 < r1.0 as i64) || (t2 == 1 && u2 < r2.0 as i64) {
                            // Below the sky is the ground: no light comes from there.
                            0.0
                        } else {
                            i0
                        };
                        incoming += tap.weight * e;
                    }
                    let incoming = incoming.min(i0);
                    self.light[v] = incoming;
                    let a = self.shade[v];
                    self.exit[v] = if a > 0.0 {
                        incoming * (-k * a).exp()
                    } else {
                        incoming
                    };
                }
            }
        }
    }

    /// Light entering the voxel holding `point`; 0 below ground.
    pub fn light_at(&self, point: Vec3) -> f32 {
        self.sky_index_at(point).map_or(0.0, |i| self.light[i])
    }

    /// Light entering the voxel at sky index `i`.
    #[inline]
    pub fn light(&self, i: usize) -> f32 {
        self.light[i]
    }

    /// Light a module of silhouette `area` m² absorbs in the voxel at sky index `i`: the
    /// voxel's absorbed light `I·s²·(1 - exp(-k·A/s²))` times the module's share `area / A`
    /// of the voxel's shading area `A` (or `I·k·area`, the limit of a lone small module, when
    /// the module's shade was not added).
    pub fn absorbed_light(&self, i: usize, area: f32) -> f32 {
        let incoming = self.light[i];
        let total = self.shade[i];
        let face = self.size * self.size;
        let k = self.settings.light.extinction as f32;
        if total > 0.0 && area <= total * (1.0 + 1e-5) {
            incoming * face * (1.0 - (-k * total / face).exp()) * (area / total)
        } else {
            incoming * k * area.max(0.0)
        }
    }

    // ----- minerals -----

    /// Grams of minerals in the soil voxel at soil index `i`.
    #[inline]
    pub fn minerals(&self, i: usize) -> f64 {
        self.minerals[i]
    }

    /// Mineral concentration at `point`, g/m³; 0 in the sky.
    pub fn concentration_at(&self, point: Vec3) -> f64 {
        self.soil_index_at(point)
            .map_or(0.0, |i| self.minerals[i] / self.voxel_volume())
    }

    /// Adds `grams` to the soil voxel holding `point`, or to the soil voxel under it when
    /// `point` is in the sky. Returns the soil index used.
    pub fn add_minerals(&mut self, point: Vec3, grams: f64) -> usize {
        let mut v = self.voxel_at(point);
        v.y = v.y.min(self.soil as u32 - 1);
        let i = self.soil_index(v).unwrap_or(0);
        self.minerals[i] += grams;
        i
    }

    /// Takes up to `grams` from the soil voxel holding `point`; returns what was taken
    /// (0 in the sky).
    pub fn take_minerals(&mut self, point: Vec3, grams: f64) -> f64 {
        let Some(i) = self.soil_index_at(point) else {
            return 0.0;
        };
        let taken = grams.clamp(0.0, self.minerals[i]);
        self.minerals[i] -= taken;
        taken
    }

    /// All minerals in the soil, grams.
    pub fn total_minerals(&self) -> f64 {
        self.minerals.iter().sum()
    }

    /// One step of diffusion (see the [module documentation](self)).
    pub fn diffuse(&mut self) {
        let rate = self.settings.minerals.diffusion / self.settings.voxel_size.powi(2);
        if rate <= 0.0 {
            return;
        }
        let substeps = (rate * 6.0).ceil().max(1.0) as usize;
        let r = rate / substeps as f64;
        for _ in 0..substeps {
            self.diffuse_once(r);
        }
    }

    fn diffuse_once(&mut self, r: f64) {
        let [nx, _, nz] = self.dims;
        let ny = self.soil;
        let (sy, sz) = (nx * nz, nx);
        let m = &self.minerals;
        let out = &mut self.scratch;
        for y in 0..ny {
            for z in 0..nz {
                let row = y * sy + z * sz;
                for x in 0..nx {
                    let i = row + x;
                    let c = m[i];
                    // Sum of differences with each existing neighbour; closed boundaries.
                    let mut flux = 0.0;
                    if x > 0 {
                        flux += m[i - 1] - c;
                    }
                    if x + 1 < nx {
                        flux += m[i + 1] - c;
                    }
                    if z > 0 {
                        flux += m[i - sz] - c;
                    }
                    if z + 1 < nz {
                        flux += m[i + sz] - c;
                    }
                    if y > 0 {
                        flux += m[i - sy] - c;
                    }
                    if y + 1 < ny {
                        flux += m[i + sy] - c;
                    }
                    out[i] = c + r * flux;
                }
            }
        }
        std::mem::swap(&mut self.minerals, &mut self.scratch);
    }

    // ----- litter -----

    /// Leaves `grams` of carbon on the ground above or below `point`.
    pub fn deposit_litter(&mut self, point: Vec3, grams: f64) {
        let v = self.voxel_at(point);
        self.litter[v.z as usize * self.dims[0] + v.x as usize] += grams;
    }

    /// All carbon in the litter, grams.
    pub fn total_litter(&self) -> f64 {
        self.litter.iter().sum()
    }

    /// Litter carbon of the column holding `point`, grams.
    pub fn litter_at(&self, point: Vec3) -> f64 {
        let v = self.voxel_at(point);
        self.litter[v.z as usize * self.dims[0] + v.x as usize]
    }
}

/// Shared mineral uptake for one step: roots state their demands, then each is served the
/// same fraction of what it asked of its voxel, so the order of plants does not matter.
///
/// ```
/// # use sylva_core::environment::{Environment, EnvironmentSettings, Uptake};
/// # use sylva_core::glam::Vec3;
/// let mut env = Environment::new(EnvironmentSettings::default())?;
/// let i = env.soil_index_at(Vec3::new(0.0, -0.1, 0.0)).unwrap();
/// let mut uptake = Uptake::default();
/// uptake.demand(i, 1e9); // more than the voxel holds: two roots share it
/// uptake.demand(i, 1e9);
/// uptake.apply(&mut env);
/// assert_eq!(uptake.granted(i, 1e9), uptake.granted(i, 1e9));
/// # Ok::<(), sylva_core::environment::EnvironmentError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct Uptake {
    /// Demand, then served fraction, per soil voxel (grown to the soil grid on first use).
    per_voxel: Vec<f64>,
    touched: Vec<usize>,
    applied: bool,
}

impl Uptake {
    /// Forgets the last step's demands.
    pub fn clear(&mut self) {
        for &i in &self.touched {
            self.per_voxel[i] = 0.0;
        }
        self.touched.clear();
        self.applied = false;
    }

    /// Asks for `grams` from the soil voxel at soil index `i`.
    pub fn demand(&mut self, i: usize, grams: f64) {
        debug_assert!(!self.applied, "demands after apply");
        if !grams.is_finite() || grams <= 0.0 {
            return;
        }
        if i >= self.per_voxel.len() {
            self.per_voxel.resize(i + 1, 0.0);
        }
        if self.per_voxel[i] == 0.0 {
            self.touched.push(i);
        }
        self.per_voxel[i] += grams;
    }

    /// Takes what can be served from each voxel (at most the environment's `max_uptake`
    /// fraction of it) and remembers the served fraction. Returns the grams taken in all.
    pub fn apply(&mut self, env: &mut Environment) -> f64 {
        let cap = env.settings.minerals.max_uptake;
        let mut total = 0.0;
        for &i in &self.touched {
            let demand = self.per_voxel[i];
            let available = env.minerals[i] * cap;
            let fraction = if demand > available {
                available / demand
            } else {
                1.0
            };
            let taken = demand * fraction;
            env.minerals[i] = (env.minerals[i] - taken).max(0.0);
            total += taken;
            self.per_voxel[i] = fraction;
        }
        self.applied = true;
        total
    }

    /// What a demand of `grams` on voxel `i` was served, after [`apply`](Self::apply).
    pub fn granted(&self, i: usize, grams: f64) -> f64 {
        if !self.applied || !grams.is_finite() || grams <= 0.0 {
            return 0.0;
        }
        grams * self.per_voxel.get(i).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(light: LightSettings) -> Environment {
        Environment::new(EnvironmentSettings {
            voxel_size: 0.25,
            size: [16, 16, 16],
            soil_layers: 4,
            light,
            ..EnvironmentSettings::default()
        })
        .unwrap()
    }

    #[test]
    fn defaults_are_the_documented_world() {
        let env = Environment::new(EnvironmentSettings::default()).unwrap();
        assert_eq!(env.dims(), [64, 64, 64]);
        let (lo, hi) = env.bounds();
        assert_eq!(lo, Vec3::new(-4.0, -2.0, -4.0));
        assert_eq!(hi, Vec3::new(4.0, 6.0, 4.0));
        assert!(env.is_soil(env.voxel_at(Vec3::new(0.0, -0.01, 0.0))));
        assert!(!env.is_soil(env.voxel_at(Vec3::new(0.0, 0.01, 0.0))));
    }

    #[test]
    fn vertical_shadow_falls_below_only() {
        let mut env = small(LightSettings::default());
        let p = Vec3::new(0.1, 2.1, 0.1);
        env.add_shade(p, 0.06);
        env.update_light();
        let s = env.voxel_size();
        assert_eq!(
            env.light_at(p),
            1.0,
            "a module does not shade its own voxel"
        );
        assert_eq!(env.light_at(p + Vec3::Y * s), 1.0, "nor the voxel above it");
        let below = env.light_at(p - Vec3::Y * s);
        assert!((below - (-1.5f32 * 0.06 / (s * s)).exp()).abs() < 1e-6);
        assert_eq!(
            env.light_at(p - Vec3::Y * 2.0),
            below,
            "the shadow reaches the ground"
        );
        assert_eq!(
            env.light_at(p + Vec3::X * s - Vec3::Y * s),
            1.0,
            "beside it, full"
        );
    }

    #[test]
    fn lateral_shadow_falls_away_from_the_light() {
        // Light from +X at 45 degrees: the shadow goes towards -X and down.
        let mut env = small(LightSettings {
            elevation: 45.0,
            ..LightSettings::default()
        });
        let s = env.voxel_size();
        let p = Vec3::new(0.1, 2.1, 0.1);
        env.add_shade(p, 0.2);
        env.update_light();
        let behind = env.light_at(p + Vec3::new(-s, -s, 0.0));
        let in_front = env.light_at(p + Vec3::new(s, s, 0.0));
        let under = env.light_at(p - Vec3::Y * s);
        assert!(behind < 0.5, "{behind}");
        assert_eq!(in_front, 1.0);
        assert!(
            under > 0.99,
            "straight below is lit under slanted light: {under}"
        );
        // Three layers further along the ray.
        assert!(env.light_at(p + Vec3::new(-3.0 * s, -3.0 * s, 0.0)) < 0.6);
    }

    #[test]
    fn grazing_light_sweeps_along_x() {
        let mut env = small(LightSettings {
            elevation: 20.0,
            azimuth: 180.0,
            ..LightSettings::default()
        });
        // Light from -X: shadow towards +X.
        let s = env.voxel_size();
        let p = Vec3::new(0.1, 1.1, 0.1);
        env.add_shade(p, 0.2);
        env.update_light();
        assert!(env.light_at(p + Vec3::new(s, 0.0, 0.0)) < 0.8);
        assert_eq!(env.light_at(p - Vec3::new(s, 0.0, 0.0)), 1.0);
    }

    #[test]
    fn capture_saturates_and_conserves_light() {
        let mut env = small(LightSettings::default());
        let p = Vec3::new(0.1, 2.1, 0.1);
        env.add_shade(p, 0.01);
        env.update_light();
        let i = env.sky_index_at(p).unwrap();
        let one = env.absorbed_light(i, 0.01);
        assert!(
            one > 0.012 && one < 0.015,
            "close to k·area when alone: {one}"
        );
        env.clear_shade();
        for _ in 0..100 {
            env.add_shade(p, 0.01);
        }
        env.update_light();
        let each = env.absorbed_light(i, 0.01);
        let face = env.voxel_size().powi(2);
        assert!(
            each * 100.0 <= face * 1.0001,
            "at most the light through a face"
        );
        let transmitted = env.light_at(p - Vec3::Y * 0.25) * face;
        assert!((each * 100.0 + transmitted - face).abs() < 1e-5);
    }

    #[test]
    fn diffusion_conserves_and_is_symmetric() {
        let mut env = Environment::new(EnvironmentSettings {
            voxel_size: 0.25,
            size: [9, 12, 9],
            soil_layers: 9,
            minerals: MineralSettings {
                concentration: 0.0,
                diffusion: 0.05, // r = 0.8: sub-stepped
                max_uptake: 0.5,
            },
            ..EnvironmentSettings::default()
        })
        .unwrap();
        let centre = env.center(VoxelCoord { x: 4, y: 4, z: 4 });
        env.add_minerals(centre, 1000.0);
        for _ in 0..20 {
            env.diffuse();
            assert!(
                env.minerals.iter().all(|&m| m >= 0.0),
                "stable: no negatives"
            );
        }
        assert!((env.total_minerals() - 1000.0).abs() < 1e-9);
        let at = |x, y, z| env.minerals[env.soil_index(VoxelCoord { x, y, z }).unwrap()];
        for (a, b) in [
            ((3, 4, 4), (5, 4, 4)),
            ((4, 3, 4), (4, 5, 4)),
            ((4, 4, 3), (4, 4, 5)),
            ((3, 4, 4), (4, 3, 4)),
            ((0, 0, 0), (8, 8, 8)),
        ] {
            let (va, vb) = (at(a.0, a.1, a.2), at(b.0, b.1, b.2));
            assert!(
                (va - vb).abs() <= 1e-12 * va.abs().max(1e-30),
                "{a:?} {b:?}"
            );
        }
        assert!(at(4, 4, 4) > at(3, 4, 4) && at(3, 4, 4) > at(2, 4, 4));
    }

    #[test]
    fn uptake_shares_a_scarce_voxel_evenly() {
        let mut env = small(LightSettings::default());
        let p = Vec3::new(0.1, -0.1, 0.1);
        let i = env.soil_index_at(p).unwrap();
        let before = env.minerals(i);
        let mut uptake = Uptake::default();
        uptake.demand(i, before);
        uptake.demand(i, before);
        let taken = uptake.apply(&mut env);
        assert!((taken - before * 0.5).abs() < 1e-12);
        assert!((uptake.granted(i, before) - before * 0.25).abs() < 1e-12);
        assert!((env.minerals(i) - before * 0.5).abs() < 1e-12);
        uptake.clear();
        assert_eq!(uptake.granted(i, 1.0), 0.0);
    }

    #[test]
    fn bad_settings_are_refused() {
        let bad = EnvironmentSettings {
            soil_layers: 64,
            ..EnvironmentSettings::default()
        };
        assert!(matches!(
            Environment::new(bad),
            Err(EnvironmentError::OutOfRange {
                field: "soil_layers",
                ..
            })
        ));
        let bad = EnvironmentSettings {
            voxel_size: f64::NAN,
            ..EnvironmentSettings::default()
        };
        assert!(Environment::new(bad).is_err());
        let huge = EnvironmentSettings {
            size: [1024, 1024, 1024],
            ..EnvironmentSettings::default()
        };
        assert!(matches!(
            Environment::new(huge),
            Err(EnvironmentError::TooLarge { .. })
        ));
    }
}
