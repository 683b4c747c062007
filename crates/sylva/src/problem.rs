//! The binary tree as an evolution problem: Susinno's GA on a bit string, scored by his six
//! weighted tree measures computed analytically (no plant is built per evaluation).

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use rand::Rng;
use sylva_automata::{
    AutomataGenome, Detail, GpConfig, GpTree, GrowOptions, Program, Semantics, Simulator,
    SubtreeCrossover, SubtreeMutation,
};
use sylva_core::glam::Vec3;
use sylva_core::{Material, MaterialKind, Plant};
use sylva_evolve::Generational;
use sylva_fitness::poncin::{PoncinContext, TERM_NAMES as PONCIN_TERMS, TargetShape};
use sylva_fitness::{PoncinFitness, PoncinScore, PoncinScratch};

use crate::config::{AutomataConfig, LSystemConfig, PlantMakerConfig};
use crate::genome::Genome;
use crate::guides::{box_wire, ellipsoid_wire, guide_plant};
use sylva_bintree::{BITS, BinTree, Bits};
use sylva_evolve::bits::{BitFlip, OnePoint, Uniform};
use sylva_evolve::{Crossover, Fitness, MeanReplacement, Problem};
use sylva_fitness::{SusinnoWeights, tree::TERM_NAMES};
use sylva_lsystem::breed::LSystemProblem;
use sylva_lsystem::{CompartmentCrossover, LSystemGenome, LSystemMutation};
use sylva_plantmaker::{Mutation as PlantMakerMutation, PlantMaker, PlantMakerCrossover};

use crate::config::{BinTreeConfig, CrossoverKind};

/// What `sylva evolve` needs from a problem besides the engine's [`Problem`]: how an evolved
/// genome becomes a genome file (to grow, export and picture it) and what to call the run.
pub trait ModelProblem: Problem {
    /// The genome file an evolved genome stands for.
    fn genome_file(&self, genome: &Self::Genome) -> Genome;
    /// A short title for plots, e.g. "Binary trees".
    fn title(&self) -> &'static str;
    /// Guides drawn beside the plant in pictures (a target surface, forbidden cells).
    fn guides(&self) -> Option<Plant> {
        None
    }
}

impl ModelProblem for BinTreeProblem {
    fn genome_file(&self, bits: &Bits) -> Genome {
        Genome::BinTree(self.decode(bits))
    }

    fn title(&self) -> &'static str {
        "Binary trees"
    }
}

/// Evolve binary trees towards Susinno's weighted fitness.
#[derive(Clone, Debug, PartialEq)]
pub struct BinTreeProblem {
    /// Minimum radius copied into every genome, metres.
    pub min_radius: f64,
    /// Fitness weights.
    pub weights: SusinnoWeights,
}

impl BinTreeProblem {
    /// The problem a config describes.
    pub fn new(config: &BinTreeConfig) -> Self {
        BinTreeProblem {
            min_radius: config.min_radius,
            weights: config.weights,
        }
    }

    /// The genome a bit string stands for.
    pub fn decode(&self, bits: &Bits) -> BinTree {
        BinTree::decode(bits, self.min_radius)
    }
}

impl Problem for BinTreeProblem {
    type Genome = Bits;

    fn term_names(&self) -> Vec<String> {
        TERM_NAMES.iter().map(|s| (*s).to_owned()).collect()
    }

