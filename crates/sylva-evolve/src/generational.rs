//! lilgp-style generational breeding: tournaments, then crossover, reproduction or mutation.
//!
//! [`Generational`] replaces the whole population every generation, as lilgp (which Poncin's
//! GP runs used) does:
//!
//! ```text
//! keep the best `elitism` members unchanged                      (operator "elite")
//! for every other slot:
//!     draw an operator: crossover 88%, reproduction 10%, mutation 2%
//!     crossover:    child of two tournament winners               ("crossover")
//!     reproduction: a copy of one tournament winner               ("reproduction")
//!     mutation:     a mutated copy of one tournament winner       ("mutation")
//! ```
//!
//! A tournament draws [`GenerationalSettings::tournament`] members uniformly, with
//! replacement, from the previous generation and returns the fittest (ties go to the lower
//! slot). The default size, 7, is lilgp's and Koza's usual choice: strong enough pressure for
//! a GP population of thousands without collapsing it in a few generations.
//!
//! Elitism (default 1) copies the best members first, so the best genome is never lost; 0 is
//! lilgp's plain generational step.
//!
//! **Demes** (Sylva's, off by default). With [`GenerationalSettings::demes`] = D > 1 the
//! population is cut into D equal runs of slots that breed apart: tournaments draw only from
//! the slot's own deme and each deme keeps its own elites. Every
//! [`GenerationalSettings::migrate_every`] generations the best
//! [`GenerationalSettings::migrants`] of each deme are copied into the next one (a ring;
//! operator "migrant"), after that deme's elites. A deme that has settled on a local optimum
//! then cannot take the whole population with it, and good parts still spread. One deme is
//! exactly the plain step.
//!
//! Slot `s` of generation `g` draws everything from `rng::stream(seed, g, s)` and is made and
//! evaluated in one job of [`Pool::map`](crate::Pool::map), so a run is identical for any thread count and
//! a resumed run continues exactly.
//!
//! **Re-evaluation.** Copies (elites and reproductions) keep their genome, so their fitness
//! could be reused. Poncin found that caching a *sampled* fitness (random pairs of endpoints)
//! lets individuals that were wrongly marked very good survive for ever, and advised
//! re-evaluating every generation; [`GenerationalSettings::reevaluate`] (default `true`)
//! does that. Turn it off to save evaluations when the fitness is exact. Note that
//! [`Problem::evaluate`] is meant to be a pure function of the genome: a sampled term only
//! changes on re-evaluation if the problem varies its sampling (for instance per
//! generation) itself.

use std::borrow::Cow;
use std::ops::Range;

use rand::RngExt;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::fitness::Fitness;
use crate::individual::{Individual, IndividualId, Origin};
use crate::problem::Problem;
use crate::rng;
use crate::strategy::{Breeding, Strategy, fittest};
use crate::variation::{Crossover, Mutate};

/// How far the three rates may add up away from 1.
const RATE_SUM_TOLERANCE: f64 = 1e-6;

/// Why generational settings are refused.
#[derive(Debug, Error, PartialEq)]
pub enum GenerationalError {
    /// A tournament of no one, or of more than [`MAX_TOURNAMENT`].
    #[error("`tournament` must be 1 to {MAX_TOURNAMENT}, got {0}")]
    Tournament(usize),
    /// No deme, or more than [`MAX_DEMES`].
    #[error("`demes` must be 1 to {MAX_DEMES}, got {0}")]
    Demes(usize),
    /// A migration interval of zero generations.
    #[error("`migrate_every` must be at least 1 generation, got 0")]
    MigrateEvery,
    /// A rate that is NaN, infinite or outside 0..=1.
    #[error("`{name}` rate must be a number from 0 to 1, got {value}")]
    BadRate {
        /// Which rate.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// Rates that do not add up to 1.
    #[error(
        "crossover, reproduction and mutation rates must add up to 1, got {crossover} + \
         {reproduction} + {mutation} = {sum}"
    )]
    RateSum {
        /// Crossover rate.
        crossover: f64,
        /// Reproduction rate.
        reproduction: f64,
        /// Mutation rate.
        mutation: f64,
        /// Their sum.
        sum: f64,
    },
}

