//! One plant growing in an [`Environment`]: its two strings, the biomass waiting at each
//! apex, its pools, and its geometry, re-interpreted whenever a rule fires.
//!
//! Derivation stays apart from interpretation: [`GrowingPlant::grow`] rewrites the strings
//! — apex by apex, when an apex has paid for its rule; an apex's surplus goes to the apexes
//! its rule makes, which fire in the same step if it covers their cost (at most
//! [`MAX_PASSES`] rounds) — then interprets them afresh into the plant's [`Plant`] and
//! [`Layout`]. The environment answers in between, through the module positions the
//! layout gives. A [`Garden`](crate::garden::Garden) drives the steps.
//!
//! Rewriting is one pass over a string per round, equivalent to
//! [`rewrite_at`](crate::grammar::rewrite_at) applied from the last ready apex to the first
//! (a test checks this), so a step costs time linear in the string, not in the number of
//! apexes times the string.
//!
//! Modules are sphylls: a module of length `L` and radius `r` has volume
//! `π·r²·L + 4/3·π·r³` (its cost), a shadow along the light of `2·r·L·sin θ + π·r²` (θ the
//! angle between module and light; the shade it casts and the light a leaf catches) and
//! surface `2·π·r·L + 4·π·r²` (where a fine root takes minerals).

use std::f64::consts::PI;

use sylva_core::environment::{Environment, Uptake};
use sylva_core::glam::Vec3;
use sylva_core::{Plant, PlantError};

use crate::genome::LSystemGenome;
use crate::grammar::{Compartment, Module, RuleSet, Symbol};
use crate::interpret::{Layout, ModuleMaterials, ModuleShape, interpret};
use crate::physiology::{Flows, Physiology, Pools, ROOT, SHOOT};

/// How far above (shoot) or below (root) the ground an apex at the foot is read, metres.
const GROUND_OFFSET: f32 = 1e-3;

/// Most rewriting passes in one step.
pub const MAX_PASSES: usize = 32;

/// Volume of a sphyll, m³.
pub fn volume(s: &ModuleShape) -> f64 {
    PI * s.radius * s.radius * s.length + 4.0 / 3.0 * PI * s.radius.powi(3)
}

/// Shadow of a sphyll along `light` (unit) when its axis is `axis` (unit): the side
/// silhouette `2·r·L` scaled by the sine of the angle between them, plus the `π·r²` of its
/// rounded ends. A trunk under vertical light shades only its cross-section; a horizontal
/// leaf shades its whole length.
pub fn shadow(s: &ModuleShape, axis: Vec3, light: Vec3) -> f32 {
    let sin = axis.cross(light).length().min(1.0);
    (2.0 * s.radius * s.length * f64::from(sin) + PI * s.radius * s.radius) as f32
}

/// Surface of a sphyll, m².
pub fn surface(s: &ModuleShape) -> f64 {
    2.0 * PI * s.radius * s.length + 4.0 * PI * s.radius * s.radius
}

/// Rewrites refused because they would pass a bound: by
/// [`max_symbols`](crate::physiology::Physiology::max_symbols) and
/// [`max_modules`](crate::physiology::Physiology::max_modules) (the biomorph workflow's own
/// type, which the front ends report).
pub use sylva_model::biomorphs::BoundsHit;

/// Where a plant is in its life.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Life {
    /// Not sown yet; it will be at this step.
    Waiting(u32),
    /// Growing.
    Growing,
    /// Dead since this step; its resources went back to the environment.
    Dead(u32),
}

/// Running totals of what a plant took and gave, grams.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Totals {
    /// Carbon its seed brought.
    pub seed_carbon: f64,
    /// Minerals its seed brought.
    pub seed_minerals: f64,
    /// Light absorbed by its leaves (light units).
    pub light: f64,
    /// Carbon fixed.
    pub fixed: f64,
    /// Minerals taken up.
    pub uptake: f64,
    /// Carbon shed as litter (growth losses, and everything at death).
    pub litter: f64,
    /// Minerals given back to the soil at death.
    pub returned: f64,
}

