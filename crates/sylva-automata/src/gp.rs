//! Typed GP operators: ramped half-and-half initialisation, subtree crossover and subtree
//! mutation (section 4.3: "the standard GP operations for strong-typed trees").
//!
//! - **Initialisation never fails.** Every type has terminals: `Wait`/`Killme` for
//!   operators, a random constant for values, any of the six variables, and for automaton
//!   numbers the legal set of the automaton being built (later automata, or Leaf/Flower for
//!   the last one), which is never empty. So a tree can be closed at any depth, and size is
//!   kept by regrowing a body shallower, down to a single terminal, which always fits.
//! - **Full** builds branching operators (`Seq`, `If…`, `PushPop`, `Repeat…`) down to one
//!   level above the chosen depth, then any operator, then terminals; **grow** picks any
//!   operator with probability [`GpConfig::grow_function_rate`] until the depth is reached.
//! - **Crossover** swaps a subtree of `a` for a subtree of `b` of the same type (Koza's 90%
//!   function points, 10% terminals), chosen among those that keep the child within
//!   [`GpConfig::max_depth`] and [`GpConfig::max_size`], from the same automaton of `b` when
//!   it has one of that type (homologous, like lilgp's branch-typed crossover), otherwise from
//!   any automaton. Automaton numbers that arrive in another automaton are **repaired** to
//!   keep their relative level: "create the automaton `k` levels below me" stays so, a level
//!   past the last becomes `Leaf`, and `Leaf`/`Flower` arriving above the last level become
//!   "the next level". After 8 tries without a legal pair the child is a copy of `a` (as
//!   lilgp keeps a parent).
//! - **Mutation** replaces a random subtree by a grown one of the same type, at most
//!   [`GpConfig::mutation_depth`] deep, within the limits (a single terminal always fits),
//!   or, for a share [`GpConfig::nudge`] of mutations (none by default), moves one value by
//!   one or two value steps: a fine tuning that a freshly drawn value almost never gives.
//!
//! Random values are multiples of [`GpConfig::value_step`] (0.1: the paper's "fixed point
//! values"), which also keeps printed trees short.

use std::cell::RefCell;

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};
use sylva_evolve::{Crossover, Mutate};

use crate::tree::{
    GpTree, MAX_AUTOMATA, MAX_NODES, Node, Target, Type, VALUE_LIMIT, VARIABLES, Var,
};

/// Operators with operator children, by family: the ones "full" uses to reach its depth.
const SEQ: &[Node] = &[Node::Seq];
const IFS: &[Node] = &[Node::IfLess, Node::IfGreater, Node::IfEqual];
const PUSH_POP: &[Node] = &[Node::PushPop];
const REPEATS: &[Node] = &[Node::Repeat, Node::RepeatIndex];
/// Operators whose children are parameters only, by family.
const ROTATIONS: &[Node] = &[Node::RotateH, Node::RotateL, Node::RotateU];
const CREATE: &[Node] = &[Node::CreateAutomaton];
const VARIABLE_OPS: &[Node] = &[Node::Assign, Node::Add, Node::Multiply];
/// Tries before crossover gives up and copies the first parent.
const ATTEMPTS: usize = 8;

/// Which automata an automaton may create in bred trees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Creation {
    /// Any later automaton (Table 1).
    #[default]
    Later,
    /// Only the next one: branches create sub-branches, never the trunk (section 3).
    Next,
}

