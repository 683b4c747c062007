//! One more fitness term beside a problem's own ([`WithTerm`]): how a goal that does not
//! belong to any one model (a target outline) joins every model's evolution.
//!
//! Without a term, `WithTerm` is its problem exactly: same names, same fitness, same
//! random genomes, so runs keep their bytes.

use std::sync::Arc;

use rand::Rng;

use crate::fitness::Fitness;
use crate::problem::Problem;

/// A fitness term over the genomes of problem `P`, 0 to 1 (higher is better).
pub trait Term<P: Problem>: Send + Sync {
    /// Its name, beside the problem's term names.
    fn name(&self) -> &str;

    /// Its value for `genome`; must be a pure function of the genome, as
    /// [`Problem::evaluate`] is.
    fn score(&self, problem: &P, genome: &P::Genome) -> f64;
}

/// A term added to a problem, and how it joins the problem's own terms.
pub struct Added<P: Problem> {
    /// The term.
    pub term: Arc<dyn Term<P>>,
    /// Its weight in the total.
    pub weight: f64,
    /// Whether the problem's own terms still count (`false`: the term alone decides, and
    /// the problem's own fitness is not computed).
    pub beside: bool,
}

impl<P: Problem> Clone for Added<P> {
    fn clone(&self) -> Self {
        Added {
            term: self.term.clone(),
            weight: self.weight,
            beside: self.beside,
        }
    }
}

/// Problem `P`, with one more term if `added` holds one.
pub struct WithTerm<P: Problem> {
    /// The problem.
    pub problem: P,
    /// The term added, if any.
    pub added: Option<Added<P>>,
}

impl<P: Problem + Clone> Clone for WithTerm<P> {
    fn clone(&self) -> Self {
        WithTerm {
            problem: self.problem.clone(),
            added: self.added.clone(),
        }
    }
}

impl<P: Problem> WithTerm<P> {
    /// `problem` as it is.
    pub fn plain(problem: P) -> Self {
        WithTerm {
            problem,
            added: None,
        }
    }
}

impl<P: Problem> Problem for WithTerm<P> {
    type Genome = P::Genome;

    fn term_names(&self) -> Vec<String> {
        match &self.added {
            None => self.problem.term_names(),
            Some(added) => {
                let mut names = if added.beside {
                    self.problem.term_names()
                } else {
                    Vec::new()
                };
                names.push(added.term.name().to_owned());
                names
            }
        }
    }

    fn evaluate(&self, genome: &P::Genome) -> Fitness {
        let Some(added) = &self.added else {
            return self.problem.evaluate(genome);
        };
        let value = added.term.score(&self.problem, genome);
        let weighted = added.weight * value;
        if !added.beside {
            return Fitness::new(weighted, &[value]);
        }
        let own = self.problem.evaluate(genome);
        let mut terms = [0.0; crate::fitness::MAX_TERMS];
        let n = own.terms().len().min(terms.len() - 1);
        terms[..n].copy_from_slice(&own.terms()[..n]);
        terms[n] = value;
        Fitness::new(own.total() + weighted, &terms[..=n])
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> P::Genome {
        self.problem.random_genome(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scores a number by itself, with one term.
    #[derive(Clone)]
    struct Identity;

    impl Problem for Identity {
        type Genome = f64;
        fn term_names(&self) -> Vec<String> {
            vec!["value".to_owned()]
        }
        fn evaluate(&self, g: &f64) -> Fitness {
            Fitness::new(*g, &[*g])
        }
        fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
            rand::RngExt::random(rng)
        }
    }

    /// Closeness to one half.
    struct Half;

    impl Term<Identity> for Half {
        fn name(&self) -> &str {
            "half"
        }
        fn score(&self, _: &Identity, g: &f64) -> f64 {
            1.0 - (g - 0.5).abs()
        }
    }

    fn with(beside: bool) -> WithTerm<Identity> {
        WithTerm {
            problem: Identity,
            added: Some(Added {
                term: Arc::new(Half),
                weight: 2.0,
                beside,
            }),
        }
    }

    #[test]
    fn without_a_term_the_problem_is_unchanged() {
        let plain = WithTerm::plain(Identity);
        assert_eq!(plain.term_names(), ["value"]);
        assert_eq!(plain.evaluate(&0.25), Identity.evaluate(&0.25));
    }

    #[test]
    fn a_term_joins_the_problems_own_or_decides_alone() {
        let beside = with(true);
        assert_eq!(beside.term_names(), ["value", "half"]);
        let f = beside.evaluate(&0.25);
        assert_eq!(f.terms(), [0.25, 0.75]);
        assert_eq!(f.total(), 0.25 + 2.0 * 0.75);
        let alone = with(false);
        assert_eq!(alone.term_names(), ["half"]);
        let f = alone.evaluate(&0.25);
        assert_eq!((f.total(), f.terms()), (1.5, &[0.75][..]));
    }
}
