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
    /// Per segment: whether any segment grows from it, whatever the endpoint rule (the bars
    /// measure).
    continued: Vec<bool>,
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

    /// F_thick by a measure that reads the whole plant ([`super::ThickMeasure::Taper`],
    /// [`super::ThickMeasure::Bars`] or [`super::ThickMeasure::Gradual`]; the endpoints
    /// measure gives 0 here). `plant` must be the plant last [`read`](Self::read).
    pub fn thick_measure(&mut self, plant: &Plant, thick: &super::ThickOptions) -> f64 {
        match thick.measure {
            super::ThickMeasure::Endpoints => 0.0,
            super::ThickMeasure::Taper => self.taper_deviation(plant, thick),
            super::ThickMeasure::Bars => {
                self.bars_deviation(plant, thick.tip_ratio, thick.step_ratio)
            }
            super::ThickMeasure::Gradual => {
                self.taper_deviation(plant, thick)
                    + self.bars_deviation(plant, thick.tip_ratio, thick.step_ratio)
            }
        }
    }

    /// F_thick's bars measure ([`super::ThickMeasure::Bars`]): how far `plant` is from a
    /// gradual taper. Along every path from the foot, per tip:
    ///
    /// - each rise in thickness, `max(0, b / a − 1)` (at most 1 each), from one radius `a`
    ///   to the next `b` (a segment's start to its end, a parent's end to its child's start);
    /// - each step to less than `step_ratio`, `max(0, step_ratio − b / a)` (the bar's is
    ///   a half, [`super::ThickOptions::step_ratio`]);
    /// - the tip's excess over `tip_ratio` of the foot's radius, `max(0, tip / foot −
    ///   tip_ratio)` (the bar's is 0.25, [`super::ThickOptions::tip_ratio`]).
    ///
    /// Rises and steps are summed over the plant and divided by the number of tips, the
    /// excesses averaged over the tips; the worst of each is added, because the bars hold
    /// for every path: one thick stub among hundreds of thin tips fails them. 0 exactly
    /// when the plant meets issue 14's taper bars (at ratios 0.25 and 0.5): it never
    /// thickens, no segment is less than `step_ratio` as thick as the one before it, and
    /// every tip is at most `tip_ratio` of the foot. 0 for a plant without segments.
    /// Needs every step drawn to see steps inside a run (the automata's `detail = "full"`).
    pub fn bars_deviation(&mut self, plant: &Plant, tip_ratio: f64, step_ratio: f64) -> f64 {
        let segments = &plant.segments();
        let foot = segments
            .iter()
            .enumerate()
            .filter(|(i, s)| s.parent.is_none_or(|p| p.index() >= *i))
            .map(|(_, s)| f64::from(s.start_radius))
            .fold(0.0, f64::max);
        if segments.is_empty() {
            return 0.0;
        }
        let ratio = |a: f32, b: f32| {
            if a > 0.0 {
                f64::from(b) / f64::from(a)
            } else {
                1.0
            }
        };
        let violation = |a: f32, b: f32| {
            let r = ratio(a, b);
            (r - 1.0).clamp(0.0, 1.0) + (step_ratio - r).max(0.0)
        };
        self.continued.clear();
        self.continued.resize(segments.len(), false);
        let (mut broken, mut worst_break) = (0.0, 0.0f64);
        for (i, s) in segments.iter().enumerate() {
            let mut v = violation(s.start_radius, s.end_radius);
            if let Some(p) = s.parent.map(|p| p.index()).filter(|&p| p < i) {
                self.continued[p] = true;
                v += violation(segments[p].end_radius, s.start_radius);
            }
            broken += v;
            worst_break = worst_break.max(v);
        }
        let (mut tips, mut excess, mut worst_excess) = (0usize, 0.0, 0.0f64);
        for (s, _) in segments.iter().zip(&self.continued).filter(|(_, c)| !**c) {
            let e = if foot > 0.0 {
                (f64::from(s.end_radius) / foot - tip_ratio).max(0.0)
            } else {
                0.0
            };
            tips += 1;
            excess += e;
            worst_excess = worst_excess.max(e);
        }
        (broken + excess) / tips.max(1) as f64 + worst_break + worst_excess
    }

    /// The endpoints of the last plant read.
    pub fn endpoints(&self) -> &[Endpoint] {
        &self.endpoints
    }
}
