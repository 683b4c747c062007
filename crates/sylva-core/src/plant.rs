//! The one plant type every model grows and every later stage reads.
//!
//! A [`Plant`] is a skeleton of [`Segment`]s (tapered cylinders, each with a parent), a list of
//! [`Organ`]s (leaves, flowers, root tips), the [`Material`]s they use, and [`PlantMeta`]
//! saying where it came from. Segments are stored parents-first: a segment's parent always has
//! a smaller [`SegmentId`], so one forward pass sees every parent before its children.
//!
//! An *axis* is a chain of segments that continue one another (`lateral == false`); a lateral
//! segment starts a new axis (a branch) from its parent. Meshing joins the segments of an
//! axis into one tube.
//!
//! A `Plant` owns its rules: segments, organs and materials go in only through checked
//! methods ([`Plant::add_segment`], [`Plant::add_organ`], [`Plant::add_material`]), and its
//! parts are read through accessors. Every plant therefore holds only finite coordinates
//! within ±[`MAX_COORD`] metres, non-negative sizes, unit orientations, parents stored
//! before their children and materials that exist, so meshing, fitness and export can
//! trust any plant they are given.
//!
//! Units are metres; Y is up.

use glam::{Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::species::Surface;

/// Index of a segment in [`Plant::segments`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct SegmentId(pub u32);

impl SegmentId {
    /// The index as `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Index of a material in [`Plant::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct MaterialId(pub u16);

impl MaterialId {
    /// The index as `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A tapered cylinder of the skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Centre of the base, metres.
    pub start: Vec3,
    /// Centre of the tip, metres.
    pub end: Vec3,
    /// Radius at `start`, metres.
    pub start_radius: f32,
    /// Radius at `end`, metres.
    pub end_radius: f32,
    /// Branch order: 0 for the trunk's axis, parent's order + 1 for a lateral branch.
    pub order: u16,
    /// The segment this one grows from; `None` for a root of the skeleton.
    pub parent: Option<SegmentId>,
    /// `true` when this segment starts a new axis (a branch) from its parent, `false` when it
    /// continues its parent's axis.
    pub lateral: bool,
    /// Bark (or root) material.
    pub material: MaterialId,
}

impl Segment {
    /// `end - start`.
    #[inline]
    pub fn vector(&self) -> Vec3 {
        self.end - self.start
    }

    /// Length in metres.
    #[inline]
    pub fn length(&self) -> f32 {
        self.vector().length()
    }
}

/// What an organ is; decides its outline when meshed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrganKind {
    /// A flat blade.
    Leaf,
    /// A star of petals.
    Flower,
    /// The absorbing tip of a fine root.
    RootTip,
}

/// A leaf, flower or root tip attached to the skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Organ {
    /// What it is.
    pub kind: OrganKind,
    /// Where its base is attached, metres.
    pub position: Vec3,
    /// Local to world: local +Y runs from base to tip along the blade, local +Z is the blade's
    /// face normal.
    pub orientation: Quat,
    /// Length (along local Y) and width (along local X), metres.
    pub size: Vec2,
    /// Its material.
    pub material: MaterialId,
    /// The segment it grows on, if any.
    pub parent: Option<SegmentId>,
}

/// The broad kind of a material; exporters and renderers may treat kinds differently
/// (leaves and petals are double-sided).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MaterialKind {
    /// Stems, trunks and branches.
    Bark,
    /// Leaf blades.
    Leaf,
    /// Petals.
    Flower,
    /// Roots below ground.
    Root,
}

impl MaterialKind {
    /// Lower-case name, used for material names in exports.
    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Bark => "bark",
            MaterialKind::Leaf => "leaf",
            MaterialKind::Flower => "flower",
            MaterialKind::Root => "root",
        }
    }

    /// Whether segments of this kind are wood (bark and root): what the pipe model
    /// ([`crate::taper`]) re-thickens and counts tips of, unlike leaves or petals drawn as
    /// segments.
    pub fn is_woody(self) -> bool {
        matches!(self, MaterialKind::Bark | MaterialKind::Root)
    }

    /// Sylva's default colour for this kind (linear RGB).
    pub fn default_color(self) -> [f32; 3] {
        match self {
            MaterialKind::Bark => [0.20, 0.11, 0.05],
            MaterialKind::Leaf => [0.10, 0.35, 0.06],
            MaterialKind::Flower => [0.85, 0.25, 0.45],
            MaterialKind::Root => [0.45, 0.32, 0.18],
        }
    }
}

