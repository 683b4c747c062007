//! The simulator of section 2.2: automata instances step in parallel and draw the plant.
//!
//! ```text
//! for each iteration:
//!     for each automaton still alive (in creation order):
//!         run states until Wait; Killme or the end of the automaton kills it
//!         (a killed automaton does not move)
//!         move one step of Length along H; record the position and the Thickness
//! ```
//!
//! [`Simulator::run`] follows this exactly and writes the [`Plant`] as it goes. The
//! simulator keeps its buffers between runs and refills the caller's plant, so evaluating a
//! population allocates nothing once the buffers have grown.
//!
//! # Drawing
//!
//! - Positions are paper units; the plant is in metres: `position × unit`.
//! - Each automaton instance draws one axis (`lateral = false` from segment to segment). A
//!   created instance's first segment is lateral, and its parent is the creator's segment
//!   ending at the creation point: the creator's current run is cut there
//!   ([`Detail::Chords`]) so that branch points are always segment boundaries. An instance
//!   that creates before it has drawn anything first draws a zero-length stub at its
//!   position, so the child still hangs from a segment of the creator's level.
//! - A Push/Pop that moved the turtle in between draws a fork: the path drawn inside ends
//!   (an endpoint), and the automaton continues from the saved point, as a second
//!   non-lateral child of the segment ending there (same branch level).
//! - Radii: `radius × map(Thickness) × unit`, with `map` the remapping of section 5.2
//!   ([`map_thickness`]): Thickness is clamped to 0.001..=1, then mapped linearly onto
//!   0.1..=1, so even a vanishing branch stays visible.
//! - `CreateAutomaton Leaf` and `Flower` add an organ at the current position (leaves near
//!   horizontal by default, section 4.5); an organ's parent is the segment of its axis that
//!   next leaves its position (or the last one, if the automaton never moves again).
//!
//! # Bounds
//!
//! Every runaway is bounded by [`Limits`] and counted in the [`GrowthReport`]; none panics
//! and none is silent: an automaton running more than `states_per_step` states in one
//! iteration is killed; creations beyond `automata` instances and organs beyond `organs`
//! are skipped; growth stops once `points` positions or `states` states in total are
//! reached; variables are clamped to ±[`VARIABLE_LIMIT`], so positions stay finite.
//!
//! # Speed
//!
//! Evolution grows tens of thousands of individuals a second, so the simulator is built for
//! speed, and each of the following changes the speed and nothing else: `tests/
//! automata_reference.rs` grows random programs, evolved ones and hand-made corner cases
//! with this simulator and with `tests/reference`, the plain interpreter it replaced (kept
//! with the tests), and requires the same plant and report bit for bit.
//!
//! - Blocks: the program's states are regrouped, as they are first reached, so that one
//!   dispatch runs a loop test, the turns, variable updates and `Repeat` entries after it,
//!   and the state that ends them (see `blocks.rs`). A block ending its step in a Wait with
//!   at most one turn and one update (most evolved loops) runs code made for its shape.
//! - Running ahead: such a step draws nothing and touches nothing but its automaton, so
//!   after one, the automaton runs its next such steps at once, one per iteration to come,
//!   with its turtle in registers; a loop waiting in its own test, and an outer loop that
//!   only enters it again, run as one counted loop of turn, update and move. The iteration
//!   loop then skips the automaton until its steps catch up. Only a bound (points, states,
//!   extent) reached before those steps' turn could tell the difference: such a growth is
//!   run again without running ahead.
//! - The frame is three SIMD vectors; each lane does exactly what [`Frame`]'s scalar code
//!   does to one coordinate. It is renormalised only when it moves after 16 turns, by one
//!   Newton step, inlined and in registers.
//! - No 16-byte load reads a value that a 4-byte store has just written (the processor
//!   would wait for the store): Length and Thickness sit apart, and a chord keeps its
//!   start's radius mapped.
//! - Instances are stepped in place (children wait in a side buffer until the iteration
//!   ends); [`Detail::Chords`] writes a segment only at branch points and tips; no buffer is
//!   freed between runs (`tests/automata_alloc.rs` checks that a warm run allocates
//!   nothing).
//!
//! `benches/automata.rs` measures it beside the reference.

use glam::{Mat3, Quat, Vec2, Vec3, Vec3A};
use serde::{Deserialize, Serialize};
use sylva_core::{Frame, Organ, OrganKind, Plant, Segment, SegmentId};

use crate::compile::Program;

mod blocks;

use blocks::{Axis, Block, Blocks, Pure, Term, UNBUILT, Update};

/// Variables are clamped to `±VARIABLE_LIMIT` after each `Add` or `Multiply`.
pub const VARIABLE_LIMIT: f32 = 1e6;

const NONE: u32 = u32::MAX;
/// A frame is made orthonormal again when it moves after this many turns (or when anything
/// else may have disturbed it). One turn with exact sine and cosine moves the vectors off
/// unit length by about one ulp, so 16 turns stay within 1e-6 and each move costs a few
/// multiplications instead of a renormalisation.
const RENORMALISE: u8 = 16;
/// The golden angle, radians: successive leaves turn by it about the vertical.
const GOLDEN_ANGLE: f32 = 2.399_963_2;
/// Leaves droop this far below horizontal, radians (10°).
const LEAF_DROOP: f32 = 0.174_532_93;

/// How finely the plant is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Detail {
    /// Every recorded step is a segment: for meshing and pictures.
    #[default]
    Full,
    /// One segment per run between branch points (creations, Push/Pop forks) and to each
    /// tip: the same tips, leaves, levels and end thicknesses as [`Detail::Full`], far fewer
    /// segments. Leaves and flowers keep their position and size but not their orientation
    /// (left at identity: no fitness term reads it, and it costs more than the rest of an
    /// organ). For fitness evaluation.
    Chords,
}

/// The variables a created automaton starts with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChildVariables {
    /// The creator's Length and Thickness; general variables 0. Default: a branch continues
    /// at the thickness of its junction, and its counters start fresh like the helix's.
    #[default]
    LengthThickness,
    /// All of the creator's variables.
    All,
    /// The root's start: Length 1, Thickness 1, general variables 0.
    Fresh,
}

/// Bounds on a run. Every field says its default and the range a genome file may give.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// States one automaton may run in one iteration before it is killed. Default 1000;
    /// 1 to 1 000 000.
    #[serde(deserialize_with = "states_per_step")]
    pub states_per_step: u32,
    /// States in the whole run; growth stops when reached. Default 2 000 000; 1 to 10^9
    /// (about ten seconds of simulation).
    #[serde(deserialize_with = "total_states")]
    pub states: u64,
    /// Automata instances in the whole run, the root included. Default 2000; 1 to 1 000 000.
    #[serde(deserialize_with = "automata")]
    pub automata: u32,
    /// Recorded positions; growth stops when reached. Default 200 000; 1 to 10^8.
    #[serde(deserialize_with = "points")]
    pub points: u32,
    /// Leaves and flowers. Default 20 000; 0 to 10^7.
    #[serde(deserialize_with = "organs")]
    pub organs: u32,
}

sylva_core::ranged!(states_per_step: u32, "limits.states_per_step", 1, 1_000_000);
sylva_core::ranged!(automata: u32, "limits.automata", 1, 1_000_000);
sylva_core::ranged!(points: u32, "limits.points", 1, 100_000_000);
sylva_core::ranged!(organs: u32, "limits.organs", 0, 10_000_000);
sylva_core::ranged!(total_states: u64, "limits.states", 1, 1_000_000_000);

impl Limits {
    /// Bytes a growth may hold at these bounds: a segment per point, the organs, and the
    /// automaton instances.
    pub fn memory_bound(&self) -> u64 {
        let segment = std::mem::size_of::<Segment>() as u64;
        let organ = std::mem::size_of::<Organ>() as u64 + 4;
        let instance = std::mem::size_of::<Inst>() as u64 + 64;
        u64::from(self.points) * segment
            + u64::from(self.organs) * organ
            + u64::from(self.automata) * instance
    }

