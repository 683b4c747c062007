//! Plant to mesh: generalised cylinders along each axis, plus leaves, flowers and root tips.
//!
//! [`Mesher`] turns a [`Plant`] into a [`Mesh`] according to [`MeshOptions`]; it keeps its
//! scratch buffers and lookup tables, so meshing many plants in a row does not allocate once
//! the buffers have grown. [`mesh_plant`] is the one-shot form.
//!
//! ```
//! use sylva_core::{Plant, PlantMeta, glam::Vec3};
//! use sylva_mesh::mesher::{MeshOptions, Mesher};
//!
//! let mut plant = Plant::new(PlantMeta::default());
//! let a = plant.add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.08), None, false, Plant::BARK)?;
//! plant.add_segment(Vec3::Y, Vec3::new(0.2, 2.0, 0.0), (0.08, 0.05), Some(a), false, Plant::BARK)?;
//! let mut mesher = Mesher::new(MeshOptions::default())?;
//! let mesh = mesher.mesh(&plant)?;
//! // Two segments of one axis share the ring at their joint: 3 rings of 12 + 1 (the last
//! // vertex repeats the first for the texture seam), plus 2 caps of 1 + 12.
//! assert_eq!(mesh.vertex_count(), 3 * 13 + 2 * 13);
//! assert_eq!(mesh.uvs.len(), mesh.vertex_count());
//! assert_eq!(mesh.triangle_count(), 2 * 2 * 12 + 2 * 12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # How a plant is meshed
//!
//! - **Axes.** An axis starts at a segment without a parent, at a lateral segment, or at a
//!   non-lateral segment that is not its parent's *first* non-lateral child (several
//!   non-lateral children: the first continues the axis, the others are meshed as laterals).
//!   Each axis becomes one tube.
//! - **Rings.** A tube of `k` segments has `k + 1` rings of `radial_segments + 1` vertices
//!   (the last repeats the first at the texture seam, with the same position and normal);
//!   two consecutive segments share the ring at their joint, so there are no cracks. A ring's
//!   radius is the start radius of the axis's first segment for the first ring and the *end*
//!   radius of the incoming segment for every later ring (a child's start radius is ignored
//!   at a shared joint).
//! - **Frames.** Rings are oriented by rotation-minimising frames carried along the axis with
//!   the double-reflection method (Wang et al. 2008), so tubes do not twist. A joint ring lies
//!   in the plane of the bisector of the two tangents and is stretched by `1 / cos(half the
//!   bend)` (at most 2×) along the bend direction only, which makes it the exact mitre of
//!   both tubes up to 120° bends. An exact reversal (180°) has no bisector; its ring is put in
//!   the plane containing the tangent, the limit of ever sharper bends.
//! - **Normals.** Smooth, from the ring's radial direction, tilted along the axis by the
//!   taper (radius change over length) so cones shade as cones.
//! - **Caps.** With `cap_ends`, each axis gets a flat-shaded fan around a centre vertex at its
//!   start and its tip (own vertices with the axis direction as normal). A cap whose ring
//!   radius is zero would be a point and is left out.
//! - **Laterals.** A branch's first ring is moved back along the branch's own direction by the
//!   parent's radius at the junction, so the branch starts inside its parent and no gap shows
//!   where they meet (for instance a branch leaving the tip of an axis); its start cap is
//!   hidden inside the parent. The move is shortened so the whole ring stays inside the parent
//!   (a thin branch leaving at a wide angle would otherwise poke out of the far side), is zero
//!   for a branch at least as thick as its parent, and never exceeds half the first segment.
//! - **Leaves** are flat lanceolate blades: `leaf_stations` pairs of outline points along
//!   local +Y between base and tip, widest a third of the way up, width along local X, face
//!   normal local +Z; `size.x` is the length and `size.y` the greatest width. Each blade is
//!   emitted twice, once per side, with opposite windings and normals.
//! - **Flowers** are a star of `flower_petals` double-sided diamond petals around local +Y,
//!   tilted 20° up from the local XZ plane so the flower opens along +Y; `size.x` is the
//!   flower's diameter and `size.y` a petal's greatest width.
//! - **Root tips** are small smooth-shaded octahedra from the base up local +Y: `size.x`
//!   long, `size.y` wide.
//! - **Cards.** A leaf whose material has a [`Surface::Leaves`] is a card instead: one quad
//!   from its base up local +Y (`size.x` long, `size.y` wide, facing local +Z), or two
//!   crossed at right angles for kinds that read better so (needle tufts), one-sided (the
//!   material is drawn from both sides), showing atlas cell [`card_variant`] of the kind
//!   ([`crate::atlas::card_uvs`]). A flower whose material has [`Surface::Petals`] is a star
//!   of such one-sided petal cards ([`crate::atlas::PETAL_UVS`]) in place of the diamonds.
//! - **Bark surfaces.** A tube whose first segment's material has a [`Surface::Bark`] runs
//!   its texture `u` round the stem as many whole times as the bark's tile fits its
//!   circumference ([`crate::bark::tile_metres`]), and `v` as many times faster, so the bark
//!   keeps its real scale on trunks and twigs alike.
//! - **Texture coordinates** (see [`crate::texture`] for the textures). Tubes: `u = k / R`
//!   around ring vertex `k` (0 to 1 at the seam, which the rotation-minimising frames keep
//!   in a straight line along the axis), and `v` the arc length along the axis divided by
//!   the circumference there (each span's by its mean radius), so texels stay square as a
//!   tube tapers and `v` runs on, unbounded, for bark textures to repeat. Caps: a planar
//!   disc, centre `(½, ½)`, rim on the circle of radius ½. Leaves: `u` across the blade (0
//!   and 1 at the margins where it is widest, ½ on the midrib), `v` from 0 at the base to 1
//!   at the tip; both sides alike. Petals: the same per petal (base `(½, 0)`, sides `(0, ½)`
//!   and `(1, ½)`, tip `(½, 1)`). Root tips: their local XY plane, `v` base to tip.
//! - **Output.** One [`Primitive`] per material that has triangles, in material order;
//!   `mesh.materials` is a copy of `plant.materials()`. Vertices come axis by axis in segment
//!   order, then organs in order, so the same plant always gives the same mesh.
//!
//! The mesher trusts its [`Plant`]: a plant holds only finite coordinates within range,
//! non-negative sizes, unit orientations, parents before children and materials that exist
//! (it refuses anything else when it is built). Degenerate geometry is handled without NaN:
//! a zero-length segment borrows the direction of its neighbours and a zero radius gives a
//! collapsed tube with valid normals. The triangle count is computed exactly before
//! anything is allocated and checked against [`MeshOptions::max_triangles`].

use std::f32::consts::{PI, TAU};

use sylva_core::species::{LeafKind, Surface};
use sylva_core::{
    OrganKind, Plant,
    glam::{Quat, Vec3},
};
use thiserror::Error;

use crate::atlas::{self, card_uvs};
use crate::bark;
use crate::mesh::{Mesh, Primitive};

/// How a plant is meshed. Every field documents its default.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshOptions {
    /// Vertices per tube ring. Default 12; legal `3..=64`.
    pub radial_segments: u32,
    /// Vertices per tube ring for axes of branch order 0, 1, 2, …, the last entry holding
    /// for every higher order (levels of detail thin twigs first). Default empty:
    /// `radial_segments` for every order. Each legal `3..=64`; at most 16 entries.
    pub radial_segments_by_order: Vec<u32>,
    /// Close each axis's start and tip with a flat cap. Default `true`.
    pub cap_ends: bool,
    /// Round the caps: the cap's centre is raised by the ring's radius and shaded smoothly,
    /// so tubes end in domes, as sphylls (cylinders with spherical ends) do. Same vertex and
    /// triangle counts as flat caps. Default `false`.
    pub round_caps: bool,
    /// Refuse plants that would need more triangles than this, rather than running out of
    /// memory. Default 50 000 000.
    pub max_triangles: usize,
    /// Pairs of outline points along a leaf blade between its base and its tip. Default 4;
    /// legal `1..=32`. A blade has `4 × leaf_stations` triangles (both sides).
    pub leaf_stations: u32,
    /// Petals per flower. Default 5; legal `3..=32`. A flower has `4 × flower_petals`
    /// triangles (both sides).
    pub flower_petals: u32,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            radial_segments: 12,
            radial_segments_by_order: Vec::new(),
            cap_ends: true,
            round_caps: false,
            max_triangles: 50_000_000,
            leaf_stations: 4,
            flower_petals: 5,
        }
    }
}

/// Why a plant could not be meshed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshError {
    /// An option is outside its legal range.
    #[error("mesh option {option} = {value} is out of range (expected {expected})")]
    BadOption {
        /// The option's field name.
        option: &'static str,
        /// The value given.
        value: u64,
        /// The legal range.
        expected: &'static str,
    },
    /// The plant needs more triangles than [`MeshOptions::max_triangles`].
    #[error("the mesh would need {needed} triangles, more than the limit of {limit}")]
    TooManyTriangles {
        /// The limit in force.
        limit: usize,
        /// What the plant needs.
        needed: u64,
    },
    /// The plant needs more vertices than 32-bit indices can address.
    #[error("the mesh would need {needed} vertices, more than 32-bit indices can address")]
    TooManyVertices {
        /// What the plant needs.
        needed: u64,
    },
    /// The mesh would not fit in the memory budget.
    #[error("the mesh does not fit in memory")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
}

/// What a call to [`Mesher::mesh_into`] produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshStats {
    /// Vertices written.
    pub vertices: usize,
    /// Triangles written.
    pub triangles: usize,
}

/// Bytes a mesh of `vertices` and `triangles` holds: a position, normal and texture
/// coordinate per vertex, three indices per triangle.
pub fn mesh_bytes(vertices: u64, triangles: u64) -> u64 {
    vertices
        .saturating_mul(32)
        .saturating_add(triangles.saturating_mul(12))
}

/// Largest bend factor `1 / cos(half angle)` applied to a joint ring (a 120° bend).
const MAX_BEND_STRETCH: f32 = 2.0;
/// Squared lengths below this are treated as zero (lengths below a picometre).
const TINY_SQ: f32 = 1e-24;
/// The taper slope used for normals is clamped to this (a cone of about 83°).
const MAX_SLOPE: f32 = 8.0;
/// Petals rise this far (radians) from the flower's plane towards its axis.
const PETAL_TILT: f32 = 20.0 * PI / 180.0;
/// Tube spans thinner than this (metres) advance texture `v` as if they were this thick, so
/// collapsed tubes keep finite coordinates.
const MIN_UV_RADIUS: f32 = 1e-4;
/// No continuation / no slot.
const NONE: u32 = u32::MAX;

