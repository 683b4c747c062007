//! Straight-line blocks: a [`Program`]'s states regrouped so that one dispatch runs a whole
//! run of states between two control states.
//!
//! A [`Block`] is an optional loop test (the head), the turns, variable updates and
//! `Repeat` entries that follow it, and the state that ends them (the [`Term`]: a control
//! state, or a Push, Pop, creation or organ, which read the turtle). Turns touch only the
//! frame, updates only the variables and a `Repeat` entry only its counter, so a block
//! keeps each kind apart, in program order; a `Repeat` entry's count is known when the
//! program is compiled, so the block goes on into the loop body (or past the loop) and
//! only sets the counter. A block is built for each state something jumps to, the first
//! time it is reached, so a shared tail is copied into each block that reaches it, and a
//! loop test is folded into its body: `(Repeat n (Seq (RotateL 1) (Seq (Multiply Thickness
//! 0.99) (Wait))))` is one dispatch per iteration instead of four.
//!
//! Every state does exactly what it did, with the same floating-point operations in the
//! same order on the same values, and counts as the states it stands for, so outputs and
//! reports are unchanged (`tests/automata_reference.rs`); only dispatches go.

use super::NONE;
use crate::compile::{Op, Program};

/// The head of a block not built yet (see [`Blocks::build`]).
pub(super) const UNBUILT: u32 = u32::MAX - 1;
/// Turns and updates at most in one block. Tails shared by several blocks are copied into
/// each, so this bounds the copies at this many times the states reached; longer runs go
/// on in another block.
const MAX_OPS: u8 = 16;
/// `Repeat` entries at most in one block (a nest of two loops starts in one dispatch).
const MAX_SETS: usize = 2;

/// Which pair of the frame a turn moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Axis {
    /// Roll: left and up.
    H,
    /// Pitch: heading and up.
    L,
    /// Yaw: heading and left.
    U,
}

/// What a variable update does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Update {
    Assign,
    Add,
    Multiply,
}

/// A turn (`axis`, the sine `x` and cosine `y` of its angle) or a variable update
/// (`update`, `vars[var]` and `x`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Pure {
    pub axis: Axis,
    pub update: Update,
    pub var: u8,
    pub x: f32,
    pub y: f32,
}

impl Pure {
    const NONE: Pure = Pure {
        axis: Axis::H,
        update: Update::Assign,
        var: 0,
        x: 0.0,
        y: 0.0,
    };
}

/// The state that ends a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Term {
    /// No state: go on with block `next` (a loop test, or the rest of a long run).
    Goto,
    Wait,
    End,
    Kill,
    IfLess,
    IfGreater,
    IfEqual,
    /// A `Repeat` entry that does not fit in the block.
    RepeatInit,
    /// A `RepeatIndex` entry, whose count depends on the automaton.
    RepeatIndexInit,
    Push,
    Pop,
    Create,
    Leaf,
    Flower,
}

/// Head, counters set, turns and updates, and terminator; `next`, `alt` and `head_alt`
/// are block indices. The first turn and the first update are kept here (most blocks have
/// at most one of each); further ones are in [`Blocks::extra`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Block {
    /// States the block runs when its head's counter is not 0 (or it has no head): head,
    /// entries, turns, updates and terminator; [`u32::MAX`] when not built yet, so that the
    /// simulator's check for a budget too small to run it all catches that too.
    pub cost: u32,
    /// The block to go to when the head's counter is 0; [`NONE`]: no head; [`UNBUILT`].
    pub head_alt: u32,
    pub next: u32,
    pub alt: u32,
    /// The terminator's operands.
    pub x: f32,
    pub y: f32,
    /// The first turn.
    pub turn: Pure,
    /// The first update.
    pub update: Pure,
    /// The turns after the first, then the updates after the first: from here in
    /// [`Blocks::extra`].
    pub extra: u32,
    /// The counters the block's `Repeat` entries set, and to what.
    pub set_slot: [u16; MAX_SETS],
    pub set_value: [u8; MAX_SETS],
    /// The head's counter slot.
    pub head_slot: u16,
    /// The terminator's counter slot.
    pub slot: u16,
    /// Between head and terminator, state `i` is a turn (bit `i` of `order`) or the first
    /// of a `Repeat` entry's two states (of `entries`), or else an update; for a kill
    /// part-way.
    pub order: u32,
    pub entries: u32,
    /// States between head and terminator.
    pub pure: u8,
    /// Of those, turns, updates and `Repeat` entries setting a counter.
    pub turns: u8,
    pub updates: u8,
    pub sets: u8,
    pub term: Term,
    /// The terminator's variable or automaton.
    pub arg: u8,
    /// For a block that ends its step (a Wait terminator) with at most one turn and one
    /// update: `1 + shape` with `shape` = head × 16 + axis × 4 + update, where axis is 0
    /// (no turn) or 1 + [`Axis`] and update 0 (none) or 1 + [`Update`]; the simulator runs
    /// these with code made for each shape. 0 for any other block.
    pub shape: u8,
}

