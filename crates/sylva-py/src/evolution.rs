//! `Config` and `Evolution`: evolution runs of any model, stepped from Python, and the
//! migrants islands exchange.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use sylva::{Evolution as Run, Member as RunMember};
use sylva::{GenerationStats, IndividualId};

use crate::errors::{IntoPy, bad_value, input_error};
use crate::genome::Genome;
use crate::json::{from_py, to_py};

/// An evolution config of any model that evolves: read from a TOML file (`Config.load`),
/// TOML text (`Config.from_toml`) or a dict shaped like the file (`Config.from_dict`).
/// Every number is range-checked as it is read; a bad one raises `InputError` naming it.
#[pyclass(module = "sylva", name = "Config")]
#[derive(Clone)]
pub struct Config {
    pub inner: sylva::Config,
    /// The folder its `start` genome files are found in.
    pub base: PathBuf,
}

/// Where a config given as a dict is named in errors.
const DICT: &str = "<config dict>";

impl Config {
    fn parse(text: &str, source: &Path, base: PathBuf) -> PyResult<Config> {
        let inner = crate::registry().parse_config(source, text).py()?;
        Ok(Config { inner, base })
    }

    /// The config with its run section changed through TOML, so the same range checks apply.
    fn with_run_field(&self, field: &str, value: toml::Value) -> PyResult<Config> {
        let mut table: toml::Table =
            toml::from_str(&self.inner.to_toml()).map_err(|e| bad_value(field, e))?;
        if let Some(toml::Value::Table(run)) = table.get_mut("run") {
            run.insert(field.to_owned(), value);
        }
        let text = toml::to_string(&table).map_err(|e| bad_value(field, e))?;
        let inner = (self.inner.registry())
            .parse_config(Path::new(DICT), &text)
            .map_err(|e| field_error(e, &text))
            .map_err(|e| input_error(&e))?;
        Ok(Config {
            inner,
            base: self.base.clone(),
        })
    }
}

/// A config error in TOML made from a dict, named by its field (`run.population`) rather
/// than a line of text the user never saw.
fn field_error(e: sylva::InputError, text: &str) -> sylva::InputError {
    if e.line == 0 {
        return e;
    }
    let mut table = String::new();
    let mut key = String::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            table = name.trim().to_owned();
        }
        if i + 1 == e.line {
            key = line.split('=').next().unwrap_or_default().trim().to_owned();
            break;
        }
    }
    let field = match (table.is_empty(), key.starts_with('[')) {
        (_, true) => table,
        (true, false) => key,
        (false, false) => format!("{table}.{key}"),
    };
    sylva::InputError::new(format!("{DICT} `{field}`"), e.message)
}

impl Config {
    /// A config given as Python code gives one: a `Config`, a dict shaped like the file,
    /// or the path of a config file.
    pub fn from_any(config: &Bound<'_, PyAny>) -> PyResult<Config> {
        if let Ok(config) = config.cast::<Config>() {
            Ok(config.borrow().clone())
        } else if config.is_instance_of::<pyo3::types::PyDict>() {
            Config::from_dict(config, None)
        } else {
            let path: PathBuf = config.extract().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "expected a Config, a dict or the path of a config file, got {}",
                    config
                        .get_type()
                        .name()
                        .map_or_else(|_| "?".into(), |n| n.to_string())
                ))
            })?;
            Config::load(path)
        }
    }
}

#[pymethods]
impl Config {
    /// Reads a config file; genome files it names are found next to it.
    #[staticmethod]
    pub(crate) fn load(path: PathBuf) -> PyResult<Config> {
        let inner = crate::registry().load_config(&path).py()?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(Config { inner, base })
    }

    /// A config from TOML text; `source` names it in errors, and genome files it names are
    /// found in `base` (the current folder by default).
    #[staticmethod]
    #[pyo3(signature = (text, source = "<toml>", base = None))]
    fn from_toml(text: &str, source: &str, base: Option<PathBuf>) -> PyResult<Config> {
        Config::parse(text, Path::new(source), base.unwrap_or_default())
    }

    /// A config from a dict shaped like the file: `{"model": "automata", "run":
    /// {"population": 500}, "automata": {...}}`. Errors name the field.
    #[staticmethod]
    #[pyo3(signature = (data, base = None))]
    pub(crate) fn from_dict(data: &Bound<'_, PyAny>, base: Option<PathBuf>) -> PyResult<Config> {
        let value = from_py(data, "config dict")?;
        let text =
            toml::to_string(&value).map_err(|e| bad_value(DICT, format!("not a config: {e}")))?;
        let inner = crate::registry()
            .parse_config(Path::new(DICT), &text)
            .map_err(|e| input_error(&field_error(e, &text)))?;
        Ok(Config {
            inner,
            base: base.unwrap_or_default(),
        })
    }