    /// Refuses bounds whose growth may not fit in the memory budget.
    pub fn check_budget(&self) -> Result<(), sylva_core::budget::OverBudget> {
        sylva_core::budget::check(
            self.memory_bound(),
            format_args!(
                "growth to `limits` of {} points, {} organs and {} automata",
                self.points, self.organs, self.automata
            ),
            "lower `limits.points`, `limits.organs` or `limits.automata`",
        )
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            states_per_step: 1000,
            states: 2_000_000,
            automata: 2000,
            points: 200_000,
            organs: 20_000,
        }
    }
}

/// How a program grows. Every field says its default; [`Simulator::run`] replaces a value
/// that is not finite, or is out of its range, by the nearest legal one (the default for NaN).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrowOptions {
    /// Iteration limit. Default 100 (section 5.1).
    pub iterations: u32,
    /// The root automaton's Length when it starts, paper units per step. Default 1; range
    /// 0..=1e3. The paper does not give it; with 100 iterations, a Length of 2 to 3 lets
    /// a tree reach across its 300-unit sphere, which evolution finds far more often than
    /// learning to raise Length (see `examples/automata/sphere.toml`).
    pub root_length: f32,
    /// Metres per paper unit. Default 0.1, so the paper's sphere of radius 150 centred 200
    /// up is 15 m wide and a 100-step trunk of Length 1 is 10 m tall. Range 1e-6..=1e3.
    pub unit: f32,
    /// Tropism towards the ground, degrees per step for a horizontal heading (scaled by
    /// the sine of the angle to vertical, as in *The Algorithmic Beauty of Plants*).
    /// Default 0 (off); Figure 17's pine bends. Range 0..=90.
    pub gravity: f32,
    /// Radius at mapped thickness 1, paper units. Default 3 (0.3 m at the default unit).
    /// Range 0..=1e3.
    pub radius: f32,
    /// Leaf length, paper units (width 0.4 of it). Default 4.
    pub leaf_length: f32,
    /// Flower diameter, paper units. Default 4.
    pub flower_size: f32,
    /// Turn leaves near horizontal, face up (section 4.5). Default true; otherwise a leaf
    /// points along the turtle's U.
    pub horizontal_leaves: bool,
    /// A created automaton's variables. Default [`ChildVariables::LengthThickness`].
    pub child_variables: ChildVariables,
    /// Runaway bounds.
    pub limits: Limits,
}

impl Default for GrowOptions {
    fn default() -> Self {
        GrowOptions {
            iterations: 100,
            root_length: 1.0,
            unit: 0.1,
            gravity: 0.0,
            radius: 3.0,
            leaf_length: 4.0,
            flower_size: 4.0,
            horizontal_leaves: true,
            child_variables: ChildVariables::LengthThickness,
            limits: Limits::default(),
        }
    }
}

fn legal(value: f32, min: f32, max: f32, default: f32) -> f32 {
    if value.is_nan() {
        default
    } else {
        value.clamp(min, max)
    }
}

impl GrowOptions {
    /// The options with every value brought into its legal range.
    pub fn sanitized(&self) -> GrowOptions {
        let d = GrowOptions::default();
        GrowOptions {
            root_length: legal(self.root_length, 0.0, 1e3, d.root_length),
            unit: legal(self.unit, 1e-6, 1e3, d.unit),
            gravity: legal(self.gravity, 0.0, 90.0, d.gravity),
            radius: legal(self.radius, 0.0, 1e3, d.radius),
            leaf_length: legal(self.leaf_length, 0.0, 1e3, d.leaf_length),
            flower_size: legal(self.flower_size, 0.0, 1e3, d.flower_size),
            limits: Limits {
                states_per_step: self.limits.states_per_step.max(1),
                ..self.limits
            },
            ..*self
        }
    }

    /// Radius in metres of a recorded Thickness.
    pub fn radius_of(&self, thickness: f32) -> f32 {
        map_thickness(thickness) * self.radius * self.unit
    }

    /// The mapped thickness (0.1..=1) of a segment radius in metres: the inverse of
    /// [`GrowOptions::radius_of`] on mapped values, for fitness terms that read thickness
    /// back from a [`Plant`].
    pub fn thickness_of_radius(&self, radius: f32) -> f32 {
        let scale = self.radius * self.unit;
        if scale > 0.0 { radius / scale } else { 0.0 }
    }
}

/// Section 5.2's remapping: Thickness clamped to 0.001..=1, then mapped linearly onto
/// 0.1..=1.
#[inline]
pub fn map_thickness(thickness: f32) -> f32 {
    0.1 + (0.9 / 0.999) * (thickness.clamp(0.001, 1.0) - 0.001)
}

/// Why growth ended.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// Every automaton died.
    #[default]
    AllDead,
    /// The iteration limit was reached with automata alive.
    Iterations,
    /// [`Limits::points`] was reached.
    Points,
    /// [`Limits::states`] was reached.
    States,
    /// A position went beyond ±[`MAX_COORD`](sylva_core::plant::MAX_COORD) metres, which
    /// no plant may hold.
    Extent,
}

/// Which bounds were hit, and how often.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
pub struct BoundsHit {
    /// Automata killed for running more than [`Limits::states_per_step`] states in one
    /// iteration.
    pub state_limit_kills: u32,
    /// Creations skipped at [`Limits::automata`].
    pub automata_refused: u32,
    /// Leaves and flowers skipped at [`Limits::organs`].
    pub organs_refused: u32,
    /// Variable values clamped to ±[`VARIABLE_LIMIT`].
    pub clamped_values: u32,
    /// Growth stopped at [`Limits::points`].
    pub points: bool,
    /// Growth stopped at [`Limits::states`].
    pub states: bool,
    /// Growth stopped at a position beyond ±[`MAX_COORD`](sylva_core::plant::MAX_COORD)
    /// metres.
    pub extent: bool,
}

impl BoundsHit {
    /// Whether any bound was hit.
    pub fn any(&self) -> bool {
        self.state_limit_kills > 0
            || self.automata_refused > 0
            || self.organs_refused > 0
            || self.clamped_values > 0
            || self.points
            || self.states
            || self.extent
    }
}

/// What a run did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
pub struct GrowthReport {
    /// Iterations run.
    pub iterations: u32,
    /// Why growth ended.
    pub stop: Stop,
    /// Automata instances created, the root included.
    pub automata: u32,
    /// Most automata alive at the end of an iteration.
    pub peak_live: u32,
    /// Automata alive when growth ended.
    pub live_at_end: u32,
    /// Automaton-steps: one automaton running one iteration.
    pub automaton_steps: u64,
    /// States run in total.
    pub states: u64,
    /// Most states one automaton ran in one iteration.
    pub max_states_per_step: u32,
    /// Positions recorded (steps moved).
    pub points: u32,
    /// Segments drawn.
    pub segments: u32,
    /// Leaves added.
    pub leaves: u32,
    /// Flowers added.
    pub flowers: u32,
    /// Positions recorded with a negative Thickness (drawn at the minimum; fitness may
    /// penalise them, section 4.4.2).
    pub negative_thickness: u32,
    /// Bounds hit.
    pub bounds: BoundsHit,
}

/// The turtle's frame as SIMD vectors, so a turn is a few vector operations. Each lane does
/// what [`Frame`]'s scalar code does to one coordinate, so the numbers are the same.
#[derive(Clone, Copy, Debug, Default)]
struct Turtle {
    heading: Vec3A,
    left: Vec3A,
    up: Vec3A,
}

impl Turtle {
    fn of(frame: Frame) -> Turtle {
        Turtle {
            heading: frame.heading.into(),
            left: frame.left.into(),
            up: frame.up.into(),
        }
    }

