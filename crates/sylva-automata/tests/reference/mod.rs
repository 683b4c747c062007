//! The simulator as it was before straight-line blocks and running ahead: one dispatch per
//! state, with the compiler's fused states (`RepeatWait`, `RepeatNest`, a loop entry's first
//! test) and nothing else.
//!
//! It is kept, unchanged, as the baseline and the test oracle of
//! [`Simulator`](sylva_automata::sim::Simulator): `tests/automata_reference.rs` grows random,
//! evolved and hand-made programs with both and requires the same [`Plant`] and
//! [`GrowthReport`] bit for bit, and every group of `benches/automata.rs` measures both in one
//! run (it includes this file). It lives with the tests, outside the crate it checks.

use glam::{Mat3, Quat, Vec2, Vec3};
use sylva_core::{Frame, Organ, OrganKind, Plant, SegmentId};

use sylva_automata::compile::{Op, Program, State};
use sylva_automata::sim::{
    ChildVariables, Detail, GrowOptions, GrowthReport, Stop, VARIABLE_LIMIT, map_thickness,
};
use sylva_automata::tree::{VARIABLES, Var};

// The simulator's own constants, repeated: the oracle stands apart from what it checks (a
// change to one of them shows as a difference in the tests).
const NONE: u32 = u32::MAX;
const LENGTH: usize = 0;
const THICKNESS: usize = 1;
/// Turns after which a frame is made orthonormal again.
const RENORMALISE: u8 = 16;
/// The golden angle, radians.
const GOLDEN_ANGLE: f32 = 2.399_963_2;
/// Leaves droop this far below horizontal, radians (10°).
const LEAF_DROOP: f32 = 0.174_532_93;

/// One live or dead automaton instance.
#[derive(Clone, Copy, Debug)]
struct Inst {
    pos: Vec3,
    frame: Frame,
    vars: [f32; VARIABLES],
    /// Next state to run.
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
    chord_start: Vec3,
    chord_radius: f32,
    chord_moves: u32,
    /// Mapped thickness recorded at `pos`.
    radius: f32,
    /// Steps moved.
    moves: u32,
    /// Birth rank among its creator's children (the root is 0).
    index: u32,
    children: u32,
    /// First organ waiting for its parent segment (a list through `organ_next`).
    pending: u32,
    counter_base: u32,
    stack_base: u32,
}

