//! Strongly typed GP trees (section 4.2, Table 1), stored flat.
//!
//! A [`GpTree`] is a `Vec<`[`Node`]`>` in prefix order: a node is followed by its children's
//! subtrees, left to right. Arities are fixed by the node (only [`Node::Top`] carries its
//! child count), so no sizes or pointers are stored: one allocation per tree, 8 bytes a node,
//! and a subtree is a contiguous slice, which makes crossover a splice of three slices.
//!
//! Every operator returns the type [`Type::TreeNode`]; its parameters are of three terminal
//! types: [`Type::Value`] (a number in -10..=10), [`Type::Var`] (a variable number) and
//! [`Type::Automaton`] (an automaton number, or a leaf or a flower). Every type has terminals,
//! so a tree can always be finished at any depth.
//!
//! [`GpTree::new`] is the only way to build a tree and it checks everything, so a `GpTree` in
//! hand is always well typed and follows the rules of construction (Table 1 and section 4.4):
//!
//! - the root is a [`Node::Top`] with 1 to [`MAX_AUTOMATA`] children, one per automaton;
//!   there is no `Top` anywhere else;
//! - automaton `i` (numbered from 1 like the paper's "Automaton 1") may only create automata
//!   numbered `i + 1` or more;
//! - only the last automaton (the last level of branches) adds leaves and flowers, and it
//!   creates nothing else;
//! - values are finite and within -10..=10;
//! - at most [`MAX_NODES`] nodes and depth at most [`MAX_TREE_DEPTH`] (the compiler and the
//!   printer recurse, so depth is bounded).

use std::fmt;
use std::ops::Range;

use thiserror::Error;

/// Variables per automaton: [`Var::LENGTH`], [`Var::THICKNESS`] and four general variables
/// `Var1`..`Var4`. Fixed, so an automaton's variables are an inline array.
pub const VARIABLES: usize = 6;
/// Most automata (children of `Top`) a tree may hold.
pub const MAX_AUTOMATA: usize = 8;
/// Values lie in `-VALUE_LIMIT..=VALUE_LIMIT`.
pub const VALUE_LIMIT: f32 = 10.0;
/// Most nodes a tree may hold (compiled state indices and Repeat slots stay in 16 bits).
pub const MAX_NODES: usize = 65_535;
/// Deepest tree accepted (root at depth 0).
pub const MAX_TREE_DEPTH: usize = 512;

/// The types of the strongly typed GP.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Type {
    /// The root's slot: only [`Node::Top`] fits it.
    Root,
    /// Every operator: a piece of automaton.
    TreeNode,
    /// A number in -10..=10.
    Value,
    /// A variable number.
    Var,
    /// An automaton number, a leaf or a flower.
    Automaton,
}

impl Type {
    /// What the type is called in messages.
    pub fn describe(self) -> &'static str {
        match self {
            Type::Root => "a (Top ...) root",
            Type::TreeNode => "an operator",
            Type::Value => "a value from -10 to 10",
            Type::Var => "a variable (Length, Thickness, Var1 to Var4)",
            Type::Automaton => "an automaton number (A2, A3, ...), Leaf or Flower",
        }
    }
}

/// A variable number: 0 is Length, 1 is Thickness, 2..=5 are `Var1`..`Var4`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Var(u8);

impl Var {
    /// The step length: each iteration an automaton moves this far along its heading.
    pub const LENGTH: Var = Var(0);
    /// The thickness recorded with each position (1 at the root's base).
    pub const THICKNESS: Var = Var(1);
    const NAMES: [&'static str; VARIABLES] =
        ["Length", "Thickness", "Var1", "Var2", "Var3", "Var4"];

    /// Variable `index` (`0..VARIABLES`), `None` beyond.
    pub fn new(index: u8) -> Option<Var> {
        (usize::from(index) < VARIABLES).then_some(Var(index))
    }

    /// The index into an automaton's variables.
    #[inline]
    pub fn index(self) -> usize {
        usize::from(self.0)
    }

    /// The name printed in S-expressions.
    pub fn name(self) -> &'static str {
        Self::NAMES[self.index()]
    }

