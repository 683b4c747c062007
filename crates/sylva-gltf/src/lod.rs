//! Levels of detail: a chain of simplified plants, each meshed at about half the triangles of
//! the level before, all made from the plant's own skeleton so that the silhouette holds.
//!
//! Level 0 is the plant as it is, meshed with the given options. Every further level is the
//! same plant simplified by one *detail* number `q` between 0 and 1:
//!
//! - **Twigs dropped.** Lateral axes are ranked by how much wood they carry (their length
//!   plus that of every axis growing from them), most first (ties by position in the plant);
//!   a level keeps the first ⌈q·n⌉ of the n, so twigs go first and limbs last, and an axis
//!   whose parent axis is dropped goes too. Axes without a parent always stay. Organs of a
//!   dropped twig stay where they are, attached to the nearest kept ancestor, so the crown
//!   keeps its outline.
//! - **Foliage thinned.** Axes that are not wood (leaves and petals drawn as segments, as
//!   the L-system model draws them) are not ranked with the wood: a level keeps an even
//!   share ⌈q·n⌉ of them wherever they grow (on the nearest kept ancestor when their twig
//!   is dropped), each thickened by min(√(n / kept), 2), so the crown keeps its leaves.
//! - **Straight runs joined.** A segment that continues its axis within (1 − q)·40° of the
//!   run before it is joined to that run (one longer segment with the same two ends), as
//!   long as the run stays within (1 − q)²/2 of the plant's diagonal: at q near 1 only
//!   short pieces join, so the count falls smoothly rather than all at once.
//! - **Fewer ring vertices by order.** An axis of branch order o gets
//!   round(R·(0.35 + 0.65q)·(0.75 + 0.25q)ᵒ) vertices per ring, at least 3 (R: the options'
//!   ring size), so twigs lose theirs first.
//! - **Leaves into cards.** Leaves of one material whose centres fall in one cell of a grid
//!   of side 0.12·(1 − q)²·(the plant's diagonal) become one card: a single blade at the
//!   cluster's centre, facing the mean of the leaves' normals, with 80% of their summed
//!   length × width (at most 1.5 cells long or wide) and their mean proportions. A leaf alone
//!   in its cell stays as it is. Blades get round(S·q) outline stations (at least 1, a
//!   diamond), flowers round(P·q) petals (at least 3).
//!
//! Level k aims at T₀ / 2ᵏ triangles (T₀: level 0's). Every rule above only removes detail
//! as q falls, so the exact triangle count ([`Mesher::counts`]) falls with it: the search
//! interpolates q on the logarithm of the count between a plant under the aim and one over
//! it (the level before), and stops at the first plant within 92% of the aim and not over
//! it, or when the two are within 0.01 in q (a step in the count, such as every twig losing
//! a ring vertex at once, can leave no plant nearer), at most 10 tries (halving the bracket
//! after two tries on one side), taking the best under the aim. When
//! even q = 0 is over the aim (a plant that is all trunk, say), the level is the q = 0 plant
//! and says so through its count.
//!
//! Each level also carries the screen coverage (the plant's height over the screen's) down
//! to which an engine should draw it: level k hands over to level k + 1 where that level's
//! triangles per screen area equal level 0's at half the screen's height, at
//! ½·√(T₍ₖ₊₁₎ / T₀); the last level is drawn down to 1% and culled below.

use std::collections::HashMap;
use std::f32::consts::PI;

use sylva_core::{
    Organ, OrganKind, Plant,
    glam::{Mat3, Quat, Vec2, Vec3},
};
use sylva_mesh::mesher::{MeshError, MeshOptions, Mesher};

