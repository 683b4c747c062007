//! The binary tree's analytic measures agree with the same measures read off its plant.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_bintree::{BITS, BinTree, Bits, Geometry, PAPER_BITS};
use sylva_core::rng;
use sylva_fitness::TreeMeasures;

fn close(a: f64, b: f64, what: &str) -> Result<(), TestCaseError> {
    // Relative, but at least 1e-5: the plant is single precision, ten levels deep.
    let tol = 1e-4 * a.abs().max(b.abs()).max(0.1);
    prop_assert!((a - b).abs() <= tol, "{what}: analytic {a} vs plant {b}");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    #[test]
    fn analytic_equals_plant(seed in any::<u64>(), min_radius in 0.005f64..0.05, paper in any::<bool>()) {
        let (geometry, width) = if paper { (Geometry::Paper, PAPER_BITS) } else { (Geometry::Sylva, BITS) };
        let bits = Bits::random(width, &mut rng::seeded(seed)).unwrap();
        let tree = BinTree::decode_as(&bits, min_radius, geometry);
        let analytic = tree.measures();
        let plant = TreeMeasures::of_plant(&tree.develop(seed).unwrap());
        close(analytic.height, plant.height, "height")?;
        close(analytic.surface_area, plant.surface_area, "surface area")?;
        close(analytic.volume, plant.volume, "volume")?;
        close(analytic.symmetry, plant.symmetry, "symmetry")?;
        close(analytic.straightness, plant.straightness, "straightness")?;
        close(analytic.radius_to_length, plant.radius_to_length, "radius to length")?;
        close(analytic.pipe_model, plant.pipe_model, "pipe model")?;
        close(analytic.roundness, plant.roundness, "roundness")?;
    }
}