    /// The default config (of the first model, binary trees, every setting at its
    /// default).
    #[staticmethod]
    fn default() -> Config {
        Config {
            inner: crate::registry().default_config().unwrap_or_default(),
            base: PathBuf::new(),
        }
    }

    /// The model evolved.
    #[getter]
    fn model(&self) -> &'static str {
        self.inner.model()
    }

    /// The folder its `start` genome files are found in.
    #[getter]
    fn base(&self) -> PathBuf {
        self.base.clone()
    }

    /// The config as TOML.
    fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    /// The config as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let table: toml::Table =
            toml::from_str(&self.inner.to_toml()).map_err(|e| bad_value("config", e))?;
        let value = serde_json::to_value(table).map_err(|e| bad_value("config", e))?;
        to_py(py, &value)
    }

    /// Generations bred after the first (0 to 1,000,000).
    #[getter]
    fn generations(&self) -> u32 {
        self.inner.run().generations
    }

    /// Individuals per generation (1 to 1,000,000).
    #[getter]
    fn population(&self) -> u32 {
        self.inner.run().population
    }

    /// Seed of every random choice.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.run().seed
    }

    /// Worker threads (0: one per core); results do not depend on it.
    #[getter]
    fn threads(&self) -> u32 {
        self.inner.run().threads
    }

    /// A copy with `[run]` fields changed (generations, population, seed, threads,
    /// checkpoint_seconds), each checked against its range.
    #[pyo3(signature = (**fields))]
    fn with_run(&self, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
        let mut config = self.clone();
        if let Some(fields) = fields {
            for (k, v) in fields.iter() {
                let key: String = k.extract()?;
                let value = from_py(&v, &key)?;
                let value = toml::Value::try_from(value).map_err(|e| bad_value(&key, e))?;
                config = config.with_run_field(&key, value)?;
            }
        }
        Ok(config)
    }

    fn __repr__(&self) -> String {
        format!("<sylva.Config {}>", self.inner.model())
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let from_toml = py.get_type::<Config>().getattr("from_toml")?;
        let base = self.base.clone();
        Ok((from_toml, (self.inner.to_toml(), "<toml>", base))
            .into_pyobject(py)?
            .into_any())
    }
}

/// A member of a run's population: its id, genome, fitness and origin.
#[pyclass(module = "sylva", name = "Member", frozen, get_all)]
pub struct Member {
    /// Its run-wide id.
    id: u64,
    /// Its genome.
    genome: Genome,
    /// Its total fitness (None before evaluation).
    fitness: Option<f64>,
    /// Its fitness terms, by name.
    terms: Py<PyAny>,
    /// The generation it was born in.
    generation: u32,
    /// The operator that made it ("random", "crossover+mutation", "immigrant", ...).
    operator: String,
    /// Its parents' ids.
    parents: Vec<u64>,
}

impl Member {
    fn of(py: Python<'_>, m: RunMember, names: &[String]) -> PyResult<Member> {
        let terms = PyDict::new(py);
        if let Some(f) = &m.fitness {
            for (name, value) in names.iter().zip(f.terms()) {
                terms.set_item(name, value)?;
            }
        }
        Ok(Member {
            id: m.id.0,
            fitness: m.fitness.map(|f| f.total()),
            genome: Genome { inner: m.genome },
            terms: terms.into_any().unbind(),
            generation: m.origin.generation,
            operator: m.origin.operator.into_owned(),
            parents: m.origin.parents.iter().map(|p| p.0).collect(),
        })
    }
}

#[pymethods]
impl Member {
    fn __repr__(&self) -> String {
        format!(
            "<sylva.Member {} fitness {}>",
            self.id,
            self.fitness.map_or("-".to_owned(), |f| format!("{f:.4}"))
        )
    }
}

/// An evolution run of any model. `Evolution(config)` makes and scores generation 0
/// (with the config's `start` genomes, or `start` given here); `step` breeds one
/// generation, `run` a batch; `stats`, `population`, `best`, `fittest` and `family` read
/// it; `checkpoint`/`save` and `Evolution.resume` stop and go on exactly. Long calls
/// release the GIL.
#[pyclass(module = "sylva", name = "Evolution")]
pub struct Evolution {
    run: Mutex<Run>,
}

