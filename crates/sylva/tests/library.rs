//! The library layer as the studio and Python use it: configs of every model, runs that step,
//! browse, checkpoint and resume, breeding by hand with each model's own operators, and a
//! fifth model added through the trait alone.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::{Path, PathBuf};

use sylva::export;
use sylva::{
    Config, Evolution, Genome, GrowOptions, Grown, InputError, ModelEntry, Registry, Settings,
};

/// Growing with `seed`, everything else at its default.
fn seeded(seed: u64) -> GrowOptions {
    GrowOptions {
        seed: Some(seed),
        ..GrowOptions::default()
    }
}
use sylva_core::par::Pool;

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(path)
}

fn config(text: &str) -> Result<Config, InputError> {
    sylva::Registry::standard().parse_config(Path::new("c.toml"), text)
}

#[test]
fn every_example_config_reads_and_the_default_is_written_out() {
    for name in [
        "bintree/default.toml",
        "bintree/paper.toml",
        "bintree/six-terms.toml",
        "automata/sphere.toml",
        "automata/box-above.toml",
        "automata/two-levels.toml",
        "automata/pine.toml",
        "plantmaker/evolve.toml",
        "lsystem/evolve.toml",
        "bintree/varieties.toml",
        "automata/varieties.toml",
        "plantmaker/varieties.toml",
        "plantmaker/varieties-cma-me.toml",
        "lsystem/varieties.toml",
        "match/varieties.toml",
    ] {
        let c = sylva::Registry::standard()
            .load_config(&example(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        // What a run records reads back as the same config.
        assert_eq!(
            config(&c.to_toml()).unwrap().to_toml(),
            c.to_toml(),
            "{name}"
        );
    }
    let tapered = config("[output]\ntaper = 2.5\n").unwrap();
    assert!(tapered.to_toml().contains("taper = 2.5"));
    let registry = sylva::Registry::standard();
    let first = registry.default_config().unwrap();
    assert!(
        !first.to_toml().contains("taper"),
        "left out when not asked for"
    );
    let default = sylva::Registry::standard()
        .load_config(&example("bintree/default.toml"))
        .unwrap();
    assert_eq!(
        default.to_toml(),
        Config::builtin_run(&registry).unwrap().to_toml()
    );
    let bare = default
        .to_toml()
        .replace("foliage = \"oak\"\n", "")
        .replace("density = 1.5\n", "");
    assert_eq!(
        bare,
        first.to_toml(),
        "the built-in run dresses, and no more"
    );
    assert_eq!(config("").unwrap().to_toml(), first.to_toml());
    let paper = sylva::Registry::standard()
        .load_config(&example("bintree/paper.toml"))
        .unwrap();
    let paper = paper.get::<sylva_bintree::BinTreeModel>().unwrap();
    assert_eq!(paper.settings.weights.pipe_model, 0.0);
    assert!(!paper.settings.cull_clones);
    assert_eq!(paper.settings.geometry, sylva_bintree::Geometry::Paper);
    assert_eq!(
        paper.settings.straightness,
        sylva_bintree::Straightness::Paper
    );
    assert_eq!(paper.settings.height, sylva_bintree::Height::Paper);
    assert_eq!(paper.settings.symmetry, sylva_bintree::Symmetry::Paper);
}

#[test]
fn config_errors_point_at_the_value() {
    let cases = [
        ("[run]\npopulation = -5\n", "c.toml:2:14", "population"),
        ("[run]\npopulation = 0\n", "c.toml:2:14", "1 to 1000000"),
        ("[bintree.weights]\nheight = nan\n", "c.toml:2:10", "weight"),
        ("[bintree.weights]\nheight = inf\n", "c.toml:2:10", "weight"),
        ("[bintree]\nmin_radius = 1e9\n", "c.toml:2:14", "min_radius"),
        (
            "[run]\npopulaton = 5\n",
            "c.toml:2:1",
            "unknown field `populaton`",
        ),
        ("model = \"oak\"\n", "c.toml:1:9", "unknown model `oak`"),
        ("[output]\nview = \"back\"\n", "c.toml:2:8", "front"),
        ("[run\n", "c.toml:1:", ""),
        // A section is a table: a list is not read field by field in order.
        ("run = [5, 10]\n", "c.toml:1:7", "expected a table: `[run]`"),
        ("run = []\n", "c.toml:1:7", "expected a table"),
        ("bintree = [\"a\"]\n", "c.toml:1:11", "`[bintree]`"),
        (
            "output = 3\n",
            "c.toml:1:10",
            "expected a table: `[output]`",
        ),
        ("[run]\nseed = 18446744073709551616\n", "c.toml:2:8", ""),
        // A section of another model is refused where it stands, not quietly ignored.
        (
            "[automata]\nautomata = 3\n",
            "c.toml:1:2",
            "this config evolves `bintree`",
        ),
        (
            "model = \"lsystem\"\n[lsystem]\nrandom_rounds = 5000\n",
            "c.toml:3:17",
            "random_rounds",
        ),
        (
            "[output]\ntaper = 5\n",
            "c.toml:2:9",
            "`taper` must be a number from 2 to 3",
        ),
        (
            "model = \"automata\"\n[automata]\ncreation = \"any\"\n",
            "c.toml:3:12",
            "expected `later` or `next`",
        ),
    ];
    for (text, location, mention) in cases {
        let e = config(text).unwrap_err();
        assert!(
            e.location.starts_with(location),
            "{text:?}: {} (expected {location})",
            e.location
        );
        assert!(e.message.contains(mention), "{text:?}: {}", e.message);
        assert!(e.line > 0 && e.snippet.is_some(), "{text:?}: {e:?}");
    }
}

/// A small run of `model` with `extra` settings.
fn small(model: &str, extra: &str) -> Config {
    config(&format!(
        "model = \"{model}\"\n[run]\ngenerations = 4\npopulation = 8\nseed = 5\n{extra}"
    ))
    .unwrap()
}

#[test]
fn runs_of_every_model_step_browse_and_resume_exactly() {
    let growth = "[lsystem.grow]\nsteps = 20\n[lsystem.grow.world]\nsize = [16, 16, 16]\n\
                  soil_layers = 4\n";
    for (model, extra) in [
        ("bintree", ""),
        ("automata", "[automata.growth]\niterations = 30\n"),
        ("plantmaker", ""),
        ("lsystem", growth),
    ] {
        let c = small(model, extra);
        let mut straight = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
        straight.step_batch(4, |_| {}).unwrap();
        assert_eq!(straight.generation(), 4);
        assert_eq!(straight.stats().len(), 5);
        assert_eq!(straight.population().len(), 8);
        assert_eq!(straight.best().genome.model(), model);

        // Stopped after two generations, saved, and resumed on two threads.
        let mut first = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
        first.step_batch(2, |_| {}).unwrap();
        let saved = first.checkpoint().unwrap();
        let mut resumed = Evolution::resume(
            &c,
            Path::new("cp.json"),
            &saved,
            Pool::with_threads(2).unwrap(),
        )
        .unwrap();
        resumed.step_batch(2, |_| {}).unwrap();
        let rows = |e: &Evolution| -> Vec<(u32, f64, f64, Vec<f64>)> {
            e.stats()
                .iter()
                .map(|s| (s.generation, s.best, s.mean, s.best_terms.clone()))
                .collect()
        };
        assert_eq!(rows(&resumed), rows(&straight), "{model}");
        assert_eq!(resumed.best(), straight.best(), "{model}");

        // A checkpoint of another config is refused.
        let other = small(model, &format!("{extra}\n[output]\nsheet_size = 3\n"));
        let refused = Evolution::resume(&other, Path::new("cp.json"), &saved, Pool::Serial);
        assert!(refused.is_err_and(|e| e.is_input()), "{model}");
    }
}

#[test]
fn a_member_s_family_is_browsed_through_kept_generations() {
    let c = small("bintree", "");
    let mut run = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
    run.keep_history(10);
    run.step_batch(4, |_| {}).unwrap();
    assert!(run.generation_members(1).is_some());
    let best = run.best();
    let family = run.family(best.id);
    assert_eq!(family[0].id, best.id);
    for m in &family[1..] {
        assert!(
            family
                .iter()
                .any(|child| child.origin.parents.contains(&m.id))
        );
    }
    if !best.origin.parents.is_empty() {
        assert!(family.len() > 1, "the parents are kept");
    }
}

#[test]
fn start_genomes_must_be_of_the_run_s_model() {
    let c = small("plantmaker", "");
    let herb = sylva::Registry::standard()
        .load_genome(&example("lsystem/herb.json"))
        .unwrap();
    let e = Evolution::start(&c, vec![herb], Pool::Serial).unwrap_err();
    assert!(
        e.is_input() && e.to_string().contains("`plantmaker`"),
        "{e}"
    );
    let tulip = sylva::Registry::standard()
        .load_genome(&example("plantmaker/tulip.json"))
        .unwrap();
    let run = Evolution::start(&c, vec![tulip.clone()], Pool::Serial).unwrap();
    assert_eq!(run.population()[0].genome, tulip);
}

#[test]
fn random_genomes_of_every_model_grow_into_branching_plants() {
    for entry in Registry::standard().models() {
        let genomes: Vec<Genome> = (0..4)
            .map(|seed| entry.random(Settings::Default, seed).unwrap())
            .collect();
        for (seed, genome) in genomes.iter().enumerate() {
            let plant = genome.develop(genome.default_seed()).unwrap();
            let tips = plant.tips().count();
            assert!(tips >= 2, "{} seed {seed}: {tips} tips", entry.name());
            let again = entry.random(Settings::Default, seed as u64).unwrap();
            assert_eq!(&again, genome, "{} seed {seed}", entry.name());
        }
        assert_ne!(genomes[0], genomes[1], "{}", entry.name());
    }
}

#[test]
fn every_model_breeds_by_hand_with_its_own_operators() {
    for name in [
        "bintree/oak.json",
        "automata/helix.json",
        "plantmaker/fern.json",
        "lsystem/herb.json",
    ] {
        let models = Registry::standard();
        let a = models.load_genome(&example(name)).unwrap();
        let model = a.model();
        let entry = models.get(model).unwrap();
        let b = entry.random(Settings::Default, 3).unwrap();
        assert_eq!(b.model(), model);
        // Mutation and crossover are the model's, deterministic in the seed.
        let m = a.mutate(Settings::Default, 9).unwrap();
        assert_eq!(m, a.mutate(Settings::Default, 9).unwrap(), "{name}");
        let (child, parents) =
            Genome::cross(&[(&a, 1.0), (&b, 2.0)], Settings::Default, 4).unwrap();
        assert_eq!(child.model(), model);
        assert!(
            !parents.is_empty() && parents.iter().all(|&p| p < 2),
            "{name}"
        );
        let (again, _) = Genome::cross(&[(&a, 1.0), (&b, 2.0)], Settings::Default, 4).unwrap();
        assert_eq!(child, again, "{name}");
        // What breeding makes is a genome file of the model that reads back the same.
        let text = child.to_json();
        assert_eq!(Registry::standard().parse_genome(&text).unwrap(), child);
    }
    let oak = sylva::Registry::standard()
        .load_genome(&example("bintree/oak.json"))
        .unwrap();
    let fern = sylva::Registry::standard()
        .load_genome(&example("plantmaker/fern.json"))
        .unwrap();
    let e = Genome::cross(&[(&oak, 1.0), (&fern, 1.0)], Settings::Default, 1).unwrap_err();
    assert!(
        e.is_input() && e.to_string().contains("cannot be crossed"),
        "{e}"
    );
    let e = Genome::cross(&[(&oak, 1.0)], Settings::Default, 1).unwrap_err();
    assert!(e.to_string().contains("two or more parents"), "{e}");
    let e = Genome::cross(&[(&oak, 1.0), (&oak, f64::NAN)], Settings::Default, 1).unwrap_err();
    assert!(e.to_string().contains("dominance"), "{e}");
    let settings = serde_json::json!({ "mutation_rat": 0.5 });
    let e = oak.mutate(Settings::Json(&settings), 1).unwrap_err();
    assert!(e.to_string().contains("mutation_rat"), "{e}");
    let settings = serde_json::json!({ "mutation_rate": 1.5 });
    let e = oak.mutate(Settings::Json(&settings), 1).unwrap_err();
    assert!(e.to_string().contains("mutation_rate"), "{e}");
    // Knobs over a run's settings: the knobs set the Depth's rates, the rest is the run's.
    let knobs = sylva::Knobs::default();
    let over = |json: &serde_json::Value, seed| fern.mutate(Settings::KnobsOver(knobs, json), seed);
    let same = serde_json::json!({ "mutation_rate": 0.9, "mutation_spread": 0.9 });
    for seed in 0..4 {
        assert_eq!(
            over(&same, seed).unwrap(),
            fern.mutate(Settings::Knobs(knobs), seed).unwrap()
        );
    }
    // How far the palette moves a genome's fan colours, in bytes of a channel (colours at
    // its edge may move by a unit when it is applied again).
    let off_foliage = |g: &Genome| -> u8 {
        let g = g.get::<sylva_plantmaker::PlantMakerModel>().unwrap();
        let mut kept = g.clone();
        sylva_plantmaker::Palette::Foliage.apply(&mut kept);
        let far = |a: sylva_plantmaker::Rgb, b: sylva_plantmaker::Rgb| {
            (a.0.iter().zip(b.0))
                .map(|(&x, y)| x.abs_diff(y))
                .max()
                .unwrap_or(0)
        };
        (g.fans.iter().zip(&kept.fans))
            .map(|(f, k)| far(f.min_color, k.min_color).max(far(f.max_color, k.max_color)))
            .max()
            .unwrap_or(0)
    };
    let foliage = serde_json::json!({ "palette": "foliage" });
    assert!(
        off_foliage(&fern) > 2,
        "the fern's colours lie outside the palette"
    );
    assert!(off_foliage(&over(&foliage, 1).unwrap()) <= 2);
    let e = over(&serde_json::json!({ "palette": "blue" }), 1).unwrap_err();
    assert!(e.to_string().contains("plantmaker settings"), "{e}");
    // PlantMaker crosses every parent by dominance, at the settings' level.
    let bush = sylva::Registry::standard()
        .load_genome(&example("plantmaker/flowering-bush.json"))
        .unwrap();
    let tulip = sylva::Registry::standard()
        .load_genome(&example("plantmaker/tulip.json"))
        .unwrap();
    let high = serde_json::json!({ "crossover": "high" });
    let (_, parents) = Genome::cross(
        &[(&fern, 1.0), (&bush, 1.0), (&tulip, 1.0)],
        Settings::Json(&high),
        2,
    )
    .unwrap();
    assert!(parents.len() >= 2, "{parents:?}");
}

#[test]
fn a_fifth_model_grows_meshes_and_exports_through_the_trait_alone() {
    use sylva_model::Model;
    use sylva_testkit::toy::Cylinder;
    // The registry line: the standard four and the cylinder (`sylva_testkit::toy`).
    let registry = Registry::standard()
        .clone()
        .with(ModelEntry::of::<Cylinder>());
    let text = r#"{"model": "cylinder", "format": 1, "height": 2.5, "radius": 0.2}"#;
    let genome = registry.parse_genome(text).unwrap();
    assert_eq!(genome.model(), "cylinder");
    assert_eq!(genome.get::<Cylinder>().unwrap().height, 2.5);
    // Its files are checked like any model's: ranges, unknown fields, positions.
    let e = registry
        .parse_genome(r#"{"model": "cylinder", "format": 1, "height": -1, "radius": 0.2}"#)
        .unwrap_err();
    assert!(e.message.contains("`height` must be"), "{}", e.message);
    assert!(
        Registry::standard().parse_genome(text).is_err(),
        "not in the standard list"
    );
    // Grown, meshed and exported as any plant, carrying its origin.
    let grown = Grown::grow(genome.clone(), &seeded(0)).unwrap();
    assert_eq!(grown.plant.segments().len(), 1);
    assert!(grown.mesh.triangle_count() > 0);
    let dir = std::env::temp_dir().join(format!("sylva-cylinder-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let glb = dir.join("cylinder.glb");
    export::write(&grown.scene(), &glb).unwrap();
    sylva_testkit::validate(std::slice::from_ref(&glb));
    let imported = sylva_gltf::import::read_glb(&std::fs::read(&glb).unwrap()).unwrap();
    assert_eq!(imported.scene().nodes.len(), 1);
    let bytes = std::fs::read(&glb).unwrap();
    assert!(String::from_utf8_lossy(&bytes).contains(r#""model":"cylinder""#));
    // Bred by hand like the four.
    let child = genome.mutate(Settings::Default, 1).unwrap();
    assert_eq!(child.model(), Cylinder::NAME);
    let random = registry
        .get("cylinder")
        .unwrap()
        .random(Settings::Default, 2)
        .unwrap();
    let (bred, _) = Genome::cross(&[(&genome, 2.0), (&random, 1.0)], Settings::Default, 3).unwrap();
    assert_eq!(bred.get::<Cylinder>().unwrap().height, 2.5);
    // It evolves through a config file that names a start genome file, read with the same
    // registry; the run checkpoints and resumes exactly.
    std::fs::write(dir.join("start.json"), text).unwrap();
    std::fs::write(
        dir.join("c.toml"),
        "model = \"cylinder\"\n[run]\ngenerations = 12\npopulation = 30\nseed = 4\n\
         [cylinder]\ntarget = 7.0\nstart = [\"start.json\"]\n",
    )
    .unwrap();
    let config = registry.load_config(&dir.join("c.toml")).unwrap();
    assert_eq!(config.model(), "cylinder");
    assert!(
        sylva::Registry::standard()
            .load_config(&dir.join("c.toml"))
            .is_err(),
        "the standard registry does not know it"
    );
    let start = config.load_start(&registry, &dir).unwrap();
    assert_eq!(start, vec![genome.clone()]);
    let pool = || Pool::with_threads(2).unwrap();
    let mut straight = Evolution::start(&config, start.clone(), pool()).unwrap();
    let mut halted = Evolution::start(&config, start, pool()).unwrap();
    for _ in 0..6 {
        halted.step().unwrap();
    }
    let checkpoint = halted.checkpoint().unwrap();
    let mut resumed = Evolution::resume(&config, Path::new("c.json"), &checkpoint, pool()).unwrap();
    for _ in 0..12 {
        straight.step().unwrap();
    }
    for _ in 6..12 {
        resumed.step().unwrap();
    }
    assert_eq!(resumed.best(), straight.best());
    let figures = |run: &Evolution| -> Vec<(u32, f64, f64)> {
        // Everything but the wall-clock seconds.
        run.stats()
            .iter()
            .map(|s| (s.generation, s.best, s.mean))
            .collect()
    };
    assert_eq!(figures(&resumed), figures(&straight));
    let best = straight.best().genome.get::<Cylinder>().unwrap().height;
    assert!((best - 7.0).abs() < 1.0, "evolved towards 7 m: {best}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A model whose every genome scores NaN: no run of it can go anywhere.
mod void {
    use rand::{Rng, RngExt};
    use sylva_core::Plant;
    use sylva_evolve::{Crossover, Fitness, Generational, Mutate, Problem};
    use sylva_model::{
        Bred, ConfigError, DevelopError, Evolve, Model, Parent, Setup, VariationError, plant_meta,
    };

    #[derive(Clone, Copy, Debug, Default)]
    pub struct Void;

    #[derive(Clone, Debug)]
    pub struct Unscorable;

    #[derive(Clone, Copy, Debug)]
    pub struct Keep;

    impl Mutate<u32> for Keep {
        fn mutate<R: Rng + ?Sized>(&self, _: &mut u32, _: &mut R) {}
    }

    impl Crossover<u32> for Keep {
        fn crossover<R: Rng + ?Sized>(&self, a: &u32, _: &u32, _: &mut R) -> u32 {
            *a
        }
    }

    impl Problem for Unscorable {
        type Genome = u32;
        fn term_names(&self) -> Vec<String> {
            vec!["x".into()]
        }
        fn evaluate(&self, _: &u32) -> Fitness {
            Fitness::new(f64::NAN, &[f64::NAN])
        }
        fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> u32 {
            rng.random()
        }
    }

    impl Model for Void {
        type Genome = u32;
        type Settings = ();
        const NAME: &'static str = "void";
        const TITLE: &'static str = "Nothing";

        fn develop(&self, g: &u32, seed: u64) -> Result<Plant, DevelopError> {
            Ok(Plant::new(plant_meta::<Self>(g, seed)))
        }
        fn random<R: Rng + ?Sized>(&self, _: &(), rng: &mut R) -> u32 {
            rng.random()
        }
        fn hand_settings(&self, _: sylva_model::Knobs, _: ()) {}
        fn schema(&self) -> sylva_model::schema::Schema {
            sylva_model::schema::Schema::of(Vec::new())
        }
        fn mutate<R: Rng + ?Sized>(&self, g: &u32, _: &(), _: &mut R) -> u32 {
            *g
        }
        fn cross<R: Rng + ?Sized>(
            &self,
            parents: &[Parent<'_, u32>],
            _: &(),
            _: &mut R,
        ) -> Result<Bred<u32>, VariationError> {
            Ok(Bred {
                genome: *parents[0].genome,
                parents: vec![0],
            })
        }
    }

    impl Evolve for Void {
        type Problem = Unscorable;
        type Strategy = Generational<Keep, Keep>;
        fn setup(&self, _: &(), _: Vec<u32>, _: u64, _: usize) -> Result<Setup<Self>, ConfigError> {
            Ok(Setup {
                problem: Unscorable,
                strategy: Generational::new(Keep, Keep, Default::default())
                    .map_err(|e| ConfigError::new("breeding", e))?,
                first: Vec::new(),
            })
        }
        fn genome_file(&self, _: &Unscorable, g: &u32) -> u32 {
            *g
        }
    }
}

#[test]
fn a_run_that_cannot_score_stops_with_an_error() {
    let config = Config::new(sylva::EvolveConfig::<void::Void>::default());
    let e = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap_err();
    assert!(e.is_input(), "{e}");
    assert!(
        e.to_string()
            .contains("no member of generation 0 has a finite fitness"),
        "{e}"
    );
}

#[test]
fn a_height_scales_the_plant_to_it_and_travels_with_the_asset() {
    for file in [
        "plantmaker/palm.json",
        "bintree/oak.json",
        "lsystem/tree.json",
    ] {
        let genome = sylva::Registry::standard()
            .load_genome(&example(file))
            .unwrap();
        let options = GrowOptions {
            height: Some(7.5),
            ..seeded(0)
        };
        let grown = Grown::grow(genome.clone(), &options).unwrap();
        let top = grown.plant.bounds().max.y;
        assert!((top - 7.5).abs() < 1e-3, "{file}: {top}");
        let mesh_top = grown.mesh.bounds().max.y;
        assert!(mesh_top > 7.0 && mesh_top < 7.6, "{file}: {mesh_top}");
        let extras = grown.scene().nodes[0].extras.clone().unwrap();
        assert_eq!(extras["height"], 7.5, "{file}");
        for bad in [0.0, -2.0, f32::NAN, 5000.0] {
            let options = GrowOptions {
                height: Some(bad),
                ..seeded(0)
            };
            let e = Grown::grow(genome.clone(), &options).err().unwrap();
            assert!(e.to_string().contains("--height"), "{e}");
        }
    }
}

#[test]
fn the_pipe_taper_keeps_the_pipes_and_travels_with_the_asset() {
    let e = 2.5;
    let taper = sylva_core::taper::PipeTaper::new(e).unwrap();
    for file in ["lsystem/tree.json", "automata/helix.json"] {
        let genome = sylva::Registry::standard()
            .load_genome(&example(file))
            .unwrap();
        let options = GrowOptions {
            roots: false,
            ..seeded(0)
        };
        let plain = Grown::grow(genome.clone(), &options).unwrap();
        let tapered = Grown::grow(
            genome,
            &GrowOptions {
                taper: Some(taper),
                ..options
            },
        )
        .unwrap();
        let s = tapered.plant.segments();
        assert_eq!(
            s.len(),
            plain.plant.segments().len(),
            "{file}: the same skeleton"
        );
        // At every fork the pipes add up: r^e of a segment is the sum over its children.
        let mut children = vec![0f64; s.len()];
        let mut twigs = Vec::new();
        let materials = tapered.plant.materials();
        let woody = |seg: &sylva_core::Segment| {
            materials[seg.material.index()].kind == sylva_core::MaterialKind::Bark
        };
        for (i, seg) in s.iter().enumerate().rev().filter(|(_, seg)| woody(seg)) {
            if let Some(p) = seg.parent {
                children[p.index()] += f64::from(seg.start_radius).powf(e);
            }
            if children[i] == 0.0 {
                twigs.push(seg.start_radius);
            } else {
                let own = f64::from(seg.start_radius).powf(e);
                assert!(
                    (own - children[i]).abs() <= 1e-4 * own,
                    "{file}: segment {i}"
                );
            }
        }
        // Every twig has the same radius, and the trunk carries them all.
        assert!(
            twigs.iter().all(|&r| (r - twigs[0]).abs() <= 1e-6 * r),
            "{file}"
        );
        let tips = twigs.len() as f64;
        let trunk = f64::from(s[0].start_radius);
        assert!((trunk - f64::from(twigs[0]) * tips.powf(1.0 / e)).abs() < 1e-4 * trunk);
        let extras = tapered.scene().nodes[0].extras.clone().unwrap();
        assert_eq!(extras["taper"]["pipe_exponent"], e, "{file}");
        assert!(
            plain.scene().nodes[0]
                .extras
                .clone()
                .unwrap()
                .get("taper")
                .is_none()
        );
    }
}
