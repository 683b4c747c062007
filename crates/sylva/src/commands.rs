//! The commands behind `sylva evolve`, `sylva grow` and `sylva render`.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::genome::Genome;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use sylva_core::io::write_atomic;
use sylva_evolve::{Checkpoint, Pool, Run, RunSettings, Strategy};
use sylva_mesh::render::{self, SheetCell, SheetOptions, View};

use crate::assets::{
    Grown, asset_format, check_png, genome_from_text, load_genome, mesh_all, mesh_options,
    origin_extras, write_picture,
};

/// Size of pictures of whole scenes (gardens, experiments): wide, for a plot of plants.
const SCENE_PICTURE: (u32, u32) = (1200, 800);
use crate::config::{EvolveConfig, ModelName, read_text};
use crate::error::InputError;
use crate::problem::{
    AutomataProblem, BinTreeProblem, ModelProblem, PlantMakerProblem, automata_strategy,
    lsystem_run, plantmaker_strategy, strategy,
};
use crate::report::{fitness_svg, stats_csv};

/// Arguments of `sylva evolve`; `None` keeps the config's value.
#[derive(Clone, Debug, Default)]
pub struct EvolveArgs {
    /// Config file; `None` runs the built-in default.
    pub config: Option<PathBuf>,
    /// Run directory; `None` is `runs/<model>-seed<seed>`.
    pub out: Option<PathBuf>,
    /// Overrides `run.generations`.
    pub generations: Option<u32>,
    /// Overrides `run.population`.
    pub population: Option<u32>,
    /// Overrides `run.seed`.
    pub seed: Option<u64>,
    /// Overrides `run.threads`.
    pub threads: Option<u32>,
    /// Continue from the run directory's checkpoint.
    pub resume: bool,
}

/// The checkpoint file: the effective config and the engine's checkpoint.
#[derive(Serialize, Deserialize)]
#[serde(bound(serialize = "G: Serialize", deserialize = "G: Deserialize<'de>"))]
struct SavedRun<G> {
    config: EvolveConfig,
    checkpoint: Checkpoint<G>,
}

const CHECKPOINT: &str = "checkpoint.json";

/// `sylva evolve`.
pub fn evolve(args: &EvolveArgs) -> anyhow::Result<()> {
    let mut config = match &args.config {
        Some(path) => EvolveConfig::load(path)?,
        None => EvolveConfig::default(),
    };
    let run = &mut config.run;
    run.generations = args.generations.unwrap_or(run.generations);
    run.population = args.population.unwrap_or(run.population);
    run.seed = args.seed.unwrap_or(run.seed);
    run.threads = args.threads.unwrap_or(run.threads);
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "runs/{}-seed{}",
            config.model.name(),
            config.run.seed
        ))
    });
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    match config.model {
        ModelName::BinTree => {
            let problem = BinTreeProblem::new(&config.bintree);
            let strategy = strategy(&config.bintree);
            evolve_problem(&config, &out, args.resume, problem, strategy, Vec::new())
        }
        ModelName::PlantMaker => {
            let problem = PlantMakerProblem::new(&config.plantmaker);
            let strategy = plantmaker_strategy(&config.plantmaker).map_err(|e| {
                InputError::new(config_name(args), format!("[plantmaker.breeding]: {e}"))
            })?;
            let base = args
                .config
                .as_ref()
                .and_then(|p| p.parent())
                .unwrap_or(Path::new("."));
            let start = plantmaker_start(&config, base)?;
            evolve_problem(&config, &out, args.resume, problem, strategy, start)
        }
        ModelName::LSystem => {
            let base = args
                .config
                .as_ref()
                .and_then(|p| p.parent())
                .unwrap_or(Path::new("."));
            let start = match &config.lsystem.start {
                Some(file) => match load_genome(&base.join(file))? {
                    Genome::LSystem(g) => *g,
                    other => {
                        return Err(InputError::new(
                            base.join(file).display().to_string(),
                            format!(
                                "`start` must be an L-system genome, not `{}`",
                                other.model()
                            ),
                        )
                        .into());
                    }
                },
                None => sylva_lsystem::LSystemGenome::empty(),
            };
            let (problem, strategy) = lsystem_run(&config.lsystem, start).map_err(|e| {
                InputError::new(config_name(args), format!("[lsystem.breeding]: {e}"))
            })?;
            evolve_problem(&config, &out, args.resume, problem, strategy, Vec::new())
        }
        ModelName::Automata => {
            let problem = AutomataProblem::new(&config.automata);
            let strategy = automata_strategy(&problem, &config.automata).map_err(|e| {
                InputError::new(config_name(args), format!("[automata.breeding]: {e}"))
            })?;
            evolve_problem(&config, &out, args.resume, problem, strategy, Vec::new())
        }
    }
}