/// One petal of the flower template, in the organ's local frame.
#[derive(Clone, Copy, Debug)]
struct Petal {
    /// From the centre to the petal's tip (unit).
    dir: Vec3,
    /// Across the petal (unit).
    side: Vec3,
    /// Front face normal (unit).
    normal: Vec3,
}

/// A reusable plant mesher; it keeps its scratch buffers and tables between calls.
#[derive(Clone, Debug)]
pub struct Mesher {
    options: MeshOptions,
    /// The tables of each ring size in use.
    rings: Vec<RingTables>,
    /// Per branch order, the index into `rings` (the last entry holds for higher orders).
    rings_of_order: Vec<usize>,
    /// Leaf outline stations: (half width for a unit width, height for a unit length).
    leaf_profile: Vec<(f32, f32)>,
    /// Both sides of a blade, relative to its first vertex.
    leaf_pattern: Vec<u32>,
    /// Texture coordinates of one side of a blade, in vertex order.
    leaf_uv: Vec<[f32; 2]>,
    /// Petal directions of the flower template.
    petals: Vec<Petal>,
    /// Per segment: its continuation child, or `NONE`.
    next: Vec<u32>,
    /// Per material: triangles it will get.
    material_triangles: Vec<u64>,
    /// Per material: its primitive in the output, or `NONE`.
    slots: Vec<u32>,
    /// Index buffers recycled from earlier outputs.
    pool: Vec<Vec<u32>>,
    /// Where each vertex came from ([`Mesher::mesh_with_sources`]), while recording.
    sources: Option<VertexSources>,
}

/// The precomputed tables of one ring size `R`.
#[derive(Clone, Debug)]
struct RingTables {
    /// `R`.
    r: u32,
    /// `(cos, sin)` of each ring vertex's angle; `R + 1` entries, the last (the seam) a copy
    /// of the first, so both have bit-identical positions and normals.
    circle: Vec<(f32, f32)>,
    /// Indices of one tube segment's quads, relative to the first vertex of its lower ring.
    quad_pattern: Vec<u32>,
    /// Texture `u` of each ring vertex: `k / R`, the seam vertex `R` at 1.
    ring_u: Vec<f32>,
    /// Texture coordinates of a cap's centre and ring vertices (a planar disc).
    cap_uv: Vec<[f32; 2]>,
    /// Fan indices of a start cap (facing back) relative to its centre vertex.
    start_cap_pattern: Vec<u32>,
    /// Fan indices of a tip cap (facing forward) relative to its centre vertex.
    tip_cap_pattern: Vec<u32>,
}

impl RingTables {
    fn new(r: u32) -> Self {
        let mut circle: Vec<(f32, f32)> = (0..r)
            .map(|k| {
                let (s, c) = (TAU * k as f32 / r as f32).sin_cos();
                (c, s)
            })
            .collect();
        circle.push(circle[0]);
        let ring_u = (0..=r).map(|k| k as f32 / r as f32).collect();
        let cap_uv = std::iter::once([0.5, 0.5])
            .chain(
                circle[..r as usize]
                    .iter()
                    .map(|&(c, s)| [0.5 + 0.5 * c, 0.5 + 0.5 * s]),
            )
            .collect();
        // Quad k joins vertices k, k+1 of the lower ring to the same ones of the upper ring
        // (rings have r + 1 vertices); with (u, v, tangent) right-handed, (a, b, d) and
        // (a, d, c) wind counter-clockwise seen from outside. Caps have no seam: their ring
        // is r vertices after the centre.
        let mut quad_pattern = Vec::with_capacity(6 * r as usize);
        let mut start_cap_pattern = Vec::with_capacity(3 * r as usize);
        let mut tip_cap_pattern = Vec::with_capacity(3 * r as usize);
        for k in 0..r {
            let (a, b) = (k, k + 1);
            let (c, d) = (a + r + 1, b + r + 1);
            quad_pattern.extend_from_slice(&[a, b, d, a, d, c]);
            let b = (k + 1) % r;
            start_cap_pattern.extend_from_slice(&[0, 1 + b, 1 + a]);
            tip_cap_pattern.extend_from_slice(&[0, 1 + a, 1 + b]);
        }
        RingTables {
            r,
            circle,
            quad_pattern,
            ring_u,
            cap_uv,
            start_cap_pattern,
            tip_cap_pattern,
        }
    }

    /// Appends a ring's vertices, at texture `v`, its `u` running `repeats` times round.
    #[inline]
    fn ring(&self, ring: &Ring, v: f32, repeats: f32, out: &mut Mesh) {
        let Ring {
            center,
            pu,
            pv,
            nu,
            nv,
            nt,
        } = *ring;
        out.positions.extend(
            self.circle
                .iter()
                .map(|&(c, s)| (center + pu * c + pv * s).to_array()),
        );
        out.normals.extend(
            self.circle
                .iter()
                .map(|&(c, s)| (nu * c + nv * s + nt).to_array()),
        );
        if repeats == 1.0 {
            out.uvs.extend(self.ring_u.iter().map(|&u| [u, v]));
        } else {
            out.uvs
                .extend(self.ring_u.iter().map(|&u| [u * repeats, v]));
        }
    }
}

/// Marks a vertex of [`Mesher::mesh_with_sources`] as an organ's (leaf, flower, root tip);
/// the low bits hold the organ's parent segment, or [`NO_SEGMENT`].
pub const ORGAN_SOURCE: u32 = 1 << 31;
/// The source segment of an organ without a parent.
pub const NO_SEGMENT: u32 = ORGAN_SOURCE - 1;

/// Where each vertex of a mesh came from ([`Mesher::mesh_with_sources`]): the index of its
/// tube's segment, or [`ORGAN_SOURCE`] with the organ's parent segment (or [`NO_SEGMENT`]).
/// Kept as runs, one per ring, cap or organ, rather than a number per vertex: recording is
/// then nearly free, and readers walk the vertices in order ([`VertexSources::iter`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VertexSources {
    /// `(end, source)`: the vertices from the previous run's end up to `end` (excluded) came
    /// from `source`. Ends rise.
    runs: Vec<(u32, u32)>,
}

impl VertexSources {
    /// Vertices described.
    pub fn len(&self) -> usize {
        self.runs.last().map_or(0, |&(end, _)| end as usize)
    }

    /// Whether no vertex is described.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Where vertex `v` came from, if it is described.
    pub fn get(&self, v: usize) -> Option<u32> {
        let run = self.runs.partition_point(|&(end, _)| end as usize <= v);
        self.runs.get(run).map(|&(_, source)| source)
    }

    /// The runs: `(end, source)`, the vertices from the previous run's end up to `end`
    /// (excluded) having come from `source`.
    pub fn runs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.runs.iter().copied()
    }

    /// Every vertex's source, in order.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        let mut start = 0;
        self.runs.iter().flat_map(move |&(end, source)| {
            let n = end - start;
            start = end;
            std::iter::repeat_n(source, n as usize)
        })
    }
}

/// Records that the vertices added since the last mark came from `source`.
#[inline]
fn mark(sources: &mut Option<VertexSources>, out: &Mesh, source: u32) {
    if let Some(s) = sources {
        let end = out.positions.len() as u32;
        if end > s.runs.last().map_or(0, |&(e, _)| e) {
            s.runs.push((end, source));
        }
    }
}

/// The octahedron of a root tip: 6 vertices (bottom, top, +X, +Z, -X, -Z), 8 faces.
const ROOT_TIP_INDICES: [u32; 24] = [
    1, 3, 2, 1, 4, 3, 1, 5, 4, 1, 2, 5, // upper faces, counter-clockwise from outside
    0, 2, 3, 0, 3, 4, 0, 4, 5, 0, 5, 2, // lower faces
];
/// The octahedron's texture coordinates: its local XY plane projected, v from base to tip.
const ROOT_TIP_UVS: [[f32; 2]; 6] = [
    [0.5, 0.0],
    [0.5, 1.0],
    [1.0, 0.5],
    [0.5, 0.5],
    [0.0, 0.5],
    [0.5, 0.5],
];
/// A petal's corners (base, right, tip, left): u across, v from base (0) to tip (1).
const PETAL_UVS: [[f32; 2]; 4] = [[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]];
const ROOT_TIP_VERTICES: u64 = 6;
const ROOT_TIP_TRIANGLES: u64 = 8;

