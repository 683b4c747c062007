//! How one generation becomes the next.
//!
//! A [`Strategy`] breeds in place: it reads the evaluated population, makes offspring with
//! variation operators, evaluates them through the [`Pool`] and writes them back.
//! Every offspring slot draws from its own random stream (see [`crate::rng`]).
//!
//! [`MeanReplacement`] is the generation step of Susinno's *Deciduous Evolution*:
//!
//! ```text
//! calculate mean fitness
//! for each tree with fitness < mean:
//!     replace it with the fitter of two offspring:
//!         a mutated child of the two best trees, or a random tree
//! ```
//!
//! Sylva adds one option, on by default in its configs: **clones are culled**. A member whose
//! genome equals an earlier member's is replaced as if it were below the mean. Without it a
//! population that has converged on copies of its best tree has nobody below the mean and
//! stops evolving for good; the paper's step only ever replaces trees below the mean.
//!
//! The paper reports that its GA sometimes threw away all its best trees. One way that
//! happens: when a population has converged, the rounded mean of nearly equal fitnesses can
//! exceed every one of them, so every tree is "below the mean". Here the best individual is
//! never replaced, whatever the mean says, and the two parents are chosen from a snapshot
//! taken before any replacement.

use std::borrow::Cow;

use crate::Pool;
use crate::fitness::Fitness;
use crate::individual::{Individual, IndividualId, Origin};
use crate::problem::Problem;
use crate::rng;
use crate::variation::{Crossover, Mutate};

/// What a strategy needs besides the population: where randomness and ids come from.
pub struct Breeding<'a> {
    /// The run seed.
    pub seed: u64,
    /// The generation being made (1 for the first bred generation).
    pub generation: u32,
    /// Where evaluation runs.
    pub evaluator: &'a Pool,
    next_id: &'a mut u64,
}

impl<'a> Breeding<'a> {
    /// A breeding context; ids are taken from `next_id` upwards.
    pub fn new(seed: u64, generation: u32, evaluator: &'a Pool, next_id: &'a mut u64) -> Self {
        Breeding {
            seed,
            generation,
            evaluator,
            next_id,
        }
    }

    /// The next unused id.
    pub fn next_id(&mut self) -> IndividualId {
        let id = IndividualId(*self.next_id);
        *self.next_id += 1;
        id
    }
}

/// Makes the next generation in place; returns how many evaluations it ran.
pub trait Strategy<P: Problem>: Sync {
    /// Replaces members of `population` with offspring and makes sure every member is
    /// evaluated.
    fn breed(
        &self,
        problem: &P,
        population: &mut [Individual<P::Genome>],
        ctx: &mut Breeding<'_>,
    ) -> u64;
}

/// Mean of the finite totals, or negative infinity if none is finite.
pub fn mean_total<G>(population: &[Individual<G>]) -> f64 {
    let (sum, n) = population
        .iter()
        .map(Individual::total)
        .filter(|t| t.is_finite())
        .fold((0.0, 0usize), |(s, n), t| (s + t, n + 1));
    if n == 0 {
        f64::NEG_INFINITY
    } else {
        sum / n as f64
    }
}

/// Slots of the `k` fittest members, fittest first (ties go to the lower slot).
pub fn fittest<G>(population: &[Individual<G>], k: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..population.len()).collect();
    order.sort_by(|&a, &b| {
        population[b]
            .total()
            .total_cmp(&population[a].total())
            .then(a.cmp(&b))
    });
    order.truncate(k);
    order
}

/// Indices of the best and second-best members (ties go to the lower index). `None` for an
/// empty population; both are the same index for a population of one.
pub fn two_best<G>(population: &[Individual<G>]) -> Option<(usize, usize)> {
    let better = |a: usize, b: usize| {
        population[a]
            .total()
            .total_cmp(&population[b].total())
            .then(b.cmp(&a))
            .is_gt()
    };
    let mut best = 0;
    for i in 1..population.len() {
        if better(i, best) {
            best = i;
        }
    }
    let mut second = if best == 0 { 1 } else { 0 };
    if second >= population.len() {
        return (!population.is_empty()).then_some((best, best));
    }
    for i in 0..population.len() {
        if i != best && better(i, second) {
            second = i;
        }
    }
    Some((best, second))
}