/// The first generation of a PlantMaker run: each start genome, then mutants of them in turn.
fn plantmaker_start(
    config: &EvolveConfig,
    base: &Path,
) -> anyhow::Result<Vec<sylva_plantmaker::PlantMaker>> {
    use sylva_evolve::Mutate;
    let pm = &config.plantmaker;
    let mut chosen = Vec::new();
    for file in &pm.start {
        let path = base.join(file);
        match load_genome(&path)? {
            Genome::PlantMaker(g) => chosen.push(*g),
            other => {
                return Err(InputError::new(
                    path.display().to_string(),
                    format!(
                        "`start` genomes must be PlantMaker genomes, not `{}`",
                        other.model()
                    ),
                )
                .into());
            }
        }
    }
    if chosen.is_empty() {
        return Ok(chosen);
    }
    let mutation = sylva_plantmaker::Mutation {
        rate: pm.mutation_rate,
        spread: pm.mutation_spread,
    };
    let mut rng = sylva_core::rng::stream(config.run.seed, 0, u32::MAX);
    let mut start = chosen.clone();
    while start.len() < config.run.population as usize {
        let mut g = chosen[start.len() % chosen.len()].clone();
        mutation.mutate(&mut g, &mut rng);
        start.push(g);
    }
    Ok(start)
}

/// How to name the config in an error: its path, or "config" for the built-in one.
fn config_name(args: &EvolveArgs) -> String {
    args.config
        .as_ref()
        .map_or("config".into(), |p| p.display().to_string())
}

/// The parts of a config that must match for a run to resume (everything but the length of
/// the run, the thread count and the checkpoint interval).
fn resumable(config: &EvolveConfig) -> EvolveConfig {
    let mut c = config.clone();
    c.run.generations = 0;
    c.run.threads = 0;
    c.run.checkpoint_seconds = 0.0;
    c
}