    /// The variable with this printed name.
    pub fn from_name(name: &str) -> Option<Var> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Var(i as u8))
    }
}

/// What `CreateAutomaton` creates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// A new instance of automaton `n` (1-based, as printed: `A2` is `Automaton(2)`).
    Automaton(u8),
    /// A leaf at the current position.
    Leaf,
    /// A flower at the current position.
    Flower,
}

impl Target {
    /// Whether automaton `automaton` (1-based) of `count` may create this.
    pub fn legal_in(self, automaton: usize, count: usize) -> bool {
        match self {
            Target::Automaton(n) => usize::from(n) > automaton && usize::from(n) <= count,
            Target::Leaf | Target::Flower => automaton == count,
        }
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Automaton(n) => write!(f, "A{n}"),
            Target::Leaf => f.write_str("Leaf"),
            Target::Flower => f.write_str("Flower"),
        }
    }
}

/// One node of a GP tree. Operators are listed with their children's types.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    /// The root: one `TreeNode` child per automaton (the count is stored).
    Top(u8),
    /// `(Seq a b)`: `a` then `b`.
    Seq,
    /// `(IfLess var value then else)`: `var < value`.
    IfLess,
    /// `(IfGreater var value then else)`: `var > value`.
    IfGreater,
    /// `(IfEqual var value then else)`: `|var - value| <= tolerance`.
    IfEqual,
    /// `(PushPop body)`: Push, `body`, Pop: frame, position and variables are restored.
    PushPop,
    /// `(Repeat count body)`: `body` `|round(count)|` times, with its own counter.
    Repeat,
    /// `(RepeatIndex count body)`: like `Repeat`, counter started from the automaton's index
    /// (`max(0, |round(count)| - index)`).
    RepeatIndex,
    /// `(RotateH value)`: roll about the heading.
    RotateH,
    /// `(RotateL value)`: pitch about the left axis (turns H towards U).
    RotateL,
    /// `(RotateU value)`: yaw about the up axis (turns H towards L).
    RotateU,
    /// `(CreateAutomaton target)`.
    CreateAutomaton,
    /// `(Assign var value)`.
    Assign,
    /// `(Add var value)`.
    Add,
    /// `(Multiply var value)`.
    Multiply,
    /// `(Wait)`: ends this iteration's steps; the automaton then moves one step.
    Wait,
    /// `(Killme)`: the automaton dies.
    Killme,
    /// A constant of type `Value`.
    Value(f32),
    /// A terminal of type `Var`.
    Var(Var),
    /// A terminal of type `Automaton`.
    Target(Target),
}

const NO_CHILDREN: &[Type] = &[];
const SEQ: &[Type] = &[Type::TreeNode, Type::TreeNode];
const IF: &[Type] = &[Type::Var, Type::Value, Type::TreeNode, Type::TreeNode];
const ONE: &[Type] = &[Type::TreeNode];
const REPEAT: &[Type] = &[Type::Value, Type::TreeNode];
const ROTATE: &[Type] = &[Type::Value];
const CREATE: &[Type] = &[Type::Automaton];
const VARIABLE: &[Type] = &[Type::Var, Type::Value];

impl Node {
    /// The type this node returns.
    pub fn ty(self) -> Type {
        match self {
            Node::Top(_) => Type::Root,
            Node::Value(_) => Type::Value,
            Node::Var(_) => Type::Var,
            Node::Target(_) => Type::Automaton,
            _ => Type::TreeNode,
        }
    }