impl Mesher {
    /// A mesher for `options`, after checking them.
    pub fn new(options: MeshOptions) -> Result<Self, MeshError> {
        check_range("radial_segments", options.radial_segments, 3, 64, "3..=64")?;
        check_range("leaf_stations", options.leaf_stations, 1, 32, "1..=32")?;
        check_range("flower_petals", options.flower_petals, 3, 32, "3..=32")?;
        if options.radial_segments_by_order.len() > 16 {
            return Err(MeshError::BadOption {
                option: "radial_segments_by_order",
                value: options.radial_segments_by_order.len() as u64,
                expected: "at most 16 entries",
            });
        }
        for &r in &options.radial_segments_by_order {
            check_range("radial_segments_by_order", r, 3, 64, "3..=64")?;
        }
        let sizes: Vec<u32> = if options.radial_segments_by_order.is_empty() {
            vec![options.radial_segments]
        } else {
            options.radial_segments_by_order.clone()
        };
        let mut rings: Vec<RingTables> = Vec::new();
        let rings_of_order = sizes
            .iter()
            .map(|&r| match rings.iter().position(|t| t.r == r) {
                Some(i) => i,
                None => {
                    rings.push(RingTables::new(r));
                    rings.len() - 1
                }
            })
            .collect();

        // Lanceolate half-width sqrt(s)·(1 - s), normalised to 1/2 at its widest (s = 1/3).
        let n = options.leaf_stations;
        let widest = (1.0f32 / 3.0).sqrt() * (2.0 / 3.0);
        let leaf_profile: Vec<(f32, f32)> = (1..=n)
            .map(|i| {
                let s = i as f32 / (n + 1) as f32;
                (0.5 * s.sqrt() * (1.0 - s) / widest, s)
            })
            .collect();
        // u across the blade (0 left margin at its widest .. 1 right), v from base to tip.
        let mut leaf_uv = Vec::with_capacity(2 * n as usize + 2);
        leaf_uv.push([0.5, 0.0]);
        for &(h, s) in &leaf_profile {
            leaf_uv.extend_from_slice(&[[0.5 - h, s], [0.5 + h, s]]);
        }
        leaf_uv.push([0.5, 1.0]);
        // One side: base 0, left i = 2i - 1, right i = 2i (i = 1..=n), tip 2n + 1.
        let mut front = Vec::with_capacity(6 * n as usize);
        front.extend_from_slice(&[0, 2, 1]);
        for i in 1..n {
            let (l0, r0, l1, r1) = (2 * i - 1, 2 * i, 2 * i + 1, 2 * i + 2);
            front.extend_from_slice(&[l0, r0, r1, l0, r1, l1]);
        }
        front.extend_from_slice(&[2 * n - 1, 2 * n, 2 * n + 1]);
        let side = 2 * n + 2;
        let mut leaf_pattern = front.clone();
        for t in front.chunks_exact(3) {
            leaf_pattern.extend_from_slice(&[t[0] + side, t[2] + side, t[1] + side]);
        }

        let petals = (0..options.flower_petals)
            .map(|p| {
                let (s, c) = (TAU * p as f32 / options.flower_petals as f32).sin_cos();
                let radial = Vec3::new(c, 0.0, s);
                let side = Vec3::new(-s, 0.0, c);
                let (ts, tc) = PETAL_TILT.sin_cos();
                let dir = radial * tc + Vec3::Y * ts;
                // side × dir = cos(tilt)·Y − sin(tilt)·radial: faces up the flower's axis.
                Petal {
                    dir,
                    side,
                    normal: side.cross(dir).normalize(),
                }
            })
            .collect();

        Ok(Mesher {
            options,
            rings,
            rings_of_order,
            leaf_profile,
            leaf_pattern,
            leaf_uv,
            petals,
            next: Vec::new(),
            material_triangles: Vec::new(),
            slots: Vec::new(),
            pool: Vec::new(),
            sources: None,
        })
    }

    /// The options this mesher was made with.
    pub fn options(&self) -> &MeshOptions {
        &self.options
    }

    /// The ring tables for axes of branch `order`.
    #[inline]
    fn rings_for(&self, order: u16) -> &RingTables {
        let last = self.rings_of_order.len() - 1;
        &self.rings[self.rings_of_order[usize::from(order).min(last)]]
    }

    /// Meshes `plant` into `out`, replacing its contents but reusing its buffers' capacity.
    /// On error `out` is left unchanged.
    pub fn mesh_into(&mut self, plant: &Plant, out: &mut Mesh) -> Result<MeshStats, MeshError> {
        self.link(plant);
        let (vertices, triangles) = self.count(plant)?;
        sylva_core::budget::check(
            mesh_bytes(vertices as u64, triangles as u64),
            format_args!("a mesh of {triangles} triangles"),
            "grow a smaller plant",
        )?;

        out.positions.clear();
        out.normals.clear();
        out.uvs.clear();
        out.positions.reserve(vertices);
        out.normals.reserve(vertices);
        out.uvs.reserve(vertices);
        out.materials.clear();
        out.materials.extend_from_slice(plant.materials());
        // Reversed, so popping hands each material back the buffer it had last time.
        for p in out.primitives.drain(..).rev() {
            self.pool.push(p.indices);
        }
        self.slots.clear();
        self.slots.resize(plant.materials().len(), NONE);
        for (m, &tris) in self.material_triangles.iter().enumerate() {
            if tris > 0 {
                let mut indices = self.pool.pop().unwrap_or_default();
                indices.clear();
                indices.reserve(3 * tris as usize);
                self.slots[m] = out.primitives.len() as u32;
                out.primitives.push(Primitive {
                    material: m,
                    indices,
                });
            }
        }

        let mut sources = self.sources.take().map(|mut s| {
            s.runs.clear();
            s
        });
        for start in 0..plant.segments().len() {
            if self.starts_axis(plant, start) {
                self.tube(plant, start, out, &mut sources);
            }
        }
        self.organs(plant, out, &mut sources);
        self.sources = sources;

        debug_assert_eq!(out.positions.len(), vertices);
        debug_assert_eq!(out.triangle_count(), triangles);
        Ok(MeshStats {
            vertices,
            triangles,
        })
    }

    /// Bytes the mesh of `plant` will hold (counted exactly, without meshing); an error if
    /// it is over [`MeshOptions::max_triangles`].
    pub fn bytes_for(&mut self, plant: &Plant) -> Result<u64, MeshError> {
        self.link(plant);
        let (vertices, triangles) = self.count(plant)?;
        Ok(mesh_bytes(vertices as u64, triangles as u64))
    }

    /// The exact vertex and triangle counts of the mesh of `plant`, without meshing it; an
    /// error if it is over [`MeshOptions::max_triangles`].
    pub fn counts(&mut self, plant: &Plant) -> Result<MeshStats, MeshError> {
        self.link(plant);
        let (vertices, triangles) = self.count(plant)?;
        Ok(MeshStats {
            vertices,
            triangles,
        })
    }

    /// Meshes `plant` into a new mesh, and says where each vertex came from
    /// ([`VertexSources`]). Skinning (wind) weights vertices by it.
    pub fn mesh_with_sources(&mut self, plant: &Plant) -> Result<(Mesh, VertexSources), MeshError> {
        self.sources = Some(VertexSources::default());
        let result = self.mesh(plant);
        let sources = self.sources.take().unwrap_or_default();
        Ok((result?, sources))
    }

    /// Meshes `plant` into a new mesh.
    pub fn mesh(&mut self, plant: &Plant) -> Result<Mesh, MeshError> {
        let mut out = Mesh::default();
        self.mesh_into(plant, &mut out)?;
        Ok(out)
    }

    /// Links each segment to its continuation (the first child that is not lateral).
    fn link(&mut self, plant: &Plant) {
        self.next.clear();
        self.next.resize(plant.segments().len(), NONE);
        for (i, s) in plant.segments().iter().enumerate() {
            if let Some(p) = s.parent
                && !s.lateral
                && self.next[p.index()] == NONE
            {
                self.next[p.index()] = i as u32;
            }
        }
    }

    /// Exact vertex and triangle counts (and triangles per material), checked against the
    /// limits before anything is allocated.
    fn count(&mut self, plant: &Plant) -> Result<(usize, usize), MeshError> {
        let caps = self.options.cap_ends;
        self.material_triangles.clear();
        self.material_triangles.resize(plant.materials().len(), 0);
        let (mut vertices, mut triangles) = (0u64, 0u64);
        for (i, s) in plant.segments().iter().enumerate() {
            // An axis keeps its first segment's order (a continuation has its parent's).
            let r = u64::from(self.rings_for(s.order).r);
            let mut tris = 2 * r;
            vertices += r + 1;
            if self.starts_axis(plant, i) {
                vertices += r + 1;
                if caps && s.start_radius > 0.0 {
                    vertices += r + 1;
                    tris += r;
                }
            }
            if caps && self.next[i] == NONE && s.end_radius > 0.0 {
                vertices += r + 1;
                tris += r;
            }
            self.material_triangles[s.material.index()] += tris;
            triangles += tris;
        }
        let n = u64::from(self.options.leaf_stations);
        let p = u64::from(self.options.flower_petals);
        for o in plant.organs() {
            let surface = plant.materials()[o.material.index()].surface;
            let (v, t) = match (o.kind, surface) {
                (OrganKind::Leaf, Some(s)) if s.leaves().is_some() => {
                    let kind = s.leaves().map_or(LeafKind::Oak, |(k, _)| k);
                    let quads = if kind.spec().crossed { 2 } else { 1 };
                    (4 * quads, 2 * quads)
                }
                (OrganKind::Flower, Some(Surface::Petals)) => (4 * p, 2 * p),
                (OrganKind::Leaf, _) => (4 * n + 4, 4 * n),
                (OrganKind::Flower, _) => (8 * p, 4 * p),
                (OrganKind::RootTip, _) => (ROOT_TIP_VERTICES, ROOT_TIP_TRIANGLES),
            };
            vertices += v;
            triangles += t;
            self.material_triangles[o.material.index()] += t;
        }
        // Counts are at most a few hundred per segment or organ, so u64 cannot overflow here.
        if triangles > self.options.max_triangles as u64 {
            return Err(MeshError::TooManyTriangles {
                limit: self.options.max_triangles,
                needed: triangles,
            });
        }
        if vertices > u64::from(u32::MAX) {
            return Err(MeshError::TooManyVertices { needed: vertices });
        }
        Ok((vertices as usize, triangles as usize))
    }

    /// Whether segment `i` begins an axis (see the module docs).
    #[inline]
    fn starts_axis(&self, plant: &Plant, i: usize) -> bool {
        let s = &plant.segments()[i];
        match s.parent {
            None => true,
            Some(p) => s.lateral || self.next[p.index()] != i as u32,
        }
    }