/// Most levels in a chain (level 0 included).
pub const MAX_LEVELS: usize = 8;
/// The coverage below which the last level is culled.
pub const CULL_COVERAGE: f32 = 0.01;
/// The coverage at which level 0's triangle density is the reference.
const FULL_COVERAGE: f32 = 0.5;
/// Most plants tried per level in the search for its detail number.
const SEARCH_STEPS: usize = 10;
/// The search stops when the detail numbers under and over the aim are this close.
const MIN_BRACKET: f32 = 0.01;
/// A level within this share of its aim (and not over it) ends the search.
const CLOSE_ENOUGH: f64 = 0.92;
/// Widest bend (radians) joined into a straight run, at q = 0.
const MAX_JOIN_ANGLE: f32 = 40.0 * PI / 180.0;
/// Card grid cell at q = 0, as a fraction of the plant's diagonal.
const MAX_CARD_CELL: f32 = 0.12;
/// A card's area over the summed area of the leaves it stands for (they overlap).
const CARD_AREA: f32 = 0.8;
/// No segment / axis.
const NONE: u32 = u32::MAX;

/// Buffers for simplifying one plant many times.
#[derive(Default)]
struct Scratch {
    /// Per axis: kept at this detail.
    kept: Vec<bool>,
    /// The simplified skeleton.
    specs: Vec<Spec>,
    /// Per segment: the output segment standing for it (its own, the run it joined, or for
    /// a dropped one the nearest kept ancestor's), or `NONE`.
    stand: Vec<u32>,
    /// Per output segment: its branch order, and whether an axis continues from it.
    order: Vec<u16>,
    continued: Vec<bool>,
}

/// One level of a chain.
#[derive(Clone, Debug)]
pub struct LodLevel {
    /// The level's plant (level 0: a copy of the original).
    pub plant: Plant,
    /// How to mesh it.
    pub options: MeshOptions,
    /// The detail number it was simplified with (1 for level 0).
    pub detail: f32,
    /// Triangles its mesh has.
    pub triangles: usize,
    /// The smallest screen coverage (plant height over screen height) it is drawn at.
    pub screen_coverage: f32,
}

/// Why a chain could not be made.
#[derive(Debug, thiserror::Error)]
pub enum LodError {
    /// The level count is out of range.
    #[error("levels of detail: {0} levels asked for, expected 1 to {MAX_LEVELS}")]
    Levels(usize),
    /// Meshing a level failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A simplified plant broke a rule of `Plant` (a bug: the rules hold for its source).
    #[error("a simplified plant was refused: {0}")]
    Plant(#[from] sylva_core::PlantError),
}

/// The chain of `levels` levels of `plant` meshed with `options` (see the module docs).
pub fn lod_levels(
    plant: &Plant,
    options: &MeshOptions,
    levels: usize,
) -> Result<Vec<LodLevel>, LodError> {
    if !(1..=MAX_LEVELS).contains(&levels) {
        return Err(LodError::Levels(levels));
    }
    let full = Mesher::new(options.clone())?.counts(plant)?.triangles;
    let skeleton = Skeleton::of(plant);
    let mut chain = vec![LodLevel {
        plant: plant.clone(),
        options: options.clone(),
        detail: 1.0,
        triangles: full,
        screen_coverage: 0.0,
    }];
    let mut scratch = Scratch::default();
    let least = (0.0, skeleton.count(0.0, options, &mut scratch));
    // What is known above the aim: level 0 (q = 1) at first, then each level found.
    let mut upper = (1.0f32, full);
    for k in 1..levels {
        let aim = full as f64 / f64::from(1u32 << k);
        let found = skeleton.search(aim, least, upper, options, &mut scratch);
        upper = found;
        let (q, triangles) = found;
        let plant = skeleton.simplify(q, &mut scratch)?;
        let options = level_options(options, q);
        debug_assert_eq!(
            Mesher::new(options.clone())?.counts(&plant)?.triangles,
            triangles,
            "the level's count is the mesher's"
        );
        chain.push(LodLevel {
            plant,
            options,
            detail: q,
            triangles,
            screen_coverage: 0.0,
        });
    }
    for k in 0..chain.len() {
        chain[k].screen_coverage = match chain.get(k + 1) {
            Some(next) => FULL_COVERAGE * (next.triangles as f32 / full.max(1) as f32).sqrt(),
            None => CULL_COVERAGE,
        };
    }
    Ok(chain)
}

impl Skeleton<'_> {
    /// The triangles of the plant at detail `q`.
    fn count(&self, q: f32, options: &MeshOptions, scratch: &mut Scratch) -> usize {
        self.skeleton_at(q, scratch);
        self.triangles(q, options, scratch)
    }