/// Settings of the GP operators. Every field says its default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpConfig {
    /// Automata per tree (children of `Top`). Default 2 (the paper: "usually 2 or 3").
    pub automata: u8,
    /// Which automata an automaton's `CreateAutomaton` makes in the trees bred: any later
    /// one (Table 1's rule, the default) or only the next (section 3's "the trunk automaton
    /// can only create branch automata, the branch automata can only create sub-branch
    /// automata"). Either way the trees read back under Table 1's rule.
    pub creation: Creation,
    /// Smallest body depth of initial trees (ramped). Default 4 (with the largest, 8, initial
    /// trees of 2 automata average about 90 nodes: the paper's "around 100").
    pub min_init_depth: u32,
    /// Largest body depth of initial trees (ramped). Default 8.
    pub max_init_depth: u32,
    /// Deepest tree crossover and mutation may make (root at depth 0). Default 17 (Koza).
    pub max_depth: u32,
    /// Most nodes of any tree made. Default 500 (the paper's largest individuals).
    pub max_size: u32,
    /// Random values are multiples of this in -10..=10; 0 draws any number. Default 0.1.
    pub value_step: f32,
    /// Probability that grow picks an operator rather than `Wait`/`Killme` above its depth
    /// limit. Default 0.85.
    pub grow_function_rate: f64,
    /// Probability that an operator chosen by grow (or by full at its last operator level) is
    /// a branching one (`Seq`, `If…`, `PushPop`, `Repeat…`) rather than an action
    /// (rotations, `CreateAutomaton`, `Assign`, `Add`, `Multiply`). Default 0.75: about one
    /// operator child per operator, so grown bodies neither die out at once nor explode.
    pub branching_rate: f64,
    /// Probability that a crossover or mutation point is a function (has children) rather
    /// than a terminal, when the tree has both. Default 0.9 (Koza).
    pub function_point_rate: f64,
    /// Deepest subtree mutation grows. Default 4.
    pub mutation_depth: u32,
    /// Share of mutations that nudge one value of the tree by one or two value steps up or
    /// down instead of replacing a subtree (when the tree has a value), 0 to 1. Default 0.
    /// Subtree mutation almost never fine-tunes a constant: a new one is drawn from 201.
    pub nudge: f64,
    /// Operator weights for initialisation and mutation.
    pub weights: Weights,
}

impl Default for GpConfig {
    fn default() -> Self {
        GpConfig {
            automata: 2,
            creation: Creation::Later,
            min_init_depth: 4,
            max_init_depth: 8,
            max_depth: 17,
            max_size: 500,
            value_step: 0.1,
            grow_function_rate: 0.85,
            branching_rate: 0.75,
            function_point_rate: 0.9,
            mutation_depth: 4,
            nudge: 0.0,
            weights: Weights::default(),
        }
    }
}

/// Relative weights of the operator families random trees are built from; variants within
/// a family (the three `If`s, the two `Repeat`s, the three rotations, `Assign`/`Add`/
/// `Multiply`) share their family's weight equally. A group whose weights are all zero (or
/// not finite) is drawn uniformly instead, so generation never fails. Every field says its
/// default: sequences, rotations and `Wait` are favoured so that random automata live a few
/// steps and draw something, which gives selection a start (with uniform weights, two thirds
/// of random individuals die before their first step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// `Seq`. Default 3.
    pub seq: f64,
    /// `IfLess`, `IfGreater` and `IfEqual` together. Default 2.
    pub conditional: f64,
    /// `PushPop`. Default 1.
    pub push_pop: f64,
    /// `Repeat` and `RepeatIndex` together. Default 2.
    pub repeat: f64,
    /// `RotateH`, `RotateL` and `RotateU` together. Default 3.
    pub rotate: f64,
    /// `CreateAutomaton`. Default 2.
    pub create: f64,
    /// `Assign`, `Add` and `Multiply` together. Default 2.
    pub variable: f64,
    /// `Wait`. Default 3.
    pub wait: f64,
    /// `Killme`. Default 1.
    pub killme: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            seq: 3.0,
            conditional: 2.0,
            push_pop: 1.0,
            repeat: 2.0,
            rotate: 3.0,
            create: 2.0,
            variable: 2.0,
            wait: 3.0,
            killme: 1.0,
        }
    }
}

/// A node from weighted families; uniform over all of them when no weight is positive.
fn pick_family<R: Rng + ?Sized>(families: &[(f64, &[Node])], rng: &mut R) -> Node {
    let weight = |w: f64| if w.is_finite() && w > 0.0 { w } else { 0.0 };
    let total: f64 = families.iter().map(|(w, _)| weight(*w)).sum();
    if total > 0.0 {
        let mut x = rng.random_range(0.0..total);
        for (w, nodes) in families {
            let w = weight(*w);
            if x < w {
                return pick(nodes, rng);
            }
            x -= w;
        }
    }
    let k = rng.random_range(0..families.len());
    pick(families[k].1, rng)
}

