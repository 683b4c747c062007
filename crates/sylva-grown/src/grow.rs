//! Self-organising growth: buds compete for the crown's free space and light, and the tree's
//! form is what comes of it.
//!
//! The tree starts as a bole rising to the crown's base. Each cycle (a year):
//!
//! 1. **Space.** Every attraction point left in the envelope is perceived by the nearest
//!    bud that has it within its reach and its perception cone (Runions, Lane and
//!    Prusinkiewicz 2007). A bud with points has space; their mean direction is where it
//!    would grow.
//! 2. **Light.** Each internode casts shade on a pyramid of voxels below it, fading by half
//!    a layer (Palubicki et al. 2009's shadow propagation). A bud's light is `1 / (1 + s)`
//!    under shade `s`: 1 in the open; the gradient of shade is where phototropism turns shoots.
//! 3. **Allocation.** A bud's resource Q is its light if it has space, else 0. Q is summed
//!    from the buds to the base; the base draws `vigour · Q` and hands it back up, at each
//!    branching splitting it between the continuing axis and the side branch by apical
//!    control λ: `v_main = v · λQ_m / (λQ_m + (1 − λ)Q_s)` (the extended Borchert–Honda
//!    model). A bud makes ⌊v⌋ internodes, at most `max_shoot`.
//! 4. **Shoots.** A shoot heads between its old heading (`straightness`), its free space,
//!    gravity (`gravitropism`) and the light (`phototropism`). Each new internode carries
//!    a side bud at `branch_angle`, turned about the shoot by `phyllotaxis` from the last,
//!    and takes the attraction points within `kill` of it.
//! 5. **Shedding.** A side branch at least two cycles old whose shoot tips get less light
//!    on average than `shedding` is shed, as shaded lower limbs are.
//!
//! Growth ends when the points are used up, no bud grows, or after `cycles`. Then the pipe
//! model gives every stem its radius (a twig's tip is `tip_radius`; a stem's radius to the
//! `pipe_exponent` is the sum of its branches'), and leaves of the foliage kind, at their
//! real size, clothe the last `leaf_span` internodes of every shoot.
//!
//! Everything is drawn from the seed's stream and done in a fixed order, so the same genome
//! and seed grow the same tree. Growth is bounded: at most [`MAX_NODES`] internodes (more is
//! an error naming the limit) and [`MAX_CYCLES`] cycles; [`Report`] says which of the ends
//! stopped it.

use std::ops::Range;

use glam::{Mat3, Quat, Vec2, Vec3};
use sylva_core::dress::BRANCHLET_HEIGHT;
use sylva_core::species::Card;
use sylva_core::{Organ, OrganKind, Plant, SegmentId};
use sylva_model::DevelopError;

use crate::crown::Envelope;
use crate::genome::{Growth, Param};

/// Most internodes a tree may have; a genome that asks for more is refused.
pub const MAX_NODES: usize = 120_000;

/// Most growth cycles ([`Param::Cycles`]'s greatest value).
pub const MAX_CYCLES: u32 = 60;

/// Layers of voxels an internode shades below itself.
const SHADE_DEPTH: i32 = 5;

/// The shade an internode casts on each voxel of the layer below it (half that on the next
/// layer, and so on), at the default kill distance; it scales with the square of the kill
/// distance, as internodes crowd closer when it is short.
const SHADE: f32 = 0.1;

/// Cycles a side bud may stay dormant before it is spent (and no longer perceives space):
/// old buds deep in a crown would otherwise fill every gap the crown's shade leaves.
const DORMANT_CYCLES: u32 = 4;

/// The most leaf area a crown holds over its spread (leaf area index): real broadleaf and
/// conifer crowns hold 3 to 8 (docs/realism.md).
const MAX_LAI: f32 = 9.0;

/// A blade's area over its length times its width.
const LEAF_FILL: f32 = 0.7;

/// The share of a leaf card its leaves cover, about (the atlases' own measure, in
/// `sylva-mesh`, is 0.3 to 0.6).
const CARD_FILL: f32 = 0.5;

/// Most leaves one internode bears.
const MAX_LEAVES_PER_INTERNODE: u32 = 6;

/// Why growth ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// Every attraction point was taken.
    SpaceUsed,
    /// No bud had the resource to grow.
    NoGrowth,
    /// The genome's cycles were grown.
    Cycles,
}