/// A Push's saved state.
#[derive(Clone, Copy, Debug, Default)]
struct Saved {
    pos: Vec3,
    frame: Frame,
    vars: [f32; VARIABLES],
    seg: u32,
    radius: f32,
    /// The automaton's `moves` when pushed: equal means it has not moved since.
    moves: u32,
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

/// The baseline simulator: runs compiled programs state by state; keeps its buffers between
/// runs.
#[derive(Clone, Debug, Default)]
pub struct ReferenceSimulator {
    insts: Vec<Inst>,
    live: Vec<u32>,
    mem: Memory,
}

/// Everything an instance's step touches besides the instance itself, so the instance can be
/// stepped in place (it is 140 bytes: copying it in and out cost more than its states).
#[derive(Clone, Debug, Default)]
struct Memory {
    stack: Vec<Saved>,
    counters: Vec<u8>,
    organ_next: Vec<u32>,
    /// The plant refused a part (a position beyond its range): growth stops.
    refused: bool,
    /// Instances created during the current step, moved into `insts` after it.
    newborn: Vec<Inst>,
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

impl ReferenceSimulator {
    /// An empty simulator.
    pub fn new() -> ReferenceSimulator {
        ReferenceSimulator::default()
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
        plant.clear_to_defaults();
        let ReferenceSimulator { insts, live, mem } = self;
        insts.clear();
        live.clear();
        mem.stack.clear();
        mem.counters.clear();
        mem.organ_next.clear();
        mem.newborn.clear();
        mem.refused = false;
        let mut rep = GrowthReport::default();
        if program.automata().is_empty() {
            return rep;
        }
        let mut vars = [0.0; VARIABLES];
        vars[LENGTH] = options.root_length;
        vars[THICKNESS] = 1.0;
        mem.spawn(&cx, 0, Vec3::ZERO, Frame::UPRIGHT, vars, NONE, 0);
        adopt(insts, live, &mut mem.newborn);
        rep.automata = 1;
        let mut stop = None;
        for _ in 0..options.iterations {
            if live.is_empty() {
                break;
            }
            rep.iterations += 1;
            let n = live.len();
            let (mut read, mut write) = (0, 0);
            while read < n {
                let id = live[read];
                read += 1;
                if mem.step(&mut insts[id as usize], &cx, plant, &mut rep) {
                    live[write] = id;
                    write += 1;
                }
                if !mem.newborn.is_empty() {
                    adopt(insts, live, &mut mem.newborn);
                }
                if rep.points >= options.limits.points {
                    stop = Some(Stop::Points);
                } else if rep.states >= options.limits.states {
                    stop = Some(Stop::States);
                }
                if stop.is_some() {
                    break;
                }
            }
            // Keep what was not run and the newborn, in order, after the survivors.
            let len = live.len();
            live.copy_within(read..len, write);
            live.truncate(write + len - read);
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
            mem.finish(&mut insts[id as usize], &cx, plant);
        }
        rep.segments = plant.segments().len() as u32;
        rep
    }
}

/// Moves the newborn into the instances, live from the next iteration.
fn adopt(insts: &mut Vec<Inst>, live: &mut Vec<u32>, newborn: &mut Vec<Inst>) {
    for inst in newborn.drain(..) {
        live.push(insts.len() as u32);
        insts.push(inst);
    }
}

impl Memory {
    /// Adds an instance of automaton `automaton` (0-based) to the newborn.
    #[allow(clippy::too_many_arguments)]
    fn spawn(
        &mut self,
        cx: &Cx,
        automaton: usize,
        pos: Vec3,
        frame: Frame,
        vars: [f32; VARIABLES],
        attach: u32,
        index: u32,
    ) {
        let code = cx.program.automata()[automaton];
        let radius = map_thickness(vars[THICKNESS]);
        self.newborn.push(Inst {
            pos,
            frame,
            vars,
            pc: code.entry,
            automaton: automaton as u8,
            turns: RENORMALISE,
            stack_len: 0,
            seg: NONE,
            attach,
            chord_start: pos,
            chord_radius: radius,
            chord_moves: 0,
            radius,
            moves: 0,
            index,
            children: 0,
            pending: NONE,
            counter_base: self.counters.len() as u32,
            stack_base: self.stack.len() as u32,
        });
        self.counters
            .resize(self.counters.len() + usize::from(code.counters), 0);
        self.stack.resize(
            self.stack.len() + usize::from(code.push_depth),
            Saved::default(),
        );
    }