/// Settings of [`Generational`], as read from a config file; defaults are the paper's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GenerationalSettings {
    /// Members drawn per tournament (with replacement), 1 to 1000. Default 7.
    #[serde(deserialize_with = "tournament_size")]
    pub tournament: usize,
    /// Share of offspring made by crossover, 0 to 1. Default 0.88.
    #[serde(deserialize_with = "crossover")]
    pub crossover: f64,
    /// Share of offspring copied unchanged, 0 to 1. Default 0.10.
    #[serde(deserialize_with = "reproduction")]
    pub reproduction: f64,
    /// Share of offspring made by mutating a copy, 0 to 1. Default 0.02.
    #[serde(deserialize_with = "mutation")]
    pub mutation: f64,
    /// Best members carried over unchanged, 0 to 1,000,000 (at most the population).
    /// Default 1.
    #[serde(deserialize_with = "elitism")]
    pub elitism: usize,
    /// Re-evaluate copies (elites, reproductions) rather than reuse their fitness.
    /// Default `true` (see the module docs).
    pub reevaluate: bool,
    /// Demes that breed apart, 1 to 1024 (at most the population is used). Default 1.
    #[serde(deserialize_with = "deme_count", skip_serializing_if = "is_one")]
    pub demes: usize,
    /// Generations between migrations, 1 to 1,000,000. Default 10.
    #[serde(deserialize_with = "migrate_every", skip_serializing_if = "is_ten")]
    pub migrate_every: u32,
    /// Best members of each deme copied into the next at a migration, 0 to 1,000,000.
    /// Default 2.
    #[serde(deserialize_with = "migrants", skip_serializing_if = "is_two")]
    pub migrants: usize,
}

// Deme settings stay out of written configs at their defaults, so those keep their bytes.
fn is_one(n: &usize) -> bool {
    *n == 1
}
fn is_ten(n: &u32) -> bool {
    *n == 10
}
fn is_two(n: &usize) -> bool {
    *n == 2
}

/// Largest tournament: beyond, selection costs more and changes nothing (a tournament of
/// 1000 picks the best of any population to within 0.1%).
pub const MAX_TOURNAMENT: usize = 1000;

sylva_core::ranged!(tournament_size: usize, "tournament", 1, MAX_TOURNAMENT);
sylva_core::ranged!(crossover: f64, "crossover", 0.0, 1.0);
sylva_core::ranged!(reproduction: f64, "reproduction", 0.0, 1.0);
sylva_core::ranged!(mutation: f64, "mutation", 0.0, 1.0);
sylva_core::ranged!(elitism: usize, "elitism", 0, 1_000_000);
sylva_core::ranged!(deme_count: usize, "demes", 1, MAX_DEMES);
sylva_core::ranged!(migrate_every: u32, "migrate_every", 1, 1_000_000);
sylva_core::ranged!(migrants: usize, "migrants", 0, 1_000_000);

/// Most demes: more would leave demes of a handful of members in any population Sylva runs.
pub const MAX_DEMES: usize = 1024;

impl Default for GenerationalSettings {
    fn default() -> Self {
        GenerationalSettings {
            tournament: 7,
            crossover: 0.88,
            reproduction: 0.10,
            mutation: 0.02,
            elitism: 1,
            reevaluate: true,
            demes: 1,
            migrate_every: 10,
            migrants: 2,
        }
    }
}

impl GenerationalSettings {
    /// Breeding that fits a target by many small steps from good members: 70% of offspring
    /// mutants and 30% crossovers, none copied, the five best kept as they are and not
    /// re-evaluated (what a match of the generational models breeds with: `Evolve::fitting`).
    pub fn mostly_mutants() -> GenerationalSettings {
        GenerationalSettings {
            crossover: 0.3,
            mutation: 0.7,
            reproduction: 0.0,
            elitism: 5,
            reevaluate: false,
            ..GenerationalSettings::default()
        }
    }

    /// Checks the tournament size and that the rates are in 0..=1 and add up to 1.
    pub fn validate(&self) -> Result<(), GenerationalError> {
        if !(1..=MAX_TOURNAMENT).contains(&self.tournament) {
            return Err(GenerationalError::Tournament(self.tournament));
        }
        if !(1..=MAX_DEMES).contains(&self.demes) {
            return Err(GenerationalError::Demes(self.demes));
        }
        if self.migrate_every == 0 {
            return Err(GenerationalError::MigrateEvery);
        }
        for (name, value) in [
            ("crossover", self.crossover),
            ("reproduction", self.reproduction),
            ("mutation", self.mutation),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(GenerationalError::BadRate { name, value });
            }
        }
        let sum = self.crossover + self.reproduction + self.mutation;
        if (sum - 1.0).abs() > RATE_SUM_TOLERANCE {
            return Err(GenerationalError::RateSum {
                crossover: self.crossover,
                reproduction: self.reproduction,
                mutation: self.mutation,
                sum,
            });
        }
        Ok(())
    }
}

