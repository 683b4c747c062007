//! `Config` and `Evolution`: evolution runs of any model, stepped from Python, and the
//! migrants islands exchange.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, TryLockError};

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};
use sylva::evolution::Stop;
use sylva::{Evolution as Run, Member as RunMember};
use sylva::{GenerationStats, IndividualId, Registry};

use crate::errors::{IntoPy, bad_value, input_error};
use crate::handle::Genome;
use crate::json::{from_py, to_py};
use crate::models::Models;
use crate::plant::Plant;
use crate::whole::{self, Whole};
use crate::work::{PyFitness, Serving, work};

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
    fn parse(registry: &Registry, text: &str, source: &Path, base: PathBuf) -> PyResult<Config> {
        let inner = registry.parse_config(source, text).py()?;
        Ok(Config { inner, base })
    }

    /// The config with its run section changed through TOML, so the same range checks apply.
    fn with_run_field(
        &self,
        registry: &Registry,
        field: &str,
        value: toml::Value,
    ) -> PyResult<Config> {
        let mut table: toml::Table =
            toml::from_str(&self.inner.to_toml()).map_err(|e| bad_value(field, e))?;
        if let Some(toml::Value::Table(run)) = table.get_mut("run") {
            run.insert(field.to_owned(), value);
        }
        let text = toml::to_string(&table).map_err(|e| bad_value(field, e))?;
        let inner = registry
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
    /// or the path of a config file; the dict and the file read with `registry`.
    pub fn from_any(registry: &Registry, config: &Bound<'_, PyAny>) -> PyResult<Config> {
        if let Ok(config) = config.cast::<Config>() {
            Ok(config.borrow().clone())
        } else if config.is_instance_of::<pyo3::types::PyDict>() {
            Config::read_dict(registry, config, None)
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
            Config::read_file(registry, path)
        }
    }

    fn read_file(registry: &Registry, path: PathBuf) -> PyResult<Config> {
        let inner = registry.load_config(&path).py()?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(Config { inner, base })
    }

    fn read_dict(
        registry: &Registry,
        data: &Bound<'_, PyAny>,
        base: Option<PathBuf>,
    ) -> PyResult<Config> {
        let value = from_py(data, "config dict")?;
        let text =
            toml::to_string(&value).map_err(|e| bad_value(DICT, format!("not a config: {e}")))?;
        let inner = registry
            .parse_config(Path::new(DICT), &text)
            .map_err(|e| input_error(&field_error(e, &text)))?;
        Ok(Config {
            inner,
            base: base.unwrap_or_default(),
        })
    }
}

#[pymethods]
impl Config {
    /// Reads a config file; genome files it names are found next to it.
    #[classmethod]
    fn load(cls: &Bound<'_, PyType>, path: PathBuf) -> PyResult<Config> {
        Config::read_file(Models::of(cls)?.get().registry(), path)
    }

    /// A config from TOML text; `source` names it in errors, and genome files it names are
    /// found in `base` (the current folder by default).
    #[classmethod]
    #[pyo3(signature = (text, source = "<toml>", base = None))]
    fn from_toml(
        cls: &Bound<'_, PyType>,
        text: &str,
        source: &str,
        base: Option<PathBuf>,
    ) -> PyResult<Config> {
        let models = Models::of(cls)?;
        Config::parse(
            models.get().registry(),
            text,
            Path::new(source),
            base.unwrap_or_default(),
        )
    }

    /// A config from a dict shaped like the file: `{"model": "automata", "run":
    /// {"population": 500}, "automata": {...}}`. Errors name the field.
    #[classmethod]
    #[pyo3(signature = (data, base = None))]
    fn from_dict(
        cls: &Bound<'_, PyType>,
        data: &Bound<'_, PyAny>,
        base: Option<PathBuf>,
    ) -> PyResult<Config> {
        Config::read_dict(Models::of(cls)?.get().registry(), data, base)
    }

