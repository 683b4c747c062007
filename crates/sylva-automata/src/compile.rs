//! Cellular encoding (section 4.2, Figures 4 to 6): a GP tree becomes flat automata.
//!
//! Every automaton of a [`Program`] is a set of [`State`]s in one shared array; a state says
//! what to do ([`Op`]) and where to go next (`next`, and `alt` for the second way out of an
//! `If` or a `Repeat` test). Index 0 is the shared [`Op::End`] state: "end of automaton
//! reached". States are 20 bytes with no pointers to chase, so compiling once per individual
//! pays for itself within one iteration. The [`Simulator`](crate::Simulator) regroups them
//! into straight-line blocks as it first reaches them; the states stay the program's
//! definition (and what [`Program::verify`] and the reference simulator read).
//!
//! The compiler works backwards, in continuation-passing style: each operator is compiled
//! knowing the entry of what follows it, which is exactly how Figure 4 links a state's
//! outgoing transition to the next state's incoming one.
//!
//! | operator | states |
//! | --- | --- |
//! | `(Seq a b)` | none of its own: `a`'s exit is linked to `b`'s entry |
//! | `(If… var value then else)` | one test state; `next` → `then`, `alt` → `else`; both branches continue after the `If` ([`ElseEnd::Rejoin`]) or the `else` branch ends the automaton ([`ElseEnd::End`]) |
//! | `(PushPop body)` | `Push` → body → `Pop` → continuation |
//! | `(Repeat n body)` | `RepeatInit`: counter := n, then the first test → body or continuation; `RepeatTest`: counter > 0 ? (counter -= 1, body → test) : continuation |
//! | `(Repeat n (Wait))` | the same, with the test marked `RepeatWait`: test and `Wait` in one dispatch |
//! | `(Repeat n (Repeat m body))` | the outer test marked `RepeatNest`: it enters the inner loop in the same dispatch |
//!
//! A loop's entry does its first test itself, a test whose body is a lone `Wait` waits
//! itself, and a test whose body begins with a loop enters it: evolved trees are mostly
//! nested `Repeat`s (how an automaton lives n steps; a `RepeatIndex` in a late-born branch
//! often counts 0, so its outer loop spins through it), and these fusions cut a third of the
//! dispatches. Each fused state still counts as the two states it stands for, so
//! reports and [`Limits::states_per_step`](crate::Limits) read as for the plain automaton.
//! | `(Wait)`, `(Killme)`, rotations, `CreateAutomaton`, `Assign`, `Add`, `Multiply` | one state each |
//!
//! By construction every state is reachable from its automaton's entry (a `Killme` keeps its
//! `next` link, never taken, so what follows it is still linked), every Push has its Pop on
//! every path, and each Repeat has its own counter slot. [`Program::verify`] checks all three
//! and the property tests run it on random trees.

use serde::{Deserialize, Serialize};

use crate::tree::{GpTree, Node, NodeInfo, Target};

/// What a state does. Field use is listed with each op.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Op {
    /// End of automaton: it dies (or restarts, [`AtEnd::Restart`]). Only state 0.
    End,
    /// Ends this iteration's steps; `next` is where the next iteration starts.
    Wait,
    /// The automaton dies (`next` is kept for the structure only).
    Kill,
    /// Roll: `x` = sin, `y` = cos of the angle.
    RotateH,
    /// Pitch: `x` = sin, `y` = cos.
    RotateL,
    /// Yaw: `x` = sin, `y` = cos.
    RotateU,
    /// New instance of automaton `arg` (0-based).
    Create,
    /// A leaf here.
    Leaf,
    /// A flower here.
    Flower,
    /// `vars[arg] = x`.
    Assign,
    /// `vars[arg] += x`.
    Add,
    /// `vars[arg] *= x`.
    Multiply,
    /// `vars[arg] < x` ? `next` : `alt`.
    IfLess,
    /// `vars[arg] > x` ? `next` : `alt`.
    IfGreater,
    /// `|vars[arg] - x| <= y` ? `next` : `alt`.
    IfEqual,
    /// Saves position, frame and variables.
    Push,
    /// Restores them.
    Pop,
    /// `counter[slot] = x` (a whole number 0..=10), then the test of [`Op::RepeatTest`].
    RepeatInit,
    /// `counter[slot] = max(0, x - index)`, index = the automaton's birth rank, then the
    /// test of [`Op::RepeatTest`].
    RepeatIndexInit,
    /// `counter[slot] > 0` ? (decrement, `next`: the body) : `alt`: after the loop.
    RepeatTest,
    /// A `RepeatTest` whose body begins with a loop: when the counter is positive, decrement
    /// it and enter that loop (its `RepeatInit` or `RepeatIndexInit` at `next`) in the same
    /// dispatch, counted as the test and the entry's two states; otherwise `alt`.
    RepeatNest,
    /// A `RepeatTest` whose body is a lone `Wait` (`next`, which links back here): when the
    /// counter is positive, decrement it and end the iteration's steps here, as test and
    /// `Wait` would (and counted as those two states); otherwise `alt`.
    RepeatWait,
}