/// lilgp's generational step (see the module docs).
#[derive(Clone, Debug)]
pub struct Generational<X, M> {
    /// Makes a child of two tournament winners.
    pub crossover: X,
    /// Changes a copy of one tournament winner.
    pub mutation: M,
    settings: GenerationalSettings,
}

impl<X, M> Generational<X, M> {
    /// A strategy with validated settings.
    pub fn new(
        crossover: X,
        mutation: M,
        settings: GenerationalSettings,
    ) -> Result<Self, GenerationalError> {
        settings.validate()?;
        Ok(Generational {
            crossover,
            mutation,
            settings,
        })
    }

    /// The settings in use.
    pub fn settings(&self) -> &GenerationalSettings {
        &self.settings
    }
}

impl<G, X: Crossover<G> + Sync, M: Mutate<G> + Sync> crate::variation::Operators<G>
    for Generational<X, M>
{
    type Crossover = X;
    type Mutation = M;
    fn crossover(&self) -> &X {
        &self.crossover
    }
    fn mutation(&self) -> &M {
        &self.mutation
    }
}

/// The operator a slot uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Operator {
    Elite,
    Migrant,
    Crossover,
    Reproduction,
    Mutation,
}

impl Operator {
    fn name(self) -> &'static str {
        match self {
            Operator::Elite => "elite",
            Operator::Migrant => "migrant",
            Operator::Crossover => "crossover",
            Operator::Reproduction => "reproduction",
            Operator::Mutation => "mutation",
        }
    }
}

/// A slot's result: genome, fitness, operator, parents (slots of the old population), and
/// whether an evaluation ran.
struct Offspring<G> {
    genome: G,
    fitness: Option<Fitness>,
    operator: Operator,
    parents: [Option<usize>; 2],
    evaluated: bool,
}

/// `a` is fitter than `b` (ties go to the lower slot).
fn fitter<G>(population: &[Individual<G>], a: usize, b: usize) -> bool {
    population[a]
        .total()
        .total_cmp(&population[b].total())
        .then(b.cmp(&a))
        .is_gt()
}

/// The population cut into `count` runs of consecutive slots whose sizes differ by at most one.
struct Demes {
    len: usize,
    count: usize,
}

impl Demes {
    fn new(len: usize, demes: usize) -> Demes {
        Demes {
            len,
            count: demes.clamp(1, len.max(1)),
        }
    }

    /// The deme of `slot`.
    fn of(&self, slot: usize) -> usize {
        slot * self.count / self.len
    }

    /// The slots of deme `d`: from ceil(d × len / count) on.
    fn range(&self, d: usize) -> Range<usize> {
        let start = |d: usize| (d * self.len).div_ceil(self.count);
        start(d)..start(d + 1)
    }
}

/// The winner of a tournament of `size` members of `deme` drawn with replacement.
fn tournament<G, R: rand::Rng + ?Sized>(
    population: &[Individual<G>],
    deme: Range<usize>,
    size: usize,
    rng: &mut R,
) -> usize {
    let mut best = rng.random_range(deme.clone());
    for _ in 1..size {
        let other = rng.random_range(deme.clone());
        if fitter(population, other, best) {
            best = other;
        }
    }
    best
}