/// What a growth did: its size and why it stopped.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Report {
    /// Cycles grown.
    pub cycles: u32,
    /// Internodes in the tree (shed ones not counted).
    pub internodes: usize,
    /// Internodes shed with their branches.
    pub shed: usize,
    /// Attraction points placed.
    pub points: usize,
    /// Attraction points still free at the end.
    pub points_left: usize,
    /// Leaves placed.
    pub leaves: usize,
    /// Why growth ended.
    pub stop: Stop,
}

/// What a node's main or side place holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    /// Nothing (a shed branch's place).
    Empty,
    /// A bud, heading this way.
    Bud(Vec3),
    /// The node an internode grew to.
    Node(u32),
}

/// The end of an internode (or the tree's foot, node 0).
#[derive(Clone, Copy, Debug)]
struct Node {
    pos: Vec3,
    /// The internode's heading (up for the foot).
    dir: Vec3,
    /// A unit vector across `dir`, turned by the phyllotaxis at each node along an axis:
    /// where the side bud points.
    across: Vec3,
    parent: u32,
    main: Slot,
    side: Slot,
    /// The cycle it grew in.
    born: u32,
    /// Whether it starts a branch (its parent's side).
    lateral: bool,
    dead: bool,
}

/// Cells of a uniform grid over a box, each listing items (counting sort, rebuilt as
/// items change).
struct Grid {
    lo: Vec3,
    cell: f32,
    dims: [i32; 3],
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Where the next item of each cell goes while filling (kept, so a refill allocates
    /// nothing).
    next: Vec<u32>,
}

impl Grid {
    /// A grid over `lo..hi` with cells of about `cell` metres, at most about 128 a side.
    fn new(lo: Vec3, hi: Vec3, cell: f32) -> Grid {
        let extent = (hi - lo).max_element().max(1e-3);
        let cell = cell.max(extent / 128.0);
        let dims = ((hi - lo) / cell).ceil().as_ivec3().max(glam::IVec3::ONE) + 1;
        Grid {
            lo,
            cell,
            dims: dims.to_array(),
            starts: Vec::new(),
            items: Vec::new(),
            next: Vec::new(),
        }
    }

    fn coords(&self, p: Vec3) -> [i32; 3] {
        // Cut towards zero after the clamp at zero, as `floor` would (without its call).
        let c = ((p - self.lo) / self.cell).max(Vec3::ZERO).as_ivec3();
        [
            c.x.clamp(0, self.dims[0] - 1),
            c.y.clamp(0, self.dims[1] - 1),
            c.z.clamp(0, self.dims[2] - 1),
        ]
    }

    fn index(&self, [x, y, z]: [i32; 3]) -> usize {
        ((y * self.dims[2] + z) * self.dims[0] + x) as usize
    }

    /// Files every point under its cell.
    fn fill(&mut self, points: impl Iterator<Item = Vec3> + Clone) {
        let cells = (self.dims[0] * self.dims[1] * self.dims[2]) as usize;
        self.starts.clear();
        self.starts.resize(cells + 1, 0);
        for p in points.clone() {
            let i = self.index(self.coords(p));
            self.starts[i + 1] += 1;
        }
        for i in 0..cells {
            self.starts[i + 1] += self.starts[i];
        }
        self.items.clear();
        self.items.resize(self.starts[cells] as usize, 0);
        self.next.clone_from(&self.starts);
        for (k, p) in points.enumerate() {
            let i = self.index(self.coords(p));
            self.items[self.next[i] as usize] = k as u32;
            self.next[i] += 1;
        }
    }

    /// Calls `f` with every item filed in a cell that meets the ball of `radius` about `p`.
    fn near(&self, p: Vec3, radius: f32, mut f: impl FnMut(u32)) {
        self.near_slots(p, radius, |slots| {
            self.items[slots].iter().for_each(|&i| f(i))
        });
    }

    /// Calls `f` with the places in [`Grid::items`] of the items filed in the cells that
    /// meet the ball of `radius` about `p`, a run of cells at a time: an array in the
    /// order of `items` is read straight along.
    fn near_slots(&self, p: Vec3, radius: f32, mut f: impl FnMut(Range<usize>)) {
        let a = self.coords(p - Vec3::splat(radius));
        let b = self.coords(p + Vec3::splat(radius));
        for y in a[1]..=b[1] {
            for z in a[2]..=b[2] {
                let row = self.index([a[0], y, z]);
                let (s, e) = (
                    self.starts[row] as usize,
                    self.starts[row + (b[0] - a[0]) as usize + 1] as usize,
                );
                if s < e {
                    f(s..e);
                }
            }
        }
    }
}

/// Shade in voxels, cast by internodes on the voxels below them.
struct Shade {
    /// What an internode casts on each voxel of the layer below it.
    strength: f32,
    lo: Vec3,
    voxel: f32,
    dims: [i32; 3],
    values: Vec<f32>,
}

impl Shade {
    fn new(lo: Vec3, hi: Vec3, voxel: f32, strength: f32) -> Shade {
        let extent = (hi - lo).max_element().max(1e-3);
        let voxel = voxel.max(extent / 96.0);
        let dims = ((hi - lo) / voxel).ceil().as_ivec3().max(glam::IVec3::ONE) + 1;
        let dims = dims.to_array();
        Shade {
            strength,
            lo,
            voxel,
            dims,
            values: vec![0.0; (dims[0] * dims[1] * dims[2]) as usize],
        }
    }