impl Evolution {
    fn with<T>(&self, f: impl FnOnce(&mut Run) -> T) -> T {
        // A panic inside a step would poison the lock; the run's state is still whole.
        let mut run = self.run.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut run)
    }

    pub(crate) fn pool(
        config: &sylva::Config,
        threads: Option<u32>,
    ) -> PyResult<sylva::core::par::Pool> {
        let threads = threads.unwrap_or(config.run().threads);
        if threads > 1024 {
            return Err(bad_value(
                "threads",
                format!("{threads}; expected 0 to 1024"),
            ));
        }
        sylva::core::par::Pool::with_threads(threads as usize)
            .map_err(sylva::Error::from)
            .py()
    }
}

/// A statistics row as a dict: generation, best, mean, best_id, evaluations, seconds, and
/// each term of the best by name.
fn row<'py>(
    py: Python<'py>,
    s: &GenerationStats,
    names: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("generation", s.generation)?;
    d.set_item("best", s.best)?;
    d.set_item("mean", s.mean)?;
    d.set_item("best_id", s.best_id.0)?;
    d.set_item("evaluations", s.evaluations)?;
    d.set_item("seconds", s.seconds)?;
    for (name, value) in names.iter().zip(&s.best_terms) {
        d.set_item(name, value)?;
    }
    Ok(d)
}

#[pymethods]
impl Evolution {
    /// Starts a run: generation 0 made and scored. `config` is a `Config`, a dict, or the
    /// path of a config file (as `islands()` takes it). `start` genomes are its first
    /// members (the config's `start` files when left out); `threads` overrides the config's.
    #[new]
    #[pyo3(signature = (config, start = None, threads = None))]
    fn new(
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        start: Option<Vec<Genome>>,
        threads: Option<u32>,
    ) -> PyResult<Evolution> {
        let config = &Config::from_any(config)?;
        let start = match start {
            Some(genomes) => genomes.into_iter().map(|g| g.inner).collect(),
            None => config.inner.load_start(&config.base).py()?,
        };
        let pool = Evolution::pool(&config.inner, threads)?;
        let inner = &config.inner;
        let run = py.detach(|| Run::start(inner, start, pool)).py()?;
        Ok(Evolution {
            run: Mutex::new(run),
        })
    }

    /// Resumes a run from a checkpoint file (`path`) or its text (`text`), written by the
    /// same config (only generations, threads and the checkpoint interval may change).
    #[staticmethod]
    #[pyo3(signature = (config, path = None, text = None, threads = None))]
    fn resume(
        py: Python<'_>,
        config: &Config,
        path: Option<PathBuf>,
        text: Option<String>,
        threads: Option<u32>,
    ) -> PyResult<Evolution> {
        let (path, text) = checkpoint_text(path, text)?;
        let pool = Evolution::pool(&config.inner, threads)?;
        let inner = &config.inner;
        let run = py.detach(|| Run::resume(inner, &path, &text, pool)).py()?;
        Ok(Evolution {
            run: Mutex::new(run),
        })
    }

    /// The effective config.
    #[getter]
    fn config(&self) -> Config {
        Config {
            inner: self.with(|r| r.config()),
            base: PathBuf::new(),
        }
    }

    /// The last completed generation.
    #[getter]
    fn generation(&self) -> u32 {
        self.with(|r| r.generation())
    }

    /// Names of the fitness terms.
    #[getter]
    fn term_names(&self) -> Vec<String> {
        self.with(|r| r.term_names().to_vec())
    }