/// A surface look: kind, colour and an optional texture id (a model decides what ids mean).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Unique within the plant; used as the exported material name.
    pub name: String,
    /// What the material is for.
    pub kind: MaterialKind,
    /// Linear RGB in 0..=1.
    pub color: [f32; 3],
    /// Texture id, if the model uses textures.
    pub texture: Option<u16>,
    /// A surface Sylva draws itself (alpha-cut leaf cards, petals, tiling bark), put on by
    /// [`crate::dress`]; `None` (the default, and left out of files) keeps the look above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<Surface>,
}

impl Material {
    /// The default material of a kind, named after it.
    pub fn of_kind(kind: MaterialKind) -> Self {
        Material {
            name: kind.name().to_owned(),
            kind,
            color: kind.default_color(),
            texture: None,
            surface: None,
        }
    }
}

/// Where a plant came from: enough to grow it again.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlantMeta {
    /// Model name (`"bintree"`, `"automata"`, `"plantmaker"`, `"lsystem"`).
    pub model: String,
    /// Stable hash of the genome's canonical JSON (see [`crate::hash`]).
    pub genome_hash: u64,
    /// The seed the plant was grown with.
    pub seed: u64,
}

/// Coordinates and sizes beyond this many metres are refused: products of them would
/// overflow to infinity.
pub const MAX_COORD: f32 = 1e12;

/// Why a segment, organ or material was refused.
#[derive(Debug, Error, PartialEq)]
pub enum PlantError {
    /// A coordinate, radius or size is NaN or infinite.
    #[error("{what} is not finite")]
    NotFinite {
        /// Which value.
        what: &'static str,
    },
    /// A radius or size is negative.
    #[error("{what} is negative ({value})")]
    Negative {
        /// Which value.
        what: &'static str,
        /// The value given.
        value: f32,
    },
    /// A coordinate or size is beyond ±[`MAX_COORD`] metres.
    #[error("{what} is beyond {MAX_COORD} m ({value})")]
    TooFar {
        /// Which value.
        what: &'static str,
        /// The value given.
        value: f32,
    },
    /// An organ's orientation is not a unit quaternion.
    #[error("organ orientation is not a unit quaternion")]
    BadOrientation,
    /// A material colour is not three numbers from 0 to 1.
    #[error("material `{name}` has colour {color:?}; each channel must be from 0 to 1")]
    BadColor {
        /// The material's name.
        name: String,
        /// The colour given.
        color: [f32; 3],
    },
    /// The organ does not exist.
    #[error("organ {organ} does not exist (the plant has {len} organs)")]
    NoSuchOrgan {
        /// The organ asked for.
        organ: usize,
        /// Organs so far.
        len: usize,
    },
    /// The parent does not exist yet.
    #[error("parent segment {parent} does not exist (the plant has {len} segments)")]
    NoSuchParent {
        /// The parent asked for.
        parent: u32,
        /// Segments so far.
        len: usize,
    },
    /// The material does not exist.
    #[error("material {0} does not exist")]
    NoSuchMaterial(u16),
    /// More segments than a `SegmentId` can index.
    #[error("too many segments")]
    TooManySegments,
    /// More materials than a `MaterialId` can index.
    #[error("too many materials")]
    TooManyMaterials,
}

/// A grown plant: skeleton, organs, materials and origin. See the [module docs](self) for
/// the rules it keeps.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Plant {
    segments: Vec<Segment>,
    organs: Vec<Organ>,
    materials: Vec<Material>,
    meta: PlantMeta,
}

/// A point: finite and within ±[`MAX_COORD`].
fn point(v: Vec3, what: &'static str) -> Result<(), PlantError> {
    if !v.is_finite() {
        return Err(PlantError::NotFinite { what });
    }
    let value = v.abs().max_element();
    if value > MAX_COORD {
        return Err(PlantError::TooFar { what, value });
    }
    Ok(())
}

/// A size: finite, non-negative and at most [`MAX_COORD`].
fn size(value: f32, what: &'static str) -> Result<(), PlantError> {
    if !value.is_finite() {
        Err(PlantError::NotFinite { what })
    } else if value < 0.0 {
        Err(PlantError::Negative { what, value })
    } else if value > MAX_COORD {
        Err(PlantError::TooFar { what, value })
    } else {
        Ok(())
    }
}