    /// The default config (of the first model, binary trees, every setting at its
    /// default).
    #[classmethod]
    fn default(cls: &Bound<'_, PyType>) -> PyResult<Config> {
        let models = Models::of(cls)?;
        let inner = models
            .get()
            .registry()
            .default_config()
            .ok_or_else(|| bad_value("model", "this module has no models"))?;
        Ok(Config {
            inner,
            base: PathBuf::new(),
        })
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
    fn with_run(&self, py: Python<'_>, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
        let models = Models::of(py.get_type::<Config>().as_any())?;
        let registry = models.get().registry();
        let mut config = self.clone();
        if let Some(fields) = fields {
            for (k, v) in fields.iter() {
                let key: String = k.extract()?;
                let value = from_py(&v, &key)?;
                let value = toml::Value::try_from(value).map_err(|e| bad_value(&key, e))?;
                config = config.with_run_field(registry, &key, value)?;
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
    /// A member of these fields (`Member._restore`, as a member unpickles).
    #[staticmethod]
    #[allow(clippy::too_many_arguments)] // One per field.
    fn _restore(
        id: u64,
        genome: Genome,
        fitness: Option<f64>,
        terms: Bound<'_, PyDict>,
        generation: u32,
        operator: String,
        parents: Vec<u64>,
    ) -> Member {
        Member {
            id,
            genome,
            fitness,
            terms: terms.into_any().unbind(),
            generation,
            operator,
            parents,
        }
    }

    /// Pickled as its fields.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let restore = py.get_type::<Member>().getattr("_restore")?;
        let args = (
            self.id,
            self.genome.clone(),
            self.fitness,
            self.terms.bind(py),
            self.generation,
            self.operator.clone(),
            self.parents.clone(),
        );
        Ok((restore, args).into_pyobject(py)?.into_any())
    }

    /// Members are equal when every field is.
    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(other) = other.cast::<Member>() else {
            return Ok(false);
        };
        let o = other.get();
        Ok(self.id == o.id
            && self.genome.inner == o.genome.inner
            && self.fitness.map(f64::to_bits) == o.fitness.map(f64::to_bits)
            && self.generation == o.generation
            && self.operator == o.operator
            && self.parents == o.parents
            && self.terms.bind(py).eq(o.terms.bind(py))?)
    }

    fn __repr__(&self) -> String {
        format!(
            "<sylva.Member {} fitness {}>",
            self.id,
            self.fitness.map_or("-".to_owned(), |f| format!("{f:.4}"))
        )
    }
}

/// How a Python fitness function joins a run (`Evolution(config, fitness=f, ...)`).
#[derive(Clone)]
struct Fitness {
    scorer: Arc<PyFitness>,
    weight: f64,
    /// "add" (beside the model's terms) or "replace" (alone).
    mode: &'static str,
    batch: usize,
}

/// The name of a Python fitness function's term.
const PYTHON_TERM: &str = "python";

impl Fitness {
    /// The function and its settings, checked; none without a function.
    fn of(
        function: Option<Bound<'_, PyAny>>,
        weight: f64,
        mode: &str,
        batch: Whole,
    ) -> PyResult<Option<Fitness>> {
        let batch: usize = batch.get("fitness_batch")?;
        let Some(function) = function else {
            return Ok(None);
        };
        if !function.is_callable() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "`fitness` must be a function taking a list of plants, got {}",
                function
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            )));
        }
        let mode = match mode {
            "add" => "add",
            "replace" => "replace",
            other => {
                return Err(bad_value(
                    "fitness_mode",
                    format!(
                        "{other:?}; expected \"add\" (beside the model's terms) or \"replace\" \
                         (in their place)"
                    ),
                ));
            }
        };
        Ok(Some(Fitness {
            scorer: Arc::new(PyFitness::new(function.unbind())),
            weight,
            mode,
            batch,
        }))
    }

    fn term(&self) -> sylva::OwnTerm {
        sylva::OwnTerm {
            name: PYTHON_TERM.to_owned(),
            scorer: self.scorer.clone(),
            weight: self.weight,
            beside: self.mode == "add",
            batch: self.batch,
        }
    }
}

/// An evolution run of any model. `Evolution(config)` makes and scores generation 0
/// (with the config's `start` genomes, or `start` given here); `step` breeds one
/// generation, `run` a batch; `stats`, `population`, `best`, `fittest` and `family` read
/// it; `checkpoint`/`save` and `Evolution.resume` stop and go on exactly. `fitness=f` adds
/// a Python fitness function: `f(plants)` gets a list of grown `Plant`s and returns one
/// finite number per plant (NaN and infinities are refused), a term named "python" weighted
/// `fitness_weight`, beside the model's terms (`fitness_mode="add"`) or in their place
/// (`"replace"`), `fitness_batch` plants per call at most. Long calls release the GIL, and Ctrl-C stops them within one member's
/// evaluation, leaving the run as it was before the generation under way.
#[pyclass(module = "sylva", name = "Evolution")]
pub struct Evolution {
    run: Mutex<Run>,
    /// Set on Ctrl-C while the run works.
    stop: Stop,
    fitness: Option<Fitness>,
    serving: Serving,
}

