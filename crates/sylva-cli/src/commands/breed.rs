//! `sylva breed`: one round of Bornhofen and Lattaud's design loop (section 4.1): the mother
//! and her mutated children grow together in one voxel world; a person picks the next
//! mother from the pictures and breeds again.

use std::fmt::Write as _;
use std::path::PathBuf;

use sylva::InputError;
use sylva::Registry;
use sylva::assets::picture;
use sylva::biomorph::{BiomorphOptions, BiomorphSettings, Biomorphs};
use sylva::files::Outputs;
use sylva::mesh::{Scene, SceneNode};
use sylva::render::{self, SheetCell, SheetOptions, View};

use super::{InFile, SCENE_PICTURE};

/// Arguments of `sylva breed`.
#[derive(clap::Args)]
pub struct BreedArgs {
    /// The mother's genome (an L-system genome file).
    mother: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// Children sown with the mother (at most 8: nine specimens in all).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=8))]
    children: u32,
    /// Seed of the mutations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Leave the roots out of the picture and the GLB.
    #[arg(long)]
    hide_roots: bool,
    /// Worker threads; 0 means one per core. Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=1024))]
    threads: u32,
}

/// `sylva breed`.
pub fn run(models: &Registry, args: &BreedArgs) -> anyhow::Result<()> {
    let mother = models.load_genome(&args.mother)?;
    let options = BiomorphOptions {
        settings: BiomorphSettings {
            children: args.children,
            ..BiomorphSettings::default()
        },
        roots: !args.hide_roots,
    };
    let pool = super::pool(args.threads)?;
    let sown = Biomorphs::sow(models, &mother, &args.mother, &options, args.seed)
        .map_err(|e| InputError::file(&args.mother, format!("breeding grows {e}")))?;
    super::announce(
        sown.work().seconds(pool.threads()),
        format_args!("growing {} plants for {} steps", sown.len(), sown.steps()),
        "lower `max_symbols` and `max_modules` in the mother's `physiology`",
    );
    let bar = super::progress_bar(u64::from(sown.steps()), "growing: step");
    let garden = sown.grow(&pool, &mut |step| bar.set_position(u64::from(step)))?;
    bar.finish_and_clear();
    let mut out = Outputs::new();
    out.create_dir(&args.out)?;
    let names: Vec<String> = garden
        .specimens
        .iter()
        .enumerate()
        .map(|(i, s)| match s.is_mother {
            true => "mother".to_owned(),
            false => format!("child-{i}"),
        })
        .collect();
    let assets = garden.assets(
        |i, _| names[i].clone(),
        |_, specimen| specimen.origin(args.seed).extras(),
    )?;

    let mut table =
        String::from("specimen,biomass_g,light,uptake,leaves,fine_roots,germinated,genome\n");
    for (specimen, name) in garden.specimens.iter().zip(&names) {
        let file = format!("{name}.json");
        out.add(&args.out.join(&file), specimen.genome.to_json().as_bytes())?;
        let s = &specimen.stats;
        let _ = writeln!(
            table,
            "{name},{},{},{},{},{},{},{},{file}",
            s.biomass,
            s.light,
            s.uptake,
            s.leaves,
            s.fine_roots,
            s.germinated,
            s.bounds.symbols + s.bounds.modules
        );
    }
    out.add(&args.out.join("specimens.csv"), table.as_bytes())?;
    for (i, specimen) in garden.specimens.iter().enumerate() {
        let b = specimen.stats.bounds;
        if b.any() {
            eprintln!(
                "note: specimen {i} hit a growth bound from step {}: {} rewrites refused by the \
                 symbol limit, {} by the module limit",
                b.first_step.unwrap_or(0),
                b.symbols,
                b.modules
            );
        }
    }
    let scene = assets.scene();
    out.add_scene(&args.out.join("garden.glb"), &scene)
        .in_file(&args.mother)?;
    out.add(
        &args.out.join("garden.png"),
        &picture(&scene, View::Iso, SCENE_PICTURE)?,
    )?;
    let cells: Vec<SheetCell> = assets
        .meshes()
        .iter()
        .zip(&names)
        .zip(&garden.specimens)
        .map(|((mesh, name), specimen)| SheetCell {
            scene: Scene::single(SceneNode::new(name.clone(), mesh)),
            caption: format!("{name} {:.2} g", specimen.stats.biomass),
        })
        .collect();
    let options = SheetOptions {
        title: Some(format!("Mother and {} children", cells.len() - 1)),
        ..SheetOptions::default()
    };
    let sheet = render::contact_sheet(&cells, &options, &pool).map_err(sylva::Error::from)?;
    let sheet = render::encode_png(&sheet).map_err(sylva::Error::from)?;
    out.add(&args.out.join("specimens.png"), &sheet)?;
    out.commit()?;
    print!("{table}");
    println!(
        "wrote {}/{{garden.glb, garden.png, specimens.png, specimens.csv, mother.json, \
         child-*.json}}; pick one and breed it: sylva breed {}/child-N.json --out NEXT",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}