/// Subtree crossover ([module docs](self)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubtreeCrossover {
    /// Limits and point choice.
    pub config: GpConfig,
}

/// Subtree mutation ([module docs](self)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubtreeMutation {
    /// Limits and how new subtrees grow.
    pub config: GpConfig,
}

/// The value `k` steps from 0, within -10..=10.
fn value_at(k: f64, step: f64) -> f32 {
    // Divide by a whole inverse when there is one, so 0.1 steps give 3.2, not 3.2000002.
    let inverse = 1.0 / step;
    let v = if (inverse - inverse.round()).abs() < 1e-4 * inverse {
        k / inverse.round()
    } else {
        k * step
    };
    (v as f32).clamp(-VALUE_LIMIT, VALUE_LIMIT)
}

fn pick<T: Copy, R: Rng + ?Sized>(items: &[T], rng: &mut R) -> T {
    items[rng.random_range(0..items.len())]
}

impl GpConfig {
    fn automata_count(&self) -> usize {
        usize::from(self.automata).clamp(1, MAX_AUTOMATA)
    }

    fn size_limit(&self) -> usize {
        (self.max_size as usize).clamp(1 + self.automata_count(), MAX_NODES)
    }

    fn depth_limit(&self) -> usize {
        (self.max_depth as usize).clamp(1, crate::tree::MAX_TREE_DEPTH)
    }

    /// A random tree: each automaton's body is grown by "grow" or "full" (even odds) to a
    /// depth drawn from `min_init_depth..=max_init_depth`.
    pub fn random_tree<R: Rng + ?Sized>(&self, rng: &mut R) -> GpTree {
        let (lo, hi) = self.init_depths();
        let depth = rng.random_range(lo..=hi);
        let full = rng.random_bool(0.5);
        self.tree_with(depth, full, rng)
    }

    /// Initial population member `i` of ramped half-and-half: depths cycle through
    /// `min_init_depth..=max_init_depth`, and "full" and "grow" alternate within each depth.
    pub fn ramped<R: Rng + ?Sized>(&self, i: usize, rng: &mut R) -> GpTree {
        let (lo, hi) = self.init_depths();
        let depth = lo + ((i / 2) % (hi - lo + 1) as usize) as u32;
        self.tree_with(depth, i.is_multiple_of(2), rng)
    }

    fn init_depths(&self) -> (u32, u32) {
        let cap = self.depth_limit() as u32 - 1;
        let lo = self.min_init_depth.min(cap);
        (lo, self.max_init_depth.clamp(lo, cap))
    }

    /// A tree whose bodies are built by one method to `depth` (shallower if too big).
    fn tree_with<R: Rng + ?Sized>(&self, depth: u32, full: bool, rng: &mut R) -> GpTree {
        let count = self.automata_count();
        let limit = self.size_limit();
        let mut nodes = Vec::with_capacity(128);
        nodes.push(Node::Top(count as u8));
        for a in 1..=count {
            // Room for this body, leaving one node for each body after it.
            let budget = limit - nodes.len() - (count - a);
            let start = nodes.len();
            let mut d = depth as usize;
            loop {
                self.generate(Type::TreeNode, 1, 1 + d, full, a, count, rng, &mut nodes);
                if nodes.len() - start <= budget {
                    break;
                }
                nodes.truncate(start);
                d = d.saturating_sub(1);
            }
        }
        // Built legal by construction; the check is a guard.
        GpTree::new(nodes).unwrap_or_else(|_| fallback(count))
    }

