//! Genome files: every valid genome round-trips, and no text, however broken, makes the
//! parser or the model panic.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_evolve::rng;
use sylva_models::Genome;
use sylva_models::bintree::{BITS, BinTree, Bits};

const OAK: &str = include_str!("../../../examples/bintree/oak.json");

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn decoded_genomes_round_trip_through_json(seed in any::<u64>()) {
        let bits = Bits::random(BITS, &mut rng::seeded(seed)).unwrap();
        let genome = Genome::BinTree(BinTree::decode(&bits, 0.02));
        let text = genome.to_json();
        prop_assert_eq!(Genome::from_json(&text).unwrap(), genome.clone());
        prop_assert_eq!(Genome::from_json(&text).unwrap().to_json(), text);
    }

    #[test]
    fn encode_inverts_decode(seed in any::<u64>()) {
        let bits = Bits::random(BITS, &mut rng::seeded(seed)).unwrap();
        let tree = BinTree::decode(&bits, 0.02);
        prop_assert_eq!(BinTree::decode(&tree.encode(), 0.02), tree);
    }

    #[test]
    fn edited_files_never_panic(edits in prop::collection::vec((any::<usize>(), any::<u8>()), 1..8)) {
        let mut bytes = OAK.as_bytes().to_vec();
        for (at, byte) in edits {
            let at = at % bytes.len();
            bytes[at] = byte;
        }
        if let Ok(text) = String::from_utf8(bytes)
            && let Ok(genome) = Genome::from_json(&text)
        {
            let plant = genome.develop(0).unwrap();
            prop_assert!(!plant.segments.is_empty());
        }
    }

    #[test]
    fn truncated_files_are_errors(cut in 0usize..OAK.len() - 2) {
        prop_assert!(Genome::from_json(&OAK[..cut]).is_err());
    }
}

#[test]
fn the_example_parses_and_grows() {
    let genome = Genome::from_json(OAK).unwrap();
    assert_eq!(genome.model(), "bintree");
    let plant = genome.develop(0).unwrap();
    assert_eq!(plant.segments.len(), 1023);
}