    fn coords(&self, p: Vec3) -> [i32; 3] {
        let v = (p - self.lo) / self.voxel;
        // Cutting towards zero is `floor` for the voxels inside, without its call.
        if v.cmpge(Vec3::ZERO).all() {
            v.as_ivec3().to_array()
        } else {
            v.floor().as_ivec3().to_array()
        }
    }

    fn get(&self, [x, y, z]: [i32; 3]) -> f32 {
        let [dx, dy, dz] = self.dims;
        if (0..dx).contains(&x) && (0..dy).contains(&y) && (0..dz).contains(&z) {
            self.values[((y * dz + z) * dx + x) as usize]
        } else {
            0.0
        }
    }

    /// Adds (`sign` 1) or takes away (-1) the shade of an internode ending at `p`.
    fn cast(&mut self, p: Vec3, sign: f32) {
        let [cx, cy, cz] = self.coords(p);
        let [dx, dy, dz] = self.dims;
        let mut amount = sign * self.strength;
        for q in 1..=SHADE_DEPTH {
            let y = cy - q;
            if !(0..dy).contains(&y) {
                break;
            }
            for z in (cz - q).max(0)..=(cz + q).min(dz - 1) {
                for x in (cx - q).max(0)..=(cx + q).min(dx - 1) {
                    self.values[((y * dz + z) * dx + x) as usize] += amount;
                }
            }
            amount *= 0.5;
        }
    }

    /// Light at `p`, 1 in the open, less under shade.
    fn light(&self, p: Vec3) -> f32 {
        1.0 / (1.0 + self.get(self.coords(p)).max(0.0))
    }

    /// The way shade lessens fastest at `p` (zero where it is even).
    fn brighter(&self, p: Vec3) -> Vec3 {
        let [x, y, z] = self.coords(p);
        let g = Vec3::new(
            self.get([x - 1, y, z]) - self.get([x + 1, y, z]),
            self.get([x, y - 1, z]) - self.get([x, y + 1, z]),
            self.get([x, y, z - 1]) - self.get([x, y, z + 1]),
        );
        g.normalize_or_zero()
    }
}

/// `v` turned by `angle` radians about the unit `axis`.
fn turn(v: Vec3, axis: Vec3, angle: f32) -> Vec3 {
    Quat::from_axis_angle(axis, angle) * v
}

/// A unit vector across unit `dir`, as near `hint` as can be.
fn across(dir: Vec3, hint: Vec3) -> Vec3 {
    let a = hint - dir * hint.dot(dir);
    if a.length_squared() > 1e-8 {
        a.normalize()
    } else {
        dir.any_orthonormal_vector()
    }
}

/// Internodes along an axis joined into one segment: from `start` (its first internode's
/// base) to node `end`.
struct Run {
    start: Vec3,
    first: u32,
    end: u32,
    count: u32,
    parent: Option<u32>,
    lateral: bool,
}

/// Most internodes of a twig left out of the wood (more when the wood is over its budget).
const TWIG: u32 = 5;

/// Most segments of a broadleaf's wood: about 13,000 triangles, beside 24,000 of its
/// leaf cards (a game's budget of 40,000 for a tree in leaf).
const BROADLEAF_SEGMENTS: usize = 800;

/// Most segments of a conifer's wood: about 11,000 triangles, beside 16,000 of its
/// crossed needle cards (a budget of 30,000).
const CONIFER_SEGMENTS: usize = 700;

/// Most internodes joined into one segment.
const RUN_MOST: u32 = 8;

/// A run goes on while each internode turns less than this (radians) from its chord.
const RUN_BEND: f32 = 0.3;

/// Everything one growth works with.
struct Tree<'g> {
    genome: &'g Growth,
    step: f32,
    nodes: Vec<Node>,
    shade: Shade,
    points: Vec<Vec3>,
    taken: Vec<bool>,
    point_grid: Grid,
    shed: usize,
}

