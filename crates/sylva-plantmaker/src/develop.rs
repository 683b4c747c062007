//! Genotype to phenotype: a [`PlantMaker`] genome and a seed grow a [`Plant`].
//!
//! **Scale.** One length unit is a centimetre and one thickness unit a millimetre of
//! diameter ([`LENGTH_UNIT`], [`THICKNESS_UNIT`]), so the tables' 1–30 per cone and 1–250
//! thickness give herbs of a few decimetres and trees of several metres with trunks up to
//! 25 cm across. Y is up and the stem starts at the origin.
//!
//! **A branch** is a chain of cones, grown like a turtle:
//!
//! - The number of cones is the average of its range (rounded up) or drawn within it; each
//!   cone's length is the average or drawn within its range; base and apex thickness follow
//!   variable 11 from cone to cone (constant: the averages; thinner: maxima to minima;
//!   thicker: minima to maxima; random: drawn per cone).
//! - Between two cones the heading turns by an x angle (about the branch's right axis,
//!   towards its up side) and a y angle (about its up axis, sideways). *Straight*: none.
//!   *Curved*: the joints are spread evenly over `waves` waves and each wave runs linearly
//!   from the minimum to the maximum angles (Table 1's words); 0–20 bows into a circle
//!   (Figure 5), 350–10 (−10 to 10) makes waves. *Curled*: `waves` full turns about the x
//!   axis, joint `i` turning in proportion to `(i + 1)²` so the branch rolls up at its tip
//!   like a fiddlehead, in the direction of the mean x angle's sign; the mean y angle twists
//!   it sideways.
//!   Noise, when on, adds an x and a y angle drawn in their ranges at every joint
//!   (Figure 6).
//! - The segment pattern shapes each cone (Figure 4): see
//!   [`SegmentPattern`]. Joints of a tube carry one radius, so steps
//!   and pinches are drawn as short extra segments: 1 segment per cone (straight), 3
//!   (segmented) or 2 (triangular, diamond).
//!
//! **Branch or leaf.** The paper draws branches and leaves with the same object, "depending
//! upon the various branch parameters". A branch prototype whose average widest thickness
//! is at least [`LEAF_RATIO`] times its average cone length (a wide, short branch; see
//! [`Branch::is_leaf`]) is drawn as a leaf wherever a fan places it: one flat
//! [`OrganKind::Leaf`] blade per cone, as wide as the cone's thickest point, facing the
//! branch's up side, on a thin midrib tube. The pattern decides how blades join: straight
//! blades reach half-way into their neighbours (one smooth strap), segmented ones leave gaps
//! (a string of leaflets), triangular ones overlap the next a little (a saw-toothed edge),
//! diamond ones meet point to point. Meshing reads only the plant, so the blade outline is
//! the mesher's. The stem is always a stem.
//!
//! **Materials.** One per distinct kind, colour and texture: leaf-like copies are
//! [`MaterialKind::Leaf`] when their colour is green (hue 70°–170°, saturation at least
//! 0.15) and [`MaterialKind::Flower`] (petals) otherwise; other copies are
//! [`MaterialKind::Bark`]. Colours are the genome's sRGB, stored linear. The fan's texture
//! id goes to [`Material::texture`] less one: the table's 0 is "no texture" and Sylva's
//! textures count from 0, so genome texture 1 is Sylva texture 0. The stem has no fan, so no genome colour:
//! it is green when thin (10 mm or less on average) and bark-brown when thick (40 mm or
//! more), blended between.
//!
//! **Fans and inflorescences.** An expressed inflorescence finds its point at `position`
//! per cent of the stem's length. Its fans share the 360° around the stem in equal sectors,
//! in fan order from `start_angle`; each fan spreads its branches evenly over its sector.
//! A branch leaves at its azimuth, slanted up from the plane across the stem by its angle
//! (above 180 slants down), with its up side towards the stem's heading. Across a fan, each
//! property is constant (length and thickness: the maximum factor; angle and colour: the
//! minimum), increasing, decreasing, alternating (min, mid, max, mid, …) or random; colour
//! is blended between the two colours in 16 steps, which bounds the materials.
//!
//! **Randomness.** Every draw comes from one ChaCha8 stream seeded by the `seed` argument
//! ([`sylva_core::rng::seeded`]), in a fixed order: stem, then each expressed
//! inflorescence and its fans' branches in order. Orphan segments draw nothing, so they never
//! change the plant.
//!
//! **Size.** Growth stops with [`DevelopError::TooLarge`] before the plant would have more
//! than [`MAX_PARTS`] segments and organs.