/// One state of a compiled automaton.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// What it does.
    pub op: Op,
    /// Variable index, or automaton index for [`Op::Create`].
    pub arg: u8,
    /// Repeat counter slot.
    pub slot: u16,
    /// Value operand (see [`Op`]).
    pub x: f32,
    /// Second operand (see [`Op`]).
    pub y: f32,
    /// The next state.
    pub next: u32,
    /// The other way out of an `If` or a `RepeatTest`.
    pub alt: u32,
}

impl State {
    const END: State = State {
        op: Op::End,
        arg: 0,
        slot: 0,
        x: 0.0,
        y: 0.0,
        next: 0,
        alt: 0,
    };
}

/// Where an `If`'s else branch goes when it ends. The paper says only that "the then
/// transition is considered as the outgoing transition" of an If.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElseEnd {
    /// Both branches continue with what follows the `If` (structured if-then-else). Default:
    /// a subtree means the same wherever crossover puts it, which keeps building blocks
    /// intact.
    #[default]
    Rejoin,
    /// The literal reading: only `then` continues; the else branch's end is the end of the
    /// automaton.
    End,
}

/// What reaching the end of an automaton does. The paper's pseudo-code kills it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AtEnd {
    /// The automaton dies (the paper's pseudo-code). Default.
    #[default]
    Die,
    /// It starts again from its first state, like the looping automata of Figure 1; only
    /// `Killme`, the iteration limit or a bound ends it.
    Restart,
}

/// Choices fixed at compile time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Semantics {
    /// Degrees per unit of a rotation's value. Default 10, so values -10..=10 span ±100° and
    /// Figure 1's 70° branch angle is `(RotateL 7)`.
    pub degrees_per_unit: f32,
    /// Default [`ElseEnd::Rejoin`].
    pub else_end: ElseEnd,
    /// Default [`AtEnd::Die`].
    pub at_end: AtEnd,
    /// `IfEqual` holds when `|var - value| <= equal_tolerance`. Default 0.5: whole-number
    /// counters compare equal after rounding, and real-valued variables still hit now and then.
    pub equal_tolerance: f32,
}

impl Default for Semantics {
    fn default() -> Self {
        Semantics {
            degrees_per_unit: 10.0,
            else_end: ElseEnd::Rejoin,
            at_end: AtEnd::Die,
            equal_tolerance: 0.5,
        }
    }
}

/// One compiled automaton.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AutomatonCode {
    /// Its first state.
    pub entry: u32,
    /// Repeat counters it needs.
    pub counters: u16,
    /// Deepest Push nesting.
    pub push_depth: u16,
}

/// A compiled individual: every automaton's states, ready for the
/// [`Simulator`](crate::Simulator).
#[derive(Clone, Debug, Default)]
pub struct Program {
    states: Vec<State>,
    automata: Vec<AutomatonCode>,
    restart: bool,
}

/// Compile-time context for one automaton.
struct Cx {
    else_end: ElseEnd,
    degrees_per_unit: f32,
    tolerance: f32,
    counters: u16,
    depth: u16,
    push_depth: u16,
}

fn value(node: Node) -> f32 {
    match node {
        Node::Value(v) => v,
        _ => 0.0,
    }
}

