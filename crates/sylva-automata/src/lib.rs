//! Poncin's GP-programmed turtle automata (*Evolving 3D Models of Trees Using Genetic
//! Programming*).
//!
//! A strongly typed GP tree ([`GpTree`], section 4.2) is compiled by cellular encoding into
//! flat automata ([`Program`], Figures 4 to 6); a [`Simulator`] runs them as the paper's
//! pseudo-code says (section 2.2) and draws a [`Plant`].
//!
//! Where each element of the paper is in Sylva, and where Sylva chose otherwise and why:
//! `docs/fidelity.md`.
//!
//! - [`tree`]: the typed GP tree, its node types and checks.
//! - [`sexpr`]: trees printed and parsed as lilgp-style S-expressions.
//! - [`compile`]: cellular encoding into flat automata, and the semantics chosen.
//! - [`sim`]: the bounded simulator.
//! - [`sprout`]: random programs built to grow into trees, for a random plant to look at.
//! - [`gp`]: ramped half-and-half initialisation, typed subtree crossover and mutation.
//! - [`genome`]: [`AutomataGenome`], the genome file (a program and how it grows).
//! - [`problem`]: Poncin's GP run as an evolution problem (the `[automata]` settings).
//! - [`AutomataModel`]: the model as Sylva's [`Model`] and [`Evolve`].
//!
//! ```
//! use sylva_core::{Plant, PlantMeta};
//! use sylva_automata::{Detail, GpTree, GrowOptions, Program, Semantics, Simulator};
//!
//! // A trunk of 35 steps that starts a branch (automaton 2) at steps 10, 20 and 30; each
//! // branch grows 8 steps, bending 5° a step.
//! let tree: GpTree = "(Top (Seq (Repeat 3 (Seq (Repeat 10 (Wait)) (PushPop (Seq (RotateL 6) \
//!     (CreateAutomaton A2))))) (Repeat 5 (Wait))) (Repeat 8 (Seq (RotateL 0.5) (Wait))))"
//!     .parse()?;
//! let program = Program::compile(&tree, &Semantics::default());
//! let mut sim = Simulator::new();
//! let mut plant = Plant::new(PlantMeta::default());
//! let report = sim.run(&program, &GrowOptions::default(), Detail::Full, &mut plant);
//! assert_eq!((report.automata, report.points), (4, 35 + 3 * 8));
//! assert_eq!(plant.segments().len(), 59);
//! assert_eq!(plant.tips().count(), 4);
//! assert!(!report.bounds.any());
//! // For fitness: the same tips from far fewer segments (4 trunk runs, 3 branches).
//! sim.run(&program, &GrowOptions::default(), Detail::Chords, &mut plant);
//! assert_eq!(plant.segments().len(), 7);
//! assert_eq!(plant.tips().count(), 4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Choices where the paper is silent or ambiguous
//!
//! The figures are missing from the text we have, so the operators' meaning is rebuilt from
//! the prose. Each choice aims at making evolution work; the important ones can be changed.
//!
//! - **Values and angles.** Values are `f32` in -10..=10. A rotation turns by
//!   `value × degrees_per_unit` degrees ([`Semantics::degrees_per_unit`], default 10): ±100°,
//!   so the helix's 70° branches are `(RotateL 7)` and small bends stay reachable.
//! - **Variables.** Length, Thickness and four general variables `Var1`..`Var4` (fixed: an
//!   inline array). The root starts with Thickness 1 (section 4.4.2), Length
//!   [`GrowOptions::root_length`] (default 1; the evolution examples use 2.5, so 100
//!   iterations reach across the paper's sphere), the rest 0, heading up (+Y). Variables are clamped to ±10⁶ (counted), so nothing becomes infinite.
//! - **If** compares a variable with a value: `IfLess` (<), `IfGreater` (>) and `IfEqual`
//!   (within [`Semantics::equal_tolerance`], default 0.5). Both branches continue after the
//!   `If` by default ([`ElseEnd::Rejoin`]); the literal reading, where only *then* is the
//!   outgoing transition and the else branch ends the automaton, is [`ElseEnd::End`].
//! - **End of an automaton** kills it (the pseudo-code), so an automaton lives as many
//!   iterations as it passes `Wait`s; `Repeat` makes long lives cheap. [`AtEnd::Restart`]
//!   loops back to the first state instead, like Figure 1's hand-made automata. A killed
//!   automaton does not move in that iteration.
//! - **Repeat** runs its body `|round(value)|` times (0 to 10; a negative count is read by
//!   its size, so half of all random Repeats are not dead code). Each Repeat node has its own
//!   counter, set when the loop is entered. **RepeatIndex** starts its counter at
//!   `max(0, |round(value)| - index)`, where `index` is the automaton's birth rank among its
//!   creator's children (the root's is 0): later branches repeat less, as in a pine.
//! - **Push/Pop** save and restore the position, the frame and the variables, not the Repeat
//!   counters (they are control flow). The compound guarantees balance.
//! - **CreateAutomaton** spawns an instance at the creator's position with the creator's
//!   current frame (so `(PushPop (Seq (RotateL 7) (CreateAutomaton A2)))` starts a branch
//!   at 70° and leaves the creator unturned), with the creator's Length and Thickness and
//!   general variables at 0 ([`ChildVariables`]). It first runs in the next iteration;
//!   instances run in creation order. Automaton `i` may create only automata after it, and
//!   only the last automaton adds leaves and flowers (Table 1, section 4.4.2).
//! - **Drawing** (see [`sim`]): each recorded step is a segment; an instance is one axis; a
//!   created instance's axis is lateral, hanging from the creator's segment that ends at the
//!   creation point. Thickness is mapped into 0.1..=1 (section 5.2) and the radius is
//!   `radius × mapped thickness × unit` ([`GrowOptions::radius`], default 3 units).
//! - **Units.** Paper units × [`GrowOptions::unit`] metres (default 0.1): the paper's target
//!   sphere of radius 150 centred 200 up is 15 m across, 5 m above the ground.
//! - **Endpoints** (the fitness cases) are chosen by the fitness
//!   (`sylva_fitness::poncin::EndpointRule`): every tip of the plant, where an instance's
//!   path ends and where a path drawn inside a Push/Pop ends; or one per instance, where it
//!   ended (Table 1's "endpoints of all the automata instantiated"), which the evolution
//!   examples use. An instance that never moves draws nothing and has no endpoint.
//! - **Gravity** ([`GrowOptions::gravity`], default off) bends every heading towards the
//!   ground each step, more the more horizontal it is (Figure 17's pine).
//! - **Leaves** are turned near horizontal by default (section 4.5), each turned about the
//!   vertical by the golden angle times its index, so leaves added at one spot fan out. The
//!   model is deterministic; the seed is only recorded.
//!
//! # The helix (Figures 1 and 2)
//!
//! `examples/automata/helix.json` rebuilds it from the prose: automaton 1 rolls about the
//! trunk every step and counts steps in `Var1` and `Var2` (10 × 7); every 70 steps it starts
//! a branch at 70° inside a Push/Pop; automaton 2 pitches slightly downward every step for
//! 400 steps (`Repeat 10 × 10 × 4`); 1000 iterations.