impl Evolution {
    /// `f` on the run: at once when it is free, else after waiting for it with the GIL
    /// released (another thread's call holds it). From the run's own fitness function, whose
    /// run is at work, an error.
    fn with<T: Send>(&self, py: Python<'_>, f: impl FnOnce(&mut Run) -> T + Send) -> PyResult<T> {
        match self.run.try_lock() {
            Ok(mut run) => Ok(f(&mut run)),
            // A panic inside a step would poison the lock; the run's state is still whole.
            Err(TryLockError::Poisoned(e)) => Ok(f(&mut e.into_inner())),
            Err(TryLockError::WouldBlock) if self.serving.here() => {
                Err(pyo3::exceptions::PyRuntimeError::new_err(
                    "the run is breeding: its own fitness function cannot read it (score the \
                     plants it is given)",
                ))
            }
            Err(TryLockError::WouldBlock) => Ok(py.detach(|| {
                let mut run = self.run.lock().unwrap_or_else(|e| e.into_inner());
                f(&mut run)
            })),
        }
    }

    /// `job` on the run, off this thread, with Ctrl-C heard and the fitness function served
    /// ([`work`]).
    fn work<T: Send>(&self, py: Python<'_>, job: impl FnOnce(&mut Run) -> T + Send) -> PyResult<T> {
        let scorer = self.fitness.as_ref().map(|f| &f.scorer);
        work(py, &self.stop, scorer, &self.serving, || {
            let mut run = self.run.lock().unwrap_or_else(|e| e.into_inner());
            job(&mut run)
        })
    }

    fn made(run: Run, stop: Stop, fitness: Option<Fitness>) -> Evolution {
        Evolution {
            run: Mutex::new(run),
            stop,
            fitness,
            serving: Serving::default(),
        }
    }

    /// Makes a run with `stop` and `fitness` hooked in, by `make`, off this thread.
    fn make(
        py: Python<'_>,
        fitness: Option<Fitness>,
        make: impl FnOnce(sylva::RunHooks) -> Result<Run, sylva::Error> + Send,
    ) -> PyResult<Evolution> {
        let stop = Stop::new();
        let hooks = sylva::RunHooks {
            stop: Some(stop.clone()),
            term: fitness.as_ref().map(Fitness::term),
        };
        let scorer = fitness.as_ref().map(|f| &f.scorer);
        let run = work(py, &stop, scorer, &Serving::default(), || make(hooks))?.py()?;
        Ok(Evolution::made(run, stop, fitness))
    }

    pub(crate) fn pool(
        config: &sylva::Config,
        threads: Option<u32>,
    ) -> PyResult<sylva::core::par::Pool> {
        Evolution::pool_of(threads.unwrap_or(config.run().threads))
    }

    /// A pool of `threads` threads (0: one per core).
    pub(crate) fn pool_of(threads: u32) -> PyResult<sylva::core::par::Pool> {
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

    fn names(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.with(py, |r| r.term_names().to_vec())
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
    /// `fitness`, `fitness_weight`, `fitness_mode` and `fitness_batch`: a Python fitness
    /// function and how it joins the model's terms (see the class). Ctrl-C while generation
    /// 0 is made raises `KeyboardInterrupt` (within one member's evaluation), and makes
    /// nothing.
    #[new]
    #[classmethod]
    #[pyo3(signature = (config, start = None, threads = None, *, fitness = None,
                        fitness_weight = 1.0, fitness_mode = "add", fitness_batch = Whole(16)))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments.
    fn new(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        start: Option<Vec<Genome>>,
        threads: Option<Whole>,
        fitness: Option<Bound<'_, PyAny>>,
        fitness_weight: f64,
        fitness_mode: &str,
        fitness_batch: Whole,
    ) -> PyResult<Evolution> {
        let models = Models::of(cls)?;
        let registry = models.get().registry();
        let config = &Config::from_any(registry, config)?;
        let fitness = Fitness::of(fitness, fitness_weight, fitness_mode, fitness_batch)?;
        let start = match start {
            Some(genomes) => genomes.into_iter().map(|g| g.inner).collect(),
            None => config.inner.load_start(registry, &config.base).py()?,
        };
        let pool = Evolution::pool(&config.inner, whole::get(threads, "threads")?)?;
        let inner = &config.inner;
        Evolution::make(py, fitness, |hooks| {
            Run::start_with(inner, start, pool, hooks)
        })
    }