    /// Appends a random subtree of type `ty` at `depth`, no deeper than `max_depth`.
    #[allow(clippy::too_many_arguments)]
    fn generate<R: Rng + ?Sized>(
        &self,
        ty: Type,
        depth: usize,
        max_depth: usize,
        full: bool,
        automaton: usize,
        count: usize,
        rng: &mut R,
        out: &mut Vec<Node>,
    ) {
        let node = match ty {
            Type::Value => Node::Value(self.random_value(rng)),
            Type::Var => {
                Node::Var(Var::new(rng.random_range(0..VARIABLES as u8)).unwrap_or(Var::LENGTH))
            }
            Type::Automaton => Node::Target(random_target(automaton, count, self.creation, rng)),
            Type::Root | Type::TreeNode => {
                let w = &self.weights;
                let branching = [
                    (w.seq, SEQ),
                    (w.conditional, IFS),
                    (w.push_pop, PUSH_POP),
                    (w.repeat, REPEATS),
                ];
                let actions = [
                    (w.rotate, ROTATIONS),
                    (w.create, CREATE),
                    (w.variable, VARIABLE_OPS),
                ];
                let terminals = [(w.wait, &[Node::Wait][..]), (w.killme, &[Node::Killme][..])];
                if depth >= max_depth {
                    pick_family(&terminals, rng)
                } else if full && depth + 1 < max_depth {
                    pick_family(&branching, rng)
                } else if full
                    || rng.random_bool(sylva_core::rng::probability(self.grow_function_rate))
                {
                    if rng.random_bool(sylva_core::rng::probability(self.branching_rate)) {
                        pick_family(&branching, rng)
                    } else {
                        pick_family(&actions, rng)
                    }
                } else {
                    pick_family(&terminals, rng)
                }
            }
        };
        out.push(node);
        for &child in node.child_types() {
            self.generate(
                child,
                depth + 1,
                max_depth,
                full,
                automaton,
                count,
                rng,
                out,
            );
        }
    }

    /// A random value: a multiple of `value_step` in -10..=10, or any number if the step is 0.
    pub fn random_value<R: Rng + ?Sized>(&self, rng: &mut R) -> f32 {
        let step = f64::from(self.value_step);
        if !(step > 0.0 && step.is_finite()) {
            return rng.random_range(-VALUE_LIMIT..=VALUE_LIMIT);
        }
        let steps = (f64::from(VALUE_LIMIT) / step).floor().max(1.0) as i64;
        let k = rng.random_range(-steps..=steps) as f64;
        value_at(k, step)
    }

    /// Moves one random value of `tree` by one or two value steps (0.1 when the step is 0),
    /// within -10..=10; false when the tree has no value.
    fn nudge<R: Rng + ?Sized>(&self, tree: &mut GpTree, rng: &mut R, found: &mut Points) -> bool {
        found.terminals.clear();
        let values = tree.nodes().iter().enumerate();
        found.terminals.extend(
            values
                .filter(|(_, n)| matches!(n, Node::Value(_)))
                .map(|(i, _)| i as u32),
        );
        if found.terminals.is_empty() {
            return false;
        }
        let i = found.terminals[rng.random_range(0..found.terminals.len())] as usize;
        let Node::Value(value) = tree.nodes()[i] else {
            return false;
        };
        let step = f64::from(self.value_step);
        let step = if step > 0.0 && step.is_finite() {
            step
        } else {
            0.1
        };
        let by = [-2.0, -1.0, 1.0, 2.0][rng.random_range(0..4)];
        let k = (f64::from(value) / step).round() + by;
        let mut nodes = tree.nodes().to_vec();
        nodes[i] = Node::Value(value_at(k, step));
        if let Ok(t) = GpTree::new(nodes) {
            *tree = t;
        }
        true
    }

    /// A random point of `tree` passing `keep`: a function point with probability
    /// `function_point_rate` when both kinds pass. One pass, gathering the candidates into
    /// `found`'s buffers.
    fn point<R: Rng + ?Sized>(
        &self,
        tree: &GpTree,
        keep: impl Fn(usize) -> bool,
        rng: &mut R,
        found: &mut Points,
    ) -> Option<usize> {
        found.functions.clear();
        found.terminals.clear();
        for (i, n) in tree.nodes().iter().enumerate() {
            if keep(i) {
                if n.arity() > 0 {
                    found.functions.push(i as u32);
                } else {
                    found.terminals.push(i as u32);
                }
            }
        }
        let want_function = match (found.functions.len(), found.terminals.len()) {
            (0, 0) => return None,
            (0, _) => false,
            (_, 0) => true,
            _ => rng.random_bool(sylva_core::rng::probability(self.function_point_rate)),
        };
        let pool = if want_function {
            &found.functions
        } else {
            &found.terminals
        };
        Some(pool[rng.random_range(0..pool.len())] as usize)
    }
}