    /// Runs an instance for one iteration; `false` when it died.
    fn step(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant, rep: &mut GrowthReport) -> bool {
        let states = cx.program.states();
        let limit = cx.options.limits.states_per_step;
        let mut pc = me.pc as usize;
        let mut budget = limit;
        let alive = loop {
            if budget == 0 {
                rep.bounds.state_limit_kills += 1;
                break false;
            }
            budget -= 1;
            let here = pc;
            let s = &states[here];
            pc = s.next as usize;
            match s.op {
                Op::Wait => break true,
                Op::End => {
                    if cx.program.restarts() {
                        pc = cx.program.automata()[usize::from(me.automaton)].entry as usize;
                    } else {
                        break false;
                    }
                }
                Op::Kill => break false,
                Op::RotateH => {
                    me.frame.turn_h(s.x, s.y);
                    me.turns = me.turns.saturating_add(1);
                }
                Op::RotateL => {
                    me.frame.turn_l(s.x, s.y);
                    me.turns = me.turns.saturating_add(1);
                }
                Op::RotateU => {
                    me.frame.turn_u(s.x, s.y);
                    me.turns = me.turns.saturating_add(1);
                }
                Op::Assign => me.vars[usize::from(s.arg)] = s.x,
                Op::Add | Op::Multiply => {
                    let v = &mut me.vars[usize::from(s.arg)];
                    let r = if s.op == Op::Add { *v + s.x } else { *v * s.x };
                    if r.abs() > VARIABLE_LIMIT {
                        rep.bounds.clamped_values += 1;
                        *v = r.clamp(-VARIABLE_LIMIT, VARIABLE_LIMIT);
                    } else {
                        *v = r;
                    }
                }
                Op::IfLess => {
                    if me.vars[usize::from(s.arg)] >= s.x {
                        pc = s.alt as usize;
                    }
                }
                Op::IfGreater => {
                    if me.vars[usize::from(s.arg)] <= s.x {
                        pc = s.alt as usize;
                    }
                }
                Op::IfEqual => {
                    if (me.vars[usize::from(s.arg)] - s.x).abs() > s.y {
                        pc = s.alt as usize;
                    }
                }
                Op::Push => self.push(me, cx),
                Op::Pop => self.pop(me, cx, plant),
                Op::RepeatInit | Op::RepeatIndexInit => {
                    // The entry and the first test: two states.
                    if budget == 0 {
                        rep.bounds.state_limit_kills += 1;
                        break false;
                    }
                    budget -= 1;
                    pc = self.enter_loop(me, s);
                }
                Op::RepeatTest => {
                    let c = &mut self.counters[(me.counter_base + u32::from(s.slot)) as usize];
                    if *c > 0 {
                        *c -= 1;
                    } else {
                        pc = s.alt as usize;
                    }
                }
                Op::RepeatNest => {
                    let c = &mut self.counters[(me.counter_base + u32::from(s.slot)) as usize];
                    if *c > 0 {
                        *c -= 1;
                        // The body is a loop entry (two states): run it here.
                        if budget < 2 {
                            rep.bounds.state_limit_kills += 1;
                            break false;
                        }
                        budget -= 2;
                        pc = self.enter_loop(me, &states[pc]);
                    } else {
                        pc = s.alt as usize;
                    }
                }
                Op::RepeatWait => {
                    let c = &mut self.counters[(me.counter_base + u32::from(s.slot)) as usize];
                    if *c > 0 {
                        // The test and its body's Wait: two states, the Wait resuming here.
                        if budget == 0 {
                            rep.bounds.state_limit_kills += 1;
                            break false;
                        }
                        budget -= 1;
                        *c -= 1;
                        pc = here;
                        break true;
                    }
                    pc = s.alt as usize;
                }
                Op::Create => self.create(me, usize::from(s.arg), cx, plant, rep),
                Op::Leaf => self.organ(me, OrganKind::Leaf, cx, plant, rep),
                Op::Flower => self.organ(me, OrganKind::Flower, cx, plant, rep),
            }
        };
        me.pc = pc as u32;
        let run = limit - budget;
        rep.states += u64::from(run);
        rep.max_states_per_step = rep.max_states_per_step.max(run);
        rep.automaton_steps += 1;
        if alive {
            self.advance(me, cx, plant, rep);
        } else {
            self.finish(me, cx, plant);
        }
        alive
    }

    /// Enters the loop whose entry is `entry` (a `RepeatInit` or `RepeatIndexInit`): sets its
    /// counter and runs its first test; returns the next state.
    #[inline(always)]
    fn enter_loop(&mut self, me: &Inst, entry: &State) -> usize {
        let count = if entry.op == Op::RepeatInit {
            entry.x as u8
        } else {
            (entry.x - me.index.min(255) as f32).max(0.0) as u8
        };
        if count > 0 {
            self.counters[(me.counter_base + u32::from(entry.slot)) as usize] = count - 1;
            entry.next as usize
        } else {
            entry.alt as usize
        }
    }