    fn frame(&self) -> Frame {
        Frame {
            heading: self.heading.into(),
            left: self.left.into(),
            up: self.up.into(),
        }
    }

    /// Gravity's turn before a move: H towards -Y about H × (-Y), by gravity × sin(angle to
    /// vertical); `turns` counts it.
    #[inline(always)]
    fn fall(&mut self, gravity: f32, turns: &mut u32) {
        let h = Vec3::from(self.heading);
        let axis = Vec3::new(h.z, 0.0, -h.x);
        let sin = axis.length();
        if sin > 1e-6 {
            let angle = (gravity * sin).min(sin.atan2(-h.y));
            let q = Quat::from_axis_angle(axis / sin, angle);
            self.heading = (q * h).into();
            self.left = (q * Vec3::from(self.left)).into();
            *turns += 1;
        }
    }

    /// [`Frame::renormalise`], with the same operations in the same order, in registers
    /// (taken and returned by value: a call into `sylva_core` through memory stalled).
    #[inline(always)]
    fn renormalised(self) -> Turtle {
        let (h, left) = (Vec3::from(self.heading), Vec3::from(self.left));
        let hh = h.length_squared();
        let l = left - h * h.dot(left);
        let ll = l.length_squared();
        if (hh - 1.0).abs() < 1e-3 && (ll - 1.0).abs() < 1e-3 {
            let heading = h * (1.5 - 0.5 * hh);
            let l = left - heading * heading.dot(left);
            let left = l * (1.5 - 0.5 * l.length_squared());
            Turtle {
                heading: heading.into(),
                left: left.into(),
                up: heading.cross(left).into(),
            }
        } else {
            self.renormalised_exactly()
        }
    }

    /// A frame that drifted too far for one Newton step: [`Frame::renormalise`] itself.
    #[cold]
    #[inline(never)]
    fn renormalised_exactly(self) -> Turtle {
        let mut frame = self.frame();
        frame.renormalise();
        Turtle::of(frame)
    }

    /// [`Frame::turn_h`], [`Frame::turn_l`] or [`Frame::turn_u`].
    #[inline(always)]
    fn turn(&mut self, t: &Pure) {
        match t.axis {
            Axis::H => turn_pair(&mut self.left, &mut self.up, t.x, t.y),
            Axis::L => turn_pair(&mut self.heading, &mut self.up, t.x, t.y),
            Axis::U => turn_pair(&mut self.heading, &mut self.left, t.x, t.y),
        }
    }
}

/// `sylva_core`'s `turn_pair`, lane by lane.
#[inline(always)]
fn turn_pair(a: &mut Vec3A, b: &mut Vec3A, sin: f32, cos: f32) {
    let (x, y) = (*a, *b);
    *a = x * cos + y * sin;
    *b = y * cos - x * sin;
}

/// An automaton's variables ([`VARIABLES`](crate::tree::VARIABLES) of them) and two unused
/// slots, at [`slot`]s.
type Vars = [f32; 8];

/// Where variable `index` lives in [`Vars`]: Length and Thickness in different halves, so
/// that the compiler never reads both with one 16-byte load, which would wait for the 4-byte
/// store an update just made to one of them (a store-forwarding stall, every step). The
/// mask only tells the compiler that the slot is in range.
#[inline(always)]
fn slot(index: u8) -> usize {
    usize::from(index.wrapping_mul(5) & 7)
}

/// [`slot`] of Length and Thickness.
const LENGTH_SLOT: usize = 0;
const THICKNESS_SLOT: usize = 5;

/// The variable at `index`.
#[inline(always)]
fn var(vars: &mut Vars, index: u8) -> &mut f32 {
    &mut vars[slot(index)]
}

/// One live or dead automaton instance.
#[derive(Clone, Copy, Debug)]
struct Inst {
    turtle: Turtle,
    pos: Vec3A,
    /// The variables, and two unused slots, so that an index masked to 0..8 needs no check.
    vars: Vars,
    /// Next block to run.
    pc: u32,
    automaton: u8,
    /// Turns since the frame was last made orthonormal (see [`RENORMALISE`]).
    turns: u8,
    stack_len: u16,
    /// The segment ending at `pos` (`NONE` before the first).
    seg: u32,
    /// The creator's segment this one's first segment hangs from (`NONE` for the root).
    attach: u32,
    /// Where the undrawn run starts, and its mapped thickness there.
    chord_start: Vec3A,
    chord_radius: f32,
    chord_moves: u32,
    /// Thickness recorded at `pos`; mapped ([`map_thickness`]) only when a segment is drawn.
    thickness: f32,
    /// Steps moved.
    moves: u32,
    /// Birth rank among its creator's children (the root is 0).
    index: u32,
    children: u32,
    /// First organ waiting for its parent segment (a list through `organ_next`).
    pending: u32,
    counter_base: u32,
    stack_base: u32,
    /// The iteration of its next step: later than the running one when it ran ahead.
    next_iteration: u32,
}

/// A Push's saved state.
#[derive(Clone, Copy, Debug, Default)]
struct Saved {
    pos: Vec3A,
    turtle: Turtle,
    vars: Vars,
    seg: u32,
    thickness: f32,
    /// The automaton's `moves` when pushed: equal means it has not moved since.
    moves: u32,
}

/// The report's counts that change at every step, kept apart from the report so that they
/// can stay in registers.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    states: u64,
    max_states_per_step: u32,
    automaton_steps: u64,
    points: u32,
    negative_thickness: u32,
}

/// Per-run constants.
struct Cx<'a> {
    program: &'a Program,
    options: GrowOptions,
    full: bool,
    /// Metres per unit of mapped thickness.
    radius_scale: f32,
    gravity: f32,
}

/// Runs compiled programs; keeps its buffers between runs.
#[derive(Clone, Debug, Default)]
pub struct Simulator {
    insts: Vec<Inst>,
    live: Vec<u32>,
    mem: Memory,
    code: Blocks,
}

/// Everything an instance's step touches besides the instance itself, so the instance can be
/// stepped in place (it is 176 bytes: copying it in and out would cost more than its states).
#[derive(Clone, Debug, Default)]
struct Memory {
    stack: Vec<Saved>,
    counters: Vec<u8>,
    organ_next: Vec<u32>,
    /// The plant refused a part (a position beyond its range): growth stops.
    refused: bool,
    /// Instances created during the current iteration, moved into `insts` after it.
    newborn: Vec<Inst>,
    /// The iteration running.
    iteration: u32,
    /// Whether automata may run ahead ([`Memory::run_ahead`]), and whether one did.
    ahead: bool,
    ran_ahead: bool,
}

/// A leaf's orientation. Horizontal leaves are also turned about the vertical by the golden
/// angle times the leaf's index: leaves an automaton adds at one spot (`(Repeat 5
/// (CreateAutomaton Leaf))` is common in evolved trees) fan out instead of lying on top of
/// each other, and the "randomly generated" leaves of section 4.5 stay deterministic.
fn leaf_rotation(frame: &Frame, horizontal: bool, index: u32) -> Quat {
    let m = if horizontal {
        let flat = [frame.up, frame.left, frame.heading]
            .into_iter()
            .map(|v| Vec3::new(v.x, 0.0, v.z))
            .find(|v| v.length_squared() > 1e-4)
            .map_or(Vec3::X, Vec3::normalize);
        let (s, c) = LEAF_DROOP.sin_cos();
        let along = (flat * c - Vec3::Y * s).normalize();
        let face = (Vec3::Y - along * along.y).normalize();
        let fan = Mat3::from_rotation_y(GOLDEN_ANGLE * (index % 1024) as f32);
        fan * Mat3::from_cols(along.cross(face), along, face)
    } else {
        Mat3::from_cols(-frame.left, frame.up, -frame.heading)
    };
    let q = Quat::from_mat3(&m).normalize();
    if q.is_finite() { q } else { Quat::IDENTITY }
}