    /// Resumes a run from a checkpoint file (`path`) or its text (`text`), written by the
    /// same config (only generations, threads and the checkpoint interval may change). A run
    /// with a Python fitness function is resumed with it again (`fitness=f` and the same
    /// `fitness_weight` and `fitness_mode`): a checkpoint holds its settings, not the
    /// function.
    #[staticmethod]
    #[pyo3(signature = (config, path = None, text = None, threads = None, *, fitness = None,
                        fitness_weight = 1.0, fitness_mode = "add", fitness_batch = Whole(16)))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments.
    fn resume(
        py: Python<'_>,
        config: &Config,
        path: Option<PathBuf>,
        text: Option<String>,
        threads: Option<Whole>,
        fitness: Option<Bound<'_, PyAny>>,
        fitness_weight: f64,
        fitness_mode: &str,
        fitness_batch: Whole,
    ) -> PyResult<Evolution> {
        let fitness = Fitness::of(fitness, fitness_weight, fitness_mode, fitness_batch)?;
        let (path, text) = checkpoint_text(path, text)?;
        let pool = Evolution::pool(&config.inner, whole::get(threads, "threads")?)?;
        let inner = &config.inner;
        Evolution::make(py, fitness, |hooks| {
            Run::resume_with(inner, &path, &text, pool, hooks)
        })
    }

    /// The effective config.
    #[getter]
    fn config(&self, py: Python<'_>) -> PyResult<Config> {
        Ok(Config {
            inner: self.with(py, |r| r.config())?,
            base: PathBuf::new(),
        })
    }

    /// The last completed generation.
    #[getter]
    fn generation(&self, py: Python<'_>) -> PyResult<u32> {
        self.with(py, |r| r.generation())
    }

    /// Names of the fitness terms.
    #[getter]
    fn term_names(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.names(py)
    }

    /// The Python fitness function, if the run has one.
    #[getter]
    fn fitness(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.fitness
            .as_ref()
            .map(|f| f.scorer.function().clone_ref(py))
    }

    /// Calls of the Python fitness function so far, the plants they scored, the seconds the
    /// calls took (the function's own work included) and the seconds dropping the plants
    /// after took: what `benches/fitness_overhead.py` reads. None without a function.
    #[getter]
    fn _fitness_calls(&self) -> Option<(u64, u64, f64, f64)> {
        self.fitness.as_ref().map(|f| f.scorer.spent())
    }

    /// Breeds one generation; returns its statistics row. Runs with the GIL released (but
    /// while the fitness function runs). Ctrl-C raises `KeyboardInterrupt` within one
    /// member's evaluation and leaves the run as it was before the generation: the next step
    /// scores that population again first (as resuming would), then breeds.
    fn step<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (stats, names) = self.work(py, |r| {
            let stats = r.step().cloned();
            (stats, r.term_names().to_vec())
        })?;
        row(py, &stats.py()?, &names)
    }

    /// Breeds `generations` generations (up to the config's last when left out), calling
    /// `on_generation(row)` after each when given. Ctrl-C raises `KeyboardInterrupt` within
    /// one member's evaluation, leaving the run whole at the last generation it finished
    /// (step it, run it on, or checkpoint it).
    #[pyo3(signature = (generations = None, on_generation = None))]
    fn run(
        &self,
        py: Python<'_>,
        generations: Option<Whole>,
        on_generation: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let todo = match whole::get::<u32>(generations, "generations")? {
            Some(n) => n,
            None => self.with(py, |r| {
                r.config().run().generations.saturating_sub(r.generation())
            })?,
        };
        for _ in 0..todo {
            let row = self.step(py)?;
            if let Some(callback) = &on_generation {
                callback.call1((row,))?;
            }
        }
        Ok(())
    }

    /// Statistics of every generation so far: one dict per generation (see `step`).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let (stats, names) = self.with(py, |r| (r.stats().to_vec(), r.term_names().to_vec()))?;
        stats.iter().map(|s| row(py, s, &names)).collect()
    }

    /// The current population, in slot order.
    fn population(&self, py: Python<'_>) -> PyResult<Vec<Member>> {
        let (members, names) = self.with(py, |r| (r.population(), r.term_names().to_vec()))?;
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// The best member of the current population.
    fn best(&self, py: Python<'_>) -> PyResult<Member> {
        let (best, names) = self.with(py, |r| (r.best(), r.term_names().to_vec()))?;
        Member::of(py, best, &names)
    }

    /// Grows `member` (the best by default) as the run's files grow it: with `[output]`'s
    /// taper, wind and height, and inside `[match]`'s outlines when the match prunes (as
    /// `sylva.match` does by default; `member.genome.grow()` grows the genome alone).
    /// Releases the GIL.
    #[pyo3(signature = (member = None))]
    fn grow(&self, py: Python<'_>, member: Option<PyRef<'_, Member>>) -> PyResult<Plant> {
        let (config, best) = self.with(py, |r| (r.config(), r.best().genome))?;
        let genome = member.map_or(best, |m| m.genome.inner.clone());
        let options = config.grow_options().py()?;
        let wind = options.wind;
        let grown = py.detach(|| sylva::Grown::grow(genome, &options)).py()?;
        Ok(Plant::with_wind(grown, wind))
    }

    /// The `count` fittest members, fittest first.
    fn fittest(&self, py: Python<'_>, count: Whole) -> PyResult<Vec<Member>> {
        let count: usize = count.get("count")?;
        let (members, names) = self.with(py, |r| (r.fittest(count), r.term_names().to_vec()))?;
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// A member by id, from the current population or a kept generation (None if gone).
    fn member(&self, py: Python<'_>, id: Whole) -> PyResult<Option<Member>> {
        let id: u64 = id.get("id")?;
        let (member, names) = self.with(py, |r| {
            (r.member(IndividualId(id)), r.term_names().to_vec())
        })?;
        member.map(|m| Member::of(py, m, &names)).transpose()
    }

    /// A member's family as far as kept generations reach: the member, its parents, theirs,
    /// each once, nearest first. Call `keep_history` before stepping to keep generations.
    fn family(&self, py: Python<'_>, id: Whole) -> PyResult<Vec<Member>> {
        let id: u64 = id.get("id")?;
        let (members, names) = self.with(py, |r| {
            (r.family(IndividualId(id)), r.term_names().to_vec())
        })?;
        members
            .into_iter()
            .map(|m| Member::of(py, m, &names))
            .collect()
    }

    /// The population of `generation`, if it is the current one or still kept.
    fn generation_members(
        &self,
        py: Python<'_>,
        generation: Whole,
    ) -> PyResult<Option<Vec<Member>>> {
        let generation: u32 = generation.get("generation")?;
        let (members, names) = self.with(py, |r| {
            (r.generation_members(generation), r.term_names().to_vec())
        })?;
        members
            .map(|ms| ms.into_iter().map(|m| Member::of(py, m, &names)).collect())
            .transpose()
    }

    /// Keeps the last `generations` generations for browsing (0 keeps only the current).
    fn keep_history(&self, py: Python<'_>, generations: Whole) -> PyResult<()> {
        let generations: usize = generations.get("generations")?;
        self.with(py, |r| r.keep_history(generations))
    }

    /// The checkpoint's text (JSON): everything needed to resume exactly.
    fn checkpoint(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |r| r.checkpoint())?.py()
    }

    /// Pickled through its checkpoint: unpickled, it resumes exactly where it was
    /// (`Evolution.resume(config, text=checkpoint)`), for multiprocessing and Ray. A run with
    /// a Python fitness function pickles it too (by reference: a module-level function).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut resume = py.get_type::<Evolution>().getattr("resume")?;
        if let Some(f) = &self.fitness {
            let kwargs = PyDict::new(py);
            kwargs.set_item("fitness", f.scorer.function().bind(py))?;
            kwargs.set_item("fitness_weight", f.weight)?;
            kwargs.set_item("fitness_mode", f.mode)?;
            kwargs.set_item("fitness_batch", f.batch)?;
            resume = py
                .import("functools")?
                .getattr("partial")?
                .call((resume,), Some(&kwargs))?;
        }
        let config = self.config(py)?;
        let text = self.checkpoint(py)?;
        Ok((resume, (config, None::<PathBuf>, text))
            .into_pyobject(py)?
            .into_any())
    }

    /// Writes the checkpoint file (atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self.checkpoint(py)?;
        py.detach(|| sylva::files::write(&path, text.as_bytes()))
            .py()
    }

    /// The `count` fittest genomes as the engine evolves them (bytes each): what an island
    /// sends its neighbours.
    fn emigrants<'py>(&self, py: Python<'py>, count: Whole) -> PyResult<Vec<Bound<'py, PyBytes>>> {
        let count: usize = count.get("count")?;
        Ok(self
            .with(py, |r| r.emigrants(count))?
            .iter()
            .map(|m| PyBytes::new(py, m.as_bytes()))
            .collect())
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
        let ids = self.work(py, |r| r.immigrate(&texts))?.py()?;
        Ok(ids.into_iter().map(|id| id.0).collect())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |r| {
            format!(
                "<sylva.Evolution {} generation {}>",
                r.title(),
                r.generation()
            )
        })
    }
}