/// A bud this cycle: its node and place, what it perceives, and its share.
#[derive(Clone, Copy)]
/// A bud as perception reads it, filed in a grid's order.
struct Filed {
    pos: Vec3,
    heading: Vec3,
    bud: u32,
}

struct Bud {
    node: u32,
    side: bool,
    pos: Vec3,
    heading: Vec3,
    seen: u32,
    toward: Vec3,
    q: f32,
    vigour: f32,
}

/// Grows the genome's tree with `seed` (which places its attraction points).
pub fn grow(genome: &Growth, seed: u64) -> Result<(Plant, Report), DevelopError> {
    let envelope = Envelope::of(genome);
    grow_into(genome, &envelope, seed)
}

/// Grows the genome's tree into `envelope` rather than the genome's own crown (a picture's
/// visual hull, say).
pub fn grow_into(
    genome: &Growth,
    envelope: &Envelope,
    seed: u64,
) -> Result<(Plant, Report), DevelopError> {
    let p = &genome.parameters;
    let height = p.f(Param::Height);
    let step = p.f(Param::Internode) * height;
    let mut rng = sylva_core::rng::seeded(seed);
    let points = envelope
        .attraction_points(p.count(Param::Points) as usize, &mut rng)
        .map_err(|e| DevelopError::Model(Box::new(e)))?;
    let (lo, hi) = envelope.bounds();
    let margin = Vec3::splat(4.0 * step);
    let (lo, hi) = (lo.min(Vec3::ZERO) - margin, hi.max(Vec3::ZERO) + margin);
    let reach = p.f(Param::Reach) * step;
    let mut point_grid = Grid::new(lo, hi, p.f(Param::Kill).max(1.0) * step);
    point_grid.fill(points.iter().copied());
    let mut tree = Tree {
        genome,
        step,
        nodes: Vec::new(),
        shade: Shade::new(lo, hi, 2.0 * step, SHADE * (0.5 * p.f(Param::Kill)).powi(2)),
        taken: vec![false; points.len()],
        points,
        point_grid,
        shed: 0,
    };
    tree.bole(envelope.base, envelope.top);
    let cycles = p.count(Param::Cycles).min(MAX_CYCLES);
    let mut bud_grid = Grid::new(lo, hi, 0.5 * reach);
    let mut filed = Vec::new();
    let mut buds = Vec::new();
    let mut stop = Stop::Cycles;
    let mut grown = 0;
    for cycle in 1..=cycles {
        if tree.taken.iter().all(|&t| t) {
            stop = Stop::SpaceUsed;
            break;
        }
        tree.buds(&mut buds, cycle);
        tree.perceive(&mut buds, &mut bud_grid, &mut filed, reach);
        tree.allocate(&mut buds);
        if !tree.shoot(&buds, cycle)? {
            stop = Stop::NoGrowth;
            break;
        }
        tree.shed_shaded(cycle);
        grown = cycle;
    }
    let points_left = tree.taken.iter().filter(|&&t| !t).count();
    let (plant, leaves) = tree.plant(seed)?;
    let report = Report {
        cycles: grown,
        internodes: tree.nodes.iter().skip(1).filter(|n| !n.dead).count(),
        shed: tree.shed,
        points: tree.points.len(),
        points_left,
        leaves,
        stop,
    };
    Ok((plant, report))
}