    /// Meshes the axis beginning at segment `start`: rings, quads and caps.
    fn tube(
        &self,
        plant: &Plant,
        start: usize,
        out: &mut Mesh,
        sources: &mut Option<VertexSources>,
    ) {
        let segs = &plant.segments();
        let first = &segs[start];
        let tables = self.rings_for(first.order);
        let r = tables.r;

        // A branch starts inside its parent (see the module docs).
        let mut x_prev = first.start;
        if let (Some(p), Some(dir)) = (first.parent, first.vector().try_normalize_tiny()) {
            x_prev -= dir * lateral_pull_back(&segs[p.index()], first, dir);
        }

        // Span 0 runs from the first ring to the first segment's end.
        let mut t_cur = self.first_tangent(plant, start, x_prev);
        let mut slope_cur = span_slope(x_prev, first.start_radius, first.end, first.end_radius);
        let mut n_prev = t_cur;
        let mut u_prev = t_cur.any_orthonormal_vector();

        let mut ring = Ring::new(x_prev, n_prev, u_prev, first.start_radius, slope_cur, None);
        if self.options.cap_ends && first.start_radius > 0.0 {
            self.cap(tables, &ring, -n_prev, first.material.index(), true, out);
        }
        let mut base = out.positions.len() as u32;
        // A bark surface repeats its tile round the stem as often as its width allows.
        let repeats = match plant.materials()[first.material.index()].surface {
            Some(Surface::Bark(kind)) => {
                let around = TAU * first.start_radius / bark::tile_metres(kind);
                around.round().clamp(1.0, 64.0)
            }
            _ => 1.0,
        };
        // Texture v: metres along the axis over the circumference there, per repeat (see
        // the docs).
        let (mut tex_v, mut r_prev) = (0.0f32, first.start_radius);
        tables.ring(&ring, tex_v, repeats, out);
        mark(sources, out, start as u32);

        let mut cur = start;
        loop {
            let seg = &segs[cur];
            let (x, radius) = (seg.end, seg.end_radius);
            let next = self.next[cur];
            let (n, stretch, slope, t_next, slope_next);
            if next == NONE {
                (n, stretch, slope) = (t_cur, None, slope_cur);
                (t_next, slope_next) = (t_cur, slope_cur);
            } else {
                let nseg = &segs[next as usize];
                t_next = (nseg.end - x).try_normalize_tiny().unwrap_or(t_cur);
                slope_next = span_slope(x, radius, nseg.end, nseg.end_radius);
                slope = 0.5 * (slope_cur + slope_next);
                let sum = t_cur + t_next;
                let bend = (t_next - t_cur).try_normalize_tiny();
                match (sum.try_normalize_tiny(), bend) {
                    (Some(bisector), Some(bend)) => {
                        let cos_half = bisector.dot(t_cur).max(1.0 / MAX_BEND_STRETCH);
                        (n, stretch) = (bisector, Some((bend, 1.0 / cos_half)));
                    }
                    (Some(bisector), None) => (n, stretch) = (bisector, None),
                    // An exact reversal: the ring contains the tangent.
                    (None, _) => {
                        let perp = (u_prev - t_cur * u_prev.dot(t_cur))
                            .try_normalize_tiny()
                            .unwrap_or_else(|| t_cur.any_orthonormal_vector());
                        (n, stretch) = (perp, Some((t_next, MAX_BEND_STRETCH)));
                    }
                }
            }
            let u = transport(x_prev, n_prev, u_prev, x, n);
            ring = Ring::new(x, n, u, radius, slope, stretch);
            let circumference = TAU * (0.5 * (r_prev + radius)).max(MIN_UV_RADIUS);
            tex_v += (x - x_prev).length() * repeats / circumference;
            tables.ring(&ring, tex_v, repeats, out);
            mark(sources, out, cur as u32);
            let slot = self.slots[seg.material.index()] as usize;
            out.primitives[slot]
                .indices
                .extend(tables.quad_pattern.iter().map(|&i| i + base));
            base += r + 1;
            r_prev = radius;

            if next == NONE {
                if self.options.cap_ends && radius > 0.0 {
                    self.cap(tables, &ring, n, seg.material.index(), false, out);
                    mark(sources, out, cur as u32);
                }
                break;
            }
            (x_prev, n_prev, u_prev) = (x, n, u);
            (t_cur, slope_cur, cur) = (t_next, slope_next, next as usize);
        }
    }

    /// The direction of the first span of the axis at `start` that has a length; if none has,
    /// the parent's direction, and failing that +Y.
    fn first_tangent(&self, plant: &Plant, start: usize, x0: Vec3) -> Vec3 {
        let segs = &plant.segments();
        let (mut from, mut cur) = (x0, start as u32);
        while cur != NONE {
            let s = &segs[cur as usize];
            if let Some(t) = (s.end - from).try_normalize_tiny() {
                return t;
            }
            from = s.end;
            cur = self.next[cur as usize];
        }
        segs[start]
            .parent
            .and_then(|p| segs[p.index()].vector().try_normalize_tiny())
            .unwrap_or(Vec3::Y)
    }

    /// Appends a flat cap over `ring`: a centre vertex, the ring again with `normal`, and a
    /// fan facing along `normal`.
    fn cap(
        &self,
        tables: &RingTables,
        ring: &Ring,
        normal: Vec3,
        material: usize,
        start: bool,
        out: &mut Mesh,
    ) {
        let center_index = out.positions.len() as u32;
        let Ring { center, pu, pv, .. } = *ring;
        let ring_circle = &tables.circle[..tables.circle.len() - 1];
        let n = normal.to_array();
        if self.options.round_caps {
            // A dome: the centre rises by the radius, and the rim keeps the tube's radial
            // normals, so shading runs smoothly from the tube over the end.
            let radius = 0.5 * (pu.length() + pv.length());
            out.positions.push((center + normal * radius).to_array());
            out.normals.push(n);
            for &(c, s) in ring_circle {
                let radial = pu * c + pv * s;
                out.positions.push((center + radial).to_array());
                out.normals.push(radial.normalize_or(normal).to_array());
            }
        } else {
            out.positions.push(center.to_array());
            out.positions.extend(
                ring_circle
                    .iter()
                    .map(|&(c, s)| (center + pu * c + pv * s).to_array()),
            );
            out.normals
                .extend(std::iter::repeat_n(n, ring_circle.len() + 1));
        }
        out.uvs.extend_from_slice(&tables.cap_uv);
        let pattern = if start {
            &tables.start_cap_pattern
        } else {
            &tables.tip_cap_pattern
        };
        let slot = self.slots[material] as usize;
        out.primitives[slot]
            .indices
            .extend(pattern.iter().map(|&i| i + center_index));
    }

    /// Appends every organ.
    fn organs(&self, plant: &Plant, out: &mut Mesh, sources: &mut Option<VertexSources>) {
        for (i, o) in plant.organs().iter().enumerate() {
            let source = ORGAN_SOURCE | o.parent.map_or(NO_SEGMENT, |p| p.0.min(NO_SEGMENT));
            // A plant's orientations are unit quaternions; normalising removes rounding.
            let q = o.orientation.normalize();
            let slot = self.slots[o.material.index()] as usize;
            let base = out.positions.len() as u32;
            let (length, width) = (o.size.x, o.size.y);
            let surface = plant.materials()[o.material.index()].surface;
            match (o.kind, surface.and_then(Surface::leaves)) {
                (OrganKind::Leaf, Some((kind, card))) => {
                    let (x, y, z) = (q * Vec3::X, q * Vec3::Y, q * Vec3::Z);
                    let uvs = card_uvs(card, card_variant(i));
                    let quad = |across: Vec3, normal: Vec3, out: &mut Mesh| {
                        let b = out.positions.len() as u32;
                        let half = across * (0.5 * width);
                        let tip = y * length;
                        for c in [-half, half, tip + half, tip - half] {
                            out.positions.push((o.position + c).to_array());
                        }
                        out.normals
                            .extend([normal.normalize_or(Vec3::Y).to_array(); 4]);
                        out.uvs.extend_from_slice(&uvs);
                        out.primitives[slot].indices.extend_from_slice(&[
                            b,
                            b + 1,
                            b + 2,
                            b,
                            b + 2,
                            b + 3,
                        ]);
                    };
                    quad(x, z, out);
                    if kind.spec().crossed {
                        quad(z, -x, out);
                    }
                }
                (OrganKind::Flower, _) if surface == Some(Surface::Petals) => {
                    let reach = 0.5 * length;
                    for petal in &self.petals {
                        let dir = q * petal.dir * reach;
                        let half = q * petal.side * (0.5 * width);
                        let normal = (q * petal.normal).normalize_or(Vec3::Y).to_array();
                        let b = out.positions.len() as u32;
                        let c = o.position;
                        for p in [c - half, c + half, c + dir + half, c + dir - half] {
                            out.positions.push(p.to_array());
                        }
                        out.normals.extend([normal; 4]);
                        out.uvs.extend_from_slice(&atlas::PETAL_UVS);
                        out.primitives[slot].indices.extend_from_slice(&[
                            b,
                            b + 1,
                            b + 2,
                            b,
                            b + 2,
                            b + 3,
                        ]);
                    }
                }
                (OrganKind::Leaf, _) => {
                    let (x, y) = (q * Vec3::X, q * Vec3::Y);
                    let at = |half_width: f32, s: f32| {
                        (o.position + x * (half_width * width) + y * (s * length)).to_array()
                    };
                    let front = (q * Vec3::Z).normalize_or(Vec3::Z);
                    for normal in [front, -front] {
                        out.positions.push(at(0.0, 0.0));
                        for &(h, s) in &self.leaf_profile {
                            out.positions.push(at(-h, s));
                            out.positions.push(at(h, s));
                        }
                        out.positions.push(at(0.0, 1.0));
                        let side = 2 * self.leaf_profile.len() + 2;
                        out.normals
                            .extend(std::iter::repeat_n(normal.to_array(), side));
                        // Both sides share the mapping: the back shows the front's mirror,
                        // as a real blade seen from behind does.
                        out.uvs.extend_from_slice(&self.leaf_uv);
                    }
                    out.primitives[slot]
                        .indices
                        .extend(self.leaf_pattern.iter().map(|&i| i + base));
                }
                (OrganKind::Flower, _) => {
                    let (reach, width) = (0.5 * length, width);
                    for (p, petal) in self.petals.iter().enumerate() {
                        let dir = q * petal.dir * reach;
                        let side = q * petal.side * (0.5 * width);
                        let front = (q * petal.normal).normalize_or(Vec3::Y);
                        let c = o.position;
                        let corners = [c, c + dir * 0.5 + side, c + dir, c + dir * 0.5 - side];
                        for normal in [front, -front] {
                            out.positions.extend(corners.map(|c| c.to_array()));
                            out.normals.extend([normal.to_array(); 4]);
                            out.uvs.extend_from_slice(&PETAL_UVS);
                        }
                        // Front (base, right, tip), (base, tip, left); back reversed.
                        let b = base + 8 * p as u32;
                        out.primitives[slot].indices.extend_from_slice(&[
                            b,
                            b + 1,
                            b + 2,
                            b,
                            b + 2,
                            b + 3,
                            b + 4,
                            b + 6,
                            b + 5,
                            b + 4,
                            b + 7,
                            b + 6,
                        ]);
                    }
                }
                (OrganKind::RootTip, _) => {
                    let (x, y, z) = (q * Vec3::X, q * Vec3::Y, q * Vec3::Z);
                    let (half, mid) = (0.5 * width, o.position + y * (0.5 * length));
                    let corners = [
                        (o.position, -y),
                        (o.position + y * length, y),
                        (mid + x * half, x),
                        (mid + z * half, z),
                        (mid - x * half, -x),
                        (mid - z * half, -z),
                    ];
                    for (p, n) in corners {
                        out.positions.push(p.to_array());
                        out.normals.push(n.normalize_or(Vec3::Y).to_array());
                    }
                    out.uvs.extend_from_slice(&ROOT_TIP_UVS);
                    out.primitives[slot]
                        .indices
                        .extend(ROOT_TIP_INDICES.iter().map(|&i| i + base));
                }
            }
            mark(sources, out, source);
        }
    }
}

