//! The binary tree's genomes as vectors ([`FieldCoding`]), for optimisers outside Sylva: one
//! entry per field of the genetic algorithm's layout ([`LAYOUT`](crate::LAYOUT) or
//! [`PAPER_LAYOUT`](crate::PAPER_LAYOUT)), in the field's own unit (depth in levels, radii
//! and length in metres, angles in degrees, each axis as its azimuth and elevation).
//!
//! A vector decodes to the bit string the genetic algorithm evolves, each entry rounded to
//! its field's nearest step, so every vector is a genome of the native run and every bit
//! string has vectors. Entries rather than bits, because nearby vectors are then nearby
//! trees, which Gaussian and CMA-ES emitters assume: a bit string read as 65 numbers puts
//! a field's highest bit beside its lowest. Each field's bounds reach half a step past its
//! range, so every step owns an equal stretch and a uniform vector draws every value alike.

use sylva_evolve::bits::Quantized;
use sylva_model::VectorCoding;

use crate::genome::{BinTree, Bits, Field, encode_values};
use crate::{BinTreeModel, BinTreeProblem};

/// The binary tree's fields as a vector, in the layout of a problem's geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldCoding {
    problem: BinTreeProblem,
    bounds: Vec<[f64; 2]>,
}

/// A field's bounds: its range and half a step beyond each end.
fn bounds_of(code: &Quantized) -> [f64; 2] {
    let half = if code.max > code.min {
        0.5 * code.step()
    } else {
        0.0
    };
    [code.min - half, code.max + half]
}

impl FieldCoding {
    /// The coding of `problem`'s genomes (its geometry's layout and minimum radius).
    pub fn new(problem: &BinTreeProblem) -> FieldCoding {
        let layout: &[Field; 11] = problem.geometry.layout();
        FieldCoding {
            problem: problem.clone(),
            bounds: layout.iter().map(|f| bounds_of(&f.code)).collect(),
        }
    }
}

impl VectorCoding<BinTreeModel> for FieldCoding {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn decode(&self, x: &[f64]) -> Bits {
        let mut values = [0.0; 11];
        for (v, x) in values.iter_mut().zip(x) {
            *v = *x;
        }
        encode_values(&values, self.problem.geometry)
    }

    /// The genome's field values in the problem's layout, clamped to its bounds (a genome
    /// of the other geometry is read in this one's ranges).
    fn encode(&self, genome: &BinTree) -> Result<Vec<f64>, String> {
        Ok(genome
            .values()
            .iter()
            .zip(&self.bounds)
            .map(|(v, [lo, hi])| v.clamp(*lo, *hi))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Geometry, LAYOUT};
    use sylva_evolve::Problem;

    #[test]
    fn every_vector_is_a_bit_string_of_the_run_and_back() {
        let problem = BinTreeProblem::new(0.02);
        let coding = FieldCoding::new(&problem);
        assert_eq!(coding.bounds().len(), LAYOUT.len());
        // Depth's codes 0..7 are 3..10 levels; the bounds reach half a level beyond.
        assert_eq!(coding.bounds()[0], [2.5, 10.5]);
        let mut rng = sylva_core::rng::seeded(4);
        for _ in 0..200 {
            let bits = problem.random_genome(&mut rng);
            let genome = problem.decode(&bits);
            let x = coding.encode(&genome).unwrap();
            assert!(
                x.iter()
                    .zip(coding.bounds())
                    .all(|(v, [lo, hi])| lo <= v && v <= hi)
            );
            assert_eq!(coding.decode(&x), bits);
        }
    }

    #[test]
    fn each_step_owns_an_equal_stretch() {
        let coding = FieldCoding::new(&BinTreeProblem::new(0.02));
        let depth = |d: f64| {
            let mut x: Vec<f64> = coding.bounds().iter().map(|b| b[0]).collect();
            x[0] = d;
            BinTree::decode(&coding.decode(&x), 0.02).depth
        };
        assert_eq!(
            [2.5, 2.99, 3.49, 3.51, 9.49, 9.51, 10.5].map(depth),
            [3, 3, 3, 4, 9, 10, 10]
        );
    }

    #[test]
    fn the_papers_fixed_ratio_is_a_point() {
        let problem = BinTreeProblem::from_settings(&crate::BinTreeSettings {
            geometry: Geometry::Paper,
            ..Default::default()
        });
        let coding = FieldCoding::new(&problem);
        assert_eq!(coding.bounds()[4], [1.0, 1.0]);
        let x: Vec<f64> = coding.bounds().iter().map(|b| b[1]).collect();
        let tree = problem.decode(&coding.decode(&x));
        assert_eq!((tree.depth, tree.length_ratio), (10, 1.0));
    }
}
