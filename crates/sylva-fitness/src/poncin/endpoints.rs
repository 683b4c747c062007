//! The fitness cases: a plant's endpoints, read once per evaluation into reusable buffers.
//!
//! Which points are endpoints is an [`EndpointRule`]: every tip of the plant
//! ([`Plant::tips`]), or one per axis, where the axis was last drawn (for the automata: where
//! each automaton instance ended). An endpoint's level is its segment's branch order (0 for
//! the trunk). Each endpoint
//! also carries the direction of the branch it ends, from the base of its axis (the start of
//! the lateral segment that began the branch, or the plant's foot for the trunk) to the
//! endpoint, which F_angle compares.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use sylva_core::Plant;

/// What counts as an endpoint (a fitness case) of a plant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndpointRule {
    /// Every tip: the end of each segment that no segment continues or branches from.
    #[default]
    Tips,
    /// One per axis (a run of non-lateral segments from a lateral one or a root): the end of
    /// its last-drawn segment. For the automata, an axis is an automaton instance and this
    /// is where it ended, the paper's "endpoints of all the automata instantiated", so a
    /// Push/Pop fork inside one automaton adds no endpoint: only creating automata does,
    /// which is what F_num is for ("encourages the creation of branches, i.e. the use of
    /// Automata 2 by Automata 1").
    Axes,
}

/// One endpoint, as the terms read it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Endpoint {
    /// Position in paper units (metres divided by the unit).
    pub position: DVec3,
    /// Unit direction from the base of its axis to it; zero for an axis without length.
    pub direction: DVec3,
    /// Branch level: the order of its segment (0 for the trunk).
    pub level: u16,
    /// Radius at the end of its segment, metres.
    pub radius: f64,
    /// For the end of a first-order branch: the endpoints of level 2 on that branch (its
    /// sub-branches' ends); 0 otherwise.
    pub sub_branches: u32,
}

/// Buffers one evaluation needs; keep one per thread and pass it to every
/// [`PoncinFitness::score`](super::PoncinFitness::score) call, so that scoring does not
/// allocate once the buffers have grown to the largest plant seen.
#[derive(Clone, Debug, Default)]
pub struct PoncinScratch {
    /// Per segment: whether any segment grows from it.
    has_child: Vec<bool>,
    /// Per segment: the first segment of its axis.
    axis: Vec<u32>,
    /// Per axis (indexed by its first segment): its last segment.
    last: Vec<u32>,
    /// Per segment: path length from the foot to its end (the taper measure).
    along: Vec<f64>,
    /// Per segment: the first segment of the first-order branch it grows on (`u32::MAX` on
    /// the trunk), and, per first-order branch, its level-2 endpoints.
    branch: Vec<u32>,
    subs: Vec<u32>,
    pub(crate) endpoints: Vec<Endpoint>,
    /// Endpoint positions as f32 columns (x, y, z), for the exact pair loop.
    pub(crate) columns: [Vec<f32>; 3],
    pub(crate) cells: Vec<u32>,
}

impl PoncinScratch {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Reads the plant's endpoints by `rule`, positions divided by `unit` (metres per paper
    /// unit). Segments whose parent is not an earlier segment are treated as roots.
    pub fn read(&mut self, plant: &Plant, unit: f64, rule: EndpointRule) -> &[Endpoint] {
        let segments = &plant.segments();
        self.has_child.clear();
        self.has_child.resize(segments.len(), false);
        self.axis.clear();
        for (i, s) in segments.iter().enumerate() {
            let axis = match s.parent.map(|p| p.index()) {
                Some(p) if p < i => {
                    self.has_child[p] = true;
                    if s.lateral { i as u32 } else { self.axis[p] }
                }
                _ => i as u32,
            };
            self.axis.push(axis);
        }
        if rule == EndpointRule::Axes {
            // An axis's end is its last segment: mark every other segment as continued.
            self.last.clear();
            self.last.resize(segments.len(), u32::MAX);
            for (i, &axis) in self.axis.iter().enumerate() {
                self.last[axis as usize] = i as u32;
            }
            for (i, &axis) in self.axis.iter().enumerate() {
                self.has_child[i] = self.last[axis as usize] != i as u32;
            }
        }
        // Each segment's first-order branch, and each branch's level-2 endpoints.
        self.branch.clear();
        self.subs.clear();
        self.subs.resize(segments.len(), 0);
        for (i, s) in segments.iter().enumerate() {
            let inherited = match s.parent.map(|p| p.index()) {
                Some(p) if p < i => self.branch[p],
                _ => u32::MAX,
            };
            let branch = if s.order == 1 {
                self.axis[i]
            } else {
                inherited
            };
            self.branch
                .push(if s.order == 0 { u32::MAX } else { branch });
            if s.order == 2 && !self.has_child[i] && branch != u32::MAX {
                self.subs[branch as usize] += 1;
            }
        }
        self.endpoints.clear();
        for column in &mut self.columns {
            column.clear();
        }
        let inv_unit = 1.0 / unit;
        let ends = segments.iter().zip(&self.has_child).zip(&self.axis);
        for ((s, _), &axis) in ends.filter(|((_, has_child), _)| !**has_child) {
            let sub_branches = if s.order == 1 {
                self.subs[axis as usize]
            } else {
                0
            };
            let position = s.end.as_dvec3() * inv_unit;
            for (column, x) in self.columns.iter_mut().zip(position.to_array()) {
                column.push(x as f32);
            }
            let base = segments[axis as usize].start;
            self.endpoints.push(Endpoint {
                position,
                direction: (s.end - base).as_dvec3().normalize_or_zero(),
                level: s.order,
                radius: f64::from(s.end_radius),
                sub_branches,
            });
        }
        &self.endpoints
    }

    /// F_thick's taper measure ([`super::ThickMeasure::Taper`]) of `plant`, which must be
    /// the plant last [`read`](Self::read): the length-weighted mean of
    /// `|thickness − reference|` over segment ends, where the reference falls geometrically
    /// with path length from the foot, from 1 there to the farthest tip's level reference.
    /// 0 for a plant without length.
    pub fn taper_deviation(&mut self, plant: &Plant, thick: &super::ThickOptions) -> f64 {
        let segments = &plant.segments();
        self.along.clear();
        let (mut farthest, mut far_level) = (0.0, 0u16);
        for (i, s) in segments.iter().enumerate() {
            let before = match s.parent.map(|p| p.index()) {
                Some(p) if p < i => self.along[p],
                _ => 0.0,
            };
            let along = before + f64::from(s.length());
            self.along.push(along);
            if along > farthest {
                (farthest, far_level) = (along, s.order);
            }
        }
        if farthest <= 0.0 {
            return 0.0;
        }
        // ln of the farthest tip's reference (kept off 0, whose logarithm is -inf).
        let ln_tip = thick.reference(far_level).max(1e-6).ln();
        let scale = 1.0 / thick.radius_per_thickness;
        let (mut deviation, mut length) = (0.0, 0.0);
        for (s, &along) in segments.iter().zip(&self.along) {
            let l = f64::from(s.length());
            if l > 0.0 {
                let reference = (ln_tip * along / farthest).exp();
                deviation += l * (f64::from(s.end_radius) * scale - reference).abs();
                length += l;
            }
        }
        deviation / length
    }

    /// The endpoints of the last plant read.
    pub fn endpoints(&self) -> &[Endpoint] {
        &self.endpoints
    }
}