pub mod compile;
pub mod genome;
pub mod gp;
pub mod problem;
pub mod sexpr;
pub mod sim;
pub mod sprout;
pub mod tree;

pub use compile::{AtEnd, ElseEnd, Program, Semantics};
pub use genome::{AutomataGenome, AutomataTag, Growth, MODEL};
pub use gp::{Creation, GpConfig, SubtreeCrossover, SubtreeMutation, Weights};
pub use problem::{AutomataProblem, AutomataSettings, AutomataStrategy, EvaluationDetail};
pub use sexpr::ParseError;
pub use sim::{
    BoundsHit, ChildVariables, Detail, GrowOptions, GrowthReport, Limits, Simulator, Stop,
    map_thickness,
};
pub use tree::{GpTree, Node, Target, TreeError, Type, Var};

use rand::Rng;
use sylva_core::Plant;
use sylva_evolve::{Crossover, Mutate};
use sylva_model::{
    Bred, ConfigError, CrossLevel, DevelopError, Evolve, Knobs, Model, Parent, Setup,
    VariationError, two_most_dominant,
};

/// Poncin's automata as a Sylva model.
#[derive(Clone, Copy, Debug, Default)]
pub struct AutomataModel;

impl Model for AutomataModel {
    type Genome = AutomataGenome;
    type Settings = AutomataSettings;
    const NAME: &'static str = MODEL;
    const TITLE: &'static str = "Automata trees (Poncin)";