    /// The detail whose plant comes nearest `aim` triangles without going over, searched
    /// between `least` (q = 0) and `upper` (a detail known to be over or at the aim), each
    /// a detail and its count (see the module docs).
    fn search(
        &self,
        aim: f64,
        least: (f32, usize),
        upper: (f32, usize),
        options: &MeshOptions,
        scratch: &mut Scratch,
    ) -> (f32, usize) {
        if least.1 as f64 > aim {
            return least;
        }
        if upper.1 as f64 <= aim {
            return upper; // the level above already meets this aim
        }
        // Interpolate on log triangles between a q under the aim and one over it.
        let ln = |t: usize| (t.max(1) as f64).ln();
        let (mut lo, mut hi) = (least, upper);
        let mut last_under = None;
        for _ in 0..SEARCH_STEPS {
            let t = (aim.ln() - ln(lo.1)) / (ln(hi.1) - ln(lo.1));
            // Halve the bracket instead when two tries in a row fell on one side (the
            // count is far from straight in log there).
            let t = match last_under {
                Some((a, b)) if a == b => 0.5,
                _ => (t as f32).clamp(0.05, 0.95),
            };
            let q = lo.0 + (hi.0 - lo.0) * t;
            let tried = (q, self.count(q, options, scratch));
            let under = tried.1 as f64 <= aim;
            last_under = Some((last_under.map_or(!under, |(_, b)| b), under));
            if under {
                lo = tried;
                if tried.1 as f64 >= CLOSE_ENOUGH * aim {
                    break;
                }
            } else {
                hi = tried;
            }
            // A step in the count (many twigs losing a ring vertex at once) can leave
            // no plant near the aim: stop once the bracket is this tight.
            if hi.0 - lo.0 < MIN_BRACKET {
                break;
            }
        }
        lo
    }
}

/// A preview of `plant` of at most about `max_triangles` triangles: the level k of its chain
/// whose aim, T₀ / 2ᵏ, is the first within `max_triangles` (k at most [`MAX_LEVELS`] − 1),
/// found by the chain's own search from the plant as it is. Level 0 (the plant itself, its
/// options and count) when it is within already. A view a few hundred pixels wide needs no
/// more, whatever the plant.
pub fn preview(
    plant: &Plant,
    options: &MeshOptions,
    max_triangles: usize,
) -> Result<LodLevel, LodError> {
    let full = Mesher::new(options.clone())?.counts(plant)?.triangles;
    let mut level = 0;
    while level + 1 < MAX_LEVELS && full >> level > max_triangles {
        level += 1;
    }
    if level == 0 {
        return Ok(LodLevel {
            plant: plant.clone(),
            options: options.clone(),
            detail: 1.0,
            triangles: full,
            screen_coverage: CULL_COVERAGE,
        });
    }
    let skeleton = Skeleton::of(plant);
    let mut scratch = Scratch::default();
    let least = (0.0, skeleton.count(0.0, options, &mut scratch));
    let aim = full as f64 / f64::from(1u32 << level);
    let (q, triangles) = skeleton.search(aim, least, (1.0, full), options, &mut scratch);
    Ok(LodLevel {
        plant: skeleton.simplify(q, &mut scratch)?,
        options: level_options(options, q),
        detail: q,
        triangles,
        screen_coverage: CULL_COVERAGE,
    })
}

/// The mesh options of detail `q`: fewer ring vertices by order, leaf stations and petals.
fn level_options(base: &MeshOptions, q: f32) -> MeshOptions {
    let r = base
        .radial_segments_by_order
        .first()
        .copied()
        .unwrap_or(base.radial_segments);
    let scaled = |n: u32, f: f32, min: u32| ((n as f32 * f).round() as u32).clamp(min, n.max(min));
    MeshOptions {
        radial_segments_by_order: (0..6)
            .map(|o| scaled(r, (0.35 + 0.65 * q) * (0.75 + 0.25 * q).powi(o), 3))
            .collect(),
        leaf_stations: scaled(base.leaf_stations, q, 1),
        flower_petals: scaled(base.flower_petals, q, 3),
        ..base.clone()
    }
}