    /// Types of the children, in order; for `Top`, see [`Node::arity`].
    pub fn child_types(self) -> &'static [Type] {
        match self {
            Node::Seq => SEQ,
            Node::IfLess | Node::IfGreater | Node::IfEqual => IF,
            Node::PushPop => ONE,
            Node::Repeat | Node::RepeatIndex => REPEAT,
            Node::RotateH | Node::RotateL | Node::RotateU => ROTATE,
            Node::CreateAutomaton => CREATE,
            Node::Assign | Node::Add | Node::Multiply => VARIABLE,
            Node::Top(_)
            | Node::Wait
            | Node::Killme
            | Node::Value(_)
            | Node::Var(_)
            | Node::Target(_) => NO_CHILDREN,
        }
    }

    /// Number of children.
    #[inline]
    pub fn arity(self) -> usize {
        // `child_types().len()`, spelled out: breeding calls this for every node.
        match self {
            Node::Top(n) => usize::from(n),
            Node::IfLess | Node::IfGreater | Node::IfEqual => 4,
            Node::Seq
            | Node::Repeat
            | Node::RepeatIndex
            | Node::Assign
            | Node::Add
            | Node::Multiply => 2,
            Node::PushPop
            | Node::RotateH
            | Node::RotateL
            | Node::RotateU
            | Node::CreateAutomaton => 1,
            Node::Wait | Node::Killme | Node::Value(_) | Node::Var(_) | Node::Target(_) => 0,
        }
    }

    /// The type of child `k`.
    #[inline]
    pub fn child_type(self, k: usize) -> Type {
        match self {
            Node::Top(_) => Type::TreeNode,
            other => other.child_types()[k],
        }
    }

    /// The operator's name as printed (`None` for the three terminal types, printed by value).
    pub fn name(self) -> Option<&'static str> {
        Some(match self {
            Node::Top(_) => "Top",
            Node::Seq => "Seq",
            Node::IfLess => "IfLess",
            Node::IfGreater => "IfGreater",
            Node::IfEqual => "IfEqual",
            Node::PushPop => "PushPop",
            Node::Repeat => "Repeat",
            Node::RepeatIndex => "RepeatIndex",
            Node::RotateH => "RotateH",
            Node::RotateL => "RotateL",
            Node::RotateU => "RotateU",
            Node::CreateAutomaton => "CreateAutomaton",
            Node::Assign => "Assign",
            Node::Add => "Add",
            Node::Multiply => "Multiply",
            Node::Wait => "Wait",
            Node::Killme => "Killme",
            Node::Value(_) | Node::Var(_) | Node::Target(_) => return None,
        })
    }

    /// The operator with this name (`Top` gives `Top(0)`: its count comes from its children).
    pub fn from_name(name: &str) -> Option<Node> {
        Some(match name {
            "Top" => Node::Top(0),
            "Seq" => Node::Seq,
            "IfLess" => Node::IfLess,
            "IfGreater" => Node::IfGreater,
            "IfEqual" => Node::IfEqual,
            "PushPop" => Node::PushPop,
            "Repeat" => Node::Repeat,
            "RepeatIndex" => Node::RepeatIndex,
            "RotateH" => Node::RotateH,
            "RotateL" => Node::RotateL,
            "RotateU" => Node::RotateU,
            "CreateAutomaton" => Node::CreateAutomaton,
            "Assign" => Node::Assign,
            "Add" => Node::Add,
            "Multiply" => Node::Multiply,
            "Wait" => Node::Wait,
            "Killme" => Node::Killme,
            _ => return None,
        })
    }

    /// Whether two nodes are identical, comparing values bit for bit.
    pub fn same(self, other: Node) -> bool {
        match (self, other) {
            (Node::Value(a), Node::Value(b)) => a.to_bits() == b.to_bits(),
            (a, b) => a == b,
        }
    }
}

