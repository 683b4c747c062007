//! Genome files: every valid genome round-trips, and no text, however broken, makes the
//! parser or the model panic.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva::{Genome, Registry};
use sylva_bintree::{BITS, BinTree, BinTreeModel, Bits};
use sylva_core::rng;

const OAK: &str = include_str!("../../../examples/bintree/oak.json");

/// One example genome file of every model.
const EXAMPLES: [&str; 4] = [
    OAK,
    include_str!("../../../examples/automata/helix.json"),
    include_str!("../../../examples/plantmaker/fern.json"),
    include_str!("../../../examples/lsystem/herb.json"),
];

fn parse(text: &str) -> Result<Genome, sylva_model::GenomeError> {
    Registry::standard().parse_genome(text)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn decoded_genomes_round_trip_through_json(seed in any::<u64>()) {
        let bits = Bits::random(BITS, &mut rng::seeded(seed)).unwrap();
        let genome = Genome::new(BinTreeModel, BinTree::decode(&bits, 0.02));
        let text = genome.to_json();
        prop_assert_eq!(parse(&text).unwrap(), genome.clone());
        prop_assert_eq!(parse(&text).unwrap().to_json(), text);
    }

    #[test]
    fn encode_inverts_decode(seed in any::<u64>()) {
        let bits = Bits::random(BITS, &mut rng::seeded(seed)).unwrap();
        let tree = BinTree::decode(&bits, 0.02);
        prop_assert_eq!(BinTree::decode(&tree.encode(), 0.02), tree);
    }

    #[test]
    fn edited_files_never_panic(
        example in 0..EXAMPLES.len(),
        edits in prop::collection::vec((any::<usize>(), any::<u8>()), 1..8),
    ) {
        let mut bytes = EXAMPLES[example].as_bytes().to_vec();
        for (at, byte) in edits {
            let at = at % bytes.len();
            bytes[at] = byte;
        }
        if let Ok(text) = String::from_utf8(bytes)
            && let Ok(genome) = parse(&text)
        {
            // Growing may refuse (an error, never a panic); what grows is finite.
            if let Ok(plant) = genome.develop(0) {
                prop_assert!(plant.segments().iter().all(|s| s.start.is_finite() && s.end.is_finite()));
            }
        }
    }

    #[test]
    fn truncated_files_are_errors(example in 0..EXAMPLES.len(), cut in any::<prop::sample::Index>()) {
        let text = EXAMPLES[example].trim_end();
        // Any proper prefix (at a character boundary) of a JSON object is incomplete.
        let cut = cut.index(text.len());
        prop_assume!(text.is_char_boundary(cut));
        prop_assert!(parse(&text[..cut]).is_err());
    }
}

#[test]
fn the_example_parses_and_grows() {
    let genome = parse(OAK).unwrap();
    assert_eq!(genome.model(), "bintree");
    let plant = genome.develop(0).unwrap();
    assert_eq!(plant.segments().len(), 1023);
}