impl Block {
    const UNBUILT: Block = Block {
        cost: u32::MAX,
        head_alt: UNBUILT,
        next: 0,
        alt: 0,
        x: 0.0,
        y: 0.0,
        turn: Pure::NONE,
        update: Pure::NONE,
        extra: 0,
        set_slot: [0; MAX_SETS],
        set_value: [0; MAX_SETS],
        head_slot: 0,
        slot: 0,
        order: 0,
        entries: 0,
        pure: 0,
        turns: 0,
        updates: 0,
        sets: 0,
        term: Term::Kill,
        arg: 0,
        shape: 0,
    };
}

/// A program's blocks, built as they are reached; the buffers are kept between programs.
#[derive(Clone, Debug, Default)]
pub(super) struct Blocks {
    pub blocks: Vec<Block>,
    /// Turns and updates beyond a block's first of each.
    pub extra: Vec<Pure>,
    /// Each automaton's entry block.
    pub entries: Vec<u32>,
    /// The state each block starts at.
    start: Vec<u32>,
    /// The block that starts at each state, or [`NONE`].
    of_state: Vec<u32>,
    /// A block's turns and updates while it is built.
    turns: Vec<Pure>,
    updates: Vec<Pure>,
}

impl Blocks {
    /// Starts over with `program`: each automaton's entry block, none built yet.
    pub fn reset(&mut self, program: &Program) {
        self.blocks.clear();
        self.extra.clear();
        self.entries.clear();
        self.start.clear();
        self.of_state.clear();
        self.of_state.resize(program.states().len(), NONE);
        for code in program.automata() {
            let entry = self.block_of(code.entry);
            self.entries.push(entry);
        }
    }

    /// The index of the block that starts at `state`, added unbuilt if new.
    fn block_of(&mut self, state: u32) -> u32 {
        let known = self.of_state[state as usize];
        if known != NONE {
            return known;
        }
        let at = self.blocks.len() as u32;
        self.blocks.push(Block::UNBUILT);
        self.start.push(state);
        self.of_state[state as usize] = at;
        at
    }