impl Simulator {
    /// An empty simulator.
    pub fn new() -> Simulator {
        Simulator::default()
    }

    /// Grows `program` into `plant` (its segments and organs are replaced; its metadata is
    /// left as it is; its materials are reset to [`Plant::new`]'s if they are not bark,
    /// leaf, flower) and reports what happened.
    pub fn run(
        &mut self,
        program: &Program,
        options: &GrowOptions,
        detail: Detail,
        plant: &mut Plant,
    ) -> GrowthReport {
        let options = options.sanitized();
        let cx = Cx {
            program,
            options,
            full: detail == Detail::Full,
            radius_scale: options.radius * options.unit,
            gravity: options.gravity.to_radians(),
        };
        // One copy of the loop per level of detail and gravity, so a step tests neither.
        let grow = match (cx.full, cx.gravity > 0.0) {
            (false, false) => Simulator::grow::<false, false>,
            (false, true) => Simulator::grow::<false, true>,
            (true, false) => Simulator::grow::<true, false>,
            (true, true) => Simulator::grow::<true, true>,
        };
        match grow(self, &cx, plant, true) {
            Some(report) => report,
            // Growth stopped at a bound while automata were running ahead: grow again,
            // each step in its turn.
            None => grow(self, &cx, plant, false).unwrap_or_default(),
        }
    }

    /// Grows the program; with `ahead`, an automaton in a loop of simple steps runs the
    /// loop's iterations at once (see [`Memory::run_ahead`]). Steps that draw nothing and
    /// touch nothing but their own automaton can be run early without changing anything,
    /// unless growth stops at a bound (points, states or the extent) before their turn
    /// comes: then `None`, and the caller grows again without `ahead`.
    fn grow<const FULL: bool, const GRAVITY: bool>(
        &mut self,
        cx: &Cx,
        plant: &mut Plant,
        ahead: bool,
    ) -> Option<GrowthReport> {
        let Simulator {
            insts,
            live,
            mem,
            code,
        } = self;
        let (program, options) = (cx.program, &cx.options);
        plant.clear_to_defaults();
        insts.clear();
        live.clear();
        mem.stack.clear();
        mem.counters.clear();
        mem.organ_next.clear();
        mem.newborn.clear();
        mem.refused = false;
        mem.iteration = 0;
        mem.ahead = ahead;
        mem.ran_ahead = false;
        code.reset(program);
        let mut rep = GrowthReport::default();
        if program.automata().is_empty() {
            return Some(rep);
        }
        let mut vars = [0.0; 8];
        vars[LENGTH_SLOT] = options.root_length;
        vars[THICKNESS_SLOT] = 1.0;
        mem.spawn(
            cx,
            code,
            0,
            Vec3A::ZERO,
            Turtle::of(Frame::UPRIGHT),
            vars,
            NONE,
            0,
        );
        // The root runs from the first iteration, a child from the one after its birth.
        mem.newborn[0].next_iteration = 0;
        adopt(insts, live, &mut mem.newborn);
        rep.automata = 1;
        let mut stop = None;
        let mut tally = Tally::default();
        for i in 0..options.iterations {
            if live.is_empty() {
                break;
            }
            mem.iteration = i;
            rep.iterations += 1;
            let n = live.len();
            let (mut read, mut write) = (0, 0);
            {
                // Children wait in `mem.newborn` until the iteration ends, so neither list
                // changes length here.
                let (ids, insts) = (&mut live[..], &mut insts[..]);
                let (points, states) = (options.limits.points, options.limits.states);
                let per_step = u64::from(options.limits.states_per_step);
                // No bound can be reached in this iteration: no checks.
                let unchecked = u64::from(tally.points) + (n as u64) < u64::from(points)
                    && tally.states + n as u64 * per_step < states;
                while read < n {
                    let id = ids[read];
                    read += 1;
                    let me = &mut insts[id as usize];
                    if me.next_iteration > i {
                        // It ran this iteration's step ahead.
                        ids[write] = id;
                        write += 1;
                        continue;
                    }
                    if mem.step::<FULL, GRAVITY>(me, code, cx, plant, &mut rep, &mut tally) {
                        ids[write] = id;
                        write += 1;
                    }
                    if unchecked {
                        continue;
                    }
                    if tally.points >= points {
                        stop = Some(Stop::Points);
                        break;
                    } else if tally.states >= states {
                        stop = Some(Stop::States);
                        break;
                    }
                }
            }
            // Keep what was not run (growth stopped), then the newborn, in order, after the
            // survivors.
            if read < n {
                live.copy_within(read..n, write);
            }
            live.truncate(write + n - read);
            if !mem.newborn.is_empty() {
                adopt(insts, live, &mut mem.newborn);
            }
            rep.peak_live = rep.peak_live.max(live.len() as u32);
            // A refused part ends growth at the end of its iteration (checked here, off the
            // per-automaton path).
            if mem.refused && stop.is_none() {
                stop = Some(Stop::Extent);
            }
            if stop.is_some() {
                break;
            }
        }
        // Steps run ahead are counted before their turn, so a bound may have been reached
        // with no check after it; in either case growth should have stopped at a step that
        // came before some of them.
        let passed = tally.points >= options.limits.points || tally.states >= options.limits.states;
        if mem.ran_ahead && (stop.is_some() || passed) {
            return None;
        }
        rep.states = tally.states;
        rep.max_states_per_step = tally.max_states_per_step;
        rep.automaton_steps = tally.automaton_steps;
        rep.points = tally.points;
        rep.negative_thickness = tally.negative_thickness;
        rep.stop = match stop {
            Some(s) => s,
            None if live.is_empty() => Stop::AllDead,
            None => Stop::Iterations,
        };
        rep.bounds.points = rep.stop == Stop::Points;
        rep.bounds.states = rep.stop == Stop::States;
        rep.bounds.extent = rep.stop == Stop::Extent;
        rep.live_at_end = live.len() as u32;
        for &id in live.iter() {
            mem.finish(&mut insts[id as usize], cx, plant);
        }
        rep.segments = plant.segments().len() as u32;
        Some(rep)
    }
}

/// Moves the newborn into the instances, live from the next iteration.
fn adopt(insts: &mut Vec<Inst>, live: &mut Vec<u32>, newborn: &mut Vec<Inst>) {
    for inst in newborn.drain(..) {
        live.push(insts.len() as u32);
        insts.push(inst);
    }
}

/// Updates `vars` as the state of `u` does; returns whether the value was clamped.
#[inline(always)]
fn update(vars: &mut Vars, u: &Pure) -> bool {
    let v = var(vars, u.var);
    let r = match u.update {
        Update::Assign => {
            *v = u.x;
            return false;
        }
        Update::Add => *v + u.x,
        Update::Multiply => *v * u.x,
    };
    if r.abs() > VARIABLE_LIMIT {
        *v = r.clamp(-VARIABLE_LIMIT, VARIABLE_LIMIT);
        true
    } else {
        *v = r;
        false
    }
}

/// Sets the counters of block `b`'s `Repeat` entries.
#[inline(always)]
fn set_counters(b: &Block, counters: &mut [u8]) {
    if b.sets > 0 {
        counters[usize::from(b.set_slot[0])] = b.set_value[0];
        if b.sets > 1 {
            counters[usize::from(b.set_slot[1])] = b.set_value[1];
        }
    }
}

/// Runs the turns and updates of block `b`.
#[inline(always)]
fn run_pure(b: &Block, extra: &[Pure], me: &mut Inst, rep: &mut GrowthReport) {
    let mut extra = &extra[b.extra as usize..];
    if b.turns > 0 {
        me.turtle.turn(&b.turn);
        me.turns = me.turns.saturating_add(b.turns);
        if b.turns > 1 {
            let (more, rest) = extra.split_at(usize::from(b.turns - 1));
            for t in more {
                me.turtle.turn(t);
            }
            extra = rest;
        }
    }
    if b.updates > 0 {
        if update(&mut me.vars, &b.update) {
            rep.bounds.clamped_values += 1;
        }
        if b.updates > 1 {
            for u in &extra[..usize::from(b.updates - 1)] {
                if update(&mut me.vars, u) {
                    rep.bounds.clamped_values += 1;
                }
            }
        }
    }
}