impl<P, X, M> Strategy<P> for Generational<X, M>
where
    P: Problem,
    X: Crossover<P::Genome> + Sync,
    M: Mutate<P::Genome> + Sync,
{
    fn breed(
        &self,
        problem: &P,
        population: &mut [Individual<P::Genome>],
        ctx: &mut Breeding<'_>,
    ) -> u64 {
        if population.is_empty() {
            return 0;
        }
        let s = &self.settings;
        let (seed, generation) = (ctx.seed, ctx.generation);
        let demes = Demes::new(population.len(), s.demes);
        let migrating = demes.count > 1 && generation % s.migrate_every == 0;
        // Slots filled by copies: each deme's elites first, then at a migration the best of
        // the deme before it.
        let mut copies: Vec<Option<(usize, Operator)>> = vec![None; population.len()];
        for d in 0..demes.count {
            let deme = demes.range(d);
            let elites = fittest(&population[deme.clone()], s.elitism.min(deme.len()));
            let mut slot = deme.start;
            for e in elites {
                copies[slot] = Some((deme.start + e, Operator::Elite));
                slot += 1;
            }
            if migrating {
                let from = demes.range((d + demes.count - 1) % demes.count);
                let room = deme.end - slot;
                for m in fittest(&population[from.clone()], s.migrants.min(room)) {
                    copies[slot] = Some((from.start + m, Operator::Migrant));
                    slot += 1;
                }
            }
        }
        let old = &*population;
        let copy = |parent: usize, operator: Operator| {
            let genome = old[parent].genome.clone();
            let (fitness, evaluated) = if s.reevaluate || old[parent].fitness.is_none() {
                (Some(crate::problem::evaluate(problem, &genome)), true)
            } else {
                (old[parent].fitness, false)
            };
            Offspring {
                genome,
                fitness,
                operator,
                parents: [Some(parent), None],
                evaluated,
            }
        };
        let offspring = ctx.evaluator.map(old.len(), |slot| {
            if let Some((parent, operator)) = copies[slot] {
                return copy(parent, operator);
            }
            let deme = demes.range(demes.of(slot));
            let mut rng = rng::stream(seed, generation, slot as u32);
            let draw: f64 = rng.random();
            if draw < s.crossover {
                let a = tournament(old, deme.clone(), s.tournament, &mut rng);
                let b = tournament(old, deme.clone(), s.tournament, &mut rng);
                let genome = self
                    .crossover
                    .crossover(&old[a].genome, &old[b].genome, &mut rng);
                Offspring {
                    fitness: Some(crate::problem::evaluate(problem, &genome)),
                    genome,
                    operator: Operator::Crossover,
                    parents: [Some(a), Some(b)],
                    evaluated: true,
                }
            } else if draw < s.crossover + s.reproduction {
                copy(
                    tournament(old, deme.clone(), s.tournament, &mut rng),
                    Operator::Reproduction,
                )
            } else {
                let parent = tournament(old, deme.clone(), s.tournament, &mut rng);
                let mut genome = old[parent].genome.clone();
                self.mutation.mutate(&mut genome, &mut rng);
                Offspring {
                    fitness: Some(crate::problem::evaluate(problem, &genome)),
                    genome,
                    operator: Operator::Mutation,
                    parents: [Some(parent), None],
                    evaluated: true,
                }
            }
        });
        let parent_ids: Vec<IndividualId> = population.iter().map(|i| i.id).collect();
        let mut evaluations = 0;
        for (slot, child) in offspring.into_iter().enumerate() {
            evaluations += u64::from(child.evaluated);
            population[slot] = Individual {
                id: ctx.next_id(),
                genome: child.genome,
                fitness: child.fitness,
                origin: Origin {
                    generation,
                    operator: Cow::Borrowed(child.operator.name()),
                    parents: child
                        .parents
                        .iter()
                        .flatten()
                        .map(|&p| parent_ids[p])
                        .collect(),
                },
            };
        }
        evaluations
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_and_valid() {
        let s = GenerationalSettings::default();
        assert_eq!(
            (s.crossover, s.reproduction, s.mutation),
            (0.88, 0.10, 0.02)
        );
        assert_eq!(s.validate(), Ok(()));
    }

    #[test]
    fn tournament_prefers_the_fitter() {
        let pop: Vec<Individual<u8>> = (0..10u8)
            .map(|i| Individual {
                id: IndividualId(u64::from(i)),
                genome: i,
                fitness: Some(Fitness::new(f64::from(i), &[])),
                origin: Origin::new(0, "random"),
            })
            .collect();
        let mut rng = rng::seeded(3);
        let wins: usize = (0..1000)
            .map(|_| tournament(&pop, 0..10, 7, &mut rng))
            .filter(|&w| w >= 7)
            .count();
        // P(winner in the top 3 of 10 with 7 draws) = 1 - 0.7^7 ≈ 0.92.
        assert!(wins > 880, "{wins}");
        assert_eq!(fittest(&pop, 3), vec![9, 8, 7]);
    }

    #[test]
    fn demes_cut_the_population_into_near_equal_runs() {
        for len in 1..40 {
            for count in 1..12 {
                let demes = Demes::new(len, count);
                let mut next = 0;
                for d in 0..demes.count {
                    let r = demes.range(d);
                    assert_eq!(r.start, next, "{len} {count}");
                    assert!(r.len() == len / demes.count || r.len() == len.div_ceil(demes.count));
                    assert!(r.clone().all(|slot| demes.of(slot) == d));
                    next = r.end;
                }
                assert_eq!(next, len);
            }
        }
    }
}