/// The three materials of [`Plant::new`].
fn default_materials() -> Vec<Material> {
    vec![
        Material::of_kind(MaterialKind::Bark),
        Material::of_kind(MaterialKind::Leaf),
        Material::of_kind(MaterialKind::Flower),
    ]
}

impl Plant {
    /// An empty plant with the given metadata and the three default materials
    /// (bark, leaf, flower), returned as ids in that order by [`Plant::BARK`] and friends.
    pub fn new(meta: PlantMeta) -> Self {
        Plant {
            segments: Vec::new(),
            organs: Vec::new(),
            materials: default_materials(),
            meta,
        }
    }

    /// An empty plant with no materials yet (add them with [`Plant::add_material`]).
    pub fn bare(meta: PlantMeta) -> Self {
        Plant {
            meta,
            ..Plant::default()
        }
    }

    /// The skeleton to edit in place, for the crate's own transforms (such as
    /// [`crate::taper`]) that keep every segment's checks true.
    pub(crate) fn segments_mut(&mut self) -> &mut [Segment] {
        &mut self.segments
    }

    /// The skeleton, parents first.
    #[inline]
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Leaves, flowers and root tips.
    #[inline]
    pub fn organs(&self) -> &[Organ] {
        &self.organs
    }

    /// Materials referenced by segments and organs.
    #[inline]
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Where the plant came from.
    #[inline]
    pub fn meta(&self) -> &PlantMeta {
        &self.meta
    }

    /// Where the plant came from, to change (it holds no rule).
    #[inline]
    pub fn meta_mut(&mut self) -> &mut PlantMeta {
        &mut self.meta
    }

    /// Removes every segment and organ, keeping the materials, the metadata and the buffers'
    /// capacity (so a plant can be regrown without allocating).
    pub fn clear(&mut self) {
        self.segments.clear();
        self.organs.clear();
    }

    /// [`Plant::clear`], and the three materials of [`Plant::new`] back unless the first
    /// three already are bark, leaf and flower.
    pub fn clear_to_defaults(&mut self) {
        self.clear();
        let kinds = [MaterialKind::Bark, MaterialKind::Leaf, MaterialKind::Flower];
        let ok =
            self.materials.len() >= 3 && self.materials.iter().zip(kinds).all(|(m, k)| m.kind == k);
        if !ok {
            self.materials = default_materials();
        }
    }

    /// Room for `segments` more segments and `organs` more organs.
    pub fn reserve(&mut self, segments: usize, organs: usize) {
        self.segments.reserve(segments);
        self.organs.reserve(organs);
    }

    /// The default bark material of [`Plant::new`].
    pub const BARK: MaterialId = MaterialId(0);
    /// The default leaf material of [`Plant::new`].
    pub const LEAF: MaterialId = MaterialId(1);
    /// The default flower material of [`Plant::new`].
    pub const FLOWER: MaterialId = MaterialId(2);

    /// Adds a material after checking its colour, and returns its id.
    pub fn add_material(&mut self, material: Material) -> Result<MaterialId, PlantError> {
        check_color(&material)?;
        let id = u16::try_from(self.materials.len()).map_err(|_| PlantError::TooManyMaterials)?;
        self.materials.push(material);
        Ok(MaterialId(id))
    }

    /// Gives a material a texture id (or none).
    pub fn set_texture(&mut self, id: MaterialId, texture: Option<u16>) -> Result<(), PlantError> {
        let slot = self
            .materials
            .get_mut(id.index())
            .ok_or(PlantError::NoSuchMaterial(id.0))?;
        slot.texture = texture;
        Ok(())
    }

    /// Replaces a material after checking it.
    pub fn replace_material(
        &mut self,
        id: MaterialId,
        material: Material,
    ) -> Result<(), PlantError> {
        check_color(&material)?;
        let slot = self
            .materials
            .get_mut(id.index())
            .ok_or(PlantError::NoSuchMaterial(id.0))?;
        *slot = material;
        Ok(())
    }