/// What simplification needs to know of a plant, worked out once for every level.
struct Skeleton<'a> {
    plant: &'a Plant,
    /// Per segment: its continuation (first non-lateral child), or `NONE`.
    next: Vec<u32>,
    /// Per segment: the axis it belongs to.
    axis: Vec<u32>,
    /// Per axis: its parent axis, or `NONE`.
    axis_parent: Vec<u32>,
    /// Per axis: its rank among lateral axes by the wood it carries (0 the most); `NONE`
    /// for an axis without a parent.
    axis_rank: Vec<u32>,
    /// Lateral woody axes (those ranked).
    laterals: usize,
    /// Per axis: its place among foliage (not woody) axes, or `NONE` for wood.
    foliage: Vec<u32>,
    /// Foliage axes.
    foliages: usize,
    /// The diagonal of the plant's bounds, metres.
    diagonal: f32,
}

impl<'a> Skeleton<'a> {
    fn of(plant: &'a Plant) -> Self {
        let segs = plant.segments();
        let mut next = vec![NONE; segs.len()];
        for (i, s) in segs.iter().enumerate() {
            if let Some(p) = s.parent
                && !s.lateral
                && next[p.index()] == NONE
            {
                next[p.index()] = i as u32;
            }
        }
        let mut axis = vec![NONE; segs.len()];
        let (mut axis_parent, mut wood) = (Vec::new(), Vec::<f32>::new());
        let (mut foliage, mut foliages) = (Vec::new(), 0u32);
        let woody = |s: &sylva_core::Segment| {
            plant
                .materials()
                .get(s.material.index())
                .is_none_or(|m| m.kind.is_woody())
        };
        for (i, s) in segs.iter().enumerate() {
            let continues = s.parent.is_some_and(|p| next[p.index()] == i as u32);
            axis[i] = match s.parent {
                Some(p) if continues => axis[p.index()],
                parent => {
                    axis_parent.push(parent.map_or(NONE, |p| axis[p.index()]));
                    wood.push(0.0);
                    if woody(s) {
                        foliage.push(NONE);
                    } else {
                        foliage.push(foliages);
                        foliages += 1;
                    }
                    (axis_parent.len() - 1) as u32
                }
            };
            if woody(s) {
                wood[axis[i] as usize] += s.length();
            }
        }
        // Children come after their parents: summing backwards gives each axis its subtree.
        for a in (0..wood.len()).rev() {
            if axis_parent[a] != NONE {
                wood[axis_parent[a] as usize] += wood[a];
            }
        }
        let mut order: Vec<usize> = (0..axis_parent.len())
            .filter(|&a| axis_parent[a] != NONE && foliage[a] == NONE)
            .collect();
        order.sort_by(|&a, &b| wood[b].total_cmp(&wood[a]).then(a.cmp(&b)));
        let mut axis_rank = vec![NONE; axis_parent.len()];
        for (rank, &a) in order.iter().enumerate() {
            axis_rank[a] = rank as u32;
        }
        let mut bounds = sylva_core::Aabb::EMPTY;
        for s in segs {
            bounds.grow(s.start, 0.0);
            bounds.grow(s.end, 0.0);
        }
        for o in plant.organs() {
            bounds.grow(o.position, 0.0);
        }
        let diagonal = if bounds.min.x <= bounds.max.x {
            (bounds.max - bounds.min).length()
        } else {
            0.0
        };
        Skeleton {
            plant,
            next,
            axis,
            axis_parent,
            axis_rank,
            laterals: order.len(),
            foliage,
            foliages: foliages as usize,
            diagonal,
        }
    }