/// Why a node list is not a valid tree. Indices are positions in the prefix-order list.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum TreeError {
    /// No nodes.
    #[error("the tree is empty")]
    Empty,
    /// A node of the wrong type for its slot.
    #[error("node {index}: expected {}, found {found}", expected.describe())]
    WrongType {
        /// Position of the node.
        index: usize,
        /// The slot's type.
        expected: Type,
        /// What the node is.
        found: String,
    },
    /// `Top` anywhere but the root.
    #[error("node {index}: Top is only allowed at the root")]
    TopBelowRoot {
        /// Position of the node.
        index: usize,
    },
    /// `Top` with no child or more than [`MAX_AUTOMATA`].
    #[error("Top must have 1 to {MAX_AUTOMATA} automata, found {0}")]
    AutomataCount(usize),
    /// The list ends before every child is given.
    #[error("the tree is cut short: {missing} more node(s) expected")]
    Truncated {
        /// Children still missing.
        missing: usize,
    },
    /// Nodes after the root's subtree.
    #[error("node {index}: the tree ended before this node")]
    Trailing {
        /// First extra node.
        index: usize,
    },
    /// A value out of -10..=10 or not finite.
    #[error("node {index}: value {value} is not a number from -10 to 10")]
    Value {
        /// Position of the node.
        index: usize,
        /// The value.
        value: f32,
    },
    /// A variable number out of range.
    #[error("node {index}: variable number {var} does not exist")]
    Variable {
        /// Position of the node.
        index: usize,
        /// Its number.
        var: u8,
    },
    /// A `CreateAutomaton` target not allowed in its automaton.
    #[error(
        "node {index}: automaton {automaton} of {count} may not create {target} ({})",
        legal_targets(*automaton, *count)
    )]
    Target {
        /// Position of the node.
        index: usize,
        /// The automaton it is in, 1-based.
        automaton: usize,
        /// Automata in the tree.
        count: usize,
        /// The target.
        target: Target,
    },
    /// More than [`MAX_NODES`] nodes.
    #[error("the tree has {0} nodes, more than {MAX_NODES}")]
    TooBig(usize),
    /// Deeper than [`MAX_TREE_DEPTH`].
    #[error("the tree is deeper than {MAX_TREE_DEPTH}")]
    TooDeep,
}

/// What automaton `automaton` (1-based) of `count` may create, in words.
pub fn legal_targets(automaton: usize, count: usize) -> String {
    if automaton >= count {
        "the last automaton creates only Leaf or Flower".to_owned()
    } else if automaton + 1 == count {
        format!("automaton {automaton} may create only A{count}")
    } else {
        format!(
            "automaton {automaton} may create only A{} to A{count}",
            automaton + 1
        )
    }
}

/// Bytes a node takes in a [`GpTree`] (the node and the facts kept about it).
pub const NODE_BYTES: u64 = (std::mem::size_of::<Node>() + std::mem::size_of::<NodeInfo>()) as u64;

/// A valid GP tree: well typed, following the rules of construction. It keeps the
/// [`NodeInfo`] of its nodes, found while checking them, for breeding (each tree is a parent
/// about twice a generation, and crossover needs the facts of every node of both parents).
#[derive(Clone, Debug)]
pub struct GpTree {
    nodes: Vec<Node>,
    info: Vec<NodeInfo>,
}

impl PartialEq for GpTree {
    /// Identical trees: same nodes, values compared bit for bit.
    fn eq(&self, other: &Self) -> bool {
        self.nodes.len() == other.nodes.len()
            && self.nodes.iter().zip(&other.nodes).all(|(a, b)| a.same(*b))
    }
}

/// Facts about one node, computed by [`GpTree::node_info`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NodeInfo {
    /// One past the last node of its subtree.
    pub end: u32,
    /// Depth (the root is 0).
    pub depth: u16,
    /// Height of its subtree (a terminal is 0).
    pub height: u16,
    /// The automaton it belongs to, 0-based (the root reports 0).
    pub automaton: u8,
}

impl GpTree {
    /// Checks `nodes` and wraps them.
    pub fn new(nodes: Vec<Node>) -> Result<GpTree, TreeError> {
        let mut info = Vec::new();
        validate(&nodes, &mut info)?;
        ends_and_heights(&nodes, &mut info);
        Ok(GpTree { nodes, info })
    }

    /// The nodes, in prefix order.
    #[inline]
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The nodes, giving up the tree.
    pub fn into_nodes(self) -> Vec<Node> {
        self.nodes
    }

    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Never true: a tree has at least a `Top` and one automaton.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Number of automata (children of `Top`).
    pub fn automata(&self) -> usize {
        self.nodes[0].arity()
    }

    /// One past the last node of the subtree at `index`.
    pub fn subtree_end(&self, index: usize) -> usize {
        subtree_end(&self.nodes, index)
    }