/// Susinno's generation step (see the module docs).
#[derive(Clone, Debug)]
pub struct MeanReplacement<X, M> {
    /// Combines the two best.
    pub crossover: X,
    /// Applied to the child of the two best.
    pub mutation: M,
    /// Replace members whose genome repeats an earlier member's (Sylva's addition; `false`
    /// is the paper's step).
    pub cull_clones: bool,
}

impl<P, X, M> Strategy<P> for MeanReplacement<X, M>
where
    P: Problem,
    P::Genome: Eq + std::hash::Hash,
    X: Crossover<P::Genome> + Sync,
    M: Mutate<P::Genome> + Sync,
{
    fn breed(
        &self,
        problem: &P,
        population: &mut [Individual<P::Genome>],
        ctx: &mut Breeding<'_>,
    ) -> u64 {
        let Some((best, second)) = two_best(population) else {
            return 0;
        };
        let mean = mean_total(population);
        let mut seen = std::collections::HashSet::new();
        let losers: Vec<usize> = (0..population.len())
            .filter(|&i| {
                // Every genome is recorded, so the first copy of each is the one kept.
                let clone = !seen.insert(&population[i].genome) && self.cull_clones;
                let t = population[i].total();
                i != best && (clone || !t.is_finite() || t < mean)
            })
            .collect();
        let (a, b) = (&population[best], &population[second]);
        let parents = [a.id, b.id];
        let (seed, generation) = (ctx.seed, ctx.generation);
        let offspring = ctx.evaluator.map(losers.len(), |k| {
            let mut rng = rng::stream(seed, generation, losers[k] as u32);
            let mut child = self.crossover.crossover(&a.genome, &b.genome, &mut rng);
            self.mutation.mutate(&mut child, &mut rng);
            let random = problem.random_genome(&mut rng);
            let child_fitness = crate::problem::evaluate(problem, &child);
            let random_fitness = crate::problem::evaluate(problem, &random);
            if random_fitness.cmp_total(&child_fitness).is_gt() {
                (random, random_fitness, false)
            } else {
                (child, child_fitness, true)
            }
        });
        for (slot, (genome, fitness, is_child)) in losers.iter().zip(offspring) {
            population[*slot] = Individual {
                id: ctx.next_id(),
                genome,
                fitness: Some(fitness),
                origin: if is_child {
                    Origin {
                        generation,
                        operator: Cow::Borrowed("crossover+mutation"),
                        parents: parents.to_vec(),
                    }
                } else {
                    Origin::new(generation, "random")
                },
            };
        }
        2 * losers.len() as u64 + evaluate_missing(problem, population, ctx.evaluator)
    }
}

impl<G, X: Crossover<G> + Sync, M: Mutate<G> + Sync> crate::variation::Operators<G>
    for MeanReplacement<X, M>
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

/// Evaluates every member whose fitness is `None`; returns how many were evaluated.
pub fn evaluate_missing<P: Problem>(
    problem: &P,
    population: &mut [Individual<P::Genome>],
    evaluator: &Pool,
) -> u64 {
    let todo: Vec<usize> = (0..population.len())
        .filter(|&i| population[i].fitness.is_none())
        .collect();
    let scores: Vec<Fitness> = {
        let pop = &*population;
        evaluator.map(todo.len(), |k| {
            crate::problem::evaluate(problem, &pop[todo[k]].genome)
        })
    };
    for (i, f) in todo.iter().zip(scores) {
        population[*i].fitness = Some(f);
    }
    todo.len() as u64
}