/// The atlas cell organ `i` shows: neighbouring cards differ, the same plant always
/// shows the same cells.
fn card_variant(i: usize) -> u32 {
    let h = (i as u32).wrapping_mul(0x9e37_79b1);
    (h ^ (h >> 15)) >> 7
}

/// Meshes one plant with a throw-away [`Mesher`].
pub fn mesh_plant(plant: &Plant, options: &MeshOptions) -> Result<Mesh, MeshError> {
    Mesher::new(options.clone())?.mesh(plant)
}

/// A ring ready to emit: vertex `k` is `center + pu·cos + pv·sin` with normal
/// `nu·cos + nv·sin + nt`.
#[derive(Clone, Copy, Debug)]
struct Ring {
    center: Vec3,
    pu: Vec3,
    pv: Vec3,
    nu: Vec3,
    nv: Vec3,
    nt: Vec3,
}

impl Ring {
    /// A ring of `radius` in the plane normal to `n`, vertex 0 towards `u`. `stretch` is a unit
    /// direction in the ring's plane and a factor to lengthen the ring by along it (a joint's
    /// mitre). Normals lean along `n` by the taper `slope` (radius lost per metre).
    #[inline]
    fn new(
        center: Vec3,
        n: Vec3,
        u: Vec3,
        radius: f32,
        slope: f32,
        stretch: Option<(Vec3, f32)>,
    ) -> Ring {
        let v = n.cross(u);
        let (mut pu, mut pv) = (u, v);
        if let Some((bend, factor)) = stretch {
            pu += bend * ((factor - 1.0) * u.dot(bend));
            pv += bend * ((factor - 1.0) * v.dot(bend));
        }
        let k = 1.0 / (1.0 + slope * slope).sqrt();
        Ring {
            center,
            pu: pu * radius,
            pv: pv * radius,
            nu: u * k,
            nv: v * k,
            nt: n * (slope * k),
        }
    }
}

/// Carries the ring direction `u0` of a frame at `x0` with normal `n0` to a frame at `x1` with
/// normal `n1` by double reflection: the rotation-minimising frame, without twist.
#[inline]
fn transport(x0: Vec3, n0: Vec3, u0: Vec3, x1: Vec3, n1: Vec3) -> Vec3 {
    let v1 = x1 - x0;
    let c1 = v1.dot(v1);
    let u = if c1 > TINY_SQ {
        let ul = u0 - v1 * (2.0 / c1 * v1.dot(u0));
        let tl = n0 - v1 * (2.0 / c1 * v1.dot(n0));
        let v2 = n1 - tl;
        let c2 = v2.dot(v2);
        if c2 > TINY_SQ {
            ul - v2 * (2.0 / c2 * v2.dot(ul))
        } else {
            ul
        }
    } else {
        // Rings at one point (a zero-length segment): a single reflection would mirror the
        // frame, so rotate by the minimal arc instead.
        Quat::from_rotation_arc(n0, n1) * u0
    };
    // Re-orthonormalise against n1 so rounding never accumulates along long axes.
    (u - n1 * n1.dot(u))
        .try_normalize_tiny()
        .unwrap_or_else(|| n1.any_orthonormal_vector())
}

/// Radius lost per metre between two rings, clamped; zero for coincident rings.
#[inline]
fn span_slope(x0: Vec3, r0: f32, x1: Vec3, r1: f32) -> f32 {
    let length = (x1 - x0).length();
    if length * length > TINY_SQ {
        ((r0 - r1) / length).clamp(-MAX_SLOPE, MAX_SLOPE)
    } else {
        0.0
    }
}

/// How far a branch's first ring moves back along the branch direction `dir`: the parent's
/// radius `R` at the junction, but no further than keeps the whole ring (radius `r`) inside
/// the parent (`pull · sin θ + r ≤ R`, θ the angle between branch and parent), and at most
/// half the branch's first segment.
#[inline]
fn lateral_pull_back(parent: &sylva_core::Segment, first: &sylva_core::Segment, dir: Vec3) -> f32 {
    let parent_radius = radius_at(parent, first.start);
    let room = parent_radius - first.start_radius;
    if room <= 0.0 {
        return 0.0;
    }
    let sin = parent
        .vector()
        .try_normalize_tiny()
        .map_or(0.0, |a| a.cross(dir).length());
    let pull = if sin * parent_radius > room {
        room / sin
    } else {
        parent_radius
    };
    pull.min(0.5 * first.length())
}

/// The radius of segment `s` at the point of its axis closest to `p`.
#[inline]
fn radius_at(s: &sylva_core::Segment, p: Vec3) -> f32 {
    let v = s.vector();
    let len_sq = v.dot(v);
    let t = if len_sq > TINY_SQ {
        ((p - s.start).dot(v) / len_sq).clamp(0.0, 1.0)
    } else {
        1.0
    };
    s.start_radius + (s.end_radius - s.start_radius) * t
}

/// `try_normalize` that also treats lengths under a picometre as zero, whose normalisation
/// would lose precision.
trait TryNormalizeTiny: Sized {
    fn try_normalize_tiny(self) -> Option<Self>;
}

impl TryNormalizeTiny for Vec3 {
    #[inline]
    fn try_normalize_tiny(self) -> Option<Vec3> {
        if self.length_squared() > TINY_SQ {
            self.try_normalize()
        } else {
            None
        }
    }
}