/// Runs block `b`, which ends its step with at most one turn and one update, with the code
/// made for its shape (see [`Block::shape`]); `false`, having done nothing, when its head's
/// counter is 0.
#[inline(always)]
fn shaped(b: &Block, me: &mut Inst, counters: &mut [u8], rep: &mut GrowthReport) -> bool {
    /// One shape: head or not, axis 0 (none) or 1 + [`Axis`], update 0 or 1 + [`Update`].
    #[inline(always)]
    fn run<const HEAD: bool, const AXIS: u8, const UPDATE: u8>(
        b: &Block,
        me: &mut Inst,
        counters: &mut [u8],
        rep: &mut GrowthReport,
    ) -> bool {
        if HEAD {
            let c = &mut counters[usize::from(b.head_slot)];
            if *c == 0 {
                return false;
            }
            *c -= 1;
        }
        set_counters(b, counters);
        let (t, pair) = (&b.turn, &mut me.turtle);
        match AXIS {
            1 => turn_pair(&mut pair.left, &mut pair.up, t.x, t.y),
            2 => turn_pair(&mut pair.heading, &mut pair.up, t.x, t.y),
            3 => turn_pair(&mut pair.heading, &mut pair.left, t.x, t.y),
            _ => {}
        }
        if AXIS != 0 {
            me.turns = me.turns.saturating_add(1);
        }
        if UPDATE != 0 && update(&mut me.vars, &b.update) {
            rep.bounds.clamped_values += 1;
        }
        true
    }
    macro_rules! shapes {
        ($($shape:literal => $head:literal, $axis:literal, $update:literal;)*) => {
            match b.shape {
                $($shape => run::<$head, $axis, $update>(b, me, counters, rep),)*
                _ => false,
            }
        };
    }
    shapes! {
        1 => false, 0, 0; 2 => false, 0, 1; 3 => false, 0, 2; 4 => false, 0, 3;
        5 => false, 1, 0; 6 => false, 1, 1; 7 => false, 1, 2; 8 => false, 1, 3;
        9 => false, 2, 0; 10 => false, 2, 1; 11 => false, 2, 2; 12 => false, 2, 3;
        13 => false, 3, 0; 14 => false, 3, 1; 15 => false, 3, 2; 16 => false, 3, 3;
        17 => true, 0, 0; 18 => true, 0, 1; 19 => true, 0, 2; 20 => true, 0, 3;
        21 => true, 1, 0; 22 => true, 1, 1; 23 => true, 1, 2; 24 => true, 1, 3;
        25 => true, 2, 0; 26 => true, 2, 1; 27 => true, 2, 2; 28 => true, 2, 3;
        29 => true, 3, 0; 30 => true, 3, 1; 31 => true, 3, 2; 32 => true, 3, 3;
    }
}

/// An automaton running ahead ([`Memory::run_ahead`]), in registers.
#[derive(Clone, Copy)]
struct Hot {
    turtle: Turtle,
    pos: Vec3A,
    vars: Vars,
    turns: u32,
    /// Moves with a negative Thickness, values clamped.
    negative: u32,
    clamped: u32,
}

impl Hot {
    /// The move of [`Memory::advance`] (the automaton's Push stack is empty, and only the
    /// last Thickness recorded is kept, by the caller).
    #[inline(always)]
    fn advance<const GRAVITY: bool>(&mut self, gravity: f32) {
        if GRAVITY {
            self.turtle.fall(gravity, &mut self.turns);
        }
        if self.turns >= u32::from(RENORMALISE) {
            self.turtle = self.turtle.renormalised();
            self.turns = 0;
        }
        self.pos += self.turtle.heading * self.vars[LENGTH_SLOT];
        self.negative += u32::from(self.vars[THICKNESS_SLOT] < 0.0);
    }
}

/// `m` more rounds of a loop whose body is block `b` (a head, then as in [`shaped`]'s
/// `AXIS` and `UPDATE`, then a Wait back to `b`), each a step followed by its move: the
/// loop as it would be written for this block, with the updated variable, Length and
/// Thickness in registers.
#[inline(always)]
fn rounds<const AXIS: u8, const UPDATE: u8, const GRAVITY: bool>(
    b: &Block,
    hot: &mut Hot,
    m: u32,
    gravity: f32,
) {
    let (mut turtle, mut pos, mut turns) = (hot.turtle, hot.pos, hot.turns);
    let (t, u) = (b.turn, b.update);
    let target = slot(u.var);
    let mut value = hot.vars[target];
    let (mut length, mut thickness) = (hot.vars[LENGTH_SLOT], hot.vars[THICKNESS_SLOT]);
    let (mut negative, mut clamped) = (0, 0);
    for _ in 0..m {
        match AXIS {
            1 => turn_pair(&mut turtle.left, &mut turtle.up, t.x, t.y),
            2 => turn_pair(&mut turtle.heading, &mut turtle.up, t.x, t.y),
            3 => turn_pair(&mut turtle.heading, &mut turtle.left, t.x, t.y),
            _ => {}
        }
        if AXIS != 0 {
            turns += 1;
        }
        if UPDATE != 0 {
            let r = match UPDATE {
                1 => u.x,
                2 => value + u.x,
                _ => value * u.x,
            };
            value = if UPDATE != 1 && r.abs() > VARIABLE_LIMIT {
                clamped += 1;
                r.clamp(-VARIABLE_LIMIT, VARIABLE_LIMIT)
            } else {
                r
            };
            if target == LENGTH_SLOT {
                length = value;
            } else if target == THICKNESS_SLOT {
                thickness = value;
            }
        }
        if GRAVITY {
            turtle.fall(gravity, &mut turns);
        }
        if turns >= u32::from(RENORMALISE) {
            turtle = turtle.renormalised();
            turns = 0;
        }
        pos += turtle.heading * length;
        negative += u32::from(thickness < 0.0);
    }
    if UPDATE != 0 {
        hot.vars[target] = value;
    }
    (hot.turtle, hot.pos, hot.turns) = (turtle, pos, turns);
    hot.negative += negative;
    hot.clamped += clamped;
}

/// After block `b` (block `here`) went on to block `pc`: when that is `b` again and `b` only
/// enters empty loops (a `RepeatIndex` counting 0 in a late child, say), its loop spins
/// through its remaining rounds and then leaves by its test. Does that at once when the
/// budget allows (moving `pc` on), and returns the budget left.
#[inline(always)]
fn spin(b: &Block, here: usize, budget: u32, counters: &mut [u8], pc: &mut usize) -> u32 {
    if *pc != here || b.head_alt == NONE || b.turns + b.updates + b.sets != 0 {
        return budget;
    }
    let c = &mut counters[usize::from(b.head_slot)];
    let spin = b.cost * u32::from(*c) + 1;
    if budget < spin {
        return budget;
    }
    *c = 0;
    *pc = b.head_alt as usize;
    budget - spin
}

/// Whether `outer`, the block `inner`'s loop test sends it to when its counter is 0 (`inner`
/// is block `at`, a loop waiting in its own test), is the test of an outer loop whose round
/// only enters `inner`'s loop again: it sets that loop's counter and then does what `inner`
/// does (the same turn and update, bit for bit) and waits, going on with `inner`. Then every
/// step of the two loops is the same turn, update and move.
#[inline(always)]
fn reenters(inner: &Block, at: usize, outer: &Block, limit: u32) -> bool {
    let same = |a: &Pure, b: &Pure| {
        a.axis == b.axis
            && a.update == b.update
            && a.var == b.var
            && a.x.to_bits() == b.x.to_bits()
            && a.y.to_bits() == b.y.to_bits()
    };
    outer.shape != 0
        && outer.head_alt != NONE
        && outer.next as usize == at
        && outer.sets == 1
        && outer.set_slot[0] == inner.head_slot
        && outer.cost < limit
        && outer.turns == inner.turns
        && outer.updates == inner.updates
        && (inner.turns == 0 || same(&outer.turn, &inner.turn))
        && (inner.updates == 0 || same(&outer.update, &inner.update))
}