    fn evaluate(&self, bits: &Bits) -> Fitness {
        let score = self.weights.score(&self.decode(bits).measures());
        Fitness::new(score.total, &score.terms)
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Bits {
        Bits::random(BITS, rng).expect("the layout fits its bit string")
    }
}

/// The crossover a config names.
#[derive(Clone, Copy, Debug)]
pub struct BitCrossover(pub CrossoverKind);

impl Crossover<Bits> for BitCrossover {
    fn crossover<R: Rng + ?Sized>(&self, a: &Bits, b: &Bits, rng: &mut R) -> Bits {
        match self.0 {
            CrossoverKind::OnePoint => OnePoint.crossover(a, b, rng),
            CrossoverKind::Uniform => Uniform.crossover(a, b, rng),
        }
    }
}

/// Susinno's generation step with the configured operators.
pub type BinTreeStrategy = MeanReplacement<BitCrossover, BitFlip>;

/// The strategy a config describes.
pub fn strategy(config: &BinTreeConfig) -> BinTreeStrategy {
    MeanReplacement {
        crossover: BitCrossover(config.crossover),
        mutation: BitFlip {
            rate: config.mutation_rate,
        },
        cull_clones: config.cull_clones,
    }
}

/// Evolve automata programs towards Poncin's fitness (a target shape, a number of branches,
/// spread, thickness and a density grid).
#[derive(Clone, Debug)]
pub struct AutomataProblem {
    /// Initialisation and breeding limits.
    pub gp: GpConfig,
    /// How programs grow (also written into `best.json`).
    pub growth: sylva_automata::Growth,
    /// The fitness.
    pub fitness: PoncinFitness,
    semantics: Semantics,
    grow: GrowOptions,
    /// Automaton-steps simulated by this problem and its clones, for speed reports.
    steps: Arc<AtomicU64>,
}

/// Per-thread buffers, so evaluating does not allocate once they have grown. They hold no
/// state between evaluations: results never depend on which thread evaluated what.
struct AutomataScratch {
    simulator: Simulator,
    program: Option<Program>,
    plant: Plant,
    poncin: PoncinScratch,
}

thread_local! {
    static SCRATCH: RefCell<AutomataScratch> = RefCell::new(AutomataScratch {
        simulator: Simulator::new(),
        program: None,
        plant: Plant::default(),
        poncin: PoncinScratch::new(),
    });
}

impl AutomataProblem {
    /// The problem a config describes.
    pub fn new(config: &AutomataConfig) -> Self {
        let gp = GpConfig {
            automata: config.automata as u8,
            min_init_depth: config.init_min_depth.min(config.init_max_depth),
            max_init_depth: config.init_max_depth.max(config.init_min_depth),
            max_depth: config.max_depth,
            max_size: config.max_size,
            ..GpConfig::default()
        };
        AutomataProblem {
            gp,
            growth: config.growth.clone(),
            fitness: config.fitness.clone(),
            semantics: config.growth.semantics(),
            grow: config.growth.grow_options(),
            steps: Arc::default(),
        }
    }

    /// Automaton-steps simulated so far by all evaluations (one automaton running one
    /// iteration is one step), across threads.
    pub fn automaton_steps(&self) -> u64 {
        self.steps.load(Ordering::Relaxed)
    }

    /// Grows a program the way evaluation does (chords only) and scores it.
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
                .run(program, &self.grow, Detail::Chords, &mut s.plant);
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

    /// The target surface and the forbidden grid cells, as wire frames in metres.
    pub fn guides(&self) -> Option<Plant> {
        let unit = self.fitness.unit as f32;
        let (mut plant, surface) = guide_plant([0.35, 0.42, 0.55]).ok()?;
        let wire = 0.4 * unit;
        match self.fitness.target {
            TargetShape::Sphere { center, radius } => ellipsoid_wire(
                &mut plant,
                center.as_vec3() * unit,
                Vec3::splat(radius as f32 * unit),
                wire,
                surface,
            ),
            TargetShape::Ellipsoid { center, radii } => ellipsoid_wire(
                &mut plant,
                center.as_vec3() * unit,
                radii.as_vec3() * unit,
                wire,
                surface,
            ),
            TargetShape::Box { center, size } => box_wire(
                &mut plant,
                (center - size * 0.5).as_vec3() * unit,
                (center + size * 0.5).as_vec3() * unit,
                wire,
                surface,
            ),
            _ => Ok(()),
        }
        .ok()?;
        if let Some(grid) = &self.fitness.grid {
            let forbidden = plant
                .add_material(Material {
                    name: "forbidden".into(),
                    kind: MaterialKind::Bark,
                    color: [0.8, 0.08, 0.05],
                    texture: None,
                })
                .ok()?;
            for i in 0..grid.len() {
                if grid.weight(i) < 0.0 {
                    let (lo, hi) = grid.cell_bounds(i);
                    box_wire(
                        &mut plant,
                        lo.as_vec3() * unit,
                        hi.as_vec3() * unit,
                        wire,
                        forbidden,
                    )
                    .ok()?;
                }
            }
        }
        Some(plant)
    }
}

impl Problem for AutomataProblem {
    type Genome = GpTree;

    fn term_names(&self) -> Vec<String> {
        PONCIN_TERMS.iter().map(|s| (*s).to_owned()).collect()
    }

    fn evaluate(&self, tree: &GpTree) -> Fitness {
        let score = self.score(tree);
        Fitness::new(score.adjusted(), &score.terms())
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> GpTree {
        self.gp.random_tree(rng)
    }
}

impl ModelProblem for AutomataProblem {
    fn genome_file(&self, tree: &GpTree) -> Genome {
        Genome::Automata(Box::new(AutomataGenome::with_growth(
            tree.clone(),
            self.growth.clone(),
        )))
    }

    fn title(&self) -> &'static str {
        "Automata trees (Poncin)"
    }