/// What a plant did in its last step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LastStep {
    /// Light its leaves absorbed.
    pub light: f64,
    /// Minerals its roots were granted.
    pub uptake: f64,
    /// The physiology's flows.
    pub flows: Flows,
    /// Rules fired.
    pub rewrites: u32,
}

/// A plant growing in a garden. See the [module documentation](self).
#[derive(Clone, Debug)]
pub struct GrowingPlant {
    genome: LSystemGenome,
    /// Foot, world coordinates.
    position: Vec3,
    words: [Vec<Symbol>; 2],
    /// Biomass waiting at each symbol of `words` (non-zero only at apexes).
    stores: [Vec<f64>; 2],
    /// Cost of each rule, per compartment.
    costs: [Vec<f64>; 2],
    shapes: [ModuleShape; 4],
    pools: Pools,
    plant: Plant,
    layout: Layout,
    materials: ModuleMaterials,
    counts: [u32; 4],
    age: u32,
    life: Life,
    totals: Totals,
    bounds: BoundsHit,
    last: LastStep,
    /// Root demands of this step: soil index and grams.
    demands: Vec<(usize, f64)>,
    /// Litter not yet laid on the ground.
    pending_litter: f64,
    /// Allocation weight of each apex of the layout, this step.
    weights: Vec<f64>,
    /// True once a dead plant's holdings went back to the environment.
    returned: bool,
    /// Scratch for rewriting.
    next_word: Vec<Symbol>,
    next_store: Vec<f64>,
    ready: Vec<usize>,
}

fn compartment(x: usize) -> Compartment {
    if x == SHOOT {
        Compartment::Shoot
    } else {
        Compartment::Root
    }
}

impl GrowingPlant {
    /// Bytes a plant of this physiology may come to hold at its bounds: both compartments'
    /// strings (and their rewriting buffers) at `max_symbols`, and `max_modules` modules
    /// drawn as segments and organs.
    pub fn memory_bound(physiology: &Physiology) -> u64 {
        let symbol = (2 * std::mem::size_of::<Symbol>() + 2 * 8) as u64;
        let module = (std::mem::size_of::<sylva_core::Segment>()
            + std::mem::size_of::<sylva_core::Organ>()
            + 64) as u64;
        2 * u64::from(physiology.max_symbols) * symbol + u64::from(physiology.max_modules) * module
    }

    /// A seed of `genome` at `position` (on the ground), sown at step `sown_at`.
    pub fn new(genome: LSystemGenome, position: Vec3, sown_at: u32) -> Result<Self, PlantError> {
        let shapes = genome.modules.as_array();
        let p = &genome.physiology;
        let cost_of = |rules: &RuleSet| -> Vec<f64> {
            rules
                .rules
                .iter()
                .map(|r| {
                    let v: f64 = r
                        .successor
                        .iter()
                        .filter_map(|s| match s {
                            Symbol::Module(m) => Some(volume(&shapes[m.index()])),
                            _ => None,
                        })
                        .sum();
                    (v * p.module_density).max(p.min_cost)
                })
                .collect()
        };
        let costs = [cost_of(&genome.shoot.rules), cost_of(&genome.root.rules)];
        let words = [genome.shoot.axiom.clone(), genome.root.axiom.clone()];
        let stores = [vec![0.0; words[0].len()], vec![0.0; words[1].len()]];
        let mut plant = Plant::new(sylva_model::plant_meta::<crate::LSystemModel>(&genome, 0));
        let materials = ModuleMaterials::add_to(&mut plant)?;
        let mut grown = GrowingPlant {
            genome,
            position,
            words,
            stores,
            costs,
            shapes,
            pools: Pools::default(),
            plant,
            layout: Layout::default(),
            materials,
            counts: [0; 4],
            age: 0,
            life: Life::Waiting(sown_at),
            totals: Totals::default(),
            bounds: BoundsHit::default(),
            last: LastStep::default(),
            demands: Vec::new(),
            pending_litter: 0.0,
            returned: false,
            weights: Vec::new(),
            next_word: Vec::new(),
            next_store: Vec::new(),
            ready: Vec::new(),
        };
        grown.interpret()?;
        Ok(grown)
    }