/// Candidate points, by kind; reused between calls.
#[derive(Default)]
struct Points {
    functions: Vec<u32>,
    terminals: Vec<u32>,
}

thread_local! {
    /// One thread's candidate points, so choosing points does not allocate once they have
    /// grown.
    static SCRATCH: RefCell<Points> = RefCell::default();
}

/// A tree of `count` automata that all just wait (never needed; a guard).
fn fallback(count: usize) -> GpTree {
    let mut nodes = vec![Node::Top(count as u8)];
    nodes.extend(std::iter::repeat_n(Node::Wait, count));
    GpTree::new(nodes).unwrap_or_else(|_| fallback(1))
}

/// A legal target of automaton `automaton` (1-based) of `count`.
fn random_target<R: Rng + ?Sized>(
    automaton: usize,
    count: usize,
    creation: Creation,
    rng: &mut R,
) -> Target {
    if automaton < count && creation == Creation::Next {
        Target::Automaton(automaton as u8 + 1)
    } else if automaton < count {
        Target::Automaton(rng.random_range(automaton + 1..=count) as u8)
    } else if rng.random_bool(0.75) {
        Target::Leaf
    } else {
        Target::Flower
    }
}

/// Moves a target from automaton `from` of `from_count` into automaton `to` of `to_count`
/// (1-based), keeping its level relative to the automaton that creates it (always the next
/// level under [`Creation::Next`]).
pub fn repair_target(
    target: Target,
    from: usize,
    from_count: usize,
    to: usize,
    to_count: usize,
    creation: Creation,
) -> Target {
    let next_only = creation == Creation::Next;
    let legal = target.legal_in(to, to_count)
        && !(next_only && matches!(target, Target::Automaton(n) if usize::from(n) != to + 1));
    if legal && from == to && from_count == to_count {
        return target;
    }
    let offset = match target {
        Target::Automaton(_) if next_only => 1,
        Target::Automaton(n) => usize::from(n).saturating_sub(from).max(1),
        Target::Leaf | Target::Flower => 1,
    };
    let level = to + offset;
    if level <= to_count && to < to_count {
        Target::Automaton(level as u8)
    } else if to < to_count {
        Target::Automaton(to_count as u8)
    } else if target == Target::Flower {
        Target::Flower
    } else {
        Target::Leaf
    }
}

impl Crossover<GpTree> for SubtreeCrossover {
    fn crossover<R: Rng + ?Sized>(&self, a: &GpTree, b: &GpTree, rng: &mut R) -> GpTree {
        SCRATCH.with(|cell| self.cross(a, b, rng, &mut cell.borrow_mut()))
    }
}

impl SubtreeCrossover {
    fn cross<R: Rng + ?Sized>(
        &self,
        a: &GpTree,
        b: &GpTree,
        rng: &mut R,
        points: &mut Points,
    ) -> GpTree {
        let c = &self.config;
        let (ia, ib) = (a.node_info(), b.node_info());
        let (limit, depth_limit) = (c.size_limit(), c.depth_limit());
        for _ in 0..ATTEMPTS {
            let Some(pa) = c.point(a, |i| i > 0, rng, points) else {
                break;
            };
            let ty = a.nodes()[pa].ty();
            let removed = ia[pa].end as usize - pa;
            let room = limit.saturating_sub(a.len() - removed);
            let depth_room = depth_limit.saturating_sub(usize::from(ia[pa].depth));
            let fits = |j: usize| {
                j > 0
                    && b.nodes()[j].ty() == ty
                    && ib[j].end as usize - j <= room
                    && usize::from(ib[j].height) <= depth_room
            };
            let ka = ia[pa].automaton;
            let pb = c
                .point(b, |j| fits(j) && ib[j].automaton == ka, rng, points)
                .or_else(|| c.point(b, fits, rng, points));
            let Some(pb) = pb else {
                continue;
            };
            let (end_a, end_b) = (ia[pa].end as usize, ib[pb].end as usize);
            let mut nodes = Vec::with_capacity(a.len() - removed + end_b - pb);
            nodes.extend_from_slice(&a.nodes()[..pa]);
            let (from, to) = (usize::from(ib[pb].automaton) + 1, usize::from(ka) + 1);
            nodes.extend(b.nodes()[pb..end_b].iter().map(|&n| match n {
                Node::Target(t) => Node::Target(repair_target(
                    t,
                    from,
                    b.automata(),
                    to,
                    a.automata(),
                    c.creation,
                )),
                other => other,
            }));
            nodes.extend_from_slice(&a.nodes()[end_a..]);
            if let Ok(child) = GpTree::new(nodes) {
                return child;
            }
        }
        a.clone()
    }
}