    /// Adds a segment after checking it: points and radii finite and within range, radii
    /// non-negative, an existing parent and material. Order is derived: the parent's order,
    /// plus one when `lateral`.
    #[inline(always)]
    pub fn add_segment(
        &mut self,
        start: Vec3,
        end: Vec3,
        radii: (f32, f32),
        parent: Option<SegmentId>,
        lateral: bool,
        material: MaterialId,
    ) -> Result<SegmentId, PlantError> {
        // One pass of comparisons on the path every segment takes (NaN fails them all);
        // which rule was broken is worked out only when one was.
        let near =
            |v: Vec3| v.x.abs() <= MAX_COORD && v.y.abs() <= MAX_COORD && v.z.abs() <= MAX_COORD;
        let sized = |r: f32| (0.0..=MAX_COORD).contains(&r);
        let order = match parent {
            None => Some(0),
            Some(p) => self
                .segments
                .get(p.index())
                .map(|s| s.order.saturating_add(u16::from(lateral))),
        };
        let id = u32::try_from(self.segments.len()).ok();
        let (Some(order), Some(id)) = (order, id) else {
            return Err(self.segment_error(start, end, radii, parent, material));
        };
        if !(near(start)
            && near(end)
            && sized(radii.0)
            && sized(radii.1)
            && material.index() < self.materials.len())
        {
            return Err(self.segment_error(start, end, radii, parent, material));
        }
        self.segments.push(Segment {
            start,
            end,
            start_radius: radii.0,
            end_radius: radii.1,
            order,
            parent,
            lateral: lateral && parent.is_some(),
            material,
        });
        Ok(SegmentId(id))
    }

    /// Why [`Plant::add_segment`] refused a segment.
    #[cold]
    #[inline(never)]
    fn segment_error(
        &self,
        start: Vec3,
        end: Vec3,
        radii: (f32, f32),
        parent: Option<SegmentId>,
        material: MaterialId,
    ) -> PlantError {
        let checks = point(start, "segment start")
            .and(point(end, "segment end"))
            .and(size(radii.0, "segment start radius"))
            .and(size(radii.1, "segment end radius"));
        if let Err(e) = checks {
            return e;
        }
        if material.index() >= self.materials.len() {
            return PlantError::NoSuchMaterial(material.0);
        }
        match parent {
            Some(p) if p.index() >= self.segments.len() => PlantError::NoSuchParent {
                parent: p.0,
                len: self.segments.len(),
            },
            _ => PlantError::TooManySegments,
        }
    }

    /// Adds an organ after checking it: a point within range, a unit orientation, sizes
    /// within range, an existing material and parent.
    pub fn add_organ(&mut self, organ: Organ) -> Result<(), PlantError> {
        point(organ.position, "organ position")?;
        if !organ.orientation.is_finite() || !organ.orientation.is_normalized() {
            return Err(PlantError::BadOrientation);
        }
        size(organ.size.x, "organ length")?;
        size(organ.size.y, "organ width")?;
        if material_missing(organ.material, &self.materials) {
            return Err(PlantError::NoSuchMaterial(organ.material.0));
        }
        if let Some(p) = organ.parent
            && p.index() >= self.segments.len()
        {
            return Err(PlantError::NoSuchParent {
                parent: p.0,
                len: self.segments.len(),
            });
        }
        self.organs.push(organ);
        Ok(())
    }

    /// Attaches organ `organ` (its index) to a segment, or to none.
    pub fn set_organ_parent(
        &mut self,
        organ: usize,
        parent: Option<SegmentId>,
    ) -> Result<(), PlantError> {
        if let Some(p) = parent
            && p.index() >= self.segments.len()
        {
            return Err(PlantError::NoSuchParent {
                parent: p.0,
                len: self.segments.len(),
            });
        }
        let len = self.organs.len();
        let o = self
            .organs
            .get_mut(organ)
            .ok_or(PlantError::NoSuchOrgan { organ, len })?;
        o.parent = parent;
        Ok(())
    }