    /// The skeleton at detail `q` (see the module docs), into `scratch.specs` and
    /// `scratch.stand`.
    fn skeleton_at(&self, q: f32, scratch: &mut Scratch) {
        let keep_laterals = (q * self.laterals as f32).ceil() as u32;
        // An even share of the foliage: axis j is kept when ⌊(j + 1)·f⌋ passes ⌊j·f⌋.
        let keep_foliage = (q * self.foliages as f32).ceil();
        let share = keep_foliage / self.foliages.max(1) as f32;
        let thicken = if keep_foliage > 0.0 {
            (self.foliages as f32 / keep_foliage).sqrt().min(2.0)
        } else {
            1.0
        };
        // Parents come first, so an axis's parent axis is decided before it.
        let kept = &mut scratch.kept;
        kept.clear();
        kept.resize(self.axis_parent.len(), false);
        for a in 0..kept.len() {
            let parent = self.axis_parent[a];
            kept[a] = match self.foliage[a] {
                NONE => {
                    parent == NONE || (self.axis_rank[a] < keep_laterals && kept[parent as usize])
                }
                j => ((j + 1) as f32 * share).floor() > (j as f32 * share).floor(),
            };
        }

        let cos_join = (MAX_JOIN_ANGLE * (1.0 - q)).cos();
        let max_run = 0.5 * (1.0 - q).powi(2) * self.diagonal;
        let segs = self.plant.segments();
        let (out, stand) = (&mut scratch.specs, &mut scratch.stand);
        out.clear();
        stand.clear();
        stand.resize(segs.len(), NONE);
        for (i, s) in segs.iter().enumerate() {
            let parent = s.parent.map_or(NONE, |p| stand[p.index()]);
            if !kept[self.axis[i] as usize] {
                stand[i] = parent;
                continue;
            }
            let continues = s.parent.is_some_and(|p| self.next[p.index()] == i as u32);
            if continues && q < 1.0 {
                let run = &mut out[parent as usize];
                let joins = (s.end - run.start).length() <= max_run
                    && match (
                        (run.end - run.start).try_normalize(),
                        s.vector().try_normalize(),
                    ) {
                        (Some(a), Some(b)) => a.dot(b) >= cos_join,
                        // A zero-length piece joins whatever it continues.
                        _ => true,
                    };
                if joins {
                    run.end = s.end;
                    run.end_radius = s.end_radius;
                    stand[i] = parent;
                    continue;
                }
            }
            let grow = if self.foliage[self.axis[i] as usize] == NONE {
                1.0
            } else {
                thicken
            };
            out.push(Spec {
                start: s.start,
                end: s.end,
                start_radius: s.start_radius * grow,
                end_radius: s.end_radius * grow,
                parent,
                // A second non-lateral child is meshed as a branch anyway: say so, so that it
                // cannot take over its parent's axis once that axis's own continuation joined.
                lateral: s.parent.is_some() && !continues,
                material: s.material,
            });
            stand[i] = (out.len() - 1) as u32;
        }
    }

    /// Triangles of the mesh of the skeleton in `scratch` at detail `q`, counted as the
    /// mesher counts them (each segment's tube, caps where an axis starts or ends) without
    /// building the plant: the search for a level tries many.
    fn triangles(&self, q: f32, options: &MeshOptions, scratch: &mut Scratch) -> usize {
        let options = level_options(options, q);
        let rings = &options.radial_segments_by_order;
        let specs = &scratch.specs;
        let (order, continued) = (&mut scratch.order, &mut scratch.continued);
        order.clear();
        continued.clear();
        continued.resize(specs.len(), false);
        for s in specs {
            let lateral = s.lateral && s.parent != NONE;
            order.push(match s.parent {
                NONE => 0,
                p => order[p as usize].saturating_add(u16::from(lateral)),
            });
            if s.parent != NONE && !lateral {
                continued[s.parent as usize] = true;
            }
        }
        let mut triangles = 0u64;
        for (i, s) in specs.iter().enumerate() {
            let r = u64::from(rings[usize::from(order[i]).min(rings.len() - 1)]);
            triangles += 2 * r;
            let starts = s.parent == NONE || s.lateral;
            if options.cap_ends && starts && s.start_radius > 0.0 {
                triangles += r;
            }
            if options.cap_ends && !continued[i] && s.end_radius > 0.0 {
                triangles += r;
            }
        }
        let (stations, petals) = (
            u64::from(options.leaf_stations),
            u64::from(options.flower_petals),
        );
        for o in cards(self.plant.organs(), self.card_cell(q)) {
            triangles += match o.kind {
                OrganKind::Leaf => 4 * stations,
                OrganKind::Flower => 4 * petals,
                OrganKind::RootTip => 8,
            };
        }
        triangles as usize
    }

