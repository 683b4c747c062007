//! Poncin's GP run as an evolution problem: the model's settings (the `[automata]` section
//! of an evolution config), programs grown the way evaluation grows them (chords only) and
//! scored by Poncin's fitness, and lilgp's generational breeding.
//!
//! ```toml
//! [automata]
//! automata = 2            # automata per individual (children of Top), 1 to 8
//! creation = "later"      # or "next": each automaton creates only the next (section 3)
//! init_min_depth = 4      # ramped half-and-half depths of initial bodies, 1 to 16
//! init_max_depth = 8
//! max_depth = 17          # deepest tree breeding may make, 2 to 64
//! max_size = 500          # most nodes of a tree, 20 to 5000
//! detail = "chords"       # how evaluation grows a program: "chords" or "full" (below)
//! nudge = 0.0             # share of mutations that move one constant by 0.1 or 0.2
//! mutation_depth = 4      # deepest subtree a mutation grows, 1 to 16
//! function_points = 0.9   # share of crossover and mutation points at operators, 0 to 1
//!
//! [automata.breeding]     # tournament 7; crossover 0.88, reproduction 0.10, mutation 0.02
//! [automata.growth]       # how programs grow (every field of an automata genome file)
//! [automata.fitness]      # Poncin's terms: target shape, counts, spread, thickness, grid
//! ```
//!
//! Evaluation grows chords (one segment per run between branch points), which carry every
//! term but a taper inside a run. The bars and gradual thickness measures look for steps
//! inside runs, so a config that uses them grows every step (`detail = "full"`, about
//! twice the cost).

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::Plant;
use sylva_evolve::{Fitness, Generational, GenerationalError, GenerationalSettings, Problem};
use sylva_fitness::poncin::{PoncinContext, TERM_NAMES};
use sylva_fitness::{PoncinFitness, PoncinScore, PoncinScratch};

use crate::genome::Growth;
use crate::gp::{Creation, GpConfig, SubtreeCrossover, SubtreeMutation};
use crate::sim::{Detail, GrowOptions, Simulator};
use crate::{GpTree, Program, Semantics};

/// The automata model's settings: tree shape limits, breeding, growth and fitness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutomataSettings {
    /// Automata per individual (children of `Top`), 1 to 8. Default 2.
    #[serde(deserialize_with = "automata_count")]
    pub automata: u32,
    /// Which automata an automaton creates in bred trees: `"later"` (any later one,
    /// Table 1; the default) or `"next"` (only the next: the trunk creates branches, the
    /// branches sub-branches, section 3).
    #[serde(skip_serializing_if = "is_later")]
    pub creation: Creation,
    /// Smallest depth of initial bodies (ramped half-and-half), 1 to 16. Default 4.
    #[serde(deserialize_with = "init_depth")]
    pub init_min_depth: u32,
    /// Largest depth of initial bodies, 1 to 16. Default 8.
    #[serde(deserialize_with = "init_depth")]
    pub init_max_depth: u32,
    /// Deepest tree breeding may make, 2 to 64. Default 17.
    #[serde(deserialize_with = "max_depth")]
    pub max_depth: u32,
    /// Most nodes of a tree, 20 to 5000. Default 500 (the paper's largest individuals).
    #[serde(deserialize_with = "max_size")]
    pub max_size: u32,
    /// How evaluation grows a program: `"chords"` (the default) or `"full"` (every step a
    /// segment, for thickness measures that look inside runs).
    #[serde(skip_serializing_if = "is_chords")]
    pub detail: EvaluationDetail,
    /// Share of mutations that nudge one constant by one or two value steps (0.1) instead
    /// of replacing a subtree, 0 to 1. Default 0 (Sylva's: the paper only replaces).
    #[serde(deserialize_with = "nudge", skip_serializing_if = "is_zero")]
    pub nudge: f64,
    /// Deepest subtree a mutation grows, 1 to 16. Default 4.
    #[serde(deserialize_with = "mutation_depth", skip_serializing_if = "is_four")]
    pub mutation_depth: u32,
    /// Share of crossover and mutation points that are operators (with the subtree below)
    /// rather than values, 0 to 1. Default 0.9 (Koza's).
    #[serde(deserialize_with = "function_points", skip_serializing_if = "is_koza")]
    pub function_points: f64,
    /// Tournament selection and the 88 / 10 / 2 operator rates.
    pub breeding: GenerationalSettings,
    /// How programs grow (written into every evolved genome).
    pub growth: Growth,
    /// Poncin's fitness: target shape, counts, spread, thickness and density grid.
    pub fitness: PoncinFitness,
}

/// How evaluation grows programs (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EvaluationDetail {
    /// One segment per run between branch points ([`Detail::Chords`]).
    #[default]
    Chords,
    /// Every step a segment ([`Detail::Full`]).
    Full,
}

/// Settings that are off stay out of written configs, so they keep their bytes.
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_four(depth: &u32) -> bool {
    *depth == 4
}

fn is_koza(rate: &f64) -> bool {
    *rate == 0.9
}

fn is_chords(detail: &EvaluationDetail) -> bool {
    *detail == EvaluationDetail::Chords
}

/// Section 3's rule stays out of written configs unless chosen, so they keep their bytes.
fn is_later(creation: &Creation) -> bool {
    *creation == Creation::Later
}