    fn develop(&self, genome: &AutomataGenome, seed: u64) -> Result<Plant, DevelopError> {
        genome.develop(seed)
    }

    /// A random program built to grow into a tree ([`sprout::random_tree`]), grown with the
    /// settings' growth. A run's random programs are the paper's ramped half-and-half trees.
    fn random<R: Rng + ?Sized>(&self, s: &AutomataSettings, rng: &mut R) -> AutomataGenome {
        AutomataGenome::with_growth(sprout::random_tree(rng), s.growth.clone())
    }

    /// Subtree mutation of the program; the growth settings stay the genome's.
    fn mutate<R: Rng + ?Sized>(
        &self,
        genome: &AutomataGenome,
        s: &AutomataSettings,
        rng: &mut R,
    ) -> AutomataGenome {
        let mut child = genome.clone();
        SubtreeMutation { config: s.gp() }.mutate(&mut child.program, rng);
        child
    }

    /// Depth 1 nudges one constant of the program by 0.1 or 0.2 (the finest change a
    /// program can take); Depth 2 is the default subtree mutation (subtrees up to 4 deep);
    /// each Depth above grows its new subtree one level deeper (up to 12 at Depth 10).
    /// The level sets where crossover cuts: low at operators only (the largest subtrees),
    /// medium at operators nine times in ten (Koza's, the default), high at operators half
    /// the time (more single values).
    fn schema(&self) -> sylva_model::schema::Schema {
        genome::schema()
    }

    fn hand_settings(&self, knobs: Knobs, base: AutomataSettings) -> AutomataSettings {
        let depth = u32::from(knobs.depth.get());
        AutomataSettings {
            nudge: if depth == 1 { 1.0 } else { 0.0 },
            mutation_depth: if depth <= 2 { 4 } else { depth + 2 },
            function_points: match knobs.level {
                CrossLevel::Low => 1.0,
                CrossLevel::Medium => 0.9,
                CrossLevel::High => 0.5,
            },
            ..base
        }
    }

    /// Typed subtree crossover of the two most dominant parents' programs; the child grows
    /// with the first one's growth settings.
    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_, AutomataGenome>],
        s: &AutomataSettings,
        rng: &mut R,
    ) -> Result<Bred<AutomataGenome>, VariationError> {
        let (a, b) = two_most_dominant(parents)?;
        let (ga, gb) = (parents[a].genome, parents[b].genome);
        let program = SubtreeCrossover { config: s.gp() }.crossover(&ga.program, &gb.program, rng);
        Ok(Bred {
            genome: AutomataGenome::with_growth(program, ga.growth.clone()),
            parents: vec![a, b],
        })
    }
}

impl Evolve for AutomataModel {
    type Problem = AutomataProblem;
    type Strategy = AutomataStrategy;

    /// Most offspring are mutants (Koza's 88% crossover finds a shape's kind; an outline
    /// is fitted by small steps). Measured on the tuning outlines (`examples/match`,
    /// docs/match.md), the outline term's mean rose from 0.595 to 0.704 (20 s a target).
    fn fitting(&self, settings: &mut AutomataSettings) {
        settings.breeding = sylva_evolve::GenerationalSettings::mostly_mutants();
    }

    fn setup(
        &self,
        settings: &AutomataSettings,
        _start: Vec<AutomataGenome>,
        _seed: u64,
        _population: usize,
    ) -> Result<Setup<Self>, ConfigError> {
        settings
            .growth
            .limits
            .check_budget()
            .map_err(|e| ConfigError::new("growth.limits", e))?;
        let problem = AutomataProblem::new(settings);
        let strategy =
            problem::strategy(&problem, settings).map_err(|e| ConfigError::new("breeding", e))?;
        Ok(Setup {
            problem,
            strategy,
            first: Vec::new(),
        })
    }

    fn genome_file(&self, problem: &AutomataProblem, tree: &GpTree) -> AutomataGenome {
        AutomataGenome::with_growth(tree.clone(), problem.growth.clone())
    }

    fn genome_bytes(&self, settings: &AutomataSettings) -> u64 {
        u64::from(settings.max_size) * tree::NODE_BYTES + 64
    }

    fn guides(&self, problem: &AutomataProblem) -> Option<Plant> {
        sylva_fitness::poncin::guides::of(&problem.fitness)
    }
}
