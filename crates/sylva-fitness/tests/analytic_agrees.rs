//! The binary tree's analytic measures agree with the same measures read off its plant.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_bintree::{BITS, BinTree, Bits};
use sylva_core::rng;
use sylva_fitness::TreeMeasures;

fn close(a: f64, b: f64, what: &str) -> Result<(), TestCaseError> {
    let tol = 1e-4 * a.abs().max(b.abs()).max(1e-3);
    prop_assert!((a - b).abs() <= tol, "{what}: analytic {a} vs plant {b}");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    #[test]
    fn analytic_equals_plant(seed in any::<u64>(), min_radius in 0.005f64..0.05) {
        let bits = Bits::random(BITS, &mut rng::seeded(seed)).unwrap();
        let tree = BinTree::decode(&bits, min_radius);
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