    /// Its genome.
    pub fn genome(&self) -> &LSystemGenome {
        &self.genome
    }

    /// Its foot, world coordinates.
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Its geometry, foot at the origin (add [`position`](Self::position) for the world).
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// Takes the geometry out.
    pub fn into_plant(self) -> Plant {
        self.plant
    }

    /// Apexes and modules of the current geometry.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The strings, `[shoot, root]`.
    pub fn words(&self) -> &[Vec<Symbol>; 2] {
        &self.words
    }

    /// Biomass waiting at each symbol of the strings (non-zero only at apexes),
    /// `[shoot, root]`.
    pub fn reserves(&self) -> [&[f64]; 2] {
        [&self.stores[0], &self.stores[1]]
    }

    /// Pools and structural biomass.
    pub fn pools(&self) -> &Pools {
        &self.pools
    }

    /// Biomass: its dry mass, structure and substrate pools (`W + C + N`), grams. A plant
    /// that fixes carbon gains biomass even before it has somewhere to grow it.
    pub fn biomass(&self) -> f64 {
        self.pools.dry_mass()
    }

    /// Modules of each kind, in [`Module::index`] order.
    pub fn counts(&self) -> [u32; 4] {
        self.counts
    }

    /// All modules.
    pub fn modules(&self) -> u32 {
        self.counts.iter().sum()
    }

    /// True once it has at least one module.
    pub fn germinated(&self) -> bool {
        self.modules() > 0
    }

    /// Steps lived.
    pub fn age(&self) -> u32 {
        self.age
    }

    /// Where it is in its life.
    pub fn life(&self) -> Life {
        self.life
    }

    /// True while growing.
    pub fn is_growing(&self) -> bool {
        self.life == Life::Growing
    }

    /// Running totals.
    pub fn totals(&self) -> &Totals {
        &self.totals
    }

    /// Rewrites refused by the bounds.
    pub fn bounds(&self) -> &BoundsHit {
        &self.bounds
    }

    /// The last step's figures.
    pub fn last(&self) -> &LastStep {
        &self.last
    }

    /// Carbon and minerals it holds (pools and biomass).
    pub fn holdings(&self) -> (f64, f64) {
        let p = &self.genome.physiology;
        (self.pools.carbon_total(p), self.pools.minerals_total(p))
    }

    /// Sows the seed if its step has come (`step` is the step about to run, 0-based).
    pub(crate) fn sow_if_due(&mut self, step: u32) {
        if let Life::Waiting(at) = self.life
            && step >= at
        {
            let p = &self.genome.physiology;
            self.pools = p.seed();
            self.totals.seed_carbon = p.seed_carbon_total();
            self.totals.seed_minerals = p.seed_minerals_total();
            self.life = Life::Growing;
        }
    }