use rand::RngExt;
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::rng::ChaCha8Rng;
use sylva_core::{Frame, Material, MaterialId, MaterialKind, Organ, OrganKind, Plant, SegmentId};

use crate::PlantMaker;
use crate::genes::{Amount, Branch, BranchShape, Progression, Rgb, SegmentPattern, Thickness};
use sylva_model::DevelopError;

/// Metres per length unit: a centimetre.
pub const LENGTH_UNIT: f32 = 0.01;
/// Metres of diameter per thickness unit: a millimetre.
pub const THICKNESS_UNIT: f32 = 0.001;
/// A branch prototype is drawn as a leaf when its average widest thickness is at least this
/// times its average cone length (see [`Branch::is_leaf`]).
pub const LEAF_RATIO: f32 = 0.4;
/// Most segments plus organs a plant may have.
pub const MAX_PARTS: usize = 200_000;
/// Colour blends are rounded to this many steps between a fan's two colours.
const COLOR_STEPS: f32 = 15.0;

/// One cone of a grown branch. Radii in metres.
#[derive(Clone, Copy, Debug)]
struct Cone {
    start: Vec3,
    frame: Frame,
    length: f32,
    base: f32,
    apex: f32,
}

/// Degrees 0–360 read as a signed turn: above 180 turns the other way.
fn signed(degrees: u16) -> f32 {
    let d = f32::from(degrees);
    if d > 180.0 { d - 360.0 } else { d }
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// Linear value of an 8-bit sRGB channel.
fn linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn blend(a: Rgb, b: Rgb, t: f32) -> Rgb {
    Rgb(std::array::from_fn(|i| {
        lerp(f32::from(a.0[i]), f32::from(b.0[i]), t).round() as u8
    }))
}

/// Whether a colour reads as foliage: a green hue, not grey.
pub(crate) fn is_green(c: Rgb) -> bool {
    let [r, g, b] = c.0.map(f32::from);
    let (max, min) = (r.max(g).max(b), r.min(g).min(b));
    if max <= 0.0 || (max - min) / max < 0.15 {
        return false;
    }
    let d = max - min;
    let hue = if max == r {
        60.0 * ((g - b) / d).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    (70.0..=170.0).contains(&hue)
}

/// Where a fan property stands for branch `j` of `k`, 0 (min) to 1 (max); `None` when
/// constant.
fn progression(mode: Progression, j: usize, k: usize, rng: &mut ChaCha8Rng) -> Option<f32> {
    let ramp = if k > 1 {
        j as f32 / (k - 1) as f32
    } else {
        0.0
    };
    match mode {
        Progression::Constant => None,
        Progression::Increasing => Some(ramp),
        Progression::Decreasing => Some(1.0 - ramp),
        Progression::Alternating => Some([0.0, 0.5, 1.0, 0.5][j % 4]),
        Progression::Random => Some(rng.random::<f32>()),
    }
}

/// Radius profile of cone `i` as `(t, radius)` points after its start (t in 0..=1).
fn profile(pattern: SegmentPattern, cones: &[Cone], i: usize) -> ([(f32, f32); 3], usize) {
    let c = &cones[i];
    let next = cones.get(i + 1);
    match pattern {
        SegmentPattern::Straight => {
            let r = next.map_or(c.apex, |n| 0.5 * (c.apex + n.base));
            ([(1.0, r), (0.0, 0.0), (0.0, 0.0)], 1)
        }
        SegmentPattern::Segmented => {
            let pinch = 0.7 * next.map_or(c.apex, |n| c.apex.min(n.base));
            ([(0.1, c.base), (0.9, c.apex), (1.0, pinch)], 3)
        }
        SegmentPattern::Triangular => match next {
            Some(n) => ([(0.94, c.apex), (1.0, n.base), (0.0, 0.0)], 2),
            None => ([(1.0, c.apex), (0.0, 0.0), (0.0, 0.0)], 1),
        },
        SegmentPattern::Diamond => ([(0.5, c.base), (1.0, c.apex), (0.0, 0.0)], 2),
    }
}

/// Radius at the very start of a branch.
fn start_radius(pattern: SegmentPattern, first: &Cone) -> f32 {
    match pattern {
        SegmentPattern::Diamond => first.apex,
        _ => first.base,
    }
}

/// Segments a tube of `cones` cones takes.
fn tube_parts(pattern: SegmentPattern, cones: usize) -> usize {
    match pattern {
        SegmentPattern::Straight => cones,
        SegmentPattern::Segmented => 3 * cones,
        SegmentPattern::Triangular => (2 * cones).saturating_sub(1),
        SegmentPattern::Diamond => 2 * cones,
    }
}

/// A point on the stem where fans attach.
#[derive(Clone, Copy)]
struct Anchor {
    point: Vec3,
    frame: Frame,
    parent: SegmentId,
}

/// One placed copy of a branch prototype.
struct Placed<'a> {
    proto: &'a Branch,
    start: Vec3,
    frame: Frame,
    length_factor: f32,
    thickness_factor: f32,
}

struct Builder {
    plant: Plant,
    rng: ChaCha8Rng,
    /// (kind, colour, texture) of each material, indexed like `plant.materials()`.
    keys: Vec<(MaterialKind, Rgb, Option<u16>)>,
    /// Scratch: the cones of the branch being grown.
    cones: Vec<Cone>,
}

impl Builder {
    /// Grows a copy's cones into `self.cones`.
    fn grow(&mut self, c: &Placed) {
        let b = c.proto;
        let rng = &mut self.rng;
        self.cones.clear();
        let (lo, hi) = {
            let (a, b) = (b.min_segments, b.max_segments);
            (a.min(b), a.max(b))
        };
        let n = match b.segment_count {
            Amount::Constant => (u32::from(lo) + u32::from(hi)).div_ceil(2) as usize,
            Amount::Random => usize::from(rng.random_range(lo..=hi)),
        };
        let (min_len, max_len) = (f32::from(b.min_length), f32::from(b.max_length));
        let (b0, b1) = (
            f32::from(b.min_base_thickness),
            f32::from(b.max_base_thickness),
        );
        let (a0, a1) = (
            f32::from(b.min_apex_thickness),
            f32::from(b.max_apex_thickness),
        );
        let length_scale = LENGTH_UNIT * c.length_factor;
        let radius_scale = 0.5 * THICKNESS_UNIT * c.thickness_factor;
        let (x0, x1) = (signed(b.min_x_angle), signed(b.max_x_angle));
        let (y0, y1) = (signed(b.min_y_angle), signed(b.max_y_angle));
        let (nx0, nx1) = (signed(b.min_noise_x_angle), signed(b.max_noise_x_angle));
        let (ny0, ny1) = (signed(b.min_noise_y_angle), signed(b.max_noise_y_angle));
        let joints = n.saturating_sub(1);
        let waves = f32::from(b.waves);
        let mut start = c.start;
        let mut frame = c.frame;
        for i in 0..n {
            let length = match b.length {
                Amount::Constant => 0.5 * (min_len + max_len),
                Amount::Random => lerp(min_len, max_len, rng.random::<f32>()),
            } * length_scale;
            let t = if n > 1 {
                i as f32 / (n - 1) as f32
            } else {
                0.0
            };
            let (base, apex) = match b.thickness {
                Thickness::Constant => (0.5 * (b0 + b1), 0.5 * (a0 + a1)),
                Thickness::Thinner => (lerp(b1, b0, t), lerp(a1, a0, t)),
                Thickness::Thicker => (lerp(b0, b1, t), lerp(a0, a1, t)),
                Thickness::Random => (
                    lerp(b0, b1, rng.random::<f32>()),
                    lerp(a0, a1, rng.random::<f32>()),
                ),
            };
            self.cones.push(Cone {
                start,
                frame,
                length,
                base: base * radius_scale,
                apex: apex * radius_scale,
            });
            start += frame.heading * length;
            if i + 1 == n {
                break;
            }
            let (mut bx, mut by) = match b.branch_shape {
                BranchShape::Straight => (0.0, 0.0),
                BranchShape::Curled => {
                    // Joint i turns in proportion to (i + 1)²: a crozier, tight at the tip.
                    let total = (joints * (joints + 1) * (2 * joints + 1) / 6) as f32;
                    let sign = if x0 + x1 < 0.0 { -1.0 } else { 1.0 };
                    let w = ((i + 1) * (i + 1)) as f32;
                    (sign * waves * 360.0 * w / total, 0.5 * (y0 + y1))
                }
                BranchShape::Curved => {
                    let phase = ((i as f32 + 0.5) / joints as f32 * waves).fract();
                    (lerp(x0, x1, phase), lerp(y0, y1, phase))
                }
            };
            if b.noise {
                bx += lerp(nx0, nx1, rng.random::<f32>());
                by += lerp(ny0, ny1, rng.random::<f32>());
            }
            frame.rotate_l(bx.to_radians());
            frame.rotate_u(by.to_radians());
        }
    }

    /// The material of a kind, colour and texture, added on first use.
    fn material(
        &mut self,
        kind: MaterialKind,
        color: Rgb,
        texture: Option<u16>,
    ) -> Result<MaterialId, DevelopError> {
        let key = (kind, color, texture);
        if let Some(i) = self.keys.iter().position(|k| *k == key) {
            return Ok(MaterialId(i as u16));
        }
        let name = match texture {
            Some(t) => format!("{}-{:06x}-t{t}", kind.name(), color.code()),
            None => format!("{}-{:06x}", kind.name(), color.code()),
        };
        let id = self.plant.add_material(Material {
            name,
            kind,
            color: color.0.map(linear),
            texture,
            surface: None,
        })?;
        self.keys.push(key);
        Ok(id)
    }

    fn check_room(&self, parts: usize) -> Result<(), DevelopError> {
        if self.plant.segments().len() + self.plant.organs().len() + parts > MAX_PARTS {
            Err(DevelopError::TooLarge { limit: MAX_PARTS })
        } else {
            Ok(())
        }
    }

    /// Emits the grown cones as a tube; returns each segment as (cone, t0, t1, id).
    fn emit_tube(
        &mut self,
        pattern: SegmentPattern,
        parent: Option<SegmentId>,
        material: MaterialId,
        mut record: Option<&mut Vec<(usize, f32, f32, SegmentId)>>,
    ) -> Result<(), DevelopError> {
        let Some(first) = self.cones.first() else {
            return Ok(());
        };
        self.check_room(tube_parts(pattern, self.cones.len()))?;
        let mut radius = start_radius(pattern, first);
        let mut prev = parent;
        let mut lateral = parent.is_some();
        for i in 0..self.cones.len() {
            let c = self.cones[i];
            let (points, len) = profile(pattern, &self.cones, i);
            let mut t0 = 0.0;
            for &(t1, r1) in &points[..len] {
                let a = c.start + c.frame.heading * (c.length * t0);
                let b = c.start + c.frame.heading * (c.length * t1);
                let id = self
                    .plant
                    .add_segment(a, b, (radius, r1), prev, lateral, material)?;
                if let Some(rec) = record.as_deref_mut() {
                    rec.push((i, t0, t1, id));
                }
                (prev, lateral, radius, t0) = (Some(id), false, r1, t1);
            }
        }
        Ok(())
    }

    /// Emits the grown cones as a leaf: a midrib tube and one blade per cone.
    fn emit_leaf(
        &mut self,
        pattern: SegmentPattern,
        parent: SegmentId,
        material: MaterialId,
    ) -> Result<(), DevelopError> {
        let n = self.cones.len();
        self.check_room(2 * n)?;
        let mean_width = self
            .cones
            .iter()
            .map(|c| 2.0 * c.base.max(c.apex))
            .sum::<f32>()
            / n.max(1) as f32;
        let rib = (0.04 * mean_width).clamp(0.0004, 0.004);
        let mut prev = parent;
        for i in 0..n {
            let c = self.cones[i];
            let end = c.start + c.frame.heading * c.length;
            let taper = |k: usize| rib * (1.0 - 0.6 * k as f32 / n as f32);
            prev = self.plant.add_segment(
                c.start,
                end,
                (taper(i), taper(i + 1)),
                Some(prev),
                i == 0,
                material,
            )?;
            // Blade extent along the cone, as (from, length) in metres from its start.
            let before = if i > 0 { self.cones[i - 1].length } else { 0.0 };
            let after = self.cones.get(i + 1).map_or(0.0, |c| c.length);
            let (from, length) = match pattern {
                // Each blade reaches half-way into its neighbours: one smooth strap.
                SegmentPattern::Straight => (-0.5 * before, 0.5 * before + c.length + 0.5 * after),
                // Separate blades with gaps: a string of leaflets.
                SegmentPattern::Segmented => (0.1 * c.length, 0.8 * c.length),
                // Each blade overlaps the next a little: a saw-toothed edge.
                SegmentPattern::Triangular => (0.0, c.length + 0.4 * after),
                // Blades meet point to point: a chain of diamonds.
                SegmentPattern::Diamond => (0.0, c.length),
            };
            self.plant.add_organ(Organ {
                kind: OrganKind::Leaf,
                position: c.start + c.frame.heading * from,
                orientation: c.frame.rotation(),
                size: Vec2::new(length, 2.0 * c.base.max(c.apex)),
                material,
                parent: Some(prev),
            })?;
        }
        Ok(())
    }
}

/// Where `fraction` (0..=1) of the stem's length lies.
fn anchor(stem: &[Cone], parts: &[(usize, f32, f32, SegmentId)], fraction: f32) -> Anchor {
    let total: f32 = stem.iter().map(|c| c.length).sum();
    let mut left = fraction.clamp(0.0, 1.0) * total;
    let mut cone = stem.len() - 1;
    let mut t = 1.0;
    for (i, c) in stem.iter().enumerate() {
        if left <= c.length {
            cone = i;
            t = if c.length > 0.0 { left / c.length } else { 0.0 };
            break;
        }
        left -= c.length;
    }
    let c = &stem[cone];
    let parent = parts
        .iter()
        .find(|&&(i, _, t1, _)| i == cone && t <= t1)
        .or(parts.last())
        .map(|p| p.3)
        .unwrap_or(SegmentId(0));
    Anchor {
        point: c.start + c.frame.heading * (c.length * t),
        frame: c.frame,
        parent,
    }
}

impl Branch {
    /// Whether copies of this branch are drawn as leaves: its average widest thickness
    /// (the larger of the base and apex averages) is at least [`LEAF_RATIO`] times its
    /// average cone length. Decided on the prototype alone, so every copy of a branch is
    /// drawn alike whatever its fan's factors and the seed.
    pub fn is_leaf(&self) -> bool {
        let avg = |a: u8, b: u8| 0.5 * (f32::from(a) + f32::from(b));
        let width = avg(self.min_base_thickness, self.max_base_thickness)
            .max(avg(self.min_apex_thickness, self.max_apex_thickness))
            * THICKNESS_UNIT;
        let length = avg(self.min_length, self.max_length) * LENGTH_UNIT;
        width >= LEAF_RATIO * length
    }
}

impl PlantMaker {
    /// Grows the genome's own plant: [`PlantMaker::develop`] with [`PlantMaker::seed`].
    pub fn grow(&self) -> Result<Plant, DevelopError> {
        self.develop(self.seed)
    }

    /// Grows the plant with `seed` (use [`PlantMaker::seed`] for the genome's own plant;
    /// other seeds give its siblings).
    ///
    /// See the [module docs](self) for how each gene is read.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        let plant = Plant::bare(sylva_model::plant_meta::<crate::PlantMakerModel>(
            self, seed,
        ));
        let mut b = Builder {
            plant,
            rng: sylva_core::rng::seeded(seed),
            keys: Vec::new(),
            cones: Vec::with_capacity(128),
        };
        let Some(stem_proto) = self.branches.first() else {
            return Ok(b.plant);
        };

        // The stem.
        b.grow(&Placed {
            proto: stem_proto,
            start: Vec3::ZERO,
            frame: Frame::UPRIGHT,
            length_factor: 1.0,
            thickness_factor: 1.0,
        });
        let stem = b.cones.clone();
        let mean_diameter_mm = stem.iter().map(|c| c.base + c.apex).sum::<f32>()
            / stem.len().max(1) as f32
            / THICKNESS_UNIT;
        let woody = ((mean_diameter_mm - 10.0) / 30.0).clamp(0.0, 1.0);
        let stem_color = blend(Rgb([0x4f, 0x7a, 0x2a]), Rgb([0x5a, 0x40, 0x30]), woody);
        let stem_material = b.material(MaterialKind::Bark, stem_color, None)?;
        let mut parts = Vec::with_capacity(3 * stem.len());
        b.emit_tube(
            stem_proto.segment_pattern,
            None,
            stem_material,
            Some(&mut parts),
        )?;
        if stem.is_empty() {
            return Ok(b.plant);
        }

        // Inflorescences, in order.
        for infl in self.inflorescences.iter().filter(|i| i.expressed) {
            let members: Vec<usize> = infl
                .fans
                .numbers()
                .filter(|&f| f <= self.fans.len())
                .map(|f| f - 1)
                .collect();
            if members.is_empty() {
                continue;
            }
            let at = anchor(&stem, &parts, f32::from(infl.position) / 100.0);
            let sector = 360.0 / members.len() as f32;
            for (q, &f) in members.iter().enumerate() {
                let fan = &self.fans[f];
                let Some(proto) = self.branches.get(usize::from(fan.branch).wrapping_sub(1)) else {
                    continue;
                };
                let k = usize::from(fan.count);
                for j in 0..k {
                    let rng = &mut b.rng;
                    let factor = |mode, lo: crate::Tenths, hi: crate::Tenths, rng: &mut _| {
                        match progression(mode, j, k, rng) {
                            None => hi.value(),
                            Some(t) => lerp(lo.value(), hi.value(), t),
                        }
                    };
                    let length_factor = factor(
                        fan.length_mode,
                        fan.min_length_factor,
                        fan.max_length_factor,
                        rng,
                    );
                    let slant = match progression(fan.angle_mode, j, k, rng) {
                        None => signed(fan.min_angle),
                        Some(t) => lerp(signed(fan.min_angle), signed(fan.max_angle), t),
                    };
                    let thickness_factor = factor(
                        fan.thickness_mode,
                        fan.min_thickness_factor,
                        fan.max_thickness_factor,
                        rng,
                    );
                    let color = match progression(fan.color_mode, j, k, rng) {
                        None => fan.min_color,
                        Some(t) => blend(
                            fan.min_color,
                            fan.max_color,
                            (t * COLOR_STEPS).round() / COLOR_STEPS,
                        ),
                    };
                    let azimuth = (f32::from(infl.start_angle)
                        + q as f32 * sector
                        + j as f32 * sector / k as f32)
                        .to_radians();
                    let slant = slant.to_radians();
                    let f0 = at.frame;
                    let radial = -f0.left * azimuth.cos() + f0.up * azimuth.sin();
                    let heading = radial * slant.cos() + f0.heading * slant.sin();
                    let frame = Frame::from_heading_up(heading, f0.heading)
                        .or_else(|| Frame::from_heading_up(heading, radial))
                        .unwrap_or(f0);
                    b.grow(&Placed {
                        proto,
                        start: at.point,
                        frame,
                        length_factor,
                        thickness_factor,
                    });
                    let texture = (fan.texture > 0).then(|| u16::from(fan.texture) - 1);
                    if proto.is_leaf() {
                        let kind = if is_green(color) {
                            MaterialKind::Leaf
                        } else {
                            MaterialKind::Flower
                        };
                        let material = b.material(kind, color, texture)?;
                        b.emit_leaf(proto.segment_pattern, at.parent, material)?;
                    } else {
                        let material = b.material(MaterialKind::Bark, color, texture)?;
                        b.emit_tube(proto.segment_pattern, Some(at.parent), material, None)?;
                    }
                }
            }
        }
        Ok(b.plant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn greens() {
        assert!(is_green(Rgb([0x3d, 0x7a, 0x25])));
        assert!(is_green(Rgb([0x20, 0x60, 0x50])));
        assert!(!is_green(Rgb([0xe0, 0x30, 0x50])));
        assert!(!is_green(Rgb([0xf0, 0xf0, 0xe8])));
        assert!(!is_green(Rgb([0xf0, 0xc0, 0x20])));
    }

    #[test]
    fn default_grows_deterministically() {
        let g = PlantMaker::default();
        let a = g.develop(3).unwrap();
        assert_eq!(a, g.develop(3).unwrap());
        assert_ne!(a, g.develop(4).unwrap());
        assert!(!a.organs().is_empty());
        assert!(a.materials().iter().any(|m| m.kind == MaterialKind::Leaf));
        assert!(a.materials().iter().any(|m| m.kind == MaterialKind::Bark));
        assert_eq!(a.segments()[0].start, Vec3::ZERO);
        // 10 cones of 12 cm.
        assert!((a.height() - 1.2).abs() < 0.3, "{}", a.height());
    }

    #[test]
    fn orphans_do_not_change_the_plant() {
        let g = PlantMaker::default();
        let mut h = g.clone();
        h.branches[4].min_segments = 90;
        h.fans[4].count = 70;
        h.inflorescences[4].position = 3;
        let (a, b) = (g.develop(9).unwrap(), h.develop(9).unwrap());
        assert_eq!(a.segments(), b.segments());
        assert_eq!(a.organs(), b.organs());
    }

    #[test]
    fn patterns_take_their_segment_counts() {
        for (pattern, per) in [
            (SegmentPattern::Straight, 1),
            (SegmentPattern::Segmented, 3),
            (SegmentPattern::Diamond, 2),
        ] {
            let mut g = PlantMaker::default();
            g.branches[0].segment_pattern = pattern;
            g.inflorescences
                .iter_mut()
                .for_each(|i| i.expressed = false);
            let p = g.develop(0).unwrap();
            assert_eq!(p.segments().len(), 10 * per, "{pattern:?}");
        }
    }

    #[test]
    fn size_is_bounded() {
        let mut g = PlantMaker::default();
        for b in &mut g.branches {
            b.min_segments = 128;
            b.max_segments = 128;
            b.segment_pattern = SegmentPattern::Segmented;
            b.min_base_thickness = 1;
            b.max_base_thickness = 1;
            b.min_apex_thickness = 1;
            b.max_apex_thickness = 1;
        }
        for f in &mut g.fans {
            f.count = 72;
        }
        for i in &mut g.inflorescences {
            i.expressed = true;
            i.fans = crate::FanSet::of(&[1, 2, 3, 4, 5]);
        }
        assert!(matches!(
            g.develop(0),
            Err(DevelopError::TooLarge { limit: MAX_PARTS })
        ));
    }
}