    /// Breeds one generation; returns its statistics row. Releases the GIL.
    fn step<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (stats, names) = py.detach(|| {
            self.with(|r| {
                let stats = r.step().cloned();
                (stats, r.term_names().to_vec())
            })
        });
        row(py, &stats.py()?, &names)
    }

    /// Breeds `generations` generations (up to the config's last when left out), calling
    /// `on_generation(row)` after each when given. Releases the GIL while it breeds. Ctrl-C
    /// raises `KeyboardInterrupt` when the generation under way ends, leaving the run whole
    /// at that generation (step it, run it on, or checkpoint it).
    #[pyo3(signature = (generations = None, on_generation = None))]
    fn run(
        &self,
        py: Python<'_>,
        generations: Option<u32>,
        on_generation: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let todo = generations.unwrap_or_else(|| {
            self.with(|r| r.config().run().generations.saturating_sub(r.generation()))
        });
        for _ in 0..todo {
            let row = self.step(py)?;
            py.check_signals()?;
            if let Some(callback) = &on_generation {
                callback.call1((row,))?;
            }
        }
        Ok(())
    }

    /// Statistics of every generation so far: one dict per generation (see `step`).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let (stats, names) = self.with(|r| (r.stats().to_vec(), r.term_names().to_vec()));
        stats.iter().map(|s| row(py, s, &names)).collect()
    }

    /// The current population, in slot order.
    fn population(&self, py: Python<'_>) -> PyResult<Vec<Member>> {
        let (members, names) = self.with(|r| (r.population(), r.term_names().to_vec()));
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// The best member of the current population.
    fn best(&self, py: Python<'_>) -> PyResult<Member> {
        let (best, names) = self.with(|r| (r.best(), r.term_names().to_vec()));
        Member::of(py, best, &names)
    }

    /// The `count` fittest members, fittest first.
    fn fittest(&self, py: Python<'_>, count: usize) -> PyResult<Vec<Member>> {
        let (members, names) = self.with(|r| (r.fittest(count), r.term_names().to_vec()));
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// A member by id, from the current population or a kept generation (None if gone).
    fn member(&self, py: Python<'_>, id: u64) -> PyResult<Option<Member>> {
        let (member, names) = self.with(|r| (r.member(IndividualId(id)), r.term_names().to_vec()));
        member.map(|m| Member::of(py, m, &names)).transpose()
    }

    /// A member's family as far as kept generations reach: the member, its parents, theirs,
    /// each once, nearest first. Call `keep_history` before stepping to keep generations.
    fn family(&self, py: Python<'_>, id: u64) -> PyResult<Vec<Member>> {
        let (members, names) = self.with(|r| (r.family(IndividualId(id)), r.term_names().to_vec()));
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// The population of `generation`, if it is the current one or still kept.
    fn generation_members(&self, py: Python<'_>, generation: u32) -> PyResult<Option<Vec<Member>>> {
        let (members, names) =
            self.with(|r| (r.generation_members(generation), r.term_names().to_vec()));
        members
            .map(|ms| ms.into_iter().map(|m| Member::of(py, m, &names)).collect())
            .transpose()
    }

    /// Keeps the last `generations` generations for browsing (0 keeps only the current).
    fn keep_history(&self, generations: usize) {
        self.with(|r| r.keep_history(generations));
    }

    /// The checkpoint's text (JSON): everything needed to resume exactly.
    fn checkpoint(&self, py: Python<'_>) -> PyResult<String> {
        py.detach(|| self.with(|r| r.checkpoint())).py()
    }

    /// Pickled through its checkpoint: unpickled, it resumes exactly where it was
    /// (`Evolution.resume(config, text=checkpoint)`), for multiprocessing and Ray.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let resume = py.get_type::<Evolution>().getattr("resume")?;
        let config = self.config();
        let text = self.checkpoint(py)?;
        Ok((resume, (config, None::<PathBuf>, text))
            .into_pyobject(py)?
            .into_any())
    }

    /// Writes the checkpoint file (atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| {
            let text = self.with(|r| r.checkpoint())?;
            sylva::files::write(&path, text.as_bytes())
        })
        .py()
    }

    /// The `count` fittest genomes as the engine evolves them (bytes each): what an island
    /// sends its neighbours.
    fn emigrants<'py>(&self, py: Python<'py>, count: usize) -> Vec<Bound<'py, PyBytes>> {
        self.with(|r| r.emigrants(count))
            .iter()
            .map(|m| PyBytes::new(py, m.as_bytes()))
            .collect()
    }

    /// Puts migrants (from `emigrants` of a run of the same config) in the places of the
    /// worst members and scores them; returns their new ids. Releases the GIL.
    fn immigrate(&self, py: Python<'_>, migrants: Vec<Vec<u8>>) -> PyResult<Vec<u64>> {
        let texts = migrants
            .into_iter()
            .enumerate()
            .map(|(i, m)| {
                String::from_utf8(m)
                    .map_err(|_| bad_value(format!("migrant {}", i + 1), "not UTF-8 text"))
            })
            .collect::<PyResult<Vec<String>>>()?;
        let ids = py.detach(|| self.with(|r| r.immigrate(&texts))).py()?;
        Ok(ids.into_iter().map(|id| id.0).collect())
    }

    fn __repr__(&self) -> String {
        self.with(|r| {
            format!(
                "<sylva.Evolution {} generation {}>",
                r.title(),
                r.generation()
            )
        })
    }
}