    fn world_segments(&self) -> impl Iterator<Item = (Module, Vec3, Vec3)> + '_ {
        self.plant
            .segments()
            .iter()
            .zip(&self.layout.modules)
            .map(|(s, &m)| (m, s.start + self.position, s.end + self.position))
    }

    /// Adds the shadows of its above-ground modules to the environment's shade.
    pub fn cast_shade(&self, env: &mut Environment) {
        if !self.is_growing() {
            return;
        }
        let light = env.settings().light.towards_source();
        for (m, a, b) in self.world_segments() {
            if !matches!(m, Module::Leaf | Module::Branch) {
                continue;
            }
            let area = shadow(&self.shapes[m.index()], (b - a).normalize_or_zero(), light);
            for (p, share) in env.samples(a, b) {
                env.add_shade(p, area * share);
            }
        }
    }

    /// Reads the light its leaves absorb and states its roots' mineral demands (all plants
    /// read the same state; nothing changes yet).
    pub fn gather(&mut self, env: &Environment) {
        self.demands.clear();
        self.last = LastStep::default();
        if !self.is_growing() {
            return;
        }
        let leaf = self.shapes[Module::Leaf.index()];
        let sun = env.settings().light.towards_source();
        let root = surface(&self.shapes[Module::FineRoot.index()]);
        let rate =
            self.genome.physiology.uptake * self.genome.physiology.uptake_factor(&self.pools);
        let volume = env.voxel_volume();
        let mut light = 0.0f64;
        let mut demands = std::mem::take(&mut self.demands);
        for (m, a, b) in self.world_segments() {
            match m {
                Module::Leaf => {
                    let leaf = shadow(&leaf, (b - a).normalize_or_zero(), sun);
                    for (p, share) in env.samples(a, b) {
                        if let Some(i) = env.sky_index_at(p) {
                            light += f64::from(env.absorbed_light(i, leaf * share));
                        }
                    }
                }
                Module::FineRoot => {
                    for (p, share) in env.samples(a, b) {
                        if let Some(i) = env.soil_index_at(p) {
                            let grams = rate * root * f64::from(share) * env.minerals(i) / volume;
                            if grams > 0.0 {
                                demands.push((i, grams));
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        self.demands = demands;
        self.last.light = light;
    }

    /// Adds its demands to the step's shared uptake.
    pub fn demand(&self, uptake: &mut Uptake) {
        for &(i, grams) in &self.demands {
            uptake.demand(i, grams);
        }
    }

    /// Collects what its demands were granted.
    pub fn collect(&mut self, uptake: &Uptake) {
        self.last.uptake = self
            .demands
            .iter()
            .map(|&(i, g)| uptake.granted(i, g))
            .sum();
    }

    fn is_active(&self, x: usize, apex: u8) -> bool {
        usize::from(apex) < self.costs[x].len()
    }

    /// One step of physiology and development. `step` is 1-based, for the bounds report.
    /// Reads the environment only; litter and death are settled by
    /// [`settle`](Self::settle).
    pub fn grow(&mut self, env: &Environment, step: u32) -> Result<(), PlantError> {
        if !self.is_growing() {
            return Ok(());
        }
        let physiology = self.genome.physiology;
        // Allocation weights by local quality, from the environment as it stands.
        let intensity = env.settings().light.intensity.max(1e-12);
        let reference = env.settings().minerals.concentration.max(1e-12);
        self.weights.clear();
        let mut totals = [0.0f64; 2];
        for site in &self.layout.apexes {
            let x = if site.compartment == Compartment::Shoot {
                SHOOT
            } else {
                ROOT
            };
            if !self.is_active(x, site.apex) {
                self.weights.push(0.0);
                continue;
            }
            // An apex at the foot stands on the ground: read the shoot's just above it,
            // the root's just below.
            let mut p = site.position + self.position;
            let quality = if x == SHOOT {
                p.y = p.y.max(GROUND_OFFSET);
                f64::from(env.light_at(p)) / intensity
            } else {
                p.y = p.y.min(-GROUND_OFFSET);
                env.concentration_at(p) / reference
            };
            let w = physiology.weight(quality);
            totals[x] += w;
            self.weights.push(w);
        }
        let flows = physiology.step(&mut self.pools, self.last.light, self.last.uptake, totals);
        self.last.flows = flows;
        self.totals.light += self.last.light;
        self.totals.fixed += flows.photosynthesis;
        self.totals.uptake += flows.uptake;
        self.totals.litter += flows.litter;
        self.pending_litter += flows.litter;
        for (site, &w) in self.layout.apexes.iter().zip(&self.weights) {
            let x = if site.compartment == Compartment::Shoot {
                SHOOT
            } else {
                ROOT
            };
            if w > 0.0 && totals[x] > 0.0 {
                self.stores[x][site.index] += flows.growth[x] * w / totals[x];
            }
        }

        // Development: fire every apex that has paid for its rule.
        // An apex that fires hands what it holds beyond the cost to the apexes it makes,
        // which may fire in turn: passes repeat until none is ready (at most
        // `MAX_PASSES`), so development keeps pace with growth.
        let mut fired = 0;
        let mut modules = self.modules() as usize;
        for _ in 0..MAX_PASSES {
            let mut this_pass = 0;
            for x in [SHOOT, ROOT] {
                this_pass += self.rewrite(x, step, &mut modules);
            }
            fired += this_pass;
            if this_pass == 0 {
                break;
            }
        }
        self.last.rewrites = fired;
        if fired > 0 {
            self.interpret()?;
        }
        self.age += 1;
        if self.age >= physiology.life_span {
            self.life = Life::Dead(step);
        }
        Ok(())
    }

    /// Fires the ready apexes of compartment `x` in one pass. The result is what
    /// [`rewrite_at`](crate::grammar::rewrite_at) would give applied from the last apex to
    /// the first, refusing those that would pass a bound.
    fn rewrite(&mut self, x: usize, step: u32, modules: &mut usize) -> u32 {
        let p = self.genome.physiology;
        let rules = self.genome.rules(compartment(x));
        let word = &self.words[x];
        let store = &self.stores[x];
        let mut length = word.len();
        self.ready.clear();
        for i in (0..word.len()).rev() {
            let Symbol::Apex(a) = word[i] else { continue };
            let Some(&cost) = self.costs[x].get(usize::from(a)) else {
                continue;
            };
            if store[i] < cost {
                continue;
            }
            let successor = &rules.rules[usize::from(a)].successor;
            let added = successor
                .iter()
                .filter(|s| matches!(s, Symbol::Module(_)))
                .count();
            let would_be = length - 1 + successor.len();
            if would_be > p.max_symbols as usize {
                self.bounds.symbols += 1;
                self.bounds.first_step.get_or_insert(step);
                continue;
            }
            if *modules + added > p.max_modules as usize {
                self.bounds.modules += 1;
                self.bounds.first_step.get_or_insert(step);
                continue;
            }
            length = would_be;
            *modules += added;
            self.ready.push(i);
        }
        if self.ready.is_empty() {
            return 0;
        }
        self.ready.reverse();
        self.next_word.clear();
        self.next_store.clear();
        let mut next = self.ready.iter().copied().peekable();
        for (i, (&symbol, &held)) in word.iter().zip(store).enumerate() {
            if next.peek() == Some(&i) {
                next.next();
                let Symbol::Apex(a) = symbol else { continue };
                let successor = &rules.rules[usize::from(a)].successor;
                let excess = held - self.costs[x][usize::from(a)];
                let heirs = successor
                    .iter()
                    .filter(
                        |s| matches!(s, Symbol::Apex(b) if usize::from(*b) < self.costs[x].len()),
                    )
                    .count();
                for s in successor {
                    self.next_word.push(*s);
                    let share = match s {
                        Symbol::Apex(b) if usize::from(*b) < self.costs[x].len() => {
                            excess / heirs as f64
                        }
                        _ => 0.0,
                    };
                    self.next_store.push(share);
                }
            } else {
                self.next_word.push(symbol);
                self.next_store.push(held);
            }
        }
        std::mem::swap(&mut self.words[x], &mut self.next_word);
        std::mem::swap(&mut self.stores[x], &mut self.next_store);
        self.ready.len() as u32
    }

    /// Interprets both strings into the plant, foot at the origin.
    fn interpret(&mut self) -> Result<(), PlantError> {
        self.plant.clear();
        self.layout.apexes.clear();
        self.layout.modules.clear();
        for (x, foot) in [(SHOOT, Vec3::ZERO), (ROOT, Vec3::ZERO)] {
            interpret(
                &self.words[x],
                compartment(x),
                foot,
                &self.shapes,
                &self.genome.angles,
                &self.materials,
                &mut self.plant,
                &mut self.layout,
            )?;
        }
        self.counts = [0; 4];
        for m in &self.layout.modules {
            self.counts[m.index()] += 1;
        }
        Ok(())
    }

    /// Lays this step's litter on the ground and, if the plant died, returns everything it
    /// holds: carbon as litter at its foot, minerals to the soil voxels of its roots (by
    /// root volume), or under its foot when it has none.
    pub fn settle(&mut self, env: &mut Environment) {
        if self.pending_litter > 0.0 {
            env.deposit_litter(self.position, self.pending_litter);
            self.pending_litter = 0.0;
        }
        if !matches!(self.life, Life::Dead(_)) || self.returned {
            return;
        }
        self.returned = true;
        let (carbon, minerals) = self.holdings();
        env.deposit_litter(self.position, carbon);
        self.totals.litter += carbon;
        self.totals.returned += minerals;
        let roots: Vec<(Vec3, Vec3, f64)> = self
            .world_segments()
            .filter(|(m, _, _)| matches!(m, Module::FineRoot | Module::RootBranch))
            .map(|(m, a, b)| (a, b, volume(&self.shapes[m.index()])))
            .collect();
        let total: f64 = roots.iter().map(|r| r.2).sum();
        if total > 0.0 {
            let mut left = minerals;
            for (k, &(a, b, v)) in roots.iter().enumerate() {
                let part = if k + 1 == roots.len() {
                    left
                } else {
                    minerals * v / total
                };
                left -= part;
                let points: Vec<Vec3> = env.samples(a, b).map(|(p, _)| p).collect();
                let each = part / points.len() as f64;
                for p in points {
                    env.add_minerals(p, each);
                }
            }
        } else {
            env.add_minerals(self.position - Vec3::Y * 1e-3, minerals);
        }
        self.pools = Pools::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::genome::LSystem;
    use crate::grammar::{Word, rewrite_at};

    #[test]
    fn one_pass_equals_rewrite_at_from_the_last_apex() {
        let mut g = LSystemGenome::empty();
        g.shoot =
            LSystem::parse("[A]B[A[B]]A", &["A -> b[B]A", "B -> l"], Compartment::Shoot).unwrap();
        let mut p = GrowingPlant::new(g.clone(), Vec3::ZERO, 0).unwrap();
        for (s, r) in p.words[SHOOT].iter().zip(p.stores[SHOOT].iter_mut()) {
            if matches!(s, Symbol::Apex(_)) {
                *r = 10.0;
            }
        }
        let mut expected = p.words[SHOOT].clone();
        for i in (0..expected.len()).rev() {
            rewrite_at(&mut expected, i, &g.shoot.rules, usize::MAX).unwrap();
        }
        let mut modules = 0;
        assert_eq!(p.rewrite(SHOOT, 1, &mut modules), 5);
        assert_eq!(modules, 5);
        assert_eq!(
            Word(&p.words[SHOOT]).to_string(),
            Word(&expected).to_string()
        );
        assert_eq!(p.stores[SHOOT].len(), p.words[SHOOT].len());
        // Each `A` hands its surplus to the `B` and `A` it makes; a `B` makes no apex.
        let cost_a = p.costs[SHOOT][0];
        let held: f64 = p.stores[SHOOT].iter().sum();
        assert!((held - 3.0 * (10.0 - cost_a)).abs() < 1e-12, "{held}");
    }

    #[test]
    fn bounds_refuse_and_count() {
        let mut g = LSystemGenome::empty();
        g.shoot = LSystem::parse("[A][A]", &["A -> bbA"], Compartment::Shoot).unwrap();
        g.physiology.max_modules = 3;
        let mut p = GrowingPlant::new(g, Vec3::ZERO, 0).unwrap();
        for r in p.stores[SHOOT].iter_mut() {
            *r = 10.0;
        }
        let mut modules = 0;
        assert_eq!(p.rewrite(SHOOT, 7, &mut modules), 1, "one of the two fits");
        assert_eq!(p.bounds().modules, 1);
        assert_eq!(p.bounds().first_step, Some(7));
    }
}