impl Mutate<GpTree> for SubtreeMutation {
    fn mutate<R: Rng + ?Sized>(&self, tree: &mut GpTree, rng: &mut R) {
        SCRATCH.with(|cell| self.mutate_with(tree, rng, &mut cell.borrow_mut()));
    }
}

impl SubtreeMutation {
    fn mutate_with<R: Rng + ?Sized>(&self, tree: &mut GpTree, rng: &mut R, points: &mut Points) {
        let c = &self.config;
        // Drawn only when nudges are on, so runs without them keep their bytes.
        if c.nudge > 0.0
            && rng.random_bool(sylva_core::rng::probability(c.nudge))
            && c.nudge(tree, rng, points)
        {
            return;
        }
        let info = tree.node_info();
        let Some(p) = c.point(tree, |i| i > 0, rng, points) else {
            return;
        };
        let node = tree.nodes()[p];
        let (end, depth) = (info[p].end as usize, usize::from(info[p].depth));
        let room = c.size_limit().saturating_sub(tree.len() - (end - p));
        let count = tree.automata();
        let automaton = usize::from(info[p].automaton) + 1;
        let mut sub = Vec::with_capacity(32);
        let mut max_depth = (depth + c.mutation_depth as usize).min(c.depth_limit());
        loop {
            sub.clear();
            c.generate(
                node.ty(),
                depth,
                max_depth,
                false,
                automaton,
                count,
                rng,
                &mut sub,
            );
            if sub.len() <= room.max(1) || max_depth <= depth {
                break;
            }
            max_depth -= 1;
        }
        let mut nodes = Vec::with_capacity(tree.len() - (end - p) + sub.len());
        nodes.extend_from_slice(&tree.nodes()[..p]);
        nodes.extend_from_slice(&sub);
        nodes.extend_from_slice(&tree.nodes()[end..]);
        if let Ok(t) = GpTree::new(nodes) {
            *tree = t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::rng;

    #[test]
    fn repair_keeps_relative_levels() {
        use Creation::{Later, Next};
        use Target::*;
        // (target, from, from count, to, to count, rule) and the repaired target.
        let cases = [
            ((Automaton(2), 1, 3, 2, 3, Later), Automaton(3)),
            ((Automaton(3), 2, 3, 1, 3, Later), Automaton(2)),
            ((Automaton(3), 1, 3, 2, 3, Later), Automaton(3)),
            ((Automaton(2), 1, 3, 3, 3, Later), Leaf),
            ((Leaf, 3, 3, 1, 3, Later), Automaton(2)),
            ((Flower, 2, 2, 2, 2, Later), Flower),
            ((Flower, 3, 3, 1, 2, Later), Automaton(2)),
            // Only the next level under section 3's rule.
            ((Automaton(3), 1, 3, 1, 3, Next), Automaton(2)),
            ((Automaton(2), 1, 3, 1, 3, Next), Automaton(2)),
            ((Automaton(3), 1, 4, 2, 4, Next), Automaton(3)),
            ((Automaton(3), 2, 3, 3, 3, Next), Leaf),
        ];
        for ((t, from, from_count, to, to_count, rule), repaired) in cases {
            let got = repair_target(t, from, from_count, to, to_count, rule);
            assert_eq!(
                got, repaired,
                "{t} from {from}/{from_count} to {to}/{to_count}"
            );
        }
    }

    #[test]
    fn next_only_trees_create_only_the_next_automaton() {
        let c = GpConfig {
            automata: 3,
            creation: Creation::Next,
            ..GpConfig::default()
        };
        let next_only = |t: &GpTree| {
            t.nodes()
                .iter()
                .zip(t.node_info())
                .all(|(n, info)| match n {
                    Node::Target(Target::Automaton(k)) => {
                        usize::from(*k) == usize::from(info.automaton) + 2
                    }
                    _ => true,
                })
        };
        let (cross, mutate) = (
            SubtreeCrossover { config: c },
            SubtreeMutation { config: c },
        );
        let mut r = rng::seeded(5);
        let mut pool: Vec<GpTree> = (0..40).map(|i| c.ramped(i, &mut r)).collect();
        // Parents bred under Table 1's rule may create any later automaton; their children
        // under section 3's are repaired to the next.
        let loose = GpConfig {
            creation: Creation::Later,
            ..c
        };
        pool.extend((0..40).map(|i| loose.ramped(i, &mut r)));
        assert!(pool[..40].iter().all(next_only));
        assert!(
            !pool[40..].iter().all(next_only),
            "the loose rule skips levels"
        );
        for i in 0..400 {
            let (a, b) = (&pool[i % 80], &pool[(i * 7 + 3) % 80]);
            let mut child = cross.crossover(a, b, &mut r);
            mutate.mutate(&mut child, &mut r);
            // What comes from the second parent is repaired, and mutation grows by the
            // rule: a child of a next-only first parent is next-only, whatever the second.
            if next_only(a) {
                assert!(next_only(&child), "child {i}");
            }
        }
    }

    #[test]
    fn values_are_on_the_grid() {
        let c = GpConfig::default();
        let mut r = rng::seeded(3);
        for _ in 0..1000 {
            let v = c.random_value(&mut r);
            assert!(v.abs() <= 10.0);
            assert!(v.to_string().len() <= 5, "{v}");
        }
    }

    #[test]
    fn nudges_move_one_value_by_one_or_two_steps() {
        let tree =
            GpTree::parse("(Top (Seq (RotateH 3.2) (Multiply Thickness 0.4)) (Killme))").unwrap();
        let nudge = SubtreeMutation {
            config: GpConfig {
                nudge: 1.0,
                ..GpConfig::default()
            },
        };
        let mut r = rng::seeded(2);
        let mut seen = std::collections::BTreeSet::new();
        for _ in 0..200 {
            let mut child = tree.clone();
            nudge.mutate(&mut child, &mut r);
            let changed: Vec<(f32, f32)> = tree
                .nodes()
                .iter()
                .zip(child.nodes())
                .filter(|(a, b)| a != b)
                .map(|pair| match pair {
                    (Node::Value(a), Node::Value(b)) => (*a, *b),
                    other => panic!("only values move: {other:?}"),
                })
                .collect();
            assert_eq!(changed.len(), 1, "{child}");
            seen.insert(changed[0].1.to_string());
        }
        // Both values, each by ±0.1 and ±0.2, printed on the grid (0.3, not 0.30000001).
        let all = ["3", "3.1", "3.3", "3.4", "0.2", "0.3", "0.5", "0.6"];
        assert_eq!(seen, all.iter().map(|v| v.to_string()).collect());

        // Values stay within -10..=10, and a tree without values gets a subtree mutation.
        let mut edge = GpTree::parse("(Top (RotateH 10) (Wait))").unwrap();
        for _ in 0..20 {
            nudge.mutate(&mut edge, &mut r);
            assert!(edge.nodes().iter().all(|n| match n {
                Node::Value(v) => v.abs() <= 10.0,
                _ => true,
            }));
        }
        let bare = GpTree::parse("(Top (Seq (Wait) (Wait)) (Killme))").unwrap();
        let changed = (0..20).any(|_| {
            let mut child = bare.clone();
            nudge.mutate(&mut child, &mut r);
            child != bare
        });
        assert!(changed, "no values: mutation replaces a subtree");
    }

    #[test]
    fn initial_sizes() {
        let c = GpConfig::default();
        let mut r = rng::seeded(1);
        let sizes: Vec<usize> = (0..500).map(|i| c.ramped(i, &mut r).len()).collect();
        let mean = sizes.iter().sum::<usize>() as f64 / sizes.len() as f64;
        assert!(sizes.iter().all(|&s| s <= 500));
        eprintln!("mean initial size {mean}, max {:?}", sizes.iter().max());
        assert!((70.0..=130.0).contains(&mean), "{mean}");
    }
}
