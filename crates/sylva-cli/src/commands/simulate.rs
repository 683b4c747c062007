//! `sylva simulate`: one of Bornhofen and Lattaud's experiments, its measured outcome as a
//! report, per-step records, and the grown plants as a scene and a picture.

use std::path::{Path, PathBuf};

use sylva::assets::{Origin, Placed, SceneAssets, check_scene_glb, picture};
use sylva::files::{Outputs, read_text};
use sylva::genome::load_genome_of;
use sylva::report::simulation_report;
use sylva::{Genome, InputError};
use sylva_core::glam::{Quat, Vec2, Vec3};
use sylva_core::{MaterialKind, Plant};
use sylva_lsystem::LSystemModel;
use sylva_lsystem::experiments::{LateralLightOutcome, Simulation, SimulationOutcome};
use sylva_lsystem::garden::records_csv;
use sylva_mesh::render::View;
use sylva_model::MeshHint;
use sylva_model::Model;

use super::{InFile, SCENE_PICTURE};

/// Arguments of `sylva simulate`.
#[derive(clap::Args)]
pub struct SimulateArgs {
    /// Experiment config (`[herbs-under-tree]`, `[lateral-light]` or `[empty-rules]`).
    config: PathBuf,
    /// Output directory [default: runs/<config name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Worker threads; 0 means one per core. Results do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=1024))]
    threads: u32,
}

/// `sylva simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let path = &args.config;
    let text = read_text(path)?;
    let simulation: Simulation =
        toml::from_str(&text).map_err(|e| InputError::toml(path, &text, &e))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let genomes = simulation
        .genome_files()
        .iter()
        .map(|file| load_genome_of::<LSystemModel>(&base.join(file), "experiments grow"))
        .collect::<Result<Vec<_>, _>>()?;
    let pool = super::pool(args.threads)?;
    let work = simulation
        .work(&genomes)
        .map_err(|e| InputError::file_error(path, &e))?;
    super::announce(
        work.seconds(pool.threads()),
        format_args!("the experiment's {} garden steps", work.steps),
        "lower `max_symbols` and `max_modules` in the genomes' `physiology`, the steps or the \
         world",
    );
    let bar = super::progress_bar(work.steps, "growing: step");
    let outcome = simulation
        .run_with(&genomes, &pool, &mut |step| bar.set_position(step))
        .map_err(|e| InputError::file_error(path, &e))?;
    bar.finish_and_clear();
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = path
            .file_stem()
            .map_or("simulation".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("runs").join(stem)
    });
    let mut files = Outputs::new();
    files.create_dir(&out)?;
    let report = simulation_report(&outcome);
    files.add(&out.join("report.txt"), report.as_bytes())?;
    files.add(
        &out.join("records.csv"),
        records_csv(outcome.records()).as_bytes(),
    )?;
    let hint = LSystemModel.mesh_hint();
    let placed: Vec<Placed> = outcome
        .plants()
        .iter()
        .map(|p| {
            // Each plant grew in a shared world; its genome and seed regrow it alone.
            let mut extras = Origin::of(&Genome::new(LSystemModel, p.genome.clone()), 0).extras();
            extras["biomass_g"] = p.biomass.into();
            Placed {
                translation: p.position,
                extras: Some(extras),
                ..Placed::new(p.label.clone(), &p.plant, hint)
            }
        })
        .collect();
    check_scene_glb(
        &placed,
        false,
        path,
        "grow smaller plants (lower `max_modules` in the genomes' `physiology`)",
    )?;
    let assets = SceneAssets::mesh(&placed, None).in_file(path)?;
    let scene = assets.scene();
    files
        .add_scene(&out.join("scene.glb"), &scene)
        .in_file(path)?;
    files.add(
        &out.join("scene.png"),
        &picture(&scene, View::Iso, SCENE_PICTURE)?,
    )?;
    let mut written = "report.txt, records.csv, scene.glb, scene.png".to_owned();
    if let SimulationOutcome::LateralLight(o) = &outcome {
        files.add(&out.join("side.png"), &side_picture(o, hint, path)?)?;
        written.push_str(", side.png");
    }
    files.commit()?;
    print!("{report}");
    println!("wrote {}/{{{written}}}", out.display());
    Ok(())
}

/// `side.png`: tree 1 under lateral light (left) beside tree 1 under vertical light
/// (right), at one scale, roots left out, seen across the light: both are turned so that the
/// lateral light comes from +X, the right of a front view, and set apart by their reach.
fn side_picture(o: &LateralLightOutcome, hint: MeshHint, config: &Path) -> anyhow::Result<Vec<u8>> {
    let t = o.towards_light;
    let turn = Quat::from_rotation_y(t.y.atan2(t.x));
    let lateral = o.plants[0].plant.without(MaterialKind::Root);
    let vertical = o.control[0].plant.without(MaterialKind::Root);
    let reach = |p: &Plant| {
        p.segments()
            .iter()
            .map(|s| Vec2::new(s.end.x, s.end.z).length())
            .fold(0.0, f32::max)
    };
    let gap = 0.25;
    let placed = [
        ("lateral light", &lateral, -(reach(&lateral) + gap)),
        ("vertical light", &vertical, reach(&vertical) + gap),
    ]
    .map(|(name, plant, x)| Placed {
        translation: Vec3::new(x, 0.0, 0.0),
        rotation: turn,
        ..Placed::new(name, plant, hint)
    });
    let assets = SceneAssets::mesh(&placed, None).in_file(config)?;
    Ok(picture(&assets.scene(), View::Front, SCENE_PICTURE)?)
}