fn var(node: Node) -> u8 {
    match node {
        Node::Var(v) => v.index() as u8,
        _ => 0,
    }
}

impl Program {
    /// Compiles `tree`.
    pub fn compile(tree: &GpTree, semantics: &Semantics) -> Program {
        let mut p = Program::default();
        p.recompile(tree, semantics);
        p
    }

    /// Compiles `tree` into `self`, reusing its buffers (no allocation once they have grown).
    pub fn recompile(&mut self, tree: &GpTree, semantics: &Semantics) {
        let nodes = tree.nodes();
        self.states.clear();
        self.automata.clear();
        self.restart = semantics.at_end == AtEnd::Restart;
        self.states.push(State::END);
        let info = tree.node_info();
        let degrees = if semantics.degrees_per_unit.is_finite() {
            semantics.degrees_per_unit
        } else {
            10.0
        };
        let mut at = 1usize;
        for _ in 0..tree.automata() {
            let mut cx = Cx {
                else_end: semantics.else_end,
                degrees_per_unit: degrees,
                tolerance: semantics.equal_tolerance.max(0.0),
                counters: 0,
                depth: 0,
                push_depth: 0,
            };
            let entry = self.op(nodes, info, at, 0, &mut cx);
            self.automata.push(AutomatonCode {
                entry,
                counters: cx.counters,
                push_depth: cx.push_depth,
            });
            at = info[at].end as usize;
        }
    }

    fn push(&mut self, state: State) -> u32 {
        self.states.push(state);
        (self.states.len() - 1) as u32
    }

    fn simple(&mut self, op: Op, arg: u8, x: f32, y: f32, next: u32) -> u32 {
        self.push(State {
            op,
            arg,
            slot: 0,
            x,
            y,
            next,
            alt: 0,
        })
    }

    /// Compiles the operator at `i`, followed by `cont`; returns its entry state.
    fn op(&mut self, nodes: &[Node], info: &[NodeInfo], i: usize, cont: u32, cx: &mut Cx) -> u32 {
        match nodes[i] {
            Node::Seq => {
                let b = info[i + 1].end as usize;
                let second = self.op(nodes, info, b, cont, cx);
                self.op(nodes, info, i + 1, second, cx)
            }
            node @ (Node::IfLess | Node::IfGreater | Node::IfEqual) => {
                let then = i + 3;
                let otherwise = info[then].end as usize;
                let then_entry = self.op(nodes, info, then, cont, cx);
                let else_cont = match cx.else_end {
                    ElseEnd::Rejoin => cont,
                    ElseEnd::End => 0,
                };
                let else_entry = self.op(nodes, info, otherwise, else_cont, cx);
                let op = match node {
                    Node::IfLess => Op::IfLess,
                    Node::IfGreater => Op::IfGreater,
                    _ => Op::IfEqual,
                };
                self.push(State {
                    op,
                    arg: var(nodes[i + 1]),
                    slot: 0,
                    x: value(nodes[i + 2]),
                    y: cx.tolerance,
                    next: then_entry,
                    alt: else_entry,
                })
            }
            Node::PushPop => {
                cx.depth += 1;
                cx.push_depth = cx.push_depth.max(cx.depth);
                let pop = self.simple(Op::Pop, 0, 0.0, 0.0, cont);
                let body = self.op(nodes, info, i + 1, pop, cx);
                cx.depth -= 1;
                self.simple(Op::Push, 0, 0.0, 0.0, body)
            }
            node @ (Node::Repeat | Node::RepeatIndex) => {
                let slot = cx.counters;
                cx.counters = cx.counters.saturating_add(1);
                let test = self.push(State {
                    op: Op::RepeatTest,
                    arg: 0,
                    slot,
                    x: 0.0,
                    y: 0.0,
                    next: 0,
                    alt: cont,
                });
                let body = self.op(nodes, info, i + 2, test, cx);
                let t = &mut self.states[test as usize];
                t.next = body;
                if nodes[i + 2] == Node::Wait {
                    t.op = Op::RepeatWait;
                }
                let body_op = self.states[body as usize].op;
                if matches!(body_op, Op::RepeatInit | Op::RepeatIndexInit) {
                    self.states[test as usize].op = Op::RepeatNest;
                }
                let op = if node == Node::Repeat {
                    Op::RepeatInit
                } else {
                    Op::RepeatIndexInit
                };
                // The entry tests too: its ways out are the test's.
                self.push(State {
                    op,
                    arg: 0,
                    slot,
                    x: value(nodes[i + 1]).round().abs(),
                    y: 0.0,
                    next: body,
                    alt: cont,
                })
            }
            node @ (Node::RotateH | Node::RotateL | Node::RotateU) => {
                let angle = (value(nodes[i + 1]) * cx.degrees_per_unit).to_radians();
                let (sin, cos) = angle.sin_cos();
                let op = match node {
                    Node::RotateH => Op::RotateH,
                    Node::RotateL => Op::RotateL,
                    _ => Op::RotateU,
                };
                self.simple(op, 0, sin, cos, cont)
            }
            Node::CreateAutomaton => {
                let (op, arg) = match nodes[i + 1] {
                    Node::Target(Target::Automaton(n)) => (Op::Create, n.saturating_sub(1)),
                    Node::Target(Target::Flower) => (Op::Flower, 0),
                    _ => (Op::Leaf, 0),
                };
                self.simple(op, arg, 0.0, 0.0, cont)
            }
            node @ (Node::Assign | Node::Add | Node::Multiply) => {
                let op = match node {
                    Node::Assign => Op::Assign,
                    Node::Add => Op::Add,
                    _ => Op::Multiply,
                };
                self.simple(op, var(nodes[i + 1]), value(nodes[i + 2]), 0.0, cont)
            }
            Node::Wait => self.simple(Op::Wait, 0, 0.0, 0.0, cont),
            Node::Killme => self.simple(Op::Kill, 0, 0.0, 0.0, cont),
            // A valid tree has nothing else in a TreeNode slot.
            Node::Top(_) | Node::Value(_) | Node::Var(_) | Node::Target(_) => cont,
        }
    }

