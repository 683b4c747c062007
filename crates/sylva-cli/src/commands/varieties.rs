//! `sylva evolve` of a config with `[run] strategy = "map-elites"`: a map of varieties,
//! with a progress bar, checkpoints while it runs, and the map's files when it ends.

use std::fmt::Write as _;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use sylva::core::par::Pool;
use sylva::files::Outputs;
use sylva::render::map::{MapAxis, MapPicture, map_picture};
use sylva::report::map_stats_csv;
use sylva::{Config, GrowOptions, Grown, InputError, Registry, Varieties, Variety};

use super::run_files::{CHECKPOINT, add_best};

/// Every file a map run writes in its folder (and `archive/cell-N.json`, one per elite).
pub(super) const FILES: [&str; 8] = [
    CHECKPOINT,
    "config.toml",
    "stats.csv",
    "archive.csv",
    "archive.png",
    "best.json",
    "best.glb",
    "best.png",
];

/// Runs the map of `config` into `out` (resuming its checkpoint if `resume`).
pub(super) fn run(
    models: &Registry,
    config: &Config,
    out: &Path,
    start_base: &Path,
    resume: bool,
    pool: &Pool,
) -> anyhow::Result<()> {
    let checkpoint = out.join(CHECKPOINT);
    let mut map = if resume {
        let text = sylva::files::read_text(&checkpoint)?;
        Varieties::resume(config, &checkpoint, &text, pool.clone())?
    } else {
        let start = config.load_start(models, start_base)?;
        Varieties::start(config, start, pool.clone())?
    };
    sylva::files::create_dir(out)?;
    sylva::files::remove_leftovers(out, &FILES);
    fill(&mut map, config, &checkpoint)?;
    write_results(&map, config, out, pool)
}

/// Breeds up to the config's generation, showing progress and checkpointing as it goes.
fn fill(map: &mut Varieties, config: &Config, checkpoint: &Path) -> anyhow::Result<()> {
    let target = config.run().generations;
    let bar = ProgressBar::new(u64::from(target))
        .with_style(
            ProgressStyle::with_template(
                "{spinner} generation {pos}/{len} {bar:30} {msg} ({elapsed}, eta {eta})",
            )
            .expect("the template is valid"),
        )
        .with_position(u64::from(map.generation().min(target)));
    let mut checkpoints = super::Checkpoints::new(checkpoint, config.run().checkpoint_seconds);
    let cells = map.cells();
    while map.generation() < target {
        let s = map.step();
        bar.set_message(format!(
            "{}/{cells} cells filled, QD-score {:.4}",
            s.filled, s.qd_score
        ));
        bar.set_position(u64::from(s.generation));
        checkpoints.due(|| map.checkpoint())?;
    }
    checkpoints.save(|| map.checkpoint())?;
    bar.finish_and_clear();
    Ok(())
}

/// The genome file of a cell's elite, relative to the run folder.
fn genome_file(cell: usize) -> String {
    format!("archive/cell-{cell}.json")
}

/// `archive.csv`: a row per elite: its cell, its place along each axis, its descriptors,
/// fitness and terms, and its genome file.
fn archive_csv(map: &Varieties, varieties: &[Variety]) -> String {
    let names: Vec<&str> = map.descriptors().iter().map(|d| d.name()).collect();
    let mut out = String::from("cell");
    for name in &names {
        let _ = write!(out, ",{name}_cell");
    }
    for name in &names {
        let _ = write!(out, ",{name}");
    }
    out.push_str(",fitness");
    for term in map.term_names() {
        let _ = write!(out, ",{term}");
    }
    out.push_str(",id,genome\n");
    for v in varieties {
        let _ = write!(out, "{}", v.cell);
        for c in &v.coordinates {
            let _ = write!(out, ",{c}");
        }
        for d in &v.descriptors {
            let _ = write!(out, ",{d}");
        }
        let _ = write!(out, ",{}", v.member.total());
        let terms = v
            .member
            .fitness
            .map(|f| f.terms().to_vec())
            .unwrap_or_default();
        for i in 0..map.term_names().len() {
            match terms.get(i) {
                Some(t) => {
                    let _ = write!(out, ",{t}");
                }
                None => out.push(','),
            }
        }
        let _ = writeln!(out, ",{},{}", v.member.id.0, genome_file(v.cell));
    }
    out
}