/// Runs block `b` when the budget may not cover it, state by state as the reference does:
/// `Some(block)` when the head's counter is 0 (the head sends it there), `None` when the
/// automaton is killed (reported). A state that finds the budget spent kills, so a kill
/// ends with the budget spent, except that a loop entered by its outer loop's test (a
/// `RepeatNest`) is killed before either of its two states is charged.
#[cold]
#[inline(never)]
fn tight(
    b: &Block,
    extra: &[Pure],
    budget: &mut u32,
    me: &mut Inst,
    counters: &mut [u8],
    rep: &mut GrowthReport,
) -> Option<u32> {
    let head = b.head_alt != NONE;
    if head {
        if *budget == 0 {
            rep.bounds.state_limit_kills += 1;
            return None;
        }
        *budget -= 1;
        let c = &mut counters[usize::from(b.head_slot)];
        if *c == 0 {
            return Some(b.head_alt);
        }
        *c -= 1;
    }
    rep.bounds.state_limit_kills += 1;
    // The states between head and terminator, in program order, until the budget runs out.
    let extra = &extra[b.extra as usize..];
    let more_turns = usize::from(b.turns.saturating_sub(1));
    let (mut t, mut u, mut i) = (0, 0, 0);
    while i < u32::from(b.pure) {
        if b.entries & (1 << i) != 0 {
            // A `Repeat` entry: two states (its counter does not matter to a dead automaton).
            if *budget < 2 {
                if !(head && i == 0) {
                    *budget = 0;
                }
                return None;
            }
            *budget -= 2;
            i += 2;
            continue;
        }
        if *budget == 0 {
            return None;
        }
        *budget -= 1;
        if b.order & (1 << i) != 0 {
            me.turtle.turn(if t == 0 { &b.turn } else { &extra[t - 1] });
            t += 1;
        } else {
            let op = if u == 0 {
                &b.update
            } else {
                &extra[more_turns + u - 1]
            };
            if update(&mut me.vars, op) {
                rep.bounds.clamped_values += 1;
            }
            u += 1;
        }
        i += 1;
    }
    // The terminator does not fit.
    let nest = head && b.pure == 0;
    if !(nest && matches!(b.term, Term::RepeatInit | Term::RepeatIndexInit)) {
        *budget = 0;
    }
    None
}

impl Memory {
    /// Adds an instance of automaton `automaton` (0-based) to the newborn.
    #[allow(clippy::too_many_arguments)]
    fn spawn(
        &mut self,
        cx: &Cx,
        code: &Blocks,
        automaton: usize,
        pos: Vec3A,
        turtle: Turtle,
        vars: Vars,
        attach: u32,
        index: u32,
    ) {
        let automata = cx.program.automata()[automaton];
        let thickness = vars[THICKNESS_SLOT];
        self.newborn.push(Inst {
            pos,
            turtle,
            vars,
            pc: code.entries[automaton],
            automaton: automaton as u8,
            turns: RENORMALISE,
            stack_len: 0,
            seg: NONE,
            attach,
            chord_start: pos,
            chord_radius: map_thickness(thickness),
            chord_moves: 0,
            thickness,
            moves: 0,
            index,
            children: 0,
            pending: NONE,
            counter_base: self.counters.len() as u32,
            stack_base: self.stack.len() as u32,
            next_iteration: self.iteration + 1,
        });
        self.counters
            .resize(self.counters.len() + usize::from(automata.counters), 0);
        self.stack.resize(
            self.stack.len() + usize::from(automata.push_depth),
            Saved::default(),
        );
    }