fn check_range(
    option: &'static str,
    value: u32,
    min: u32,
    max: u32,
    expected: &'static str,
) -> Result<(), MeshError> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(MeshError::BadOption {
            option,
            value: u64::from(value),
            expected,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::HashMap;
    use sylva_core::glam::Vec2;
    use sylva_core::{Organ, PlantMeta, SegmentId};

    const R: usize = 12;
    /// Vertices of a tube ring: the seam vertex repeats the first.
    const RV: usize = R + 1;

    /// Checks what every mesh must satisfy; returns nothing, panics with a reason.
    fn check_invariants(mesh: &Mesh) {
        assert_eq!(mesh.positions.len(), mesh.normals.len());
        assert_eq!(mesh.positions.len(), mesh.uvs.len());
        for uv in &mesh.uvs {
            assert!(uv.iter().all(|c| c.is_finite()), "uv {uv:?}");
            // Bark surfaces run u round a stem several times (at most 64).
            assert!((0.0..=64.0).contains(&uv[0]) && uv[1] >= 0.0, "uv {uv:?}");
        }
        for p in &mesh.positions {
            assert!(p.iter().all(|c| c.is_finite()), "position {p:?}");
        }
        for n in &mesh.normals {
            let len = Vec3::from_array(*n).length();
            assert!((len - 1.0).abs() < 1e-4, "normal {n:?} has length {len}");
        }
        let mut last = None;
        for p in &mesh.primitives {
            assert!(!p.indices.is_empty(), "no empty primitives");
            assert_eq!(p.indices.len() % 3, 0);
            assert!(p.material < mesh.materials.len());
            assert!(
                last < Some(p.material),
                "one primitive per material, in order"
            );
            last = Some(p.material);
            assert!(
                p.indices
                    .iter()
                    .all(|&i| (i as usize) < mesh.positions.len())
            );
        }
    }

    /// The fraction of non-degenerate triangles whose winding agrees with their normals.
    fn winding_agreement(mesh: &Mesh) -> f32 {
        let (mut good, mut total) = (0, 0);
        for p in &mesh.primitives {
            for t in p.indices.chunks_exact(3) {
                let [a, b, c] =
                    [t[0], t[1], t[2]].map(|i| Vec3::from_array(mesh.positions[i as usize]));
                let face = (b - a).cross(c - a);
                if face.length() < 1e-9 {
                    continue;
                }
                let n: Vec3 = t
                    .iter()
                    .map(|&i| Vec3::from_array(mesh.normals[i as usize]))
                    .sum();
                total += 1;
                if face.dot(n) > 0.0 {
                    good += 1;
                }
            }
        }
        good as f32 / total.max(1) as f32
    }

    fn plant() -> Plant {
        Plant::new(PlantMeta::default())
    }

    /// A chain of segments through `points`, all with `radius`.
    fn chain(points: &[Vec3], radius: f32) -> Plant {
        let mut p = plant();
        let mut parent = None;
        for w in points.windows(2) {
            let id = p
                .add_segment(w[0], w[1], (radius, radius), parent, false, Plant::BARK)
                .unwrap();
            parent = Some(id);
        }
        p
    }

    fn mesh_of(p: &Plant) -> Mesh {
        let m = mesh_plant(p, &MeshOptions::default()).unwrap();
        check_invariants(&m);
        m
    }

    fn organ(
        kind: OrganKind,
        orientation: Quat,
        size: Vec2,
        material: sylva_core::MaterialId,
    ) -> Organ {
        Organ {
            kind,
            position: Vec3::new(0.5, 1.0, -0.25),
            orientation,
            size,
            material,
            parent: None,
        }
    }

    #[test]
    fn sources_name_each_vertex_s_segment_or_organ() {
        let mut p = chain(&[Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 2.0, 0.5)], 0.1);
        p.add_organ(Organ {
            position: Vec3::new(0.0, 2.0, 0.5),
            parent: Some(sylva_core::SegmentId(1)),
            ..organ(
                OrganKind::Leaf,
                Quat::IDENTITY,
                Vec2::new(0.3, 0.1),
                Plant::LEAF,
            )
        })
        .unwrap();
        let mut mesher = Mesher::new(MeshOptions::default()).unwrap();
        let (mesh, sources) = mesher.mesh_with_sources(&p).unwrap();
        assert_eq!(mesh, mesher.mesh(&p).unwrap(), "recording changes nothing");
        assert_eq!(sources.len(), mesh.positions.len());
        assert_eq!(sources.iter().count(), mesh.positions.len());
        let organ = sources.iter().filter(|&s| s == ORGAN_SOURCE | 1).count();
        assert!(organ > 0);
        assert!(
            sources
                .iter()
                .all(|s| s == 0 || s == 1 || s == ORGAN_SOURCE | 1)
        );
        for (v, s) in sources.iter().enumerate() {
            assert_eq!(
                sources.get(v),
                Some(s),
                "random access agrees with the walk"
            );
        }
        assert_eq!(sources.get(mesh.positions.len()), None);
        // Tube vertices lie near their segment.
        for (v, s) in mesh.positions.iter().zip(sources.iter()) {
            if s & ORGAN_SOURCE == 0 {
                let seg = &p.segments()[s as usize];
                let d = distance_to_segment(Vec3::from_array(*v), seg.start, seg.end);
                assert!(d < 0.2, "vertex {v:?} is {d} m from its segment {s}");
            }
        }
    }

    fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        (a + ab * t - p).length()
    }

    #[test]
    fn round_caps_are_domes() {
        let p = chain(&[Vec3::ZERO, Vec3::Y * 2.0], 0.25);
        let flat = mesh_of(&p);
        let options = MeshOptions {
            round_caps: true,
            ..MeshOptions::default()
        };
        let round = Mesher::new(options).unwrap().mesh(&p).unwrap();
        assert_eq!(round.vertex_count(), flat.vertex_count());
        assert_eq!(round.triangle_count(), flat.triangle_count());
        let top = round
            .positions
            .iter()
            .map(|p| p[1])
            .fold(f32::MIN, f32::max);
        let bottom = round
            .positions
            .iter()
            .map(|p| p[1])
            .fold(f32::MAX, f32::min);
        assert!(
            (top - 2.25).abs() < 1e-5 && (bottom + 0.25).abs() < 1e-5,
            "{top} {bottom}"
        );
        check_invariants(&round);
    }

    #[test]
    fn options_are_checked() {
        assert!(Mesher::new(MeshOptions::default()).is_ok());
        for (options, name) in [
            (
                MeshOptions {
                    radial_segments: 2,
                    ..Default::default()
                },
                "radial_segments",
            ),
            (
                MeshOptions {
                    radial_segments: 65,
                    ..Default::default()
                },
                "radial_segments",
            ),
            (
                MeshOptions {
                    radial_segments_by_order: vec![12, 2],
                    ..Default::default()
                },
                "radial_segments_by_order",
            ),
            (
                MeshOptions {
                    radial_segments_by_order: vec![3; 17],
                    ..Default::default()
                },
                "radial_segments_by_order",
            ),
            (
                MeshOptions {
                    leaf_stations: 0,
                    ..Default::default()
                },
                "leaf_stations",
            ),
            (
                MeshOptions {
                    flower_petals: 2,
                    ..Default::default()
                },
                "flower_petals",
            ),
        ] {
            match Mesher::new(options) {
                Err(MeshError::BadOption { option, .. }) => assert_eq!(option, name),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn empty_plant_gives_empty_mesh() {
        let p = plant();
        let m = mesh_of(&p);
        assert_eq!(m.vertex_count(), 0);
        assert!(m.primitives.is_empty());
        assert_eq!(m.materials, p.materials());
    }

    #[test]
    fn straight_axis_shares_rings() {
        for n in 1..6 {
            let points: Vec<Vec3> = (0..=n).map(|i| Vec3::Y * i as f32).collect();
            let p = chain(&points, 0.1);
            let m = mesh_of(&p);
            assert_eq!(m.vertex_count(), (n + 1) * RV + 2 * (R + 1));
            assert_eq!(m.triangle_count(), 2 * R * n + 2 * R);
            let options = MeshOptions {
                cap_ends: false,
                radial_segments: 7,
                ..Default::default()
            };
            let m = mesh_plant(&p, &options).unwrap();
            assert_eq!(m.vertex_count(), (n + 1) * 8);
            assert_eq!(m.triangle_count(), 2 * 7 * n);
            assert_eq!(winding_agreement(&m), 1.0);
        }
    }

    #[test]
    fn stats_match_the_mesh() {
        let mut p = chain(&[Vec3::ZERO, Vec3::Y, Vec3::new(1.0, 2.0, 0.0)], 0.1);
        p.add_organ(organ(
            OrganKind::Leaf,
            Quat::IDENTITY,
            Vec2::new(0.2, 0.1),
            Plant::LEAF,
        ))
        .unwrap();
        let mut mesher = Mesher::new(MeshOptions::default()).unwrap();
        let mut out = Mesh::default();
        let stats = mesher.mesh_into(&p, &mut out).unwrap();
        assert_eq!(stats.vertices, out.vertex_count());
        assert_eq!(stats.triangles, out.triangle_count());
    }

    #[test]
    fn caps_face_outwards_and_are_flat() {
        let p = chain(&[Vec3::ZERO, Vec3::Y], 0.1);
        let m = mesh_of(&p);
        // Start cap first: centre and ring with normal -Y; tip cap last with +Y.
        assert!(m.normals[..=R].iter().all(|n| *n == [0.0, -1.0, 0.0]));
        assert!(
            m.normals[m.vertex_count() - R - 1..]
                .iter()
                .all(|n| *n == [0.0, 1.0, 0.0])
        );
        assert_eq!(winding_agreement(&m), 1.0);
        assert_eq!(m.positions[0], [0.0, 0.0, 0.0]);
    }

    #[test]
    fn bent_joint_is_a_mitre() {
        // 90° bend: the joint ring must lie on both tubes' surfaces.
        let r = 0.2;
        let p = chain(&[Vec3::ZERO, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)], r);
        let m = mesh_of(&p);
        let joint = &m.positions[(R + 1) + RV..(R + 1) + 2 * RV];
        for q in joint {
            let q = Vec3::from_array(*q);
            // Distance to the incoming axis (the Y axis) and to the outgoing one (y = 1).
            let d_in = Vec2::new(q.x, q.z).length();
            let d_out = Vec2::new(q.y - 1.0, q.z).length();
            assert!((d_in - r).abs() < 1e-5, "{d_in}");
            assert!((d_out - r).abs() < 1e-5, "{d_out}");
        }
        assert_eq!(winding_agreement(&m), 1.0);
    }

    #[test]
    fn sharp_bends_clamp_the_stretch() {
        // A 170° bend: the stretch stops at 2 radii.
        let turn = Vec3::new(
            170f32.to_radians().sin(),
            1.0 + 170f32.to_radians().cos(),
            0.0,
        );
        let p = chain(&[Vec3::ZERO, Vec3::Y, turn], 0.1);
        let m = mesh_of(&p);
        let joint = &m.positions[(R + 1) + RV..(R + 1) + 2 * RV];
        let far = joint
            .iter()
            .map(|q| (Vec3::from_array(*q) - Vec3::Y).length())
            .fold(0.0, f32::max);
        assert!(far <= 0.2 + 1e-5, "{far}");
    }

    /// The ring frames of the axis starting at `first_ring` (vertex index of its first ring):
    /// vertex 0's normal is the frame's `u` for untapered tubes.
    fn ring_us(m: &Mesh, first_ring: usize, rings: usize) -> Vec<Vec3> {
        (0..rings)
            .map(|i| Vec3::from_array(m.normals[first_ring + i * RV]))
            .collect()
    }

    #[test]
    fn planar_curves_do_not_twist() {
        // An arc in the XY plane: a rotation-minimising frame keeps its angle to Z.
        let points: Vec<Vec3> = (0..=40)
            .map(|i| {
                let a = i as f32 * 0.07;
                Vec3::new(1.0 - a.cos(), a.sin(), 0.0)
            })
            .collect();
        let m = mesh_of(&chain(&points, 0.05));
        let us = ring_us(&m, R + 1, points.len());
        for u in &us {
            assert!((u.z - us[0].z).abs() < 1e-4, "{} vs {}", u.z, us[0].z);
        }
    }

    #[test]
    fn helices_twist_only_as_a_minimal_rotation_would() {
        let points: Vec<Vec3> = (0..=200)
            .map(|i| {
                let a = i as f32 * 0.1;
                Vec3::new(a.cos(), 0.05 * i as f32, a.sin())
            })
            .collect();
        let p = chain(&points, 0.05);
        let m = mesh_of(&p);
        let us = ring_us(&m, R + 1, points.len());
        let tangent = |i: usize| (points[i + 1] - points[i]).normalize();
        let ring_normal = |i: usize| {
            if i == 0 {
                tangent(0)
            } else if i == points.len() - 1 {
                tangent(i - 1)
            } else {
                (tangent(i - 1) + tangent(i)).normalize()
            }
        };
        for i in 1..points.len() {
            let carried = Quat::from_rotation_arc(ring_normal(i - 1), ring_normal(i)) * us[i - 1];
            let angle = carried.dot(us[i]).clamp(-1.0, 1.0).acos();
            assert!(angle < 2e-3, "ring {i} twists {angle} rad");
        }
    }

    #[test]
    fn taper_uses_incoming_end_radius_and_tilts_normals() {
        let mut p = plant();
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.3, 0.2), None, false, Plant::BARK)
            .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::Y * 2.0,
            (0.9, 0.1),
            Some(a),
            false,
            Plant::BARK,
        )
        .unwrap();
        let m = mesh_of(&p);
        let radius = |ring: usize| {
            let q = Vec3::from_array(m.positions[R + 1 + ring * RV]);
            Vec2::new(q.x, q.z).length()
        };
        assert!((radius(0) - 0.3).abs() < 1e-6);
        assert!(
            (radius(1) - 0.2).abs() < 1e-6,
            "joint uses the incoming end radius"
        );
        assert!((radius(2) - 0.1).abs() < 1e-6);
        // A narrowing tube's normals lean towards its tip.
        assert!(m.normals[R + 1][1] > 0.05);
    }

    #[test]
    fn laterals_start_inside_their_parent() {
        let mut p = plant();
        let trunk = p
            .add_segment(
                Vec3::ZERO,
                Vec3::Y * 2.0,
                (0.2, 0.1),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        let dir = Vec3::new(1.0, 1.0, 0.0).normalize();
        p.add_segment(
            Vec3::Y,
            Vec3::Y + dir,
            (0.05, 0.04),
            Some(trunk),
            true,
            Plant::BARK,
        )
        .unwrap();
        // A short branch: pulled back by at most half its length.
        p.add_segment(
            Vec3::Y * 2.0,
            Vec3::Y * 2.0 + dir * 0.1,
            (0.05, 0.04),
            Some(trunk),
            true,
            Plant::BARK,
        )
        .unwrap();
        let m = mesh_of(&p);
        // Axis 0: cap, 2 rings, cap. Axis 1 starts with its cap's centre vertex.
        let axis = 2 * (R + 1) + 2 * RV;
        let start = Vec3::from_array(m.positions[axis]);
        // The trunk's radius halfway up is 0.15; the whole ring of radius 0.05 stays inside it.
        let pull = (0.15 - 0.05) / std::f32::consts::FRAC_1_SQRT_2;
        let expected = Vec3::Y - dir * pull;
        assert!((start - expected).length() < 1e-5, "{start}");
        for q in &m.positions[axis + 1..axis + 1 + R] {
            let off_axis = Vec2::new(q[0], q[2]).length();
            assert!(off_axis <= 0.15 + 1e-5, "{off_axis}");
        }
        let start = Vec3::from_array(m.positions[2 * axis]);
        let expected = Vec3::Y * 2.0 - dir * 0.05;
        assert!((start - expected).length() < 1e-5, "{start}");
    }

    #[test]
    fn thick_branches_are_not_pulled_back() {
        let mut p = plant();
        let trunk = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.0),
            (0.2, 0.2),
            Some(trunk),
            true,
            Plant::BARK,
        )
        .unwrap();
        let m = mesh_of(&p);
        let axis = 2 * (R + 1) + 2 * RV;
        assert_eq!(m.positions[axis], [0.0, 1.0, 0.0]);
    }

    #[test]
    fn extra_continuations_become_laterals() {
        let mut p = plant();
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::Y * 2.0,
            (0.1, 0.1),
            Some(a),
            false,
            Plant::BARK,
        )
        .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::new(1.0, 2.0, 0.0),
            (0.1, 0.1),
            Some(a),
            false,
            Plant::BARK,
        )
        .unwrap();
        let m = mesh_of(&p);
        // Two axes: one of two segments (3 rings), one of one (2 rings), each with two caps.
        assert_eq!(m.vertex_count(), 5 * RV + 4 * (R + 1));
    }

    #[test]
    fn degenerate_segments_stay_finite() {
        let cases: Vec<Vec<Vec3>> = vec![
            vec![Vec3::ZERO, Vec3::Y, Vec3::Y, Vec3::Y * 2.0], // zero-length middle
            vec![Vec3::ZERO, Vec3::ZERO, Vec3::Y],             // zero-length first
            vec![Vec3::ONE, Vec3::ONE, Vec3::ONE],             // all zero length
            vec![Vec3::ZERO, Vec3::Y, Vec3::ZERO],             // exact reversal
            vec![Vec3::ZERO, Vec3::Y, Vec3::ZERO, Vec3::Y],    // back and forth
            vec![Vec3::ZERO, Vec3::Y, Vec3::new(1e-7, 0.0, 0.0)], // almost a reversal
            vec![Vec3::ZERO, Vec3::X * 1e-13, Vec3::X * 2e-13], // sub-picometre
        ];
        for points in cases {
            for radius in [0.0, 0.1] {
                let m = mesh_of(&chain(&points, radius));
                let segments = points.len() - 1;
                let caps = if radius > 0.0 { 2 * (R + 1) } else { 0 };
                assert_eq!(m.vertex_count(), (segments + 1) * RV + caps, "{points:?}");
            }
        }
    }

    #[test]
    fn reversal_keeps_consistent_winding() {
        let m = mesh_of(&chain(&[Vec3::ZERO, Vec3::Y, Vec3::Y * 0.5], 0.1));
        assert!(winding_agreement(&m) > 0.9, "{}", winding_agreement(&m));
    }

    #[test]
    fn too_many_triangles_is_an_error_and_leaves_out_alone() {
        let p = chain(&[Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0], 0.1);
        let options = MeshOptions {
            max_triangles: 10,
            ..Default::default()
        };
        let mut mesher = Mesher::new(options).unwrap();
        let mut out = mesh_of(&chain(&[Vec3::ZERO, Vec3::X], 0.2));
        let before = out.clone();
        match mesher.mesh_into(&p, &mut out) {
            Err(MeshError::TooManyTriangles { limit: 10, needed }) => {
                assert_eq!(needed as usize, 2 * 2 * R + 2 * R)
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(out, before);
        // Exactly at the limit is fine.
        let options = MeshOptions {
            max_triangles: 6 * R,
            ..Default::default()
        };
        assert!(mesh_plant(&p, &options).is_ok());
    }

    /// Asserts that every triangle of `indices` has a twin with reversed winding at the same
    /// positions and opposite normals.
    fn assert_double_sided(m: &Mesh, indices: &[u32]) {
        let key = |i: u32| m.positions[i as usize].map(f32::to_bits);
        let mut faces: HashMap<[[u32; 3]; 3], [f32; 3]> = HashMap::new();
        for t in indices.chunks_exact(3) {
            faces.insert([key(t[0]), key(t[1]), key(t[2])], m.normals[t[0] as usize]);
        }
        for t in indices.chunks_exact(3) {
            let n = Vec3::from_array(m.normals[t[0] as usize]);
            // The twin may start at any corner of the reversed cycle.
            let (a, b, c) = (key(t[0]), key(t[2]), key(t[1]));
            let twin = [[a, b, c], [b, c, a], [c, a, b]]
                .iter()
                .find_map(|k| faces.get(k));
            let twin = twin.unwrap_or_else(|| panic!("no twin for {t:?}"));
            assert!((Vec3::from_array(*twin) + n).length() < 1e-6);
        }
    }

    #[test]
    fn leaf_surfaces_are_one_sided_cards_showing_their_cells() {
        use sylva_core::species::{Card, LeafKind, Surface};
        let mut p = plant();
        let mut add = |surface: Surface| {
            let m = p
                .add_material(sylva_core::Material {
                    surface: Some(surface),
                    ..sylva_core::Material::of_kind(sylva_core::MaterialKind::Leaf)
                })
                .unwrap();
            for _ in 0..3 {
                p.add_organ(organ(
                    OrganKind::Leaf,
                    Quat::IDENTITY,
                    Vec2::new(0.3, 0.2),
                    m,
                ))
                .unwrap();
            }
        };
        add(Surface::Leaves(LeafKind::Oak));
        add(Surface::Branchlets(LeafKind::Pine));
        let bare = mesh_of(&plant());
        let m = mesh_of(&p);
        check_invariants(&m);
        // Three flat cards (4 vertices, 2 triangles) and three crossed ones (twice that).
        assert_eq!(m.vertex_count() - bare.vertex_count(), 3 * 4 + 3 * 8);
        assert_eq!(m.triangle_count() - bare.triangle_count(), 3 * 2 + 3 * 4);
        let cards = &m.uvs[bare.vertex_count()..];
        // An oak card: 0.2 wide, 0.3 tall, facing +Z, its corners the cell's (base at the
        // cell's bottom), and neighbouring cards showing other cells.
        let first = &m.positions[bare.vertex_count()..bare.vertex_count() + 4];
        assert_eq!(first[0], [0.4, 1.0, -0.25]);
        assert_eq!(first[2], [0.6, 1.3, -0.25]);
        assert_eq!(m.normals[bare.vertex_count()], [0.0, 0.0, 1.0]);
        assert_eq!(
            cards[..4],
            crate::atlas::card_uvs(Card::Spray, card_variant(0))
        );
        assert_ne!(card_variant(0) % 8, card_variant(1) % 8);
        // The pine cards' second quad stands square to the first.
        let second = bare.vertex_count() + 12 + 4;
        assert_eq!(m.normals[second], [-1.0, 0.0, 0.0]);
        assert_eq!(
            cards[12..16],
            crate::atlas::card_uvs(Card::Branchlet, card_variant(3))
        );
    }

    #[test]
    fn bark_surfaces_repeat_round_the_stem_at_their_own_scale() {
        use sylva_core::species::{BarkKind, Surface};
        let mut p = Plant::new(PlantMeta::default());
        // Radius 0.5 m: a 3.1 m circumference holds seven furrowed tiles (0.45 m each).
        p.add_segment(
            Vec3::ZERO,
            Vec3::Y * 3.0,
            (0.5, 0.5),
            None,
            false,
            Plant::BARK,
        )
        .unwrap();
        let plain = mesh_of(&p);
        let m = p.materials()[Plant::BARK.index()].clone();
        p.replace_material(
            Plant::BARK,
            sylva_core::Material {
                surface: Some(Surface::Bark(BarkKind::Furrowed)),
                ..m
            },
        )
        .unwrap();
        let dressed = mesh_of(&p);
        assert_eq!(plain.positions, dressed.positions);
        // The start cap (a centre and 12 rim vertices) comes first, then the first ring,
        // whose last vertex is the seam.
        let seam = 13 + 12;
        assert_eq!(plain.uvs[seam][0], 1.0);
        assert_eq!(dressed.uvs[seam][0], 7.0);
        // Along the stem v runs seven times as fast: texels stay square.
        let top = seam + 13;
        assert!((dressed.uvs[top][1] - 7.0 * plain.uvs[top][1]).abs() < 1e-4);
    }

    #[test]
    fn leaves_are_double_sided_blades() {
        let mut p = plant();
        let q = Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.3);
        p.add_organ(organ(OrganKind::Leaf, q, Vec2::new(0.4, 0.1), Plant::LEAF))
            .unwrap();
        let m = mesh_of(&p);
        assert_eq!(m.primitives.len(), 1);
        assert_eq!(m.primitives[0].material, Plant::LEAF.index());
        assert_eq!(m.triangle_count(), 16);
        assert_double_sided(&m, &m.primitives[0].indices);
        assert_eq!(winding_agreement(&m), 1.0);
        // Base, tip, length and width as documented.
        let o = p.organs()[0];
        let local = |v: [f32; 3]| q.inverse() * (Vec3::from_array(v) - o.position);
        let tip = local(m.positions[9]);
        assert!((tip - Vec3::new(0.0, 0.4, 0.0)).length() < 1e-6, "{tip}");
        let widest = m.positions.iter().map(|v| local(*v).x).fold(0.0, f32::max);
        assert!((widest - 0.05).abs() < 0.005, "{widest}");
        assert!(
            m.normals[0]
                .iter()
                .zip((q * Vec3::Z).to_array())
                .all(|(a, b)| (a - b).abs() < 1e-6)
        );
    }

    #[test]
    fn leaf_sides_share_uvs_spanning_the_blade() {
        let mut p = plant();
        let q = Quat::from_rotation_z(0.3) * Quat::from_rotation_y(1.0);
        p.add_organ(organ(OrganKind::Leaf, q, Vec2::new(0.4, 0.1), Plant::LEAF))
            .unwrap();
        let m = mesh_of(&p);
        let side = m.vertex_count() / 2;
        assert_eq!(m.uvs[..side], m.uvs[side..], "both sides map alike");
        assert_eq!(m.uvs[0], [0.5, 0.0], "base");
        assert_eq!(m.uvs[side - 1], [0.5, 1.0], "tip");
        let u = m.uvs.iter().map(|uv| uv[0]);
        let (lo, hi) = u.fold((1.0f32, 0.0f32), |(lo, hi), u| (lo.min(u), hi.max(u)));
        assert!(lo < 0.02 && hi > 0.98, "{lo}..{hi}");
        // u − ½ is the offset across over the width, v the height over the length.
        let o = p.organs()[0];
        for (pos, uv) in m.positions.iter().zip(&m.uvs) {
            let local = q.inverse() * (Vec3::from_array(*pos) - o.position);
            assert!(
                (local.x / 0.1 - (uv[0] - 0.5)).abs() < 1e-5,
                "{local} {uv:?}"
            );
            assert!((local.y / 0.4 - uv[1]).abs() < 1e-5, "{local} {uv:?}");
        }
    }

    #[test]
    fn tube_uvs_wrap_at_a_seam_and_run_along_the_axis() {
        // A straight tube of radius 0.1 up Y in two segments of 1 m.
        let m = mesh_of(&chain(&[Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0], 0.1));
        for ring in 0..3 {
            let first = R + 1 + ring * RV;
            let uvs = &m.uvs[first..first + RV];
            for (k, uv) in uvs.iter().enumerate() {
                assert_eq!(uv[0], k as f32 / R as f32);
            }
            // The seam vertex sits on the first, with the same normal.
            assert_eq!(m.positions[first], m.positions[first + R]);
            assert_eq!(m.normals[first], m.normals[first + R]);
            let expected = ring as f32 / (TAU * 0.1);
            assert!(uvs.iter().all(|uv| (uv[1] - expected).abs() < 1e-5));
        }
        // Caps are planar discs around (½, ½).
        assert_eq!(m.uvs[0], [0.5, 0.5]);
        for uv in &m.uvs[1..=R] {
            let r = Vec2::new(uv[0] - 0.5, uv[1] - 0.5).length();
            assert!((r - 0.5).abs() < 1e-5, "{uv:?}");
        }
    }

    #[test]
    fn tapering_tubes_keep_texels_square() {
        let mut p = plant();
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.2, 0.1), None, false, Plant::BARK)
            .unwrap();
        p.add_segment(
            Vec3::Y,
            Vec3::Y * 2.0,
            (0.1, 0.05),
            Some(a),
            false,
            Plant::BARK,
        )
        .unwrap();
        let m = mesh_of(&p);
        let v = |ring: usize| m.uvs[R + 1 + ring * RV][1];
        // Each span advances v by its length over its mean circumference.
        assert!((v(1) - 1.0 / (TAU * 0.15)).abs() < 1e-5);
        assert!((v(2) - v(1) - 1.0 / (TAU * 0.075)).abs() < 1e-4);
    }

    #[test]
    fn petal_and_root_tip_uvs() {
        let mut p = plant();
        p.add_organ(organ(
            OrganKind::Flower,
            Quat::IDENTITY,
            Vec2::new(0.2, 0.05),
            Plant::FLOWER,
        ))
        .unwrap();
        p.add_organ(organ(
            OrganKind::RootTip,
            Quat::IDENTITY,
            Vec2::new(0.05, 0.01),
            Plant::FLOWER,
        ))
        .unwrap();
        let m = mesh_of(&p);
        let petals = &m.uvs[..8 * 5];
        for corners in petals.chunks_exact(4) {
            assert_eq!(corners, [[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]]);
        }
        assert_eq!(m.uvs[8 * 5], [0.5, 0.0], "root tip base");
        assert_eq!(m.uvs[8 * 5 + 1], [0.5, 1.0], "root tip point");
    }

    #[test]
    fn flowers_are_double_sided_stars_facing_up_their_axis() {
        let mut p = plant();
        let q = Quat::from_rotation_z(0.4);
        p.add_organ(organ(
            OrganKind::Flower,
            q,
            Vec2::new(0.2, 0.05),
            Plant::FLOWER,
        ))
        .unwrap();
        let m = mesh_of(&p);
        assert_eq!(m.triangle_count(), 4 * 5);
        assert_eq!(m.primitives[0].material, Plant::FLOWER.index());
        assert_double_sided(&m, &m.primitives[0].indices);
        assert_eq!(winding_agreement(&m), 1.0);
        let axis = q * Vec3::Y;
        let up = m
            .normals
            .iter()
            .filter(|n| Vec3::from_array(**n).dot(axis) > 0.5)
            .count();
        assert_eq!(
            up,
            m.vertex_count() / 2,
            "front faces look along the flower's axis"
        );
        let reach = m
            .positions
            .iter()
            .map(|v| (Vec3::from_array(*v) - p.organs()[0].position).length())
            .fold(0.0, f32::max);
        assert!(
            (reach - 0.1).abs() < 1e-6,
            "petals reach half the diameter: {reach}"
        );
    }

    #[test]
    fn root_tips_are_closed() {
        let mut p = plant();
        let root = p
            .add_material(sylva_core::Material::of_kind(
                sylva_core::MaterialKind::Root,
            ))
            .unwrap();
        p.add_organ(organ(
            OrganKind::RootTip,
            Quat::from_rotation_x(2.0),
            Vec2::new(0.05, 0.01),
            root,
        ))
        .unwrap();
        let m = mesh_of(&p);
        assert_eq!(m.triangle_count(), 8);
        assert_eq!(m.primitives[0].material, root.index());
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in m.primitives[0].indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edges.entry((a, b)).or_default() += 1;
                assert!(
                    !edges.contains_key(&(a, b)) || edges[&(a, b)] == 1,
                    "edge used twice one way"
                );
            }
        }
        for &(a, b) in edges.keys() {
            assert!(
                edges.contains_key(&(b, a)),
                "every edge has its opposite: closed and oriented"
            );
        }
        assert_eq!(winding_agreement(&m), 1.0);
    }

    #[test]
    fn zero_sized_organs_stay_finite() {
        let mut p = plant();
        for kind in [OrganKind::Leaf, OrganKind::Flower, OrganKind::RootTip] {
            p.add_organ(organ(kind, Quat::IDENTITY, Vec2::ZERO, Plant::LEAF))
                .unwrap();
        }
        mesh_of(&p);
    }

    #[test]
    fn one_primitive_per_used_material_and_deterministic() {
        let mut p = plant();
        let root = p
            .add_material(sylva_core::Material::of_kind(
                sylva_core::MaterialKind::Root,
            ))
            .unwrap();
        let trunk = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        let top = Vec3::new(0.3, 2.0, 0.1);
        p.add_segment(Vec3::Y, top, (0.1, 0.1), Some(trunk), false, root)
            .unwrap();
        p.add_organ(organ(
            OrganKind::Leaf,
            Quat::IDENTITY,
            Vec2::new(0.2, 0.1),
            Plant::LEAF,
        ))
        .unwrap();
        let m = mesh_of(&p);
        let used: Vec<usize> = m.primitives.iter().map(|p| p.material).collect();
        assert_eq!(used, [0, 1, 3]);
        assert_eq!(m.materials, p.materials());
        assert_eq!(mesh_of(&p), m);
        // Reusing an output that held a bigger mesh gives the same result.
        let mut mesher = Mesher::new(MeshOptions::default()).unwrap();
        let mut out = mesh_of(&chain(
            &[Vec3::ZERO, Vec3::Y, Vec3::X, Vec3::Z, Vec3::ONE],
            0.3,
        ));
        let capacity = out.positions.capacity();
        mesher.mesh_into(&p, &mut out).unwrap();
        assert_eq!(out, m);
        assert!(out.positions.capacity() >= capacity, "capacity is kept");
        // Meshing the same plant again reuses every buffer without reallocating.
        let buffers = |m: &Mesh| {
            let mut b: Vec<*const u32> = m.primitives.iter().map(|p| p.indices.as_ptr()).collect();
            b.push(m.positions.as_ptr().cast());
            b.push(m.normals.as_ptr().cast());
            b.push(m.uvs.as_ptr().cast());
            b
        };
        let before = buffers(&out);
        mesher.mesh_into(&p, &mut out).unwrap();
        assert_eq!(buffers(&out), before);
    }

    fn arb_point() -> impl Strategy<Value = Vec3> {
        prop_oneof![
            3 => (-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
            1 => Just(Vec3::ZERO),
            1 => Just(Vec3::Y),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// Random skeletons (zero lengths, reversals, zero radii, laterals) mesh to valid meshes
        /// of exactly the counted size.
        #[test]
        fn random_plants_give_valid_meshes(
            segs in prop::collection::vec(
                (arb_point(), any::<prop::sample::Index>(), prop::bool::ANY, 0.0f32..0.3, 0.0f32..0.3, prop::bool::ANY),
                0..40,
            ),
            radial in 3u32..20,
            caps in prop::bool::ANY,
        ) {
            let mut p = plant();
            for (i, (end, parent, lateral, r0, r1, has_parent)) in segs.into_iter().enumerate() {
                let parent = (has_parent && i > 0).then(|| SegmentId(parent.index(i) as u32));
                let start = parent.map_or(Vec3::ZERO, |q| p.segment(q).end);
                p.add_segment(start, end, (r0, r1), parent, lateral, Plant::BARK).unwrap();
            }
            let options = MeshOptions { radial_segments: radial, cap_ends: caps, ..Default::default() };
            let mut mesher = Mesher::new(options).unwrap();
            let mut m = Mesh::default();
            let stats = mesher.mesh_into(&p, &mut m).unwrap();
            check_invariants(&m);
            prop_assert_eq!(stats.vertices, m.vertex_count());
            prop_assert_eq!(stats.triangles, m.triangle_count());
            prop_assert!(m.triangle_count() >= 2 * radial as usize * p.segments().len());
        }
    }
}