/// `archive.png`: the map, a thumbnail per filled cell. A map of three axes shows, in
/// each cell of the first two, the fittest elite along the third.
fn archive_png(
    map: &Varieties,
    varieties: &[Variety],
    config: &Config,
    pool: &Pool,
) -> anyhow::Result<Vec<u8>> {
    let axes = map.axes();
    let names = map.descriptors();
    let axis = |i: usize| MapAxis {
        name: names[i].name().to_owned(),
        min: axes[i].min,
        max: axes[i].max,
        cells: axes[i].cells,
    };
    let picture_options = MapPicture {
        x: axis(0),
        y: (axes.len() > 1).then(|| axis(1)),
        title: format!(
            "{}: {} of {} cells filled, generation {}",
            map.title(),
            varieties.len(),
            map.cells(),
            map.generation()
        ),
        ..MapPicture::default()
    };
    let columns = axes[0].cells as usize;
    let rows = axes.get(1).map_or(1, |a| a.cells as usize);
    // The elite shown in each cell of the picture.
    let mut shown: Vec<Option<&Variety>> = vec![None; columns * rows];
    for v in varieties {
        let at =
            v.coordinates[0] as usize + v.coordinates.get(1).map_or(0, |&y| y as usize) * columns;
        if shown[at].is_none_or(|s| v.member.total() > s.member.total()) {
            shown[at] = Some(v);
        }
    }
    // Roots are below the ground: a thumbnail framed on them shows a small shoot.
    let options = GrowOptions {
        taper: config.output().pipe_taper(),
        roots: false,
        ..GrowOptions::default()
    };
    let grown: Vec<Option<Grown>> = shown
        .iter()
        .map(|v| {
            v.map(|v| Grown::grow(v.member.genome.clone(), &options))
                .transpose()
        })
        .collect::<Result<_, _>>()?;
    let scenes: Vec<_> = grown.iter().map(|g| g.as_ref().map(Grown::scene)).collect();
    let image = map_picture(&scenes, &picture_options, pool).map_err(sylva::Error::from)?;
    Ok(sylva::render::encode_png(&image).map_err(sylva::Error::from)?)
}

/// Writes the config, statistics, archive (table, genomes, picture) and the best elite
/// with its asset and picture, all or none; genome files of cells no longer filled (from
/// an earlier run in the folder) go.
fn write_results(map: &Varieties, config: &Config, out: &Path, pool: &Pool) -> anyhow::Result<()> {
    let varieties = map.varieties();
    let best = map
        .best()
        .ok_or_else(|| InputError::new("[map]", "no plant could be placed in the map"))?;
    let mut files = Outputs::new();
    let effective = map.config();
    files.add(&out.join("config.toml"), effective.to_toml().as_bytes())?;
    files.add(
        &out.join("stats.csv"),
        map_stats_csv(map.stats()).as_bytes(),
    )?;
    files.add(
        &out.join("archive.csv"),
        archive_csv(map, &varieties).as_bytes(),
    )?;
    files.create_dir(&out.join("archive"))?;
    for v in &varieties {
        files.add(
            &out.join(genome_file(v.cell)),
            v.member.genome.to_json().as_bytes(),
        )?;
    }
    files.add(
        &out.join("archive.png"),
        &archive_png(map, &varieties, config, pool)?,
    )?;
    add_best(&mut files, out, &best.member.genome, config, map.guides())?;
    files.commit()?;
    remove_stale_cells(out, &varieties);

    let last = map
        .stats()
        .last()
        .ok_or_else(|| InputError::new("run", "no statistics"))?;
    let evaluations: u64 = map.stats().iter().map(|s| s.evaluations).sum();
    let seconds: f64 = map.stats().iter().map(|s| s.seconds).sum();
    println!(
        "generation {}: {} of {} cells filled ({:.1}%), QD-score {:.4}, best fitness {:.4} \
         (cell {}); {} evaluations, {:.0}/s",
        last.generation,
        last.filled,
        map.cells(),
        100.0 * last.coverage,
        last.qd_score,
        last.best,
        best.cell,
        evaluations,
        evaluations as f64 / seconds.max(1e-9),
    );
    println!(
        "wrote {}/{{archive.png, archive.csv, archive/ ({} genomes), stats.csv, best.json, \
         best.glb, best.png, config.toml, checkpoint.json}}",
        out.display(),
        varieties.len()
    );
    Ok(())
}

/// Removes `archive/cell-N.json` files of cells the map does not hold.
fn remove_stale_cells(out: &Path, varieties: &[Variety]) {
    let Ok(entries) = std::fs::read_dir(out.join("archive")) else {
        return;
    };
    let kept: std::collections::HashSet<String> = varieties
        .iter()
        .map(|v| format!("cell-{}.json", v.cell))
        .collect();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with("cell-") && name.ends_with(".json") && !kept.contains(&name) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}