    /// All states; index 0 is [`Op::End`].
    #[inline]
    pub fn states(&self) -> &[State] {
        &self.states
    }

    /// The compiled automata, in `Top`'s order.
    #[inline]
    pub fn automata(&self) -> &[AutomatonCode] {
        &self.automata
    }

    /// Whether reaching the end restarts the automaton ([`AtEnd::Restart`]).
    #[inline]
    pub fn restarts(&self) -> bool {
        self.restart
    }

    /// Most Repeat counters any automaton needs.
    pub fn max_counters(&self) -> usize {
        self.automata
            .iter()
            .map(|a| usize::from(a.counters))
            .max()
            .unwrap_or(0)
    }

    /// Deepest Push nesting of any automaton.
    pub fn max_push_depth(&self) -> usize {
        self.automata
            .iter()
            .map(|a| usize::from(a.push_depth))
            .max()
            .unwrap_or(0)
    }

    /// Checks the guarantees of cellular encoding: every state is reachable from an entry
    /// by `next`/`alt` links, each state is reached at one Push depth only, no Pop is
    /// reached at depth 0, links stay in range, counters and Push depths fit what each
    /// automaton declares. Returns what is wrong.
    pub fn verify(&self) -> Result<(), String> {
        let n = self.states.len();
        // Push depth at which each state is reached; u32::MAX: not reached yet.
        let mut depth = vec![u32::MAX; n];
        let mut work: Vec<(u32, u32)> = Vec::new();
        depth[0] = 0;
        for code in &self.automata {
            work.push((code.entry, 0));
            while let Some((s, d)) = work.pop() {
                let s = s as usize;
                if s >= n {
                    return Err(format!("a link to state {s} of {n}"));
                }
                if s == 0 {
                    continue;
                }
                if depth[s] != u32::MAX {
                    if depth[s] != d {
                        return Err(format!(
                            "state {s} is reached at push depths {} and {d}",
                            depth[s]
                        ));
                    }
                    continue;
                }
                depth[s] = d;
                let st = self.states[s];
                if matches!(
                    st.op,
                    Op::RepeatInit
                        | Op::RepeatIndexInit
                        | Op::RepeatTest
                        | Op::RepeatNest
                        | Op::RepeatWait
                ) && st.slot >= code.counters
                {
                    return Err(format!(
                        "state {s} uses counter {} of {}",
                        st.slot, code.counters
                    ));
                }
                let after = match st.op {
                    Op::Push => d + 1,
                    Op::Pop if d == 0 => return Err(format!("state {s} pops an empty stack")),
                    Op::Pop => d - 1,
                    _ => d,
                };
                if after > u32::from(code.push_depth) {
                    return Err(format!("state {s} pushes deeper than {}", code.push_depth));
                }
                work.push((st.next, after));
                if matches!(
                    st.op,
                    Op::IfLess
                        | Op::IfGreater
                        | Op::IfEqual
                        | Op::RepeatInit
                        | Op::RepeatIndexInit
                        | Op::RepeatTest
                        | Op::RepeatNest
                        | Op::RepeatWait
                ) {
                    work.push((st.alt, d));
                }
            }
        }
        match depth.iter().position(|&d| d == u32::MAX) {
            Some(s) => Err(format!(
                "state {s} ({:?}) is unreachable",
                self.states[s].op
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compile(text: &str) -> Program {
        let p = Program::compile(&GpTree::parse(text).unwrap(), &Semantics::default());
        p.verify().unwrap();
        p
    }

    #[test]
    fn seq_links_states() {
        let p = compile("(Top (Seq (RotateH 9) (Seq (Wait) (Killme))))");
        let s = p.states();
        let a = p.automata()[0].entry as usize;
        assert_eq!(s[a].op, Op::RotateH);
        assert!((s[a].x - 1.0).abs() < 1e-6, "sin 90° = 1");
        let w = s[a].next as usize;
        assert_eq!(s[w].op, Op::Wait);
        assert_eq!(s[s[w].next as usize].op, Op::Kill);
        assert_eq!(s[s[w].next as usize].next, 0);
    }

    #[test]
    fn if_and_repeat_and_push() {
        let p =
            compile("(Top (Seq (IfLess Var1 3 (PushPop (Wait)) (Repeat -2.6 (Wait))) (Killme)))");
        let s = p.states();
        let code = p.automata()[0];
        assert_eq!(code.counters, 1);
        assert_eq!(code.push_depth, 1);
        let i = &s[code.entry as usize];
        assert_eq!((i.op, i.arg, i.x), (Op::IfLess, 2, 3.0));
        assert_eq!(s[i.next as usize].op, Op::Push);
        let init = &s[i.alt as usize];
        assert_eq!((init.op, init.x), (Op::RepeatInit, 3.0));
        assert_eq!(
            s[init.alt as usize].op,
            Op::Kill,
            "an empty loop is skipped"
        );
        let wait = &s[init.next as usize];
        assert_eq!(wait.op, Op::Wait, "the entry tests and goes to the body");
        let test = &s[wait.next as usize];
        assert_eq!(
            test.op,
            Op::RepeatWait,
            "a lone Wait body is fused into its test"
        );
        assert_eq!((test.next, test.alt), (init.next, init.alt));
    }

    #[test]
    fn else_end_links_to_the_end() {
        let tree = GpTree::parse("(Top (Seq (IfLess Var1 3 (Wait) (Wait)) (Killme)))").unwrap();
        let sem = Semantics {
            else_end: ElseEnd::End,
            ..Semantics::default()
        };
        let p = Program::compile(&tree, &sem);
        p.verify().unwrap();
        let s = p.states();
        let i = &s[p.automata()[0].entry as usize];
        assert_eq!(s[i.next as usize].next as usize, i.next as usize - 1);
        assert_eq!(s[i.alt as usize].next, 0);
    }

    #[test]
    fn recompile_reuses() {
        let a = GpTree::parse("(Top (Seq (Wait) (CreateAutomaton A2)) (CreateAutomaton Leaf))")
            .unwrap();
        let mut p = Program::compile(&a, &Semantics::default());
        let first = p.states().to_vec();
        p.recompile(&a, &Semantics::default());
        assert_eq!(p.states(), &first[..]);
        assert_eq!(p.automata().len(), 2);
        assert_eq!(p.states()[p.automata()[1].entry as usize].op, Op::Leaf);
    }
}