/// Runs (or resumes) an evolution and writes every result file.
fn evolve_problem<P, S>(
    config: &EvolveConfig,
    out: &Path,
    resume: bool,
    problem: P,
    strategy: S,
    start: Vec<P::Genome>,
) -> anyhow::Result<()>
where
    P: ModelProblem + Clone,
    P::Genome: Serialize + for<'de> Deserialize<'de>,
    S: Strategy<P>,
{
    let pool =
        Pool::with_threads(config.run.threads as usize).context("starting the worker threads")?;
    let checkpoint_path = out.join(CHECKPOINT);
    let mut run: Run<P, S> = if resume {
        let text = read_text(&checkpoint_path)?;
        let saved: SavedRun<P::Genome> = serde_json::from_str(&text).map_err(|e| {
            InputError::at(&checkpoint_path, &text, e.line(), e.column(), e.to_string())
        })?;
        if resumable(&saved.config) != resumable(config) {
            return Err(InputError::new(
                checkpoint_path.display().to_string(),
                "the checkpoint was written by a different config (only `generations`, `threads` and \
                 `checkpoint_seconds` may change when resuming)",
            )
            .into());
        }
        Run::resume(problem.clone(), strategy, pool.clone(), saved.checkpoint)
            .map_err(|e| InputError::new(checkpoint_path.display().to_string(), e.to_string()))?
    } else {
        let settings = RunSettings {
            seed: config.run.seed,
            population: config.run.population as usize,
            keep_history: 0,
        };
        Run::with_genomes(problem.clone(), strategy, pool.clone(), settings, start)?
    };

    let target = config.run.generations;
    let bar = ProgressBar::new(u64::from(target)).with_style(
        ProgressStyle::with_template(
            "{spinner} generation {pos}/{len} {bar:30} best {msg} ({per_sec}, eta {eta})",
        )
        .expect("the template is valid"),
    );
    bar.set_position(u64::from(run.generation().min(target)));
    let save = |run: &Run<P, S>| -> anyhow::Result<()> {
        let saved = SavedRun {
            config: config.clone(),
            checkpoint: run.checkpoint(),
        };
        write_atomic(&checkpoint_path, &serde_json::to_vec(&saved)?)
            .with_context(|| format!("writing {}", checkpoint_path.display()))
    };
    let checkpoint_every = Duration::from_secs_f64(config.run.checkpoint_seconds);
    let mut last_save = Instant::now();
    while run.generation() < target {
        let stats = run.step();
        bar.set_message(format!("{:.4}", stats.best));
        bar.set_position(u64::from(run.generation()));
        if last_save.elapsed() >= checkpoint_every {
            save(&run)?;
            last_save = Instant::now();
        }
    }
    save(&run)?;
    bar.finish_and_clear();

    // Results.
    let write = |name: &str, bytes: &[u8]| -> anyhow::Result<()> {
        let path = out.join(name);
        write_atomic(&path, bytes).with_context(|| format!("writing {}", path.display()))
    };
    write("config.toml", config.to_toml().as_bytes())?;
    write(
        "stats.csv",
        stats_csv(run.term_names(), run.stats()).as_bytes(),
    )?;
    let title = format!("{}, seed {}", problem.title(), config.run.seed);
    write("fitness.svg", fitness_svg(run.stats(), &title)?.as_bytes())?;
    let best = run.best();
    let genome = problem.genome_file(&best.genome);
    write("best.json", genome.to_json().as_bytes())?;
    let seed = genome.default_seed();
    let grown = Grown::new(genome, seed)?;
    grown.export(&out.join("best.glb"))?;
    let size = config.output.image_size;
    let guides = match problem.guides() {
        Some(plant) => Some(guide_mesh(&plant)?),
        None => None,
    };
    grown.picture_with(
        &out.join("best.png"),
        config.output.view,
        (size, size),
        guides.as_ref(),
    )?;
    population_sheet(
        &run,
        &pool,
        &problem,
        config.output.sheet_size as usize,
        &out.join("population.png"),
    )?;

    let last = run.stats().last().expect("a run has statistics");
    let total_evals: u64 = run.stats().iter().map(|s| s.evaluations).sum();
    let seconds: f64 = run.stats().iter().map(|s| s.seconds).sum();
    println!(
        "generation {}: best fitness {:.4} (individual #{}), mean {:.4}; {} evaluations, {:.0}/s",
        last.generation,
        last.best,
        last.best_id.0,
        last.mean,
        total_evals,
        total_evals as f64 / seconds.max(1e-9),
    );
    println!(
        "best plant: {} segments, {} organs, {} triangles; wrote {}/{{stats.csv, best.json, best.glb, best.png, fitness.svg, population.png, config.toml, checkpoint.json}}",
        grown.plant.segments().len(),
        grown.plant.organs().len(),
        grown.mesh.triangle_count(),
        out.display()
    );
    Ok(())
}

/// Meshes guide wires thinly.
fn guide_mesh(plant: &sylva_core::Plant) -> anyhow::Result<sylva_mesh::Mesh> {
    let options = sylva_mesh::mesher::MeshOptions {
        radial_segments: 4,
        cap_ends: false,
        ..Default::default()
    };
    sylva_mesh::mesher::mesh_plant(plant, &options).context("meshing the guides")
}