impl Default for AutomataSettings {
    fn default() -> Self {
        AutomataSettings {
            automata: 2,
            creation: Creation::Later,
            init_min_depth: 4,
            init_max_depth: 8,
            max_depth: 17,
            max_size: 500,
            detail: EvaluationDetail::Chords,
            nudge: 0.0,
            mutation_depth: 4,
            function_points: 0.9,
            breeding: GenerationalSettings::default(),
            growth: Growth::default(),
            fitness: PoncinFitness::default(),
        }
    }
}

sylva_core::ranged!(automata_count: u32, "automata", 1, 8);
sylva_core::ranged!(init_depth: u32, "init depth", 1, 16);
sylva_core::ranged!(max_depth: u32, "max_depth", 2, 64);
sylva_core::ranged!(max_size: u32, "max_size", 20, 5000);
sylva_core::ranged!(nudge: f64, "nudge", 0.0, 1.0);
sylva_core::ranged!(mutation_depth: u32, "mutation_depth", 1, 16);
sylva_core::ranged!(function_points: f64, "function_points", 0.0, 1.0);

impl AutomataSettings {
    /// The GP operators' limits.
    pub fn gp(&self) -> GpConfig {
        GpConfig {
            automata: self.automata as u8,
            creation: self.creation,
            min_init_depth: self.init_min_depth.min(self.init_max_depth),
            max_init_depth: self.init_max_depth.max(self.init_min_depth),
            max_depth: self.max_depth,
            max_size: self.max_size,
            nudge: self.nudge,
            mutation_depth: self.mutation_depth,
            function_point_rate: self.function_points,
            ..GpConfig::default()
        }
    }
}

/// Evolve automata programs towards Poncin's fitness (a target shape, a number of branches,
/// spread, thickness and a density grid).
#[derive(Clone, Debug)]
pub struct AutomataProblem {
    /// Initialisation and breeding limits.
    pub gp: GpConfig,
    /// How programs grow (also written into every evolved genome).
    pub growth: Growth,
    /// The fitness.
    pub fitness: PoncinFitness,
    semantics: Semantics,
    grow: GrowOptions,
    detail: Detail,
    /// Automaton-steps simulated by this problem and its clones, for speed reports.
    steps: Arc<AtomicU64>,
}

/// Per-thread buffers, so evaluating does not allocate once they have grown. They hold no
/// state between evaluations: results never depend on which thread evaluated what.
struct Scratch {
    simulator: Simulator,
    program: Option<Program>,
    plant: Plant,
    poncin: PoncinScratch,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch {
        simulator: Simulator::new(),
        program: None,
        plant: Plant::default(),
        poncin: PoncinScratch::new(),
    });
}

impl AutomataProblem {
    /// The problem the settings describe.
    pub fn new(settings: &AutomataSettings) -> Self {
        AutomataProblem {
            gp: settings.gp(),
            growth: settings.growth.clone(),
            fitness: settings.fitness.clone(),
            semantics: settings.growth.semantics(),
            grow: settings.growth.grow_options(),
            detail: match settings.detail {
                EvaluationDetail::Chords => Detail::Chords,
                EvaluationDetail::Full => Detail::Full,
            },
            steps: Arc::default(),
        }
    }

    /// Automaton-steps simulated so far by all evaluations (one automaton running one
    /// iteration is one step), across threads.
    pub fn automaton_steps(&self) -> u64 {
        self.steps.load(Ordering::Relaxed)
    }

    /// Grows a program the way evaluation does (chords, unless the settings ask for every
    /// step) and scores it.
    pub fn score(&self, tree: &GpTree) -> PoncinScore {
        SCRATCH.with(|cell| {
            let mut guard = cell.borrow_mut();
            let s = &mut *guard;
            let program = match &mut s.program {
                Some(p) => {
                    p.recompile(tree, &self.semantics);
                    p
                }
                None => s.program.insert(Program::compile(tree, &self.semantics)),
            };
            let report = s
                .simulator
                .run(program, &self.grow, self.detail, &mut s.plant);
            self.steps
                .fetch_add(report.automaton_steps, Ordering::Relaxed);
            // Pairs are exact up to 64 endpoints; beyond, the fixed seed keeps evaluation a
            // pure function of the genome.
            let ctx = PoncinContext {
                seed: 0,
                negative_thickness: report.negative_thickness,
            };
            self.fitness.score(&s.plant, ctx, &mut s.poncin)
        })
    }
}

impl Problem for AutomataProblem {
    type Genome = GpTree;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    fn evaluate(&self, tree: &GpTree) -> Fitness {
        let score = self.score(tree);
        Fitness::new(score.adjusted(), &score.terms())
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> GpTree {
        self.gp.random_tree(rng)
    }
}

/// Poncin's GP breeding with the configured operators.
pub type AutomataStrategy = Generational<SubtreeCrossover, SubtreeMutation>;

/// The breeding the settings describe.
pub fn strategy(
    problem: &AutomataProblem,
    settings: &AutomataSettings,
) -> Result<AutomataStrategy, GenerationalError> {
    Generational::new(
        SubtreeCrossover { config: problem.gp },
        SubtreeMutation { config: problem.gp },
        settings.breeding.clone(),
    )
}
