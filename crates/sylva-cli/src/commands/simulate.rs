//! `sylva simulate`: one of Bornhofen and Lattaud's experiments, its measured outcome as a
//! report, per-step records, and the grown plants as a scene and a picture.

use std::path::PathBuf;

use sylva::assets::picture;
use sylva::files::Outputs;
use sylva::render::View;
use sylva::{Experiment, Registry};

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
pub fn run(models: &Registry, args: &SimulateArgs) -> anyhow::Result<()> {
    let path = &args.config;
    let experiment = Experiment::load(models, path)?;
    let pool = super::pool(args.threads)?;
    let work = experiment.work()?;
    super::announce(
        work.seconds(pool.threads()),
        format_args!("the experiment's {} garden steps", work.steps),
        "lower `max_symbols` and `max_modules` in the genomes' `physiology`, the steps or the \
         world",
    );
    let bar = super::progress_bar(work.steps, "growing: step");
    let result = experiment.run(&pool, &mut |step| bar.set_position(step))?;
    bar.finish_and_clear();
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = path
            .file_stem()
            .map_or("simulation".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("runs").join(stem)
    });
    let mut files = Outputs::new();
    files.create_dir(&out)?;
    files.add(&out.join("report.txt"), result.report.as_bytes())?;
    files.add(&out.join("records.csv"), result.records_csv.as_bytes())?;
    let scene = result.scene.scene();
    files
        .add_scene(&out.join("scene.glb"), &scene)
        .in_file(path)?;
    files.add(
        &out.join("scene.png"),
        &picture(&scene, View::Iso, SCENE_PICTURE)?,
    )?;
    let mut written = "report.txt, records.csv, scene.glb, scene.png".to_owned();
    if let Some(side) = &result.side {
        files.add(
            &out.join("side.png"),
            &picture(&side.scene(), View::Front, SCENE_PICTURE)?,
        )?;
        written.push_str(", side.png");
    }
    files.commit()?;
    print!("{}", result.report);
    println!("wrote {}/{{{written}}}", out.display());
    Ok(())
}