    /// The side of the card grid at detail `q`, metres.
    fn card_cell(&self, q: f32) -> f32 {
        MAX_CARD_CELL * (1.0 - q).powi(2) * self.diagonal
    }

    /// The plant at detail `q` (see the module docs).
    fn simplify(&self, q: f32, scratch: &mut Scratch) -> Result<Plant, LodError> {
        self.skeleton_at(q, scratch);
        let (out, stand) = (&scratch.specs, &scratch.stand);
        let mut plant = Plant::bare(self.plant.meta().clone());
        for m in self.plant.materials() {
            plant.add_material(m.clone())?;
        }
        plant.reserve(out.len(), self.plant.organs().len());
        for s in out {
            let parent = (s.parent != NONE).then_some(sylva_core::SegmentId(s.parent));
            plant.add_segment(
                s.start,
                s.end,
                (s.start_radius, s.end_radius),
                parent,
                s.lateral,
                s.material,
            )?;
        }
        let reparent = |o: &Organ| {
            o.parent
                .map(|p| stand[p.index()])
                .filter(|&p| p != NONE)
                .map(sylva_core::SegmentId)
        };
        for organ in cards(self.plant.organs(), self.card_cell(q)) {
            plant.add_organ(Organ {
                parent: reparent(&organ),
                ..organ
            })?;
        }
        Ok(plant)
    }
}

/// An output segment while runs are being joined.
struct Spec {
    start: Vec3,
    end: Vec3,
    start_radius: f32,
    end_radius: f32,
    parent: u32,
    lateral: bool,
    material: sylva_core::MaterialId,
}

/// A cluster of leaves on its way to a card.
#[derive(Default)]
struct Cluster {
    leaves: u32,
    center: Vec3,
    normal: Vec3,
    up: Vec3,
    area: f32,
    aspect: f32,
}