    /// A copy without the segments and organs whose material is of `kind` (for instance
    /// roots, to show a plant above ground only). Segments whose parent goes are kept as
    /// roots of the skeleton; ids are renumbered, parents first as before.
    pub fn without(&self, kind: MaterialKind) -> Plant {
        let hidden = |m: MaterialId| {
            self.materials
                .get(m.index())
                .is_some_and(|x| x.kind == kind)
        };
        let mut new_id: Vec<Option<SegmentId>> = Vec::with_capacity(self.segments.len());
        let mut plant = Plant {
            segments: Vec::new(),
            organs: Vec::new(),
            materials: self.materials.clone(),
            meta: self.meta.clone(),
        };
        for s in &self.segments {
            if hidden(s.material) {
                new_id.push(None);
                continue;
            }
            let parent = s.parent.and_then(|p| new_id[p.index()]);
            let mut kept = *s;
            kept.parent = parent;
            kept.lateral = s.lateral && parent.is_some();
            new_id.push(Some(SegmentId(plant.segments.len() as u32)));
            plant.segments.push(kept);
        }
        plant.organs = self
            .organs
            .iter()
            .filter(|o| !hidden(o.material))
            .map(|o| Organ {
                parent: o.parent.and_then(|p| new_id[p.index()]),
                ..*o
            })
            .collect();
        plant
    }

    /// A copy pruned as a gardener prunes: a segment `keep_segment` refuses goes with
    /// everything that grows from it (the segments after it and their organs), and so does
    /// an organ `keep_organ` refuses. Ids are renumbered, parents first as before.
    pub fn cut(
        &self,
        mut keep_segment: impl FnMut(&Segment) -> bool,
        mut keep_organ: impl FnMut(&Organ) -> bool,
    ) -> Plant {
        self.cut_into(
            |_, s| keep_segment(s),
            |o, keep| {
                if keep_organ(o) {
                    keep(*o);
                }
            },
        )
    }

    /// [`Plant::cut`], but `keep_segment` is told each segment's id too, and each organ on a
    /// kept stem is replaced by what `organ` passes to its second argument (none, itself, or
    /// pieces of it: a leaf clipped by the shears); their parents are renumbered as the
    /// stem's is.
    pub fn cut_into(
        &self,
        mut keep_segment: impl FnMut(SegmentId, &Segment) -> bool,
        mut organ: impl FnMut(&Organ, &mut dyn FnMut(Organ)),
    ) -> Plant {
        let mut new_id: Vec<Option<SegmentId>> = Vec::with_capacity(self.segments.len());
        let mut plant = Plant {
            segments: Vec::with_capacity(self.segments.len()),
            organs: Vec::with_capacity(self.organs.len()),
            materials: self.materials.clone(),
            meta: self.meta.clone(),
        };
        for (i, s) in self.segments.iter().enumerate() {
            let parent = match s.parent {
                Some(p) => match new_id[p.index()] {
                    Some(id) => Some(id),
                    None => {
                        new_id.push(None);
                        continue;
                    }
                },
                None => None,
            };
            if !keep_segment(SegmentId(i as u32), s) {
                new_id.push(None);
                continue;
            }
            new_id.push(Some(SegmentId(plant.segments.len() as u32)));
            plant.segments.push(Segment { parent, ..*s });
        }
        for o in &self.organs {
            let parent = match o.parent {
                Some(p) => match new_id[p.index()] {
                    Some(id) => Some(id),
                    None => continue,
                },
                None => None,
            };
            let organs = &mut plant.organs;
            organ(o, &mut |kept| organs.push(Organ { parent, ..kept }));
        }
        plant
    }

    /// Scales the plant about its origin by `factor` (positive): every point, radius and
    /// blade, so that it keeps its shape at another size. Refused, and the plant left as it
    /// was, when the factor is not a positive finite number or a point would go beyond
    /// [`MAX_COORD`].
    pub fn scale(&mut self, factor: f32) -> Result<(), PlantError> {
        if !factor.is_finite() {
            return Err(PlantError::NotFinite { what: "scale" });
        }
        if factor <= 0.0 {
            return Err(PlantError::Negative {
                what: "scale",
                value: factor,
            });
        }
        let far = self
            .segments
            .iter()
            .flat_map(|s| [s.start.abs().max_element(), s.end.abs().max_element()])
            .chain(self.organs.iter().map(|o| o.position.abs().max_element()))
            .fold(0.0f32, f32::max);
        if far * factor > MAX_COORD {
            return Err(PlantError::TooFar {
                what: "scaled point",
                value: far * factor,
            });
        }
        for s in &mut self.segments {
            s.start *= factor;
            s.end *= factor;
            s.start_radius *= factor;
            s.end_radius *= factor;
        }
        for o in &mut self.organs {
            o.position *= factor;
            o.size *= factor;
        }
        Ok(())
    }