    /// Builds block `at` (reached for the first time).
    #[cold]
    #[inline(never)]
    pub fn build(&mut self, program: &Program, at: usize) {
        let states = program.states();
        let mut b = Block {
            head_alt: NONE,
            term: Term::Goto,
            ..Block::UNBUILT
        };
        let (mut turns, mut updates) = (
            std::mem::take(&mut self.turns),
            std::mem::take(&mut self.updates),
        );
        turns.clear();
        updates.clear();
        // `Repeat` entries folded in, setting a counter or not.
        let mut folded = 0;
        let mut i = self.start[at] as usize;
        let s = states[i];
        if matches!(s.op, Op::RepeatTest | Op::RepeatNest | Op::RepeatWait) {
            // The fused tests are this head followed by a Wait or a loop entry.
            b.head_alt = self.block_of(s.alt);
            b.head_slot = s.slot;
            i = s.next as usize;
        }
        loop {
            let s = states[i];
            let full = b.turns + b.updates == MAX_OPS;
            let term = match s.op {
                Op::RotateH | Op::RotateL | Op::RotateU | Op::Assign | Op::Add | Op::Multiply
                    if full =>
                {
                    b.next = self.block_of(i as u32);
                    break;
                }
                Op::RotateH | Op::RotateL | Op::RotateU => {
                    let axis = match s.op {
                        Op::RotateH => Axis::H,
                        Op::RotateL => Axis::L,
                        _ => Axis::U,
                    };
                    turns.push(Pure {
                        axis,
                        x: s.x,
                        y: s.y,
                        ..Pure::NONE
                    });
                    b.order |= 1 << b.pure;
                    b.turns += 1;
                    b.pure += 1;
                    i = s.next as usize;
                    continue;
                }
                Op::Assign | Op::Add | Op::Multiply => {
                    let update = match s.op {
                        Op::Assign => Update::Assign,
                        Op::Add => Update::Add,
                        _ => Update::Multiply,
                    };
                    updates.push(Pure {
                        update,
                        var: s.arg,
                        x: s.x,
                        ..Pure::NONE
                    });
                    b.updates += 1;
                    b.pure += 1;
                    i = s.next as usize;
                    continue;
                }
                Op::RepeatInit if folded < MAX_SETS => {
                    folded += 1;
                    // The count is the state's: enter the body with the counter set, or
                    // skip the loop.
                    let count = s.x as u8;
                    if count > 0 {
                        b.set_slot[usize::from(b.sets)] = s.slot;
                        b.set_value[usize::from(b.sets)] = count - 1;
                        b.sets += 1;
                        i = s.next as usize;
                    } else {
                        i = s.alt as usize;
                    }
                    b.entries |= 1 << b.pure;
                    b.pure += 2;
                    continue;
                }
                Op::RepeatTest | Op::RepeatNest | Op::RepeatWait => {
                    b.next = self.block_of(i as u32);
                    break;
                }
                // What follows a Killme is never run; End restarts at the automaton's entry.
                Op::Kill => Term::Kill,
                Op::End => Term::End,
                Op::Wait => Term::Wait,
                Op::Push => Term::Push,
                Op::Pop => Term::Pop,
                Op::Create => Term::Create,
                Op::Leaf => Term::Leaf,
                Op::Flower => Term::Flower,
                Op::IfLess => Term::IfLess,
                Op::IfGreater => Term::IfGreater,
                Op::IfEqual => Term::IfEqual,
                Op::RepeatInit => Term::RepeatInit,
                Op::RepeatIndexInit => Term::RepeatIndexInit,
            };
            b.term = term;
            (b.arg, b.slot, b.x, b.y) = (s.arg, s.slot, s.x, s.y);
            if !matches!(term, Term::Kill | Term::End) {
                b.next = self.block_of(s.next);
            }
            if matches!(
                term,
                Term::IfLess
                    | Term::IfGreater
                    | Term::IfEqual
                    | Term::RepeatInit
                    | Term::RepeatIndexInit
            ) {
                b.alt = self.block_of(s.alt);
            }
            break;
        }
        b.cost = u32::from(b.head_alt != NONE)
            + u32::from(b.pure)
            + match b.term {
                Term::Goto => 0,
                Term::RepeatInit | Term::RepeatIndexInit => 2,
                _ => 1,
            };
        if b.term == Term::Wait && b.turns <= 1 && b.updates <= 1 {
            let head = u8::from(b.head_alt != NONE);
            let axis = if b.turns == 1 {
                1 + turns[0].axis as u8
            } else {
                0
            };
            let update = if b.updates == 1 {
                1 + updates[0].update as u8
            } else {
                0
            };
            b.shape = 1 + head * 16 + axis * 4 + update;
        }
        b.turn = turns.first().copied().unwrap_or(Pure::NONE);
        b.update = updates.first().copied().unwrap_or(Pure::NONE);
        b.extra = self.extra.len() as u32;
        self.extra
            .extend_from_slice(turns.get(1..).unwrap_or_default());
        self.extra
            .extend_from_slice(updates.get(1..).unwrap_or_default());
        (self.turns, self.updates) = (turns, updates);
        self.blocks[at] = b;
    }
}