/// The organs with leaves clustered into cards on a grid of side `cell` (no clustering when
/// `cell` is zero); in the organs' order, each card where its cluster's first leaf was.
fn cards(organs: &[Organ], cell: f32) -> Vec<Organ> {
    if cell <= 0.0 || !cell.is_finite() {
        return organs.to_vec();
    }
    let center = |o: &Organ| o.position + o.orientation * Vec3::Y * (0.5 * o.size.x);
    let mut cluster_of: Vec<u32> = vec![NONE; organs.len()];
    let mut index: HashMap<(u16, [i32; 3]), u32> = HashMap::new();
    let mut clusters: Vec<Cluster> = Vec::new();
    for (i, o) in organs.iter().enumerate() {
        if o.kind != OrganKind::Leaf {
            continue;
        }
        // Float-to-int casts saturate, so far-off or huge coordinates stay defined.
        let key = (
            o.material.0,
            (center(o) / cell).floor().to_array().map(|c| c as i32),
        );
        let c = *index.entry(key).or_insert_with(|| {
            clusters.push(Cluster::default());
            (clusters.len() - 1) as u32
        });
        cluster_of[i] = c;
        let k = &mut clusters[c as usize];
        let mut normal = o.orientation * Vec3::Z;
        if k.leaves > 0 && normal.dot(k.normal) < 0.0 {
            normal = -normal; // blades are two-sided: either face will do
        }
        k.leaves += 1;
        k.center += center(o);
        k.normal += normal;
        k.up += o.orientation * Vec3::Y;
        k.area += o.size.x * o.size.y;
        k.aspect += if o.size.y > 0.0 {
            o.size.x / o.size.y
        } else {
            1.0
        };
    }

    let mut out = Vec::with_capacity(organs.len());
    let mut done = vec![false; clusters.len()];
    for (i, o) in organs.iter().enumerate() {
        let c = cluster_of[i];
        if c == NONE || clusters[c as usize].leaves == 1 {
            out.push(*o);
            continue;
        }
        if std::mem::replace(&mut done[c as usize], true) {
            continue;
        }
        let k = &clusters[c as usize];
        let n = k.leaves as f32;
        let z = k.normal.try_normalize().unwrap_or(o.orientation * Vec3::Z);
        let y = (k.up - z * k.up.dot(z))
            .try_normalize()
            .unwrap_or_else(|| z.any_orthonormal_vector());
        let x = y.cross(z);
        let aspect = (k.aspect / n).clamp(0.5, 4.0);
        let area = CARD_AREA * k.area;
        let length = (area * aspect).sqrt().min(1.5 * cell);
        let width = (area / aspect).sqrt().min(1.5 * cell);
        out.push(Organ {
            position: k.center / n - y * (0.5 * length),
            orientation: Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize(),
            size: Vec2::new(length, width),
            ..*o
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::PlantMeta;

    /// A trunk of 12 slightly bent segments, a lateral branch on each joint with four leaves,
    /// and a sub-branch on each branch.
    fn plant() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let mut parent = None;
        let mut at = Vec3::ZERO;
        for i in 0..12 {
            let r = 0.3 * (1.0 - i as f32 / 13.0);
            let end = at + Vec3::new(0.02 * (i % 2) as f32, 1.0, 0.0);
            let s = p
                .add_segment(at, end, (r, r * 0.95), parent, false, Plant::BARK)
                .unwrap();
            let dir = Vec3::new((i as f32).cos(), 0.6, (i as f32).sin()).normalize();
            let b = p
                .add_segment(
                    end,
                    end + dir * 2.0,
                    (r * 0.3, r * 0.2),
                    Some(s),
                    true,
                    Plant::BARK,
                )
                .unwrap();
            let tip = end + dir * 2.0;
            p.add_segment(
                tip,
                tip + Vec3::Y,
                (r * 0.1, r * 0.05),
                Some(b),
                true,
                Plant::BARK,
            )
            .unwrap();
            for l in 0..4 {
                p.add_organ(Organ {
                    kind: OrganKind::Leaf,
                    position: end + dir * (0.5 * l as f32),
                    orientation: Quat::from_rotation_z(0.3 * l as f32),
                    size: Vec2::new(0.3, 0.1),
                    material: Plant::LEAF,
                    parent: Some(b),
                })
                .unwrap();
            }
            (parent, at) = (Some(s), end);
        }
        p
    }

    #[test]
    fn each_level_about_halves_the_triangles() {
        let p = plant();
        let chain = lod_levels(&p, &MeshOptions::default(), 4).unwrap();
        assert_eq!(chain.len(), 4);
        let full = Mesher::new(MeshOptions::default())
            .unwrap()
            .mesh(&p)
            .unwrap();
        assert_eq!(chain[0].triangles, full.triangle_count());
        for k in 1..4 {
            let (prev, this) = (&chain[k - 1], &chain[k]);
            let mesh = Mesher::new(this.options.clone())
                .unwrap()
                .mesh(&this.plant)
                .unwrap();
            assert_eq!(mesh.triangle_count(), this.triangles, "counts are exact");
            let aim = chain[0].triangles as f64 / f64::from(1u32 << k);
            assert!(
                this.triangles as f64 <= aim,
                "level {k}: {} > {aim}",
                this.triangles
            );
            assert!(
                this.triangles as f64 >= 0.6 * aim,
                "level {k}: {} far under {aim}",
                this.triangles
            );
            assert!(this.detail < prev.detail || k == 1);
            assert!(this.screen_coverage < prev.screen_coverage);
            // The silhouette holds: the bounds stay within a tenth of the plant's size.
            let (a, b) = (full.bounds(), mesh.bounds());
            let size = (a.max - a.min).length();
            assert!((a.max - b.max).length() < 0.1 * size && (a.min - b.min).length() < 0.1 * size);
        }
        assert_eq!(chain[3].screen_coverage, CULL_COVERAGE);
    }

    #[test]
    fn previews_are_the_first_level_within_the_budget() {
        let p = plant();
        let options = MeshOptions::default();
        let full = Mesher::new(options.clone())
            .unwrap()
            .counts(&p)
            .unwrap()
            .triangles;
        let whole = preview(&p, &options, full).unwrap();
        assert_eq!((whole.detail, whole.triangles), (1.0, full));
        for budget in [full - 1, full / 3, full / 5] {
            let level = preview(&p, &options, budget).unwrap();
            let k = (0..MAX_LEVELS).find(|&k| full >> k <= budget).unwrap();
            let aim = full as f64 / f64::from(1u32 << k);
            assert!(level.triangles as f64 <= aim && level.triangles as f64 >= 0.6 * aim);
            assert_eq!(
                Mesher::new(level.options.clone())
                    .unwrap()
                    .mesh(&level.plant)
                    .unwrap()
                    .triangle_count(),
                level.triangles,
                "counts are exact"
            );
        }
        // However small the budget, the chain's last level (or the plainest plant, q = 0).
        let least = preview(&p, &options, 1).unwrap();
        let last_aim = full as f64 / f64::from(1u32 << (MAX_LEVELS - 1));
        assert!(least.triangles as f64 <= last_aim || least.detail == 0.0);
    }

    #[test]
    fn detail_one_keeps_the_skeleton_and_zero_keeps_the_trunk() {
        let p = plant();
        let skeleton = Skeleton::of(&p);
        let mut scratch = Scratch::default();
        let same = skeleton.simplify(1.0, &mut scratch).unwrap();
        assert_eq!(same.segments(), p.segments());
        assert_eq!(same.organs(), p.organs());
        let bare = skeleton.simplify(0.0, &mut scratch).unwrap();
        // Every branch dropped, the gently bent trunk joined into runs of at most half the
        // plant's diagonal.
        assert_eq!(bare.segments().len(), 2);
        assert!(bare.segments().iter().all(|s| !s.lateral));
        assert_eq!(bare.segments()[0].start, p.segments()[0].start);
        assert_eq!(bare.segments()[1].end, p.segments()[33].end);
        // Leaves stay, as cards on the trunk.
        assert!(!bare.organs().is_empty() && bare.organs().len() < p.organs().len());
        assert!(bare.organs().iter().all(|o| o.parent.is_some()));
    }

    #[test]
    fn counting_a_simplified_skeleton_agrees_with_the_mesher() {
        let p = plant();
        let skeleton = Skeleton::of(&p);
        let mut scratch = Scratch::default();
        for q in [0.0, 0.1, 0.33, 0.5, 0.8, 0.97, 1.0] {
            let plant = skeleton.simplify(q, &mut scratch).unwrap();
            let counted = skeleton.triangles(q, &MeshOptions::default(), &mut scratch);
            let options = level_options(&MeshOptions::default(), q);
            let meshed = Mesher::new(options).unwrap().mesh(&plant).unwrap();
            assert_eq!(counted, meshed.triangle_count(), "q = {q}");
        }
    }

    #[test]
    fn bad_level_counts_are_refused_and_levels_are_deterministic() {
        let p = plant();
        assert!(matches!(
            lod_levels(&p, &MeshOptions::default(), 0),
            Err(LodError::Levels(0))
        ));
        assert!(lod_levels(&p, &MeshOptions::default(), MAX_LEVELS + 1).is_err());
        let a = lod_levels(&p, &MeshOptions::default(), 3).unwrap();
        let b = lod_levels(&p, &MeshOptions::default(), 3).unwrap();
        for (a, b) in a.iter().zip(&b) {
            assert_eq!(a.plant, b.plant);
            assert_eq!(a.triangles, b.triangles);
        }
        let empty = Plant::new(PlantMeta::default());
        let chain = lod_levels(&empty, &MeshOptions::default(), 3).unwrap();
        assert!(chain.iter().all(|l| l.triangles == 0));
    }
}