/// A contact sheet of the best `count` members of the current population.
fn population_sheet<P: ModelProblem, S: Strategy<P>>(
    run: &Run<P, S>,
    pool: &Pool,
    problem: &P,
    count: usize,
    path: &Path,
) -> anyhow::Result<()> {
    let mut order: Vec<usize> = (0..run.population().len()).collect();
    let pop = run.population();
    order.sort_by(|&a, &b| pop[b].total().total_cmp(&pop[a].total()).then(a.cmp(&b)));
    order.truncate(count);
    let grown = order
        .iter()
        .map(|&i| {
            let genome = problem.genome_file(&pop[i].genome);
            let seed = genome.default_seed();
            Grown::new(genome, seed)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let cells: Vec<SheetCell> = order
        .iter()
        .zip(&grown)
        .map(|(&i, g)| SheetCell {
            scene: g.scene(),
            caption: format!("#{} {:.3}", pop[i].id.0, pop[i].total()),
        })
        .collect();
    let options = SheetOptions {
        title: Some(format!(
            "Generation {}: best {} of {}",
            run.generation(),
            cells.len(),
            pop.len()
        )),
        ..SheetOptions::default()
    };
    let image =
        render::contact_sheet(&cells, &options, pool).context("drawing the contact sheet")?;
    render::write_png(path, &image).with_context(|| format!("writing {}", path.display()))
}

/// Arguments of `sylva grow`.
#[derive(Clone, Debug)]
pub struct GrowArgs {
    /// Genome JSON.
    pub genome: PathBuf,
    /// Asset to write (.glb, .obj or .wrl).
    pub output: PathBuf,
    /// Optional picture.
    pub png: Option<PathBuf>,
    /// Seed of the model's random choices; `None` is the genome's default.
    pub seed: Option<u64>,
    /// Leave the roots out.
    pub hide_roots: bool,
}

/// `sylva grow`.
pub fn grow(args: &GrowArgs) -> anyhow::Result<()> {
    asset_format(&args.output)?;
    if let Some(png) = &args.png {
        check_png(png)?;
    }
    let genome = load_genome(&args.genome)?;
    let seed = args.seed.unwrap_or_else(|| genome.default_seed());
    let grown = Grown::with_roots(genome, seed, !args.hide_roots)?;
    grown.export(&args.output)?;
    if let Some(png) = &args.png {
        grown.picture(png, View::Iso, (800, 800))?;
    }
    println!(
        "wrote {}: {} segments, {} organs, {} vertices, {} triangles",
        args.output.display(),
        grown.plant.segments().len(),
        grown.plant.organs().len(),
        grown.mesh.vertex_count(),
        grown.mesh.triangle_count()
    );
    Ok(())
}

/// Arguments of `sylva render`.
#[derive(Clone, Debug)]
pub struct RenderArgs {
    /// Genome JSON or GLB.
    pub file: PathBuf,
    /// PNG to write.
    pub output: PathBuf,
    /// Camera.
    pub view: View,
    /// Width and height.
    pub size: (u32, u32),
    /// Seed for genomes; `None` is the genome's default.
    pub seed: Option<u64>,
    /// Leave the roots out (genomes only).
    pub hide_roots: bool,
}

/// `sylva render`: a genome is grown and pictured; a GLB is read and pictured as it is.
pub fn render(args: &RenderArgs) -> anyhow::Result<()> {
    check_png(&args.output)?;
    let is_glb = args
        .file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if is_glb {
        let shown = args.file.display().to_string();
        let bytes = std::fs::read(&args.file)
            .map_err(|e| InputError::new(&shown, format!("cannot read: {e}")))?;
        let imported = sylva_mesh::import::read_glb(&bytes)
            .map_err(|e| InputError::new(&shown, e.to_string()))?;
        write_picture(&imported.scene(), &args.output, args.view, args.size)?;
    } else {
        let genome = load_genome(&args.file)?;
        let seed = args.seed.unwrap_or_else(|| genome.default_seed());
        let grown = Grown::with_roots(genome, seed, !args.hide_roots)?;
        grown.picture(&args.output, args.view, args.size)?;
    }
    println!("wrote {}", args.output.display());
    Ok(())
}

/// Arguments of `sylva garden`.
#[derive(Clone, Debug)]
pub struct GardenArgs {
    /// Genome files, or one garden file.
    pub inputs: Vec<PathBuf>,
    /// Plants per genome.
    pub count: u32,
    /// Plot width and depth, metres.
    pub area: (f64, f64),
    /// Seed of seeds, positions and turns.
    pub seed: u64,
    /// Scene to write.
    pub output: PathBuf,
    /// Optional picture.
    pub png: Option<PathBuf>,
}

/// `sylva garden`: grows a garden file, or plants genomes into a new one, and writes the
/// scene (one node per plant, each carrying its genome and seed) and the garden file.
pub fn garden(args: &GardenArgs) -> anyhow::Result<()> {
    use sylva_plantmaker::Garden;
    asset_format(&args.output)?;
    if let Some(png) = &args.png {
        check_png(png)?;
    }
    let shown = |p: &Path| p.display().to_string();
    let first = &args.inputs[0];
    let text = read_text(first)?;
    #[derive(Deserialize)]
    struct Header {
        model: String,
    }
    let is_garden =
        serde_json::from_str::<Header>(&text).is_ok_and(|h| h.model == "plantmaker-garden");
    let garden = if is_garden {
        if args.inputs.len() > 1 {
            return Err(InputError::new(
                shown(first),
                "a garden file is grown on its own; give either one garden file or genome files",
            )
            .into());
        }
        Garden::from_json(&text)
            .map_err(|e| InputError::at(first, &text, e.line, e.column, e.message))?
    } else {
        let mut garden: Option<Garden> = None;
        for (i, path) in args.inputs.iter().enumerate() {
            // The first file is already read.
            let genome = if i == 0 {
                genome_from_text(path, &text)?
            } else {
                load_genome(path)?
            };
            let genome = match genome {
                Genome::PlantMaker(g) => *g,
                other => {
                    return Err(InputError::new(
                        shown(path),
                        format!(
                            "gardens grow PlantMaker genomes; this is a `{}` genome",
                            other.model()
                        ),
                    )
                    .into());
                }
            };
            match &mut garden {
                Some(g) => g.add(genome, args.count as usize),
                None => {
                    garden = Some(Garden::new(
                        genome,
                        args.count as usize,
                        [args.area.0, args.area.1],
                        args.seed,
                    ))
                }
            }
        }
        garden.expect("clap requires at least one input")
    };
    let grown = garden
        .grow()
        .map_err(|e| InputError::new(shown(first), e.to_string()))?;
    let meshes = mesh_all(&grown.plants, &mesh_options(sylva_plantmaker::MODEL))?;
    let mut scene = sylva_mesh::Scene::default();
    for ((placement, mesh), i) in grown.placements.iter().zip(&meshes).zip(0..) {
        let genome = &garden.plants[placement.group].genome;
        let mut node = sylva_mesh::SceneNode::new(format!("plant-{i}"), mesh);
        node.translation = placement.translation;
        node.rotation = placement.rotation();
        node.extras = Some(origin_extras(serde_json::to_value(genome)?, placement.seed));
        scene.nodes.push(node);
    }
    sylva_mesh::export::write_scene(&args.output, &scene)
        .with_context(|| format!("writing {}", args.output.display()))?;
    if !is_garden {
        let garden_path = args.output.with_extension("garden.json");
        write_atomic(&garden_path, garden.to_json().as_bytes())
            .with_context(|| format!("writing {}", garden_path.display()))?;
        println!("wrote {}", garden_path.display());
    }
    if let Some(png) = &args.png {
        write_picture(&scene, png, View::Iso, SCENE_PICTURE)?;
    }
    println!(
        "wrote {}: {} plants, {} triangles",
        args.output.display(),
        scene.nodes.len(),
        scene.triangle_count()
    );
    Ok(())
}

/// `sylva simulate`: runs an L-system experiment and writes its report, per-step records,
/// the grown garden as a GLB and a picture.
pub fn simulate(config: &Path, out: Option<&Path>) -> anyhow::Result<()> {
    use sylva_lsystem::experiments::Simulation;
    let text = read_text(config)?;
    let simulation: Simulation = toml::from_str(&text).map_err(|e| match e.span() {
        Some(span) => InputError::spanned(config, &text, span, e.message().to_owned()),
        None => InputError::new(config.display().to_string(), e.message().to_owned()),
    })?;
    let out = out.map(Path::to_path_buf).unwrap_or_else(|| {
        let stem = config
            .file_stem()
            .map_or("simulation".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from("runs").join(stem)
    });
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let base = config.parent().unwrap_or(Path::new("."));
    let genomes = simulation
        .genome_files()
        .iter()
        .map(|file| match load_genome(&base.join(file))? {
            Genome::LSystem(g) => Ok(*g),
            other => Err(InputError::new(
                base.join(file).display().to_string(),
                format!(
                    "experiments grow L-system genomes; this is a `{}` genome",
                    other.model()
                ),
            )
            .into()),
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let pool = Pool::with_threads(0).context("starting the worker threads")?;
    let outcome = simulation
        .run(&genomes, &pool)
        .map_err(|e| InputError::new(config.display().to_string(), e.to_string()))?;
    let report = crate::report::simulation_report(&outcome);
    let write = |name: &str, bytes: &[u8]| -> anyhow::Result<()> {
        let path = out.join(name);
        write_atomic(&path, bytes).with_context(|| format!("writing {}", path.display()))
    };
    write("report.txt", report.as_bytes())?;
    write(
        "records.csv",
        sylva_lsystem::garden::records_csv(outcome.records()).as_bytes(),
    )?;
    let meshes = mesh_all(
        outcome.plants().iter().map(|p| &p.plant),
        &mesh_options(sylva_lsystem::genome::MODEL),
    )?;
    let mut scene = sylva_mesh::Scene::default();
    for (placed, mesh) in outcome.plants().iter().zip(&meshes) {
        let mut node = sylva_mesh::SceneNode::new(placed.label.clone(), mesh);
        node.translation = placed.position;
        node.extras = Some(serde_json::json!({
            "biomass_g": placed.biomass,
            "sylva_version": env!("CARGO_PKG_VERSION"),
        }));
        scene.nodes.push(node);
    }
    sylva_mesh::export::write_scene(&out.join("scene.glb"), &scene).context("writing scene.glb")?;
    write_picture(&scene, &out.join("scene.png"), View::Iso, SCENE_PICTURE)?;
    print!("{report}");
    println!(
        "wrote {}/{{report.txt, records.csv, scene.glb, scene.png}}",
        out.display()
    );
    Ok(())
}

/// `sylva breed`: one round of the paper's design loop.
pub fn breed(
    mother: &Path,
    out: &Path,
    children: usize,
    seed: u64,
    hide_roots: bool,
) -> anyhow::Result<()> {
    use sylva_lsystem::breed::{BreedSettings, breed_garden};
    let genome = match load_genome(mother)? {
        Genome::LSystem(g) => *g,
        other => {
            return Err(InputError::new(
                mother.display().to_string(),
                format!(
                    "breeding grows L-system genomes; this is a `{}` genome",
                    other.model()
                ),
            )
            .into());
        }
    };
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let settings = BreedSettings {
        children,
        ..BreedSettings::default()
    };
    let mut rng = sylva_core::rng::seeded(seed);
    let pool = Pool::with_threads(0).context("starting the worker threads")?;
    let garden = breed_garden(&genome, &settings, &mut rng, &pool)
        .map_err(|e| InputError::new(mother.display().to_string(), e.to_string()))?;
    let shown = |p: &sylva_core::Plant| {
        if hide_roots {
            p.without(sylva_core::MaterialKind::Root)
        } else {
            p.clone()
        }
    };
    let plants: Vec<sylva_core::Plant> = garden.specimens.iter().map(|s| shown(&s.plant)).collect();
    let meshes = mesh_all(&plants, &mesh_options(sylva_lsystem::genome::MODEL))?;
    let mut scene = sylva_mesh::Scene::default();
    let mut cells = Vec::new();
    let mut table =
        String::from("specimen,biomass_g,light,uptake,leaves,fine_roots,germinated,genome\n");
    for (i, (specimen, mesh)) in garden.specimens.iter().zip(&meshes).enumerate() {
        let name = if specimen.is_mother {
            "mother".to_owned()
        } else {
            format!("child-{i}")
        };
        let file = format!("{name}.json");
        write_atomic(&out.join(&file), specimen.genome.to_json().as_bytes())
            .with_context(|| format!("writing {file}"))?;
        let mut node = sylva_mesh::SceneNode::new(name.clone(), mesh);
        node.translation =
            sylva_core::glam::Vec3::new(specimen.position.x, 0.0, specimen.position.y);
        node.extras = Some(origin_extras(serde_json::to_value(&specimen.genome)?, seed));
        scene.nodes.push(node);
        cells.push(SheetCell {
            scene: sylva_mesh::Scene::single(sylva_mesh::SceneNode::new(name.clone(), mesh)),
            caption: format!("{name} {:.2} g", specimen.stats.biomass),
        });
        let _ = std::fmt::Write::write_fmt(
            &mut table,
            format_args!(
                "{name},{},{},{},{},{},{},{},{file}\n",
                specimen.stats.biomass,
                specimen.stats.light,
                specimen.stats.uptake,
                specimen.stats.leaves(),
                specimen.stats.fine_roots(),
                specimen.stats.germinated(),
                specimen.stats.bounds.symbols + specimen.stats.bounds.modules
            ),
        );
    }
    write_atomic(&out.join("specimens.csv"), table.as_bytes()).context("writing specimens.csv")?;
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
    sylva_mesh::export::write_scene(&out.join("garden.glb"), &scene)
        .context("writing garden.glb")?;
    write_picture(&scene, &out.join("garden.png"), View::Iso, SCENE_PICTURE)?;
    let sheet = render::contact_sheet(
        &cells,
        &SheetOptions {
            title: Some(format!("Mother and {} children", cells.len() - 1)),
            ..SheetOptions::default()
        },
        &pool,
    )
    .context("drawing the specimens")?;
    render::write_png(&out.join("specimens.png"), &sheet).context("writing specimens.png")?;
    print!("{table}");
    println!(
        "wrote {}/{{garden.glb, garden.png, specimens.png, specimens.csv, mother.json, child-*.json}}; \
         pick one and breed it: sylva breed {}/child-N.json --out NEXT",
        out.display(),
        out.display()
    );
    Ok(())
}

/// Parses `WIDTHxDEPTH` in metres, each from 0.1 to 100,000.
pub fn parse_area(text: &str) -> Result<(f64, f64), String> {
    let bad = || {
        format!("expected WIDTHxDEPTH in metres, each from 0.1 to 100000, like 30x20; got {text:?}")
    };
    let (w, d) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: f64 = w.trim().parse().map_err(|_| bad())?;
    let d: f64 = d.trim().parse().map_err(|_| bad())?;
    if [w, d]
        .iter()
        .all(|v| v.is_finite() && (0.1..=100_000.0).contains(v))
    {
        Ok((w, d))
    } else {
        Err(bad())
    }
}

/// Parses `WIDTHxHEIGHT`, each 16 to 8192 pixels.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad =
        || format!("expected WIDTHxHEIGHT with each from 16 to 8192, like 800x600; got {text:?}");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if (16..=8192).contains(&w) && (16..=8192).contains(&h) {
        Ok((w, h))
    } else {
        Err(bad())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert_eq!(parse_size("64X64"), Ok((64, 64)));
        for bad in ["", "800", "x600", "0x10", "800x99999", "-5x10", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