impl Tree<'_> {
    fn param(&self, p: Param) -> f32 {
        self.genome.parameters.f(p)
    }

    /// The foot and the bole up to the crown's base (and on up until the crown is within
    /// reach, below `top`), a side bud at each node.
    fn bole(&mut self, base: f32, top: f32) {
        let foot = Node {
            pos: Vec3::ZERO,
            dir: Vec3::Y,
            across: Vec3::X,
            parent: u32::MAX,
            main: Slot::Bud(Vec3::Y),
            side: Slot::Empty,
            born: 0,
            lateral: false,
            dead: false,
        };
        self.nodes.push(foot);
        self.shade.cast(foot.pos, 1.0);
        let internodes = (base / self.step).floor().max(1.0) as usize;
        for _ in 0..internodes {
            self.add(self.nodes.len() as u32 - 1, false, Vec3::Y, 0);
        }
        // On up until the crown is within the top bud's reach, as a sapling's leader rises
        // through the space below the crown.
        let reach = self.param(Param::Reach) * self.step;
        while (self.nodes.len() as f32) * self.step < top {
            let at = self.nodes[self.nodes.len() - 1].pos;
            let mut near = false;
            self.point_grid.near(at, reach, |i| {
                near |= !self.taken[i as usize]
                    && self.points[i as usize].distance_squared(at) < reach * reach;
            });
            if near {
                break;
            }
            self.add(self.nodes.len() as u32 - 1, false, Vec3::Y, 0);
        }
    }

    /// Adds an internode from `parent` heading `dir`, in its main or side place.
    fn add(&mut self, parent: u32, side: bool, dir: Vec3, born: u32) -> u32 {
        let id = self.nodes.len() as u32;
        let from = self.nodes[parent as usize];
        let pos = from.pos + dir * self.step;
        let divergence = self.param(Param::Phyllotaxis).to_radians();
        let across = turn(across(dir, from.across), dir, divergence);
        let angle = self.param(Param::BranchAngle).to_radians();
        let side_bud = turn(dir, dir.cross(across).normalize_or(Vec3::X), angle);
        self.nodes.push(Node {
            pos,
            dir,
            across,
            parent,
            main: Slot::Bud(dir),
            side: Slot::Bud(side_bud),
            born,
            lateral: side,
            dead: false,
        });
        let place = &mut self.nodes[parent as usize];
        if side {
            place.side = Slot::Node(id);
        } else {
            place.main = Slot::Node(id);
        }
        self.shade.cast(pos, 1.0);
        // The points this internode reaches are taken.
        let kill = self.param(Param::Kill) * self.step;
        let (points, taken) = (&self.points, &mut self.taken);
        self.point_grid.near(pos, kill, |i| {
            if points[i as usize].distance_squared(pos) <= kill * kill {
                taken[i as usize] = true;
            }
        });
        id
    }

    /// Every bud of the living tree that can still grow in `cycle`, in node order (main
    /// before side): a side bud left dormant for [`DORMANT_CYCLES`] is spent.
    fn buds(&self, buds: &mut Vec<Bud>, cycle: u32) {
        buds.clear();
        for (i, n) in self.nodes.iter().enumerate() {
            if n.dead {
                continue;
            }
            let spent = n.born + DORMANT_CYCLES < cycle;
            for (slot, side) in [(n.main, false), (n.side, true)] {
                if side && spent {
                    continue;
                }
                if let Slot::Bud(heading) = slot {
                    buds.push(Bud {
                        node: i as u32,
                        side,
                        pos: n.pos,
                        heading,
                        seen: 0,
                        toward: Vec3::ZERO,
                        q: 0.0,
                        vigour: 0.0,
                    });
                }
            }
        }
    }

    /// Step 1 and 2: each free point goes to the nearest bud that perceives it; a bud with
    /// points gets its light as its resource.
    fn perceive(&self, buds: &mut [Bud], grid: &mut Grid, filed: &mut Vec<Filed>, reach: f32) {
        grid.fill(buds.iter().map(|b| b.pos));
        // What the test needs of each bud, in the grid's order: read straight along.
        filed.clear();
        filed.extend(grid.items.iter().map(|&b| {
            let bud = &buds[b as usize];
            Filed {
                pos: bud.pos,
                heading: bud.heading,
                bud: b,
            }
        }));
        let cone = self.param(Param::PerceptionAngle).to_radians().cos();
        let reach2 = reach * reach;
        for (i, &point) in self.points.iter().enumerate() {
            if self.taken[i] {
                continue;
            }
            let mut best = (f32::MAX, u32::MAX);
            grid.near_slots(point, reach, |slots| {
                for f in &filed[slots] {
                    let to = point - f.pos;
                    let d2 = to.length_squared();
                    // Within reach, in the cone (`to·h ≥ |to| cos θ`), nearest; ties to the
                    // first bud, so the order of buds decides, not the grid's.
                    let nearer = d2 < best.0 || (d2 == best.0 && f.bud < best.1);
                    if d2 < reach2 && nearer && to.dot(f.heading) >= cone * d2.sqrt() {
                        best = (d2, f.bud);
                    }
                }
            });
            if best.1 != u32::MAX {
                let bud = &mut buds[best.1 as usize];
                bud.seen += 1;
                bud.toward += (point - bud.pos).normalize_or_zero();
            }
        }
        for bud in buds.iter_mut() {
            if bud.seen > 0 {
                bud.q = 1.0;
                bud.toward = bud.toward.normalize_or_zero();
            }
        }
    }

    /// Step 3: resource summed to the base, handed back up by apical control.
    fn allocate(&self, buds: &mut [Bud]) {
        let n = self.nodes.len();
        // Q of each node's main and side places: a bud's own, or the node grown there.
        let mut q = vec![[0.0f32; 2]; n];
        for bud in buds.iter() {
            q[bud.node as usize][usize::from(bud.side)] = bud.q;
        }
        for i in (1..n).rev() {
            let node = &self.nodes[i];
            if node.dead {
                continue;
            }
            let total = q[i][0] + q[i][1];
            q[node.parent as usize][usize::from(node.lateral)] = total;
        }
        let lambda = self.param(Param::ApicalControl);
        let mut v = vec![[0.0f32; 2]; n];
        let base = self.param(Param::Vigour) * (q[0][0] + q[0][1]);
        let split = |v: f32, [qm, qs]: [f32; 2]| {
            let (m, s) = (lambda * qm, (1.0 - lambda) * qs);
            if m + s > 0.0 {
                [v * m / (m + s), v * s / (m + s)]
            } else {
                [0.0, 0.0]
            }
        };
        v[0] = split(base, q[0]);
        for i in 1..n {
            let node = &self.nodes[i];
            if node.dead {
                continue;
            }
            let incoming = v[node.parent as usize][usize::from(node.lateral)];
            v[i] = split(incoming, q[i]);
        }
        for bud in buds.iter_mut() {
            bud.vigour = v[bud.node as usize][usize::from(bud.side)];
        }
    }

    /// Step 4: every bud with the resource grows its shoot. Whether any grew.
    fn shoot(&mut self, buds: &[Bud], cycle: u32) -> Result<bool, DevelopError> {
        let most = self.genome.parameters.count(Param::MaxShoot) as f32;
        let straight = self.param(Param::Straightness);
        let gravity = Vec3::Y * self.param(Param::Gravitropism);
        let photo = self.param(Param::Phototropism);
        let mut any = false;
        for bud in buds {
            let count = bud.vigour.floor().min(most) as u32;
            if count == 0 || bud.seen == 0 {
                continue;
            }
            any = true;
            let (mut at, mut side, mut heading) = (bud.node, bud.side, bud.heading);
            for _ in 0..count {
                if self.nodes.len() >= MAX_NODES {
                    return Err(DevelopError::TooLarge { limit: MAX_NODES });
                }
                let from = self.nodes[at as usize].pos;
                let light = self.shade.brighter(from) * photo;
                let dir = (heading * straight + bud.toward + gravity + light)
                    .try_normalize()
                    .unwrap_or(heading);
                at = self.add(at, side, dir, cycle);
                (side, heading) = (false, dir);
            }
        }
        Ok(any)
    }

    /// Step 5: side branches at least two cycles old whose shoot tips get too little light
    /// on average are shed (their inner wood is shaded in any crown; a branch lives by its
    /// leaves).
    fn shed_shaded(&mut self, cycle: u32) {
        let threshold = self.param(Param::Shedding);
        if threshold <= 0.0 {
            return;
        }
        let n = self.nodes.len();
        // Light summed over each subtree's tips, and their count, from the tips down.
        let mut sums = vec![(0.0f32, 0u32); n];
        for i in (1..n).rev() {
            let node = self.nodes[i];
            if node.dead {
                continue;
            }
            if sums[i].1 == 0 {
                sums[i] = (self.shade.light(node.pos), 1);
            }
            let (light, count) = sums[i];
            let parent = &mut sums[node.parent as usize];
            parent.0 += light;
            parent.1 += count;
        }
        for (i, &(light, tips)) in sums.iter().enumerate().skip(1) {
            let node = self.nodes[i];
            let parent = node.parent as usize;
            let shed = node.lateral
                && !node.dead
                && !self.nodes[parent].dead
                && node.born + 2 <= cycle
                && light < threshold * tips as f32;
            if shed {
                self.nodes[parent].side = Slot::Empty;
                self.nodes[i].dead = true;
            }
            // Parents come before children: a dead parent's children die in this pass.
            if !self.nodes[i].dead && self.nodes[parent].dead {
                self.nodes[i].dead = true;
            }
            if self.nodes[i].dead && !node.dead {
                self.shade.cast(node.pos, -1.0);
                self.shed += 1;
            }
        }
    }

    /// The living tree as a plant: stems by the pipe model, leaves on the last internodes
    /// of every shoot. Also the leaves placed.
    fn plant(&self, seed: u64) -> Result<(Plant, usize), DevelopError> {
        let g = self.genome;
        let n = self.nodes.len();
        let exponent = self.param(Param::PipeExponent);
        let tip = self.param(Param::TipRadius);
        // Radius to the pipe exponent, and internodes to the nearest tip, summed from the
        // tips down.
        let mut flow = vec![0.0f32; n];
        let mut to_tip = vec![u32::MAX; n];
        for i in (1..n).rev() {
            let node = &self.nodes[i];
            if node.dead {
                continue;
            }
            if flow[i] == 0.0 {
                flow[i] = tip.powf(exponent);
                to_tip[i] = 0;
            }
            let parent = node.parent as usize;
            flow[parent] += flow[i];
            to_tip[parent] = to_tip[parent].min(to_tip[i].saturating_add(1));
        }
        let radius = |i: usize| flow[i].powf(1.0 / exponent);
        let mut plant = Plant::new(sylva_model::plant_meta::<crate::GrownModel>(g, seed));
        let spec = g.foliage.spec();
        let leaf_length = 0.5 * (spec.length.0 + spec.length.1);
        let leaf_size = Vec2::new(leaf_length, leaf_length * spec.width_ratio);
        let per_internode =
            ((self.step / (0.6 * leaf_length)).round() as u32).clamp(1, MAX_LEAVES_PER_INTERNODE);
        let leaf_span = g.parameters.count(Param::LeafSpan);
        // Internodes joined into runs along each axis, so a gently curving stem is a few
        // segments (a few rings to mesh), not one per internode.
        let mut run_of = vec![u32::MAX; n];
        let mut runs: Vec<Run> = Vec::new();
        for i in 1..n {
            let node = &self.nodes[i];
            if node.dead {
                continue;
            }
            let parent = node.parent as usize;
            let from = self.nodes[parent].pos;
            if !node.lateral && parent != 0 {
                let k = run_of[parent] as usize;
                let run = &mut runs[k];
                let chord = (from - run.start).normalize_or(node.dir);
                if run.end == parent as u32
                    && run.count < RUN_MOST
                    && chord.dot(node.dir) >= RUN_BEND.cos()
                {
                    run.end = i as u32;
                    run.count += 1;
                    run_of[i] = k as u32;
                    continue;
                }
            }
            run_of[i] = runs.len() as u32;
            runs.push(Run {
                start: from,
                first: i as u32,
                end: i as u32,
                count: 1,
                parent: (parent != 0).then(|| run_of[parent]),
                lateral: node.lateral,
            });
        }
        // Twigs are left out of the wood and their leaves go to the stem they grow from: a
        // leaf card pictures a twig with its leaves, and meshing thousands of twigs would blow
        // a game's budget. A twig is a branch of at most `most` internodes in all (from
        // TWIG up, until the wood is within the budget of segments).
        let mut size = runs.iter().map(|r| r.count).collect::<Vec<_>>();
        for k in (0..runs.len()).rev() {
            if let Some(p) = runs[k].parent {
                size[p as usize] += size[k];
            }
        }
        let budget = if spec.needles {
            CONIFER_SEGMENTS
        } else {
            BROADLEAF_SEGMENTS
        };
        let mut most = TWIG;
        let twig = loop {
            let twig: Vec<bool> = (runs.iter().zip(&size))
                .map(|(r, &n)| r.parent.is_some() && n <= most)
                .collect();
            if twig.iter().filter(|&&t| !t).count() <= budget || most > MAX_NODES as u32 {
                break twig;
            }
            most = most * 3 / 2;
        };
        let mut id_of = vec![u32::MAX; runs.len()];
        let mut kept = 0;
        for (k, run) in runs.iter().enumerate() {
            id_of[k] = match run.parent {
                Some(p) if twig[k] => id_of[p as usize],
                _ => {
                    kept += 1;
                    kept - 1
                }
            };
        }
        for (k, run) in runs.iter().enumerate() {
            if twig[k] {
                continue;
            }
            let (first, end) = (run.first as usize, &self.nodes[run.end as usize]);
            let end_radius = match end.main {
                Slot::Node(m) => radius(m as usize),
                _ => tip,
            };
            plant.add_segment(
                run.start,
                end.pos,
                (radius(first), end_radius.min(radius(first))),
                run.parent.map(|p| SegmentId(id_of[p as usize])),
                run.lateral,
                Plant::BARK,
            )?;
        }
        // Leaves on the last internodes of every shoot; where they would be more than a real
        // crown holds (a leaf area index of MAX_LAI over the crown's spread), the most shaded
        // go first, as a crown sheds the leaves its shade starves: its outline stays.
        let leafy: Vec<usize> = (1..n)
            .filter(|&i| {
                let node = &self.nodes[i];
                !node.dead && to_tip[i] < leaf_span && node.born > 0
            })
            .collect();
        let (lo, hi) = (self.nodes.iter().filter(|n| !n.dead)).fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), n| (lo.min(n.pos), hi.max(n.pos)),
        );
        let spread = std::f32::consts::FRAC_PI_4 * (hi.x - lo.x) * (hi.z - lo.z);
        // Dressed (as the genome's own foliage dresses it), each leaf is a card of the kind:
        // the leaf area a leaf stands for is its card's when that is larger.
        let card = if hi.y >= BRANCHLET_HEIGHT {
            Card::Branchlet
        } else {
            Card::Spray
        };
        let card_edge = leaf_length / spec.leaf_of(card);
        let faces = if spec.crossed { 2.0 } else { 1.0 };
        let card_area = CARD_FILL * card_edge * card_edge * faces;
        let blade = (LEAF_FILL * leaf_size.x * leaf_size.y).max(card_area) * per_internode as f32;
        let most = (MAX_LAI * spread / blade).max(1.0) as usize;
        let mut shed = vec![false; n];
        if leafy.len() > most {
            let mut by_light: Vec<(f32, usize)> = leafy
                .iter()
                .map(|&i| (self.shade.light(self.nodes[i].pos), i))
                .collect();
            by_light.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            for &(_, i) in &by_light[most..] {
                shed[i] = true;
            }
        }
        let mut leaves = 0;
        let mut turn_count = seed as u32;
        for &i in &leafy {
            let node = &self.nodes[i];
            if shed[i] {
                continue;
            }
            let from = self.nodes[node.parent as usize].pos;
            for k in 0..per_internode {
                turn_count = turn_count.wrapping_add(1);
                let t = (k as f32 + 0.5) / per_internode as f32;
                let spin = turn(node.across, node.dir, turn_count as f32 * 2.399_963);
                let out = (node.dir * 0.6 + spin - Vec3::Y * 0.25).normalize_or(spin);
                let face = across(out, Vec3::Y);
                let orientation = Quat::from_mat3(&Mat3::from_cols(out.cross(face), out, face));
                plant.add_organ(Organ {
                    kind: OrganKind::Leaf,
                    position: from.lerp(node.pos, t),
                    orientation: orientation.normalize(),
                    size: leaf_size,
                    material: Plant::LEAF,
                    parent: Some(SegmentId(id_of[run_of[i] as usize])),
                })?;
                leaves += 1;
            }
        }
        Ok((plant, leaves))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::genome::CrownShape;

    #[test]
    fn the_default_tree_fills_its_crown() {
        let genome = Growth::default();
        let (plant, report) = grow(&genome, genome.seed).unwrap();
        assert!(report.internodes > 300, "{report:?}");
        assert!(report.leaves > 1000, "{report:?}");
        assert!(report.points_left * 4 < report.points, "{report:?}");
        let top = plant
            .segments()
            .iter()
            .map(|s| s.end.y)
            .fold(0.0f32, f32::max);
        assert!((9.0..=13.5).contains(&top), "{top}");
        // One trunk from the ground; the pipe model makes it the thickest stem.
        let roots: Vec<_> = plant
            .segments()
            .iter()
            .filter(|s| s.parent.is_none())
            .collect();
        assert_eq!(roots.len(), 1);
        let thickest = plant
            .segments()
            .iter()
            .map(|s| s.start_radius)
            .fold(0.0f32, f32::max);
        assert_eq!(roots[0].start_radius, thickest);
    }

    #[test]
    fn growth_is_repeatable_and_the_seed_matters() {
        let genome = Growth::default();
        let a = grow(&genome, 3).unwrap().0;
        let b = grow(&genome, 3).unwrap().0;
        let c = grow(&genome, 4).unwrap().0;
        assert_eq!(a.segments(), b.segments());
        assert_eq!(a.organs(), b.organs());
        assert_ne!(a.segments(), c.segments());
    }

    #[test]
    fn every_crown_shape_grows_a_tree() {
        for crown in CrownShape::ALL {
            let genome = Growth {
                crown,
                ..Growth::default()
            };
            let (_, report) = grow(&genome, 1).unwrap();
            assert!(report.internodes > 200, "{crown:?} {report:?}");
        }
    }

    #[test]
    fn shading_sheds_branches() {
        let mut genome = Growth::default();
        genome.parameters.set(Param::Shedding, 0.0);
        let kept = grow(&genome, 1).unwrap().1;
        genome.parameters.set(Param::Shedding, 0.6);
        let shed = grow(&genome, 1).unwrap().1;
        assert_eq!(kept.shed, 0);
        assert!(shed.shed > 0, "{shed:?}");
    }
}