    /// Moves one step along H and records the position.
    fn advance(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant, rep: &mut GrowthReport) {
        if cx.gravity > 0.0 {
            let h = me.frame.heading;
            // Turn H towards -Y about H × (-Y), by gravity × sin(angle to vertical).
            let axis = Vec3::new(h.z, 0.0, -h.x);
            let sin = axis.length();
            if sin > 1e-6 {
                let angle = (cx.gravity * sin).min(sin.atan2(-h.y));
                let q = Quat::from_axis_angle(axis / sin, angle);
                me.frame.heading = q * h;
                me.frame.left = q * me.frame.left;
                me.turns = me.turns.saturating_add(1);
            }
        }
        if me.turns >= RENORMALISE {
            me.frame.renormalise();
            me.turns = 0;
        }
        // Pushes since the last move: the point they saved becomes a segment boundary.
        let top = usize::from(me.stack_len);
        if top > 0 {
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
        me.pos += me.frame.heading * me.vars[LENGTH];
        me.moves += 1;
        me.chord_moves += 1;
        let thickness = me.vars[THICKNESS];
        if thickness < 0.0 {
            rep.negative_thickness += 1;
        }
        me.radius = map_thickness(thickness);
        rep.points += 1;
        if cx.full {
            self.close_chord(me, cx, plant);
        }
    }

    /// Saves position, frame and variables.
    #[inline(never)]
    fn push(&mut self, me: &mut Inst, cx: &Cx) {
        let code = cx.program.automata()[usize::from(me.automaton)];
        // Always true for compiled programs; a guard, not a bound.
        if me.stack_len < code.push_depth {
            self.stack[(me.stack_base + u32::from(me.stack_len)) as usize] = Saved {
                pos: me.pos,
                frame: me.frame,
                vars: me.vars,
                seg: me.seg,
                radius: me.radius,
                moves: me.moves,
            };
            me.stack_len += 1;
        }
    }

    /// Restores the last Push.
    #[inline(never)]
    fn pop(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        if me.stack_len == 0 {
            return;
        }
        me.stack_len -= 1;
        let saved = self.stack[(me.stack_base + u32::from(me.stack_len)) as usize];
        me.frame = saved.frame;
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
        me.radius = saved.radius;
        me.chord_start = saved.pos;
        me.chord_radius = saved.radius;
        me.chord_moves = 0;
    }

    /// Draws the run since the last segment, if the automaton moved.
    fn close_chord(&mut self, me: &mut Inst, cx: &Cx, plant: &mut Plant) {
        if me.chord_moves == 0 {
            return;
        }
        let id = self.segment(me, me.chord_start, me.chord_radius, cx, plant);
        me.seg = id;
        me.chord_start = me.pos;
        me.chord_radius = me.radius;
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

    #[inline(never)]
    fn create(
        &mut self,
        me: &mut Inst,
        automaton: usize,
        cx: &Cx,
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
            me.seg = self.segment(me, me.pos, me.radius, cx, plant);
        }
        let vars = match cx.options.child_variables {
            ChildVariables::All => me.vars,
            ChildVariables::LengthThickness => {
                let mut v = [0.0; VARIABLES];
                v[LENGTH] = me.vars[Var::LENGTH.index()];
                v[THICKNESS] = me.vars[Var::THICKNESS.index()];
                v
            }
            ChildVariables::Fresh => {
                let mut v = [0.0; VARIABLES];
                v[LENGTH] = 1.0;
                v[THICKNESS] = 1.0;
                v
            }
        };
        self.spawn(cx, automaton, me.pos, me.frame, vars, me.seg, me.children);
        me.children += 1;
        rep.automata += 1;
    }

    #[inline(never)]
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
        let mut frame = me.frame;
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
            position: me.pos * unit,
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

    /// Draws the segment from `start` to the instance's position; [`NONE`] (and growth
    /// stops) if the plant refuses it.
    #[inline(always)]
    fn segment(
        &mut self,
        me: &Inst,
        start: Vec3,
        start_radius: f32,
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
        let radii = (start_radius * cx.radius_scale, me.radius * cx.radius_scale);
        match plant.add_segment(
            start * unit,
            me.pos * unit,
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