    /// Runs an instance for one iteration; `false` when it died.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn step<const FULL: bool, const GRAVITY: bool>(
        &mut self,
        me: &mut Inst,
        code: &mut Blocks,
        cx: &Cx,
        plant: &mut Plant,
        rep: &mut GrowthReport,
        tally: &mut Tally,
    ) -> bool {
        let limit = cx.options.limits.states_per_step;
        let mut pc = me.pc as usize;
        let mut budget = limit;
        let counters = &mut self.counters[me.counter_base as usize..];
        // The commonest step: one block, then Wait (after loop tests that send it on).
        loop {
            let b = &code.blocks[pc];
            if b.shape == 0 || b.cost > budget {
                break;
            }
            if !shaped(b, me, counters, rep) {
                // The head's counter is 0: the test sends it on.
                budget -= 1;
                pc = b.head_alt as usize;
                continue;
            }
            me.pc = b.next;
            let run = limit - budget + b.cost;
            tally.states += u64::from(run);
            tally.max_states_per_step = tally.max_states_per_step.max(run);
            tally.automaton_steps += 1;
            me.next_iteration = self.iteration + 1;
            self.advance::<FULL, GRAVITY>(me, cx, plant, tally);
            if !FULL
                && self.ahead
                && me.stack_len == 0
                && me.next_iteration < cx.options.iterations
                && code.blocks[me.pc as usize].shape != 0
            {
                self.run_ahead::<GRAVITY>(me, code, cx, rep, tally);
            }
            return true;
        }
        self.step_blocks::<FULL, GRAVITY>(me, pc, budget, code, cx, plant, rep, tally)
    }

    /// [`Memory::step`] for any program, from block `pc` with `budget` states left: block
    /// after block until a Wait or a death.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn step_blocks<const FULL: bool, const GRAVITY: bool>(
        &mut self,
        me: &mut Inst,
        mut pc: usize,
        mut budget: u32,
        code: &mut Blocks,
        cx: &Cx,
        plant: &mut Plant,
        rep: &mut GrowthReport,
        tally: &mut Tally,
    ) -> bool {
        let limit = cx.options.limits.states_per_step;
        let base = me.counter_base as usize;
        let mut counters = &mut self.counters[base..];
        let (mut blocks, mut extra) = (&code.blocks[..], &code.extra[..]);
        let alive = loop {
            let here = pc;
            let b = &blocks[pc];
            if budget < b.cost {
                // Rare: the block is not built yet, or the budget runs out in it.
                if b.head_alt == UNBUILT {
                    code.build(cx.program, pc);
                    (blocks, extra) = (&code.blocks[..], &code.extra[..]);
                    continue;
                }
                match tight(b, extra, &mut budget, me, counters, rep) {
                    Some(alt) => {
                        pc = alt as usize;
                        continue;
                    }
                    None => break false,
                }
            }
            if b.head_alt != NONE {
                let c = &mut counters[usize::from(b.head_slot)];
                if *c == 0 {
                    budget -= 1;
                    pc = b.head_alt as usize;
                    continue;
                }
                *c -= 1;
            }
            budget -= b.cost;
            if b.pure > 0 {
                set_counters(b, counters);
                run_pure(b, extra, me, rep);
            }
            pc = b.next as usize;
            match b.term {
                Term::Wait => break true,
                Term::Goto => budget = spin(b, here, budget, counters, &mut pc),
                Term::IfLess => {
                    if *var(&mut me.vars, b.arg) >= b.x {
                        pc = b.alt as usize;
                    }
                }
                Term::IfGreater => {
                    if *var(&mut me.vars, b.arg) <= b.x {
                        pc = b.alt as usize;
                    }
                }
                Term::IfEqual => {
                    if (*var(&mut me.vars, b.arg) - b.x).abs() > b.y {
                        pc = b.alt as usize;
                    }
                }
                Term::RepeatInit | Term::RepeatIndexInit => {
                    let count = if b.term == Term::RepeatInit {
                        b.x as u8
                    } else {
                        (b.x - me.index.min(255) as f32).max(0.0) as u8
                    };
                    if count > 0 {
                        counters[usize::from(b.slot)] = count - 1;
                    } else {
                        pc = b.alt as usize;
                        budget = spin(b, here, budget, counters, &mut pc);
                    }
                }
                Term::End => {
                    if cx.program.restarts() {
                        pc = code.entries[usize::from(me.automaton)] as usize;
                    } else {
                        break false;
                    }
                }
                Term::Kill => break false,
                term @ (Term::Push | Term::Pop | Term::Create | Term::Leaf | Term::Flower) => {
                    let arg = b.arg;
                    self.turtle_state(me, term, arg, cx, code, plant, rep);
                    // A creation may have moved the counters.
                    counters = &mut self.counters[base..];
                }
            }
        };
        me.pc = pc as u32;
        let run = limit - budget;
        tally.states += u64::from(run);
        tally.max_states_per_step = tally.max_states_per_step.max(run);
        tally.automaton_steps += 1;
        me.next_iteration = self.iteration + 1;
        if alive {
            self.advance::<FULL, GRAVITY>(me, cx, plant, tally);
        } else {
            self.finish(me, cx, plant);
        }
        alive
    }

    /// Runs a Push, Pop, creation or organ: the states that read or reset the turtle.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn turtle_state(
        &mut self,
        me: &mut Inst,
        term: Term,
        arg: u8,
        cx: &Cx,
        code: &Blocks,
        plant: &mut Plant,
        rep: &mut GrowthReport,
    ) {
        match term {
            Term::Push => self.push(me, cx),
            Term::Pop => self.pop(me, cx, plant),
            Term::Create => self.create(me, usize::from(arg), cx, code, plant, rep),
            Term::Leaf => self.organ(me, OrganKind::Leaf, cx, plant, rep),
            _ => self.organ(me, OrganKind::Flower, cx, plant, rep),
        }
    }

    /// After a step that ended in a Wait: runs the automaton's next steps now, one per
    /// growth iteration to come, as long as each is one block (after loop tests that send
    /// it on) of at most one turn and one update and its Wait, with the automaton in
    /// registers; a loop that waits in its own test runs its rounds in a loop made for its
    /// block. These steps draw nothing, create nothing and touch nothing but this automaton
    /// (its Push stack is empty, so a move closes no segment), so running them early changes
    /// nothing, unless growth stops at a bound before their turn (see [`Simulator::grow`]).
    /// A step that does not qualify is not started: it runs in its turn.
    #[inline(never)]
    fn run_ahead<const GRAVITY: bool>(
        &mut self,
        me: &mut Inst,
        code: &Blocks,
        cx: &Cx,
        rep: &mut GrowthReport,
        tally: &mut Tally,
    ) {
        // The caller checked that its Push stack is empty and iterations are left.
        let left = cx.options.iterations - me.next_iteration;
        let limit = cx.options.limits.states_per_step;
        let counters = &mut self.counters[me.counter_base as usize..];
        let mut hot = Hot {
            turtle: me.turtle,
            pos: me.pos,
            vars: me.vars,
            turns: u32::from(me.turns),
            negative: 0,
            clamped: 0,
        };
        let (mut pc, mut done) = (me.pc as usize, 0);
        let (mut states, mut most) = (0u64, tally.max_states_per_step);
        while done < left {
            // The step's block, after the loop tests that send it on; the step does not
            // start (nothing has changed) if that block does not qualify.
            let (mut budget, mut at) = (limit, pc);
            let shaped = loop {
                let b = &code.blocks[at];
                if b.shape == 0 || b.cost > budget {
                    break false;
                }
                if b.head_alt == NONE {
                    break true;
                }
                let c = &mut counters[usize::from(b.head_slot)];
                if *c > 0 {
                    *c -= 1;
                    break true;
                }
                budget -= 1;
                at = b.head_alt as usize;
            };
            if !shaped {
                break;
            }
            let blocks = &code.blocks[..];
            let b = &blocks[at];
            pc = at;
            let run = limit - budget + b.cost;
            if b.next as usize == pc && b.head_alt != NONE && b.sets == 0 {
                // A loop waiting in its own test: this round and the counter's others, and
                // when an outer loop only enters it again, that loop's rounds too.
                let avail = left - done;
                let inner = u32::from(counters[usize::from(b.head_slot)]) + 1;
                let mut m = inner.min(avail);
                let o = &blocks[b.head_alt as usize];
                if m == inner && m < avail && reenters(b, pc, o, limit) {
                    let round = 1 + u32::from(o.set_value[0]);
                    let outer = u32::from(counters[usize::from(o.head_slot)]);
                    m = (inner + outer * round).min(avail);
                    // Steps past the inner loop's: each round of the outer loop is a step
                    // of `o` (after `b`'s test) and then `round - 1` steps of `b`.
                    let past = m - inner;
                    let entered = past.div_ceil(round);
                    let rest = past % round;
                    counters[usize::from(o.head_slot)] -= entered as u8;
                    counters[usize::from(b.head_slot)] =
                        if rest > 0 { (round - rest) as u8 } else { 0 };
                    states += u64::from(entered) * u64::from(1 + o.cost)
                        + u64::from(past - entered) * u64::from(b.cost);
                    if entered > 0 {
                        most = most.max(1 + o.cost);
                    }
                } else {
                    counters[usize::from(b.head_slot)] -= (m - 1) as u8;
                }
                macro_rules! shapes {
                    ($($shape:literal => $axis:literal, $update:literal;)*) => {
                        match b.shape {
                            $($shape => rounds::<$axis, $update, GRAVITY>(b, &mut hot, m, cx.gravity),)*
                            _ => unreachable!("a block with a head"),
                        }
                    };
                }
                shapes! {
                    17 => 0, 0; 18 => 0, 1; 19 => 0, 2; 20 => 0, 3;
                    21 => 1, 0; 22 => 1, 1; 23 => 1, 2; 24 => 1, 3;
                    25 => 2, 0; 26 => 2, 1; 27 => 2, 2; 28 => 2, 3;
                    29 => 3, 0; 30 => 3, 1; 31 => 3, 2; 32 => 3, 3;
                }
                states += u64::from(run) + u64::from(m.min(inner) - 1) * u64::from(b.cost);
                most = most.max(run).max(b.cost);
                done += m;
                continue;
            }
            set_counters(b, counters);
            if b.turns > 0 {
                hot.turtle.turn(&b.turn);
                hot.turns += 1;
            }
            if b.updates > 0 && update(&mut hot.vars, &b.update) {
                hot.clamped += 1;
            }
            hot.advance::<GRAVITY>(cx.gravity);
            states += u64::from(run);
            most = most.max(run);
            pc = b.next as usize;
            done += 1;
        }
        if done == 0 {
            return;
        }
        self.ran_ahead = true;
        me.turtle = hot.turtle;
        me.pos = hot.pos;
        me.vars = hot.vars;
        me.turns = hot.turns.min(255) as u8;
        me.pc = pc as u32;
        me.next_iteration += done;
        me.moves += done;
        me.chord_moves += done;
        me.thickness = me.vars[THICKNESS_SLOT];
        tally.states += states;
        tally.max_states_per_step = most;
        tally.automaton_steps += u64::from(done);
        tally.points += done;
        tally.negative_thickness += hot.negative;
        rep.bounds.clamped_values += hot.clamped;
    }

    /// Moves one step along H and records the position.
    #[inline(always)]
    fn advance<const FULL: bool, const GRAVITY: bool>(
        &mut self,
        me: &mut Inst,
        cx: &Cx,
        plant: &mut Plant,
        tally: &mut Tally,
    ) {
        if GRAVITY {
            let mut turns = u32::from(me.turns);
            me.turtle.fall(cx.gravity, &mut turns);
            me.turns = turns.min(255) as u8;
        }
        if me.turns >= RENORMALISE {
            me.turtle = me.turtle.renormalised();
            me.turns = 0;
        }
        // Pushes since the last move: the point they saved becomes a segment boundary.
        let top = usize::from(me.stack_len);
        if top > 0 {
            self.saved_points(me, cx, plant);
        }
        me.pos += me.turtle.heading * me.vars[LENGTH_SLOT];
        me.moves += 1;
        me.chord_moves += 1;
        let thickness = me.vars[THICKNESS_SLOT];
        tally.negative_thickness += u32::from(thickness < 0.0);
        me.thickness = thickness;
        tally.points += 1;
        if FULL {
            self.close_chord(me, cx, plant);
        }
    }

    /// Before a move with Pushes on the stack: those made since the last move saved this
    /// point, which becomes a segment boundary.
    #[inline(never)]
    fn saved_points(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        let top = usize::from(me.stack_len);
        let base = me.stack_base as usize;
        if self.stack[base + top - 1].moves == me.moves {
            self.close_chord(me, cx, plant);
            for saved in self.stack[base..base + top].iter_mut().rev() {
                if saved.moves != me.moves {
                    break;
                }
                saved.seg = me.seg;
            }
        }
    }

    /// Saves position, frame and variables.
    fn push(&mut self, me: &mut Inst, cx: &Cx) {
        let code = cx.program.automata()[usize::from(me.automaton)];
        // Always true for compiled programs; a guard, not a bound.
        if me.stack_len < code.push_depth {
            self.stack[(me.stack_base + u32::from(me.stack_len)) as usize] = Saved {
                pos: me.pos,
                turtle: me.turtle,
                vars: me.vars,
                seg: me.seg,
                thickness: me.thickness,
                moves: me.moves,
            };
            me.stack_len += 1;
        }
    }

    /// Restores the last Push.
    fn pop(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        if me.stack_len == 0 {
            return;
        }
        me.stack_len -= 1;
        let saved = self.stack[(me.stack_base + u32::from(me.stack_len)) as usize];
        me.turtle = saved.turtle;
        me.vars = saved.vars;
        me.turns = RENORMALISE;
        if saved.moves == me.moves {
            // Not moved since the Push: nothing was drawn, the position is the same.
            return;
        }
        // The path drawn since the Push ends here; continue from the saved point.
        self.close_chord(me, cx, plant);
        let seg = me.seg;
        self.patch_organs(me, plant, seg);
        me.pos = saved.pos;
        me.seg = saved.seg;
        me.thickness = saved.thickness;
        me.chord_start = saved.pos;
        me.chord_radius = map_thickness(saved.thickness);
        me.chord_moves = 0;
    }

    /// Draws the run since the last segment, if the automaton moved.
    fn close_chord(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        if me.chord_moves == 0 {
            return;
        }
        let radius = map_thickness(me.thickness);
        let id = self.segment(me, me.chord_start, me.chord_radius, radius, cx, plant);
        me.seg = id;
        me.chord_start = me.pos;
        me.chord_radius = radius;
        me.chord_moves = 0;
        self.patch_organs(me, plant, id);
    }

    /// Gives the waiting organs their parent segment.
    fn patch_organs(&mut self, me: &mut Inst, plant: &mut Plant, seg: u32) {
        let parent = (seg != NONE).then_some(SegmentId(seg));
        let mut o = me.pending;
        while o != NONE {
            // The parent was just drawn and the organ added: neither can be missing.
            self.refused |= plant.set_organ_parent(o as usize, parent).is_err();
            o = self.organ_next[o as usize];
        }
        me.pending = NONE;
    }

    /// The end of an automaton (death, or the end of growth).
    fn finish(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        self.close_chord(me, cx, plant);
        let seg = if me.seg != NONE { me.seg } else { me.attach };
        self.patch_organs(me, plant, seg);
    }

    fn create(
        &mut self,
        me: &mut Inst,
        automaton: usize,
        cx: &Cx,
        code: &Blocks,
        plant: &mut Plant,
        rep: &mut GrowthReport,
    ) {
        if rep.automata >= cx.options.limits.automata || automaton >= cx.program.automata().len() {
            rep.bounds.automata_refused += 1;
            return;
        }
        // The creation point becomes a segment boundary of the creator.
        self.close_chord(me, cx, plant);
        if me.seg == NONE {
            let radius = map_thickness(me.thickness);
            me.seg = self.segment(me, me.pos, radius, radius, cx, plant);
        }
        let vars = match cx.options.child_variables {
            ChildVariables::All => me.vars,
            ChildVariables::LengthThickness => {
                let mut v = [0.0; 8];
                v[LENGTH_SLOT] = me.vars[LENGTH_SLOT];
                v[THICKNESS_SLOT] = me.vars[THICKNESS_SLOT];
                v
            }
            ChildVariables::Fresh => {
                let mut v = [0.0; 8];
                v[LENGTH_SLOT] = 1.0;
                v[THICKNESS_SLOT] = 1.0;
                v
            }
        };
        self.spawn(
            cx,
            code,
            automaton,
            me.pos,
            me.turtle,
            vars,
            me.seg,
            me.children,
        );
        me.children += 1;
        rep.automata += 1;
    }

    fn organ(
        &mut self,
        me: &mut Inst,
        kind: OrganKind,
        cx: &Cx,
        plant: &mut Plant,
        rep: &mut GrowthReport,
    ) {
        if rep.leaves + rep.flowers >= cx.options.limits.organs {
            rep.bounds.organs_refused += 1;
            return;
        }
        let unit = cx.options.unit;
        let mut frame = me.turtle.frame();
        if cx.full && me.turns > 0 {
            frame.renormalise();
        }
        let (orientation, size, material) = if kind == OrganKind::Leaf {
            rep.leaves += 1;
            let len = cx.options.leaf_length * unit;
            let q = if cx.full {
                leaf_rotation(&frame, cx.options.horizontal_leaves, rep.leaves)
            } else {
                Quat::IDENTITY
            };
            (q, Vec2::new(len, 0.4 * len), Plant::LEAF)
        } else {
            rep.flowers += 1;
            let size = cx.options.flower_size * unit;
            let q = if cx.full {
                frame.rotation()
            } else {
                Quat::IDENTITY
            };
            (
                if q.is_finite() { q } else { Quat::IDENTITY },
                Vec2::new(size, 0.35 * size),
                Plant::FLOWER,
            )
        };
        let organ = Organ {
            kind,
            position: Vec3::from(me.pos) * unit,
            orientation,
            size,
            material,
            parent: None,
        };
        if plant.add_organ(organ).is_err() {
            self.refused = true;
            return;
        }
        self.organ_next.push(me.pending);
        me.pending = (plant.organs().len() - 1) as u32;
    }

    /// Draws the segment from `start` to the instance's position, with mapped thicknesses
    /// `start_radius` and `radius`; [`NONE`] (and growth stops) if the plant refuses it.
    #[inline(always)]
    fn segment(
        &mut self,
        me: &Inst,
        start: Vec3A,
        start_radius: f32,
        radius: f32,
        cx: &Cx,
        plant: &mut Plant,
    ) -> u32 {
        let (parent, lateral) = if me.seg != NONE {
            (me.seg, false)
        } else {
            (me.attach, me.attach != NONE)
        };
        let parent = (parent != NONE).then_some(SegmentId(parent));
        let unit = cx.options.unit;
        let radii = (start_radius * cx.radius_scale, radius * cx.radius_scale);
        match plant.add_segment(
            Vec3::from(start) * unit,
            Vec3::from(me.pos) * unit,
            radii,
            parent,
            lateral,
            Plant::BARK,
        ) {
            Ok(id) => id.0,
            Err(_) => {
                self.refused = true;
                NONE
            }
        }
    }
}