    /// The node ranges of the automata's bodies, in order.
    pub fn bodies(&self) -> Vec<Range<usize>> {
        let mut out = Vec::with_capacity(self.automata());
        let mut at = 1;
        for _ in 0..self.automata() {
            let end = self.subtree_end(at);
            out.push(at..end);
            at = end;
        }
        out
    }

    /// Depth of the tree: edges on the longest path from the root (a `Top` with terminal
    /// bodies has depth 1).
    pub fn depth(&self) -> usize {
        usize::from(self.info[0].height)
    }

    /// One [`NodeInfo`] per node.
    #[inline]
    pub fn node_info(&self) -> &[NodeInfo] {
        &self.info
    }
}

/// One past the end of the subtree at `index` of a well-formed prefix list.
pub(crate) fn subtree_end(nodes: &[Node], index: usize) -> usize {
    let mut open = 1usize;
    let mut i = index;
    while open > 0 && i < nodes.len() {
        open = open - 1 + nodes[i].arity();
        i += 1;
    }
    i
}

/// Fills in the ends and heights of `info` (depths and automata already set) for a
/// well-formed prefix list: backwards, since children come after their parent, their ends
/// are known, and a subtree ends where its last child's does.
fn ends_and_heights(nodes: &[Node], info: &mut [NodeInfo]) {
    let n = nodes.len();
    for i in (0..n).rev() {
        let mut end = i as u32 + 1;
        let mut height = 0u16;
        let mut child = i + 1;
        for _ in 0..nodes[i].arity() {
            if child >= n {
                break;
            }
            let c = info[child];
            end = c.end;
            height = height.max(c.height + 1);
            child = c.end as usize;
        }
        info[i].end = end;
        info[i].height = height;
    }
}

/// Checks types, rules of construction and limits; fills `info` with each node's depth and
/// automaton on the way.
fn validate(nodes: &[Node], info: &mut Vec<NodeInfo>) -> Result<(), TreeError> {
    if nodes.is_empty() {
        return Err(TreeError::Empty);
    }
    if nodes.len() > MAX_NODES {
        return Err(TreeError::TooBig(nodes.len()));
    }
    let count = match nodes[0] {
        Node::Top(n) => usize::from(n),
        other => {
            return Err(TreeError::WrongType {
                index: 0,
                expected: Type::Root,
                found: describe_node(other),
            });
        }
    };
    if !(1..=MAX_AUTOMATA).contains(&count) {
        return Err(TreeError::AutomataCount(count));
    }
    info.clear();
    info.reserve(nodes.len());
    info.push(NodeInfo::default());
    // Slots still to fill: (type, automaton 1-based, depth), last to be filled first.
    let mut slots: Vec<(Type, usize, usize)> = Vec::with_capacity(64);
    for a in (1..=count).rev() {
        slots.push((Type::TreeNode, a, 1));
    }
    for (index, &node) in nodes.iter().enumerate().skip(1) {
        let Some((ty, automaton, depth)) = slots.pop() else {
            return Err(TreeError::Trailing { index });
        };
        if depth > MAX_TREE_DEPTH {
            return Err(TreeError::TooDeep);
        }
        if matches!(node, Node::Top(_)) {
            return Err(TreeError::TopBelowRoot { index });
        }
        if node.ty() != ty {
            return Err(TreeError::WrongType {
                index,
                expected: ty,
                found: describe_node(node),
            });
        }
        match node {
            Node::Value(value) if !(value.is_finite() && value.abs() <= VALUE_LIMIT) => {
                return Err(TreeError::Value { index, value });
            }
            Node::Var(var) if var.index() >= VARIABLES => {
                return Err(TreeError::Variable { index, var: var.0 });
            }
            Node::Target(target) if !target.legal_in(automaton, count) => {
                return Err(TreeError::Target {
                    index,
                    automaton,
                    count,
                    target,
                });
            }
            _ => {}
        }
        info.push(NodeInfo {
            end: 0,
            depth: depth as u16,
            height: 0,
            automaton: (automaton - 1) as u8,
        });
        for &ty in node.child_types().iter().rev() {
            slots.push((ty, automaton, depth + 1));
        }
    }
    if slots.is_empty() {
        Ok(())
    } else {
        Err(TreeError::Truncated {
            missing: slots.len(),
        })
    }
}