/// Evolves a plant whose outline matches a picture and returns the run, as `sylva match`
/// does: `target` is the outline seen from the front and `side` the one seen from the side
/// (the front one by default), each a PNG or JPEG file or a numpy array (a 2-D mask, ink
/// True or nonzero; or a uint8 image, grey (h, w), RGB or RGBA (h, w, 3 or 4), read as its
/// PNG file would be); `model` a model's name or `"auto"` (each model briefly, then on with
/// the best); for `generations` (the same bytes each time) or `seconds` of breeding (60 by
/// default); `threshold` `"otsu"` or a luminance from 0 to 1. The best member's
/// `terms["iou"]` is its outline term (docs/match.md); with `topiary=True` the plants are
/// clipped to the outlines as a topiary is, pruned where they would show outside them
/// (`run.grow()` grows the best so); by default they grow whole towards the outline. Releases the GIL while it breeds; Ctrl-C raises `KeyboardInterrupt` within
/// one member's evaluation.
#[pyfunction(name = "match")]
#[pyo3(pass_module, signature = (target, side = None, model = "auto", generations = None,
                    seconds = None, population = Whole(100), seed = Whole(1), threshold = None,
                    threads = Whole(0), topiary = false))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments.
pub fn match_outline(
    module: &Bound<'_, PyModule>,
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    side: Option<&Bound<'_, PyAny>>,
    model: &str,
    generations: Option<Whole>,
    seconds: Option<f64>,
    population: Whole,
    seed: Whole,
    threshold: Option<&Bound<'_, PyAny>>,
    threads: Whole,
    topiary: bool,
) -> PyResult<Evolution> {
    let generations: Option<u32> = whole::get(generations, "generations")?;
    let population: u32 = population.get("population")?;
    let seed: u64 = seed.get("seed")?;
    let threads: u32 = threads.get("threads")?;
    use sylva::evolution::outline::{
        Limit, breed_until, match_config, outlines, start_auto, start_within,
    };
    let threshold = match threshold {
        None => sylva::picture::Threshold::Otsu,
        Some(t) => serde_json::from_value(from_py(t, "threshold")?)
            .map_err(|e| bad_value("threshold", e))?,
    };
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_owned());
    let front = absolute(&crate::mask::picture_path(py, target, "target")?);
    let side = match side {
        Some(side) => absolute(&crate::mask::picture_path(py, side, "side")?),
        None => front.clone(),
    };
    let outline = sylva::evolution::MatchConfig {
        side: Some(side),
        front,
        threshold,
        weight: 1.0,
        beside: false,
        rows: sylva::evolution::MatchConfig::DEFAULT_ROWS,
        closeness: 0.0,
        topiary: Some(topiary),
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
    let models = Models::of(module.as_any())?;
    let registry = models.get().registry();
    let config = match model {
        "auto" => None,
        model => Some(
            match_config(registry, model, &run, &outline)
                .map_err(|e| bad_value(e.field, e.message))?,
        ),
    };
    let pool = Evolution::pool_of(threads)?;
    let stop = Stop::new();
    let (evolution, elsewhere) = work(py, &stop, None, &Serving::default(), || {
        match &config {
            Some(config) => Ok((start_within(config, limit, &pool, &stop)?, 0.0)),
            // The trials are thrown away if stopped.
            None => {
                let (mut run, elsewhere) = stop.watch(|| {
                    start_auto(registry, &outline, &run, limit, &pool, &stop, |_| {})
                })??;
                run.set_stop(Some(stop.clone()));
                Ok::<_, sylva::Error>((run, elsewhere))
            }
        }
    })?
    .py()?;
    let remaining = limit.remaining(&evolution, elsewhere);
    let evolution = Evolution::made(evolution, stop.clone(), None);
    let started = std::time::Instant::now();
    evolution
        .work(py, |r| {
            breed_until(r, remaining, started, &stop, |_| Ok::<_, sylva::Error>(()))
        })?
        .py()?;
    Ok(evolution)
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
