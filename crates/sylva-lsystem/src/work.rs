//! What growing L-system plants costs, estimated before it starts.
//!
//! Legal settings can ask for a great deal of work: every physiology setting at its maximum
//! lets a plant's strings reach a million symbols a compartment and a million modules within
//! a step or two, and a plant pays for its size on every step it grows. Each step re-reads
//! both strings (the allocation of growth among the apexes, up to [`MAX_PASSES`] rewriting
//! passes, the interpretation), spreads every module over the voxels it crosses (a leaf
//! shades and catches light, a branch shades, a fine root asks for minerals), and the world
//! recomputes its light and diffuses its minerals. [`Work`] counts that at the bounds, for
//! every plant on every step it grows, before the first step:
//!
//! | unit | nanoseconds |
//! | --- | --- |
//! | a symbol of a string, each step ([`SYMBOL_NS`]) | 100 |
//! | a voxel sample of a leaf ([`LEAF_SAMPLE_NS`]) | 120 |
//! | a voxel sample of a branch ([`BRANCH_SAMPLE_NS`]) | 25 |
//! | a voxel sample of a fine root ([`FINE_ROOT_SAMPLE_NS`]) | 30 |
//! | a sky voxel, each step ([`SKY_VOXEL_NS`]) | 4 |
//! | a soil voxel, each diffusion sub-step ([`SOIL_VOXEL_NS`]) | 3.5 |
//!
//! A module of length `L` has `⌈L / (s/2)⌉` samples in a world of voxels of size `s`. The
//! rates were measured on the 2-core development machine (release build; the least of three
//! runs of nine plants held at their bounds, fitted within 10% over eight genomes of leaves,
//! branches, fine roots, root branches and bare apexes). The symbol rate is that of a step
//! in which all 32 passes fire (a rule such as `B -> B` keeps firing however long the string);
//! most steps cost a fifth of it. So the estimate is of the slowest such plants can be: a
//! breeding round of exponential rules at the maximal physiology is estimated at 2.8 min on
//! two threads and took about one.
//!
//! [`Rules::Known`] estimates a genome as it is: each compartment's string reaches
//! `max_symbols` only if it has rules, and holds at most the largest share of each module
//! that its axiom or a successor holds (a string is made of pieces of those).
//! [`Rules::Any`] estimates what evolution may make of it: mutation writes any rule, so both
//! strings reach `max_symbols` and every module may be of the dearest kind, at the genome's
//! own sizes (mutation nudges a size by at most a tenth at a time; the symbol rate's margin
//! covers some drift, not a run that makes every module ten times longer).

use sylva_core::environment::EnvironmentSettings;

use crate::garden::Sowing;
use crate::genome::{LSystem, LSystemGenome};
use crate::grammar::{Module, Symbol};
use crate::growth::MAX_PASSES;
use crate::physiology::Physiology;

/// Nanoseconds a symbol of a string costs on a step in which every rewriting pass fires.
pub const SYMBOL_NS: f64 = 100.0;
/// Nanoseconds a voxel sample of a leaf costs on a step (its shade and the light it catches).
pub const LEAF_SAMPLE_NS: f64 = 120.0;
/// Nanoseconds a voxel sample of a branch costs on a step (its shade).
pub const BRANCH_SAMPLE_NS: f64 = 25.0;
/// Nanoseconds a voxel sample of a fine root costs on a step (its demand for minerals).
pub const FINE_ROOT_SAMPLE_NS: f64 = 30.0;
/// Nanoseconds a sky voxel costs on a step (shade cleared, light swept).
pub const SKY_VOXEL_NS: f64 = 4.0;
/// Nanoseconds a soil voxel costs on a diffusion sub-step.
pub const SOIL_VOXEL_NS: f64 = 3.5;

/// How much of a genome is known when its growth is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rules {
    /// Its own rules and module sizes: a genome grown as it is.
    Known,
    /// Any rules mutation may give it: a genome evolved over generations (its physiology,
    /// and so its bounds, stay).
    Any,
}

/// Estimated work of growing, model-neutral ([`sylva_model::Work`]); see the
/// [module docs](self) for what it counts here.
pub use sylva_model::Work;

/// Nanoseconds one step of the world costs: its sky's light and its soil's diffusion
/// (`⌈6·D/s²⌉` sub-steps).
pub fn world_step_ns(world: &EnvironmentSettings) -> f64 {
    let [x, y, z] = world.size.map(f64::from);
    let soil_layers = f64::from(world.soil_layers).min(y);
    let sky = x * (y - soil_layers) * z;
    let soil = x * soil_layers * z;
    let rate = world.minerals.diffusion / world.voxel_size.powi(2);
    let substeps = if rate > 0.0 {
        (rate * 6.0).ceil().max(1.0)
    } else {
        0.0
    };
    sky * SKY_VOXEL_NS + soil * substeps * SOIL_VOXEL_NS
}