    /// A segment by id.
    #[inline]
    pub fn segment(&self, id: SegmentId) -> &Segment {
        &self.segments[id.index()]
    }

    /// How many children each segment has, indexed like `segments`.
    pub fn child_counts(&self) -> Vec<u32> {
        let mut counts = vec![0u32; self.segments.len()];
        for s in &self.segments {
            if let Some(p) = s.parent {
                counts[p.index()] += 1;
            }
        }
        counts
    }
}

fn material_missing(id: MaterialId, materials: &[Material]) -> bool {
    id.index() >= materials.len()
}

fn check_color(material: &Material) -> Result<(), PlantError> {
    if material.color.iter().all(|c| (0.0..=1.0).contains(c)) {
        Ok(())
    } else {
        Err(PlantError::BadColor {
            name: material.name.clone(),
            color: material.color,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_follow_laterals() {
        let mut p = Plant::new(PlantMeta::default());
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        let b = p
            .add_segment(
                Vec3::Y,
                Vec3::Y * 2.0,
                (0.1, 0.1),
                Some(a),
                false,
                Plant::BARK,
            )
            .unwrap();
        let c = p
            .add_segment(Vec3::Y, Vec3::X, (0.1, 0.1), Some(a), true, Plant::BARK)
            .unwrap();
        assert_eq!(p.segment(b).order, 0);
        assert_eq!(p.segment(c).order, 1);
        assert_eq!(p.child_counts(), vec![2, 0, 0]);
    }

    #[test]
    fn without_removes_a_kind_and_renumbers() {
        let mut p = Plant::new(PlantMeta::default());
        let root = p
            .add_material(Material::of_kind(MaterialKind::Root))
            .unwrap();
        let a = p
            .add_segment(Vec3::ZERO, -Vec3::Y, (0.1, 0.1), None, false, root)
            .unwrap();
        p.add_segment(-Vec3::Y, -Vec3::Y * 2.0, (0.1, 0.1), Some(a), false, root)
            .unwrap();
        let b = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::Y * 2.0,
            (0.1, 0.1),
            Some(b),
            true,
            Plant::BARK,
        )
        .unwrap();
        let shoot = p.without(MaterialKind::Root);
        assert_eq!(shoot.segments.len(), 2);
        assert_eq!(shoot.segments[1].parent, Some(SegmentId(0)));
        assert_eq!(p.without(MaterialKind::Leaf), p);
    }

    #[test]
    fn cutting_a_stem_takes_all_that_grows_from_it() {
        let mut p = Plant::new(PlantMeta::default());
        let trunk = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        let cut = p
            .add_segment(Vec3::Y, Vec3::X, (0.1, 0.1), Some(trunk), true, Plant::BARK)
            .unwrap();
        let after_cut = p
            .add_segment(
                Vec3::X,
                Vec3::X * 2.0,
                (0.1, 0.1),
                Some(cut),
                false,
                Plant::BARK,
            )
            .unwrap();
        let top = p
            .add_segment(
                Vec3::Y,
                Vec3::Y * 2.0,
                (0.1, 0.1),
                Some(trunk),
                false,
                Plant::BARK,
            )
            .unwrap();
        let leaf = |parent, x: f32| Organ {
            kind: OrganKind::Leaf,
            position: Vec3::new(x, 1.0, 0.0),
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.3, 0.1),
            material: Plant::LEAF,
            parent: Some(parent),
        };
        p.add_organ(leaf(after_cut, 2.0)).unwrap();
        p.add_organ(leaf(top, 0.0)).unwrap();
        p.add_organ(leaf(top, -1.0)).unwrap();
        let pruned = p.cut(|s| s.end != Vec3::X, |o| o.position.x > -1.0);
        assert_eq!(pruned.segments.len(), 2);
        assert_eq!(pruned.segments[1].end, Vec3::Y * 2.0);
        assert_eq!(pruned.segments[1].parent, Some(SegmentId(0)));
        assert_eq!(pruned.organs, vec![leaf(SegmentId(1), 0.0)]);
        assert_eq!(p.cut(|_| true, |_| true), p);
    }

    #[test]
    fn scaling_keeps_the_shape_at_another_size() {
        let mut p = Plant::new(PlantMeta::default());
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.2, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Leaf,
            position: Vec3::new(0.5, 1.0, 0.0),
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.3, 0.1),
            material: Plant::LEAF,
            parent: Some(a),
        })
        .unwrap();
        let before = p.clone();
        p.scale(3.0).unwrap();
        assert_eq!(p.segments[0].end, Vec3::Y * 3.0);
        assert_eq!(p.segments[0].start_radius, 0.6f32);
        assert_eq!(p.organs[0].position, Vec3::new(1.5, 3.0, 0.0));
        assert!((p.organs[0].size - Vec2::new(0.9, 0.3)).abs().max_element() < 1e-6);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e13] {
            let mut q = before.clone();
            assert!(q.scale(bad).is_err(), "{bad}");
            assert_eq!(q, before, "a refused scale changes nothing");
        }
    }

    #[test]
    fn refuses_bad_segments() {
        let mut p = Plant::new(PlantMeta::default());
        let nan = Vec3::new(f32::NAN, 0.0, 0.0);
        assert!(matches!(
            p.add_segment(nan, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK),
            Err(PlantError::NotFinite { .. })
        ));
        assert!(matches!(
            p.add_segment(Vec3::ZERO, Vec3::Y, (-0.1, 0.1), None, false, Plant::BARK),
            Err(PlantError::Negative { .. })
        ));
        assert!(matches!(
            p.add_segment(
                Vec3::ZERO,
                Vec3::Y,
                (0.1, 0.1),
                Some(SegmentId(3)),
                false,
                Plant::BARK
            ),
            Err(PlantError::NoSuchParent { .. })
        ));
        assert!(matches!(
            p.add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, MaterialId(9)),
            Err(PlantError::NoSuchMaterial(9))
        ));
        assert!(p.segments.is_empty());
    }

    #[test]
    fn refuses_far_points_big_sizes_bad_organs_and_colours() {
        let mut p = Plant::new(PlantMeta::default());
        let far = Vec3::new(2e12, 0.0, 0.0);
        assert!(matches!(
            p.add_segment(Vec3::ZERO, far, (0.1, 0.1), None, false, Plant::BARK),
            Err(PlantError::TooFar { .. })
        ));
        assert!(matches!(
            p.add_segment(Vec3::ZERO, Vec3::Y, (0.1, 1e13), None, false, Plant::BARK),
            Err(PlantError::TooFar { .. })
        ));
        let leaf = Organ {
            kind: OrganKind::Leaf,
            position: Vec3::Y,
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.1, 0.05),
            material: Plant::LEAF,
            parent: None,
        };
        let squashed = Organ {
            orientation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.5),
            ..leaf
        };
        assert_eq!(p.add_organ(squashed), Err(PlantError::BadOrientation));
        let nan = Organ {
            orientation: Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0),
            ..leaf
        };
        assert_eq!(p.add_organ(nan), Err(PlantError::BadOrientation));
        let wide = Organ {
            size: Vec2::new(0.1, -1.0),
            ..leaf
        };
        assert!(matches!(
            p.add_organ(wide),
            Err(PlantError::Negative { .. })
        ));
        p.add_organ(leaf).unwrap();
        assert!(matches!(
            p.set_organ_parent(0, Some(SegmentId(0))),
            Err(PlantError::NoSuchParent { .. })
        ));
        assert!(matches!(
            p.set_organ_parent(3, None),
            Err(PlantError::NoSuchOrgan { organ: 3, len: 1 })
        ));
        let s = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.set_organ_parent(0, Some(s)).unwrap();
        assert_eq!(p.organs()[0].parent, Some(s));
        let odd = Material {
            color: [0.5, f32::NAN, 0.5],
            ..Material::of_kind(MaterialKind::Root)
        };
        assert!(matches!(
            p.add_material(odd.clone()),
            Err(PlantError::BadColor { .. })
        ));
        assert!(matches!(
            p.replace_material(Plant::BARK, odd),
            Err(PlantError::BadColor { .. })
        ));
        assert_eq!(p.materials().len(), 3);
    }

    #[test]
    fn clearing_keeps_or_restores_the_default_materials() {
        let mut p = Plant::bare(PlantMeta::default());
        p.add_material(Material::of_kind(MaterialKind::Root))
            .unwrap();
        p.clear_to_defaults();
        assert_eq!(p.materials(), Plant::new(PlantMeta::default()).materials());
        p.add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.clear();
        assert!(p.segments().is_empty());
        assert_eq!(p.materials().len(), 3);
    }
}