    fn guides(&self) -> Option<Plant> {
        AutomataProblem::guides(self)
    }
}

/// Poncin's GP breeding with the configured operators.
pub type AutomataStrategy = Generational<SubtreeCrossover, SubtreeMutation>;

/// The breeding a config describes.
pub fn automata_strategy(
    problem: &AutomataProblem,
    config: &AutomataConfig,
) -> Result<AutomataStrategy, sylva_evolve::GenerationalError> {
    Generational::new(
        SubtreeCrossover { config: problem.gp },
        SubtreeMutation { config: problem.gp },
        config.breeding.clone(),
    )
}

/// Evolve PlantMaker genomes without a person, towards Poncin's shared terms over the grown
/// plant (a target shape, a number of endpoints, spread, and a density grid of leaves).
#[derive(Clone, Debug)]
pub struct PlantMakerProblem {
    /// Genome sizes and operators.
    pub config: PlantMakerConfig,
}

impl PlantMakerProblem {
    /// The problem a config describes.
    pub fn new(config: &PlantMakerConfig) -> Self {
        PlantMakerProblem {
            config: config.clone(),
        }
    }
}

impl Problem for PlantMakerProblem {
    type Genome = PlantMaker;

    fn term_names(&self) -> Vec<String> {
        PONCIN_TERMS.iter().map(|s| (*s).to_owned()).collect()
    }

    /// Grows the genome with its own seed; a genome that fails to grow (too large) scores
    /// the worst fitness.
    fn evaluate(&self, genome: &PlantMaker) -> Fitness {
        let Ok(plant) = genome.develop(genome.seed) else {
            return Fitness::new(0.0, &[]);
        };
        SCRATCH.with(|cell| {
            let ctx = PoncinContext {
                seed: 0,
                negative_thickness: 0,
            };
            let score = self
                .config
                .fitness
                .score(&plant, ctx, &mut cell.borrow_mut().poncin);
            Fitness::new(score.adjusted(), &score.terms())
        })
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> PlantMaker {
        PlantMaker::random(
            self.config.branches as usize,
            self.config.fans as usize,
            self.config.inflorescences as usize,
            rng,
        )
    }
}

impl ModelProblem for PlantMakerProblem {
    fn genome_file(&self, genome: &PlantMaker) -> Genome {
        Genome::PlantMaker(Box::new(genome.clone()))
    }

    fn title(&self) -> &'static str {
        "PlantMaker"
    }
}

/// PlantMaker breeding with the configured crossover level and mutation.
pub type PlantMakerStrategy = Generational<PlantMakerCrossover, PlantMakerMutation>;

/// The breeding a config describes.
pub fn plantmaker_strategy(
    config: &PlantMakerConfig,
) -> Result<PlantMakerStrategy, sylva_evolve::GenerationalError> {
    Generational::new(
        PlantMakerCrossover {
            level: config.crossover,
        },
        PlantMakerMutation {
            rate: config.mutation_rate,
            spread: config.mutation_spread,
        },
        config.breeding.clone(),
    )
}

/// Evolve L-system plants without a person ([`LSystemProblem`] grows each alone and scores it).
#[derive(Clone, Debug)]
pub struct LSystemRun(pub LSystemProblem);

impl Problem for LSystemRun {
    type Genome = LSystemGenome;

    fn term_names(&self) -> Vec<String> {
        self.0.term_names()
    }

    fn evaluate(&self, genome: &LSystemGenome) -> Fitness {
        self.0.evaluate(genome)
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> LSystemGenome {
        self.0.random_genome(rng)
    }
}

impl ModelProblem for LSystemRun {
    fn genome_file(&self, genome: &LSystemGenome) -> Genome {
        Genome::LSystem(Box::new(genome.clone()))
    }

    fn title(&self) -> &'static str {
        "L-system plants (Bornhofen and Lattaud)"
    }
}

/// L-system breeding: mutation (and, if asked, compartment crossover).
pub type LSystemStrategy = Generational<CompartmentCrossover, LSystemMutation>;

/// The problem and breeding an `[lsystem]` config describes; `start` is the first
/// generation's origin.
pub fn lsystem_run(
    config: &LSystemConfig,
    start: LSystemGenome,
) -> Result<(LSystemRun, LSystemStrategy), sylva_evolve::GenerationalError> {
    let mutation = LSystemMutation {
        rates: config.rates,
        parameter_scale: 0.0,
    };
    let problem = LSystemProblem {
        grow: config.grow,
        score: config.score,
        start,
        random_rounds: config.random_rounds,
        mutation,
    };
    let strategy = Generational::new(CompartmentCrossover, mutation, config.breeding.clone())?;
    Ok((LSystemRun(problem), strategy))
}