/// Nanoseconds one step of a plant of `genome` costs at most, at its bounds, in `world`.
pub fn plant_step_ns(genome: &LSystemGenome, world: &EnvironmentSettings, rules: Rules) -> f64 {
    let p = &genome.physiology;
    let grows = |system: &LSystem| rules == Rules::Any || !system.rules.rules.is_empty();
    let symbols = |system: &LSystem| {
        let axiom = system.axiom.len() as f64;
        if grows(system) {
            axiom.max(f64::from(p.max_symbols))
        } else {
            axiom
        }
    };
    let strings = [symbols(&genome.shoot), symbols(&genome.root)];
    // Per kind: the most modules its compartment's string can hold, and what each costs.
    let mut kinds: Vec<(usize, f64, f64)> = Module::ALL
        .iter()
        .map(|&m| {
            let (system, x) = match m.compartment() {
                crate::grammar::Compartment::Shoot => (&genome.shoot, 0),
                crate::grammar::Compartment::Root => (&genome.root, 1),
            };
            let share = match rules {
                Rules::Any => 1.0,
                Rules::Known => module_share(system, m),
            };
            let length = genome.modules.get(m).length;
            (
                x,
                (share * strings[x]).floor(),
                samples(length, world) * sample_ns(m),
            )
        })
        .collect();
    // The dearest first, within each string's length and the plant's module bound.
    kinds.sort_by(|a, b| b.2.total_cmp(&a.2));
    let axiom_modules = [&genome.shoot, &genome.root]
        .iter()
        .flat_map(|s| &s.axiom)
        .filter(|s| matches!(s, Symbol::Module(_)))
        .count() as f64;
    let mut modules_left = f64::from(p.max_modules).max(axiom_modules);
    let mut room = strings;
    let mut ns = (strings[0] + strings[1]) * SYMBOL_NS;
    for (x, most, each) in kinds {
        let n = most.min(room[x]).min(modules_left);
        ns += n * each;
        room[x] -= n;
        modules_left -= n;
    }
    ns
}

/// The work of growing `sowings` together in `world` for `steps` steps (from the start):
/// each plant from its sowing for as long as it lives, at its bounds.
pub fn garden(world: &EnvironmentSettings, sowings: &[Sowing], steps: u32, rules: Rules) -> Work {
    let mut work = Work {
        steps: u64::from(steps),
        world_ns: f64::from(steps) * world_step_ns(world),
        width: sowings.len(),
        ..Work::default()
    };
    for s in sowings {
        let grows = steps
            .saturating_sub(s.sown_at)
            .min(s.genome.physiology.life_span.max(1));
        work.plant_steps += u64::from(grows);
        work.plants_ns += f64::from(grows) * plant_step_ns(&s.genome, world, rules);
    }
    work
}

/// What a plant may grow to, in words: "1000000 symbols a compartment and 4000 modules".
pub fn bounds(physiology: &Physiology) -> String {
    format!(
        "{} symbols a compartment and {} modules",
        physiology.max_symbols, physiology.max_modules
    )
}

/// The largest share of `module` among the symbols of the axiom and of each successor.
fn module_share(system: &LSystem, module: Module) -> f64 {
    let share = |word: &[Symbol]| {
        if word.is_empty() {
            0.0
        } else {
            word.iter()
                .filter(|&&s| s == Symbol::Module(module))
                .count() as f64
                / word.len() as f64
        }
    };
    system
        .rules
        .rules
        .iter()
        .map(|r| share(&r.successor))
        .fold(share(&system.axiom), f64::max)
}

/// Voxel samples of a module of `length` in `world` (as [`Environment::samples`] spreads
/// it).
///
/// [`Environment::samples`]: sylva_core::environment::Environment::samples
fn samples(length: f64, world: &EnvironmentSettings) -> f64 {
    (length / (0.5 * world.voxel_size))
        .ceil()
        .clamp(1.0, 4096.0)
}

/// Nanoseconds a voxel sample of `module` costs on a step (root branches are only walked
/// past, which their symbol's rate covers).
fn sample_ns(module: Module) -> f64 {
    match module {
        Module::Leaf => LEAF_SAMPLE_NS,
        Module::Branch => BRANCH_SAMPLE_NS,
        Module::FineRoot => FINE_ROOT_SAMPLE_NS,
        Module::RootBranch => 0.0,
    }
}