/// A node in words, for messages.
pub(crate) fn describe_node(node: Node) -> String {
    match node {
        Node::Value(v) => format!("the value {v}"),
        Node::Var(v) if v.index() < VARIABLES => format!("the variable {}", v.name()),
        Node::Var(v) => format!("variable number {}", v.0),
        Node::Target(t) => format!("the target {t}"),
        other => other.name().unwrap_or("?").to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn helix_like() -> Vec<Node> {
        vec![
            Node::Top(2),
            Node::Seq,
            Node::RotateH,
            Node::Value(3.2),
            Node::CreateAutomaton,
            Node::Target(Target::Automaton(2)),
            Node::Seq,
            Node::CreateAutomaton,
            Node::Target(Target::Leaf),
            Node::Wait,
        ]
    }

    #[test]
    fn arity_counts_the_child_types() {
        let value = Node::Value(1.0);
        let all = [
            Node::Seq,
            Node::IfLess,
            Node::IfGreater,
            Node::IfEqual,
            Node::PushPop,
            Node::Repeat,
            Node::RepeatIndex,
            Node::RotateH,
            Node::RotateL,
            Node::RotateU,
            Node::CreateAutomaton,
            Node::Assign,
            Node::Add,
            Node::Multiply,
            Node::Wait,
            Node::Killme,
            value,
            Node::Var(Var::LENGTH),
            Node::Target(Target::Leaf),
        ];
        for node in all {
            assert_eq!(node.arity(), node.child_types().len(), "{node:?}");
        }
        assert_eq!(Node::Top(3).arity(), 3);
    }

    #[test]
    fn node_is_small() {
        assert_eq!(std::mem::size_of::<Node>(), 8);
    }

    #[test]
    fn valid_tree_and_info() {
        let t = GpTree::new(helix_like()).unwrap();
        assert_eq!(t.automata(), 2);
        assert_eq!(t.bodies(), vec![1..6, 6..10]);
        assert_eq!(t.depth(), 3);
        let info = t.node_info();
        assert_eq!(info[0].end, 10);
        assert_eq!(info[1].end, 6);
        assert_eq!(info[1].automaton, 0);
        assert_eq!(info[6].automaton, 1);
        assert_eq!(info[8].automaton, 1);
        assert_eq!(info[8].depth, 3);
        assert_eq!(info[3].depth, 3);
        assert_eq!(info[1].height, 2);
    }

    #[test]
    fn rules_of_construction() {
        let mut n = helix_like();
        n[5] = Node::Target(Target::Leaf);
        assert!(matches!(
            GpTree::new(n),
            Err(TreeError::Target { automaton: 1, .. })
        ));
        let mut n = helix_like();
        n[8] = Node::Target(Target::Automaton(1));
        assert!(matches!(
            GpTree::new(n),
            Err(TreeError::Target { automaton: 2, .. })
        ));
        let mut n = helix_like();
        n[9] = Node::Top(1);
        assert_eq!(GpTree::new(n), Err(TreeError::TopBelowRoot { index: 9 }));
        let mut n = helix_like();
        n[3] = Node::Value(10.5);
        assert!(matches!(GpTree::new(n), Err(TreeError::Value { .. })));
        let mut n = helix_like();
        n.pop();
        assert_eq!(GpTree::new(n), Err(TreeError::Truncated { missing: 1 }));
        let mut n = helix_like();
        n.push(Node::Wait);
        assert_eq!(GpTree::new(n), Err(TreeError::Trailing { index: 10 }));
        assert_eq!(
            GpTree::new(vec![Node::Top(0)]),
            Err(TreeError::AutomataCount(0))
        );
    }

    #[test]
    fn too_deep_is_refused() {
        let mut n = vec![Node::Top(1)];
        n.extend(std::iter::repeat_n(Node::PushPop, MAX_TREE_DEPTH + 1));
        n.push(Node::Wait);
        assert_eq!(GpTree::new(n), Err(TreeError::TooDeep));
    }
}