/// Evolves a plant whose outline matches a picture and returns the run, as `sylva match`
/// does: `target` is a PNG or JPEG of the outline seen from the front, `side` the one seen
/// from the side (the front picture by default); `model` a model's name or `"auto"` (each
/// model briefly, then on with the best); for `generations` (the same bytes each time) or
/// `seconds` of breeding (60 by default); `threshold` `"otsu"` or a luminance from 0 to 1.
/// The best member's `terms["iou"]` is its outline term (docs/match.md). Releases the GIL
/// while it breeds; Ctrl-C raises `KeyboardInterrupt` between generations.
#[pyfunction(name = "match")]
#[pyo3(signature = (target, side = None, model = "auto", generations = None, seconds = None,
                    population = 100, seed = 1, threshold = None, threads = 0))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments.
pub fn match_outline(
    py: Python<'_>,
    target: PathBuf,
    side: Option<PathBuf>,
    model: &str,
    generations: Option<u32>,
    seconds: Option<f64>,
    population: u32,
    seed: u64,
    threshold: Option<&Bound<'_, PyAny>>,
    threads: u32,
) -> PyResult<Evolution> {
    use sylva::evolution::outline::{Limit, match_config, outlines, start_auto};
    let threshold = match threshold {
        None => sylva::picture::Threshold::Otsu,
        Some(t) => serde_json::from_value(from_py(t, "threshold")?)
            .map_err(|e| bad_value("threshold", e))?,
    };
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_owned());
    let front = absolute(&target);
    let outline = sylva::evolution::MatchConfig {
        side: Some(side.as_deref().map_or_else(|| front.clone(), absolute)),
        front,
        threshold,
        weight: 1.0,
        beside: false,
        rows: 64,
        closeness: 0.0,
    };
    outlines(&outline, Path::new("")).py()?;
    let limit = match (generations, seconds) {
        (Some(_), Some(_)) => {
            return Err(bad_value(
                "seconds",
                "give `generations` or `seconds`, not both",
            ));
        }
        (Some(n), None) => Limit::Generations(n),
        (None, s) => match s.unwrap_or(60.0) {
            s if (1.0..=86_400.0).contains(&s) => Limit::Seconds(s),
            s => return Err(bad_value("seconds", format!("{s}; expected 1 to 86400"))),
        },
    };
    let run = sylva::RunConfig {
        generations: match limit {
            Limit::Generations(n) => n,
            Limit::Seconds(_) => 1_000_000,
        },
        population,
        seed,
        threads,
        ..sylva::RunConfig::default()
    };
    let registry = crate::registry();
    let config = match model {
        "auto" => None,
        model => Some(
            match_config(registry, model, &run, &outline)
                .map_err(|e| bad_value(e.field, e.message))?,
        ),
    };
    let pool = Evolution::pool(
        config.as_ref().unwrap_or(&sylva::Config::default()),
        Some(threads),
    )?;
    let (mut evolution, elsewhere) = py
        .detach(|| -> Result<(Run, f64), sylva::Error> {
            match &config {
                Some(config) => Ok((Run::start(config, Vec::new(), pool)?, 0.0)),
                None => start_auto(registry, &outline, &run, limit, &pool, |_| {}),
            }
        })
        .py()?;
    py.check_signals()?;
    let remaining = limit.remaining(&evolution, elsewhere);
    let started = std::time::Instant::now();
    // A generation at a time, so Ctrl-C is heard between them.
    while !remaining.reached(&evolution, started) {
        py.detach(|| evolution.step().map(|_| ())).py()?;
        py.check_signals()?;
    }
    Ok(Evolution {
        run: Mutex::new(evolution),
    })
}

/// A checkpoint to resume from: the file at `path`, or `text` (named `<checkpoint>` in
/// errors); exactly one of them.
pub(crate) fn checkpoint_text(
    path: Option<PathBuf>,
    text: Option<String>,
) -> PyResult<(PathBuf, String)> {
    match (path, text) {
        (Some(path), None) => {
            let text = sylva::files::read_text(&path).py()?;
            Ok((path, text))
        }
        (None, Some(text)) => Ok((PathBuf::from("<checkpoint>"), text)),
        _ => Err(bad_value("resume", "give either `path` or `text`")),
    }
}