// Every pass re-reads the string: the symbol rate is of a step of `MAX_PASSES` passes.
const _: () = assert!(MAX_PASSES == 32);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::Compartment;
    use sylva_core::par::Pool;

    fn maximal(shoot: &[&str], root: &[&str]) -> LSystemGenome {
        let mut g = LSystemGenome::bush();
        g.shoot = LSystem::parse("[A]", shoot, Compartment::Shoot).unwrap();
        g.root = LSystem::parse("[A]", root, Compartment::Root).unwrap();
        g.physiology.max_symbols = 1_000_000;
        g.physiology.max_modules = 1_000_000;
        g
    }

    #[test]
    fn the_bounds_and_the_rules_set_the_estimate() {
        let world = EnvironmentSettings::default();
        // Default world: 64 x 48 x 64 sky voxels, 64 x 16 x 64 soil voxels, 1 sub-step.
        assert_eq!(
            world_step_ns(&world),
            64.0 * 48.0 * 64.0 * 4.0 + 64.0 * 16.0 * 64.0 * 3.5
        );
        // Exponential rules: both strings at a million symbols; a sixth of each is leaves
        // (2 samples of 0.1 m) or fine roots (1 sample), a twelfth branches (3 samples).
        let g = maximal(&["A -> bA[+lA][-lA]"], &["A -> cA[<rA][>rA]"]);
        let ns = plant_step_ns(&g, &world, Rules::Known);
        let leaves = (1e6f64 / 6.0).floor() * 2.0 * LEAF_SAMPLE_NS;
        let branches = (1e6f64 / 12.0).floor() * 3.0 * BRANCH_SAMPLE_NS;
        let fine_roots = (1e6f64 / 6.0).floor() * FINE_ROOT_SAMPLE_NS;
        assert_eq!(ns, 2e6 * SYMBOL_NS + leaves + branches + fine_roots);
        // Without rules a string keeps its axiom.
        let still = maximal(&[], &[]);
        assert_eq!(plant_step_ns(&still, &world, Rules::Known), 6.0 * SYMBOL_NS);
        // Evolution may write any rule: a million leaves (2 samples each).
        let any = plant_step_ns(&still, &world, Rules::Any);
        assert_eq!(any, 2e6 * SYMBOL_NS + 1e6 * 2.0 * LEAF_SAMPLE_NS);
        // A garden: nine plants for 150 steps, the world serial, the plants spread.
        let sowings: Vec<Sowing> = (0..9)
            .map(|_| Sowing::new(g.clone(), sylva_core::glam::Vec2::ZERO))
            .collect();
        let work = garden(&world, &sowings, 150, Rules::Known);
        assert_eq!(work.plant_steps, 1350);
        assert_eq!(work.width, 9);
        let one = work.seconds(1);
        assert!((one - (150.0 * world_step_ns(&world) + 1350.0 * ns) / 1e9).abs() < 1e-9);
        assert!(work.seconds(2) < one && work.seconds(64) == work.seconds(9));
        // A plant sown late or dying young grows fewer steps.
        let mut late = sowings[0].clone();
        late.sown_at = 100;
        late.genome.physiology.life_span = 20;
        assert_eq!(garden(&world, &[late], 150, Rules::Known).plant_steps, 20);
        assert_eq!(work.times(3).plant_steps, 4050);
        assert_eq!(work.then(work).steps, 300);
    }

    /// The estimate bounds what a garden does: symbols read and voxel samples taken, step
    /// by step, priced at the same rates, for genomes of each kind of module grown at
    /// small bounds until they are held there.
    #[test]
    fn the_estimate_bounds_the_work_done() {
        let world = EnvironmentSettings {
            size: [24, 24, 24],
            soil_layers: 8,
            ..EnvironmentSettings::default()
        };
        let genomes = [
            (&["A -> bA[+lA][-lA]"][..], &["A -> cA[<rA][>rA]"][..]),
            (&["A -> [+A][-A]$A"], &["A -> [<A][>A]&A"]),
            (&["A -> l[+lA][-lA]lA"], &["A -> r[<rA][>rA]rA"]),
            (&["A -> AA"], &[]),
        ];
        for (shoot, root) in genomes {
            let mut g = maximal(shoot, root);
            g.physiology.max_symbols = 3000;
            g.physiology.max_modules = 800;
            g.physiology.min_cost = 1e-5;
            g.physiology.module_density = 1.0;
            g.physiology.growth_rate = 1e4;
            g.physiology.apex_capacity = 1e3;
            let sowings = vec![Sowing::new(g.clone(), sylva_core::glam::Vec2::ZERO)];
            let steps = 40;
            let estimate = garden(&world, &sowings, steps, Rules::Known);
            let mut garden = crate::garden::Garden::new(world, sowings).unwrap();
            let mut done = 0.0;
            for _ in 0..steps {
                garden.step(&Pool::Serial).unwrap();
                let p = &garden.plants()[0];
                let symbols: usize = p.words().iter().map(Vec::len).sum();
                done += symbols as f64 * SYMBOL_NS;
                for m in Module::ALL {
                    let n = f64::from(p.counts()[m.index()]);
                    done += n * samples(g.modules.get(m).length, &world) * sample_ns(m);
                }
            }
            // Each grew into its bounds, so the estimate is tested where it is tightest.
            assert!(
                garden.plants()[0].bounds().any(),
                "{shoot:?} reached a bound"
            );
            assert!(
                done <= estimate.plants_ns,
                "{shoot:?}: {done} > {}",
                estimate.plants_ns
            );
        }
    }
}
