//! `Varieties`: a MAP-Elites run of any model (a map of the fittest plant of every kind),
//! stepped from Python, its archive as numpy arrays; `Variety`, one filled cell.

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};
use sylva::MapStats;
use sylva::Varieties as Map;
use sylva::evolution::Stop;

use crate::errors::IntoPy;
use crate::evolution::{Config, Evolution, checkpoint_text};
use crate::handle::Genome;
use crate::models::Models;
use crate::whole::{self, Whole};
use crate::work::{Serving, work};

/// One filled cell of a map: where it is, and its elite.
#[pyclass(module = "sylva", name = "Variety", frozen, get_all)]
pub struct Variety {
    /// The cell, row-major over the axes (the first slowest).
    cell: usize,
    /// The cell's place along each axis.
    coordinates: Vec<u32>,
    /// The elite's descriptors, one per axis.
    descriptors: Vec<f64>,
    /// The elite's genome.
    genome: Genome,
    /// The elite's total fitness.
    fitness: f64,
    /// The elite's fitness terms, by name.
    terms: Py<PyAny>,
    /// The elite's run-wide id.
    id: u64,
    /// The generation it was born in.
    generation: u32,
    /// The operator that made it ("random", "mutation", "crossover+mutation", "given").
    operator: String,
    /// Its parents' ids.
    parents: Vec<u64>,
}

impl Variety {
    fn of(py: Python<'_>, v: sylva::Variety, names: &[String]) -> PyResult<Variety> {
        let terms = PyDict::new(py);
        if let Some(f) = &v.member.fitness {
            for (name, value) in names.iter().zip(f.terms()) {
                terms.set_item(name, value)?;
            }
        }
        let origin = v.member.origin;
        Ok(Variety {
            cell: v.cell,
            coordinates: v.coordinates,
            descriptors: v.descriptors,
            fitness: v.member.fitness.map_or(f64::NEG_INFINITY, |f| f.total()),
            genome: Genome {
                inner: v.member.genome,
            },
            terms: terms.into_any().unbind(),
            id: v.member.id.0,
            generation: origin.generation,
            operator: origin.operator.into_owned(),
            parents: origin.parents.iter().map(|p| p.0).collect(),
        })
    }
}

#[pymethods]
impl Variety {
    fn __repr__(&self) -> String {
        format!(
            "<sylva.Variety cell {} {:?} fitness {:.4}>",
            self.cell, self.coordinates, self.fitness
        )
    }
}

/// A map's filled cells at one moment, in cell order, as numpy arrays (the columns
/// pyribs' `archive.data()` gives): `cells` (n,) int64, `coordinates` (n, k) int64,
/// `descriptors` (n, k) float64, `fitness` (n,) float64, `terms` (n, t) float64 (the
/// columns named by `term_names`), `ids` (n,) int64, and `genomes`, a list of n `Genome`.
/// `data()` gives them under pyribs' names.
#[pyclass(module = "sylva", name = "Archive", frozen, get_all)]
pub struct Archive {
    /// Each elite's cell, row-major over the axes.
    cells: Py<PyArray1<i64>>,
    /// Each elite's cell along each axis.
    coordinates: Py<PyArray2<i64>>,
    /// Each elite's descriptors.
    descriptors: Py<PyArray2<f64>>,
    /// Each elite's total fitness.
    fitness: Py<PyArray1<f64>>,
    /// Each elite's fitness terms, in the order of `term_names`.
    terms: Py<PyArray2<f64>>,
    /// The names of the columns of `terms`.
    term_names: Vec<String>,
    /// Each elite's run-wide id.
    ids: Py<PyArray1<i64>>,
    /// Each elite's genome.
    genomes: Vec<Genome>,
}

#[pymethods]
impl Archive {
    fn __len__(&self) -> usize {
        self.genomes.len()
    }

    /// The columns under pyribs' names: `index` (the cells), `objective` (the fitness),
    /// `measures` (the descriptors) and `solution` (the genomes, a list).
    fn data<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("index", self.cells.clone_ref(py))?;
        d.set_item("objective", self.fitness.clone_ref(py))?;
        d.set_item("measures", self.descriptors.clone_ref(py))?;
        d.set_item("solution", self.genomes.clone())?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("<sylva.Archive {} elites>", self.genomes.len())
    }
}

/// `values`, `columns` to a row, as an (n, columns) array.
fn matrix<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    columns: usize,
) -> PyResult<Py<PyArray2<T>>> {
    let rows = values.len().checked_div(columns).unwrap_or(0);
    Ok(PyArray1::from_vec(py, values)
        .reshape([rows, columns])?
        .unbind())
}

/// A statistics row as a dict: generation, filled, coverage, qd_score, best, mean,
/// best_id (None while the map is empty), improved, evaluations, seconds.
fn row<'py>(py: Python<'py>, s: &MapStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("generation", s.generation)?;
    d.set_item("filled", s.filled)?;
    d.set_item("coverage", s.coverage)?;
    d.set_item("qd_score", s.qd_score)?;
    d.set_item("best", s.best)?;
    d.set_item("mean", s.mean)?;
    d.set_item("best_id", s.best_id.map(|id| id.0))?;
    d.set_item("improved", s.improved)?;
    d.set_item("evaluations", s.evaluations)?;
    d.set_item("seconds", s.seconds)?;
    Ok(d)
}

/// A MAP-Elites run of any model: a map of the fittest plant of every kind, each cell a
/// kind by the config's `[map]` descriptors (docs/varieties.md). `Varieties(config)` (or
/// `sylva.varieties(config)`) fills generation 0; `step` breeds one generation, `run` a
/// batch; `archive()` gives the filled cells as numpy arrays; `checkpoint` and
/// `Varieties.resume` stop and go on exactly, and a map pickles through its checkpoint.
/// Long calls release the GIL.
#[pyclass(module = "sylva", name = "Varieties")]
pub struct Varieties {
    map: Mutex<Map>,
    /// Set on Ctrl-C while native work runs ([`work`]).
    stop: Stop,
    serving: Serving,
}

/// Runs `job` off this thread with Ctrl-C heard ([`work`]): `KeyboardInterrupt` within one
/// genome's evaluation, `job`'s own error otherwise.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    serving: &Serving,
    job: impl FnOnce() -> Result<T, sylva::Error> + Send,
) -> PyResult<T> {
    work(py, stop, None, serving, || stop.watch(job))?
        .map_err(sylva::Error::from)
        .and_then(|r| r)
        .py()
}

impl Varieties {
    fn with<T>(&self, f: impl FnOnce(&mut Map) -> T) -> T {
        // A panic inside a step would poison the lock; the map's state is still whole.
        let mut map = self.map.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut map)
    }

    /// Starts a map of `config`, a dict or a file read with the models of `models`.
    pub(crate) fn start(
        py: Python<'_>,
        models: &Bound<'_, Models>,
        config: &Bound<'_, PyAny>,
        start: Option<Vec<Genome>>,
        threads: Option<Whole>,
    ) -> PyResult<Varieties> {
        let threads = whole::get(threads, "threads")?;
        let registry = models.get().registry();
        let config = Config::from_any(registry, config)?;
        let start = match start {
            Some(genomes) => genomes.into_iter().map(|g| g.inner).collect(),
            None => config.inner.load_start(registry, &config.base).py()?,
        };
        let pool = Evolution::pool(&config.inner, threads)?;
        let inner = &config.inner;
        let (stop, serving) = (Stop::new(), Serving::default());
        let map = interruptible(py, &stop, &serving, || Map::start(inner, start, pool))?;
        Ok(Varieties {
            map: Mutex::new(map),
            stop,
            serving,
        })
    }
}

#[pymethods]
impl Varieties {
    /// Starts a map: generation 0 made, scored and placed. `config` is a `Config`, a dict
    /// or the path of a config file; its `[map]` (or the default map: height_to_width by
    /// porosity, 10 by 10) whatever its `[run] strategy`. `start` genomes are the first of
    /// generation 0 for models that take start genomes (the config's `start` files when
    /// left out); `threads` overrides the config's (0: one per core).
    #[new]
    #[classmethod]
    #[pyo3(signature = (config, start = None, threads = None))]
    fn new(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        start: Option<Vec<Genome>>,
        threads: Option<Whole>,
    ) -> PyResult<Varieties> {
        Varieties::start(py, &Models::of(cls)?, config, start, threads)
    }

    /// Resumes a map from a checkpoint file (`path`) or its text (`text`), written by the
    /// same config (only generations, threads and the checkpoint interval may change).
    #[classmethod]
    #[pyo3(signature = (config, path = None, text = None, threads = None))]
    fn resume(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        path: Option<PathBuf>,
        text: Option<String>,
        threads: Option<Whole>,
    ) -> PyResult<Varieties> {
        let config = Config::from_any(Models::of(cls)?.get().registry(), config)?;
        let (path, text) = checkpoint_text(path, text)?;
        let pool = Evolution::pool(&config.inner, whole::get(threads, "threads")?)?;
        let inner = &config.inner;
        let (stop, serving) = (Stop::new(), Serving::default());
        let map = interruptible(py, &stop, &serving, || {
            Map::resume(inner, &path, &text, pool)
        })?;
        Ok(Varieties {
            map: Mutex::new(map),
            stop,
            serving,
        })
    }

    /// The effective config (its `[map]` filled in).
    #[getter]
    fn config(&self) -> Config {
        Config {
            inner: self.with(|m| m.config()),
            base: PathBuf::new(),
        }
    }

    /// The model's name.
    #[getter]
    fn model(&self) -> String {
        self.with(|m| m.config().model().to_owned())
    }

    /// The last completed generation.
    #[getter]
    fn generation(&self) -> u32 {
        self.with(|m| m.generation())
    }

    /// Cells in the map.
    #[getter]
    fn cells(&self) -> usize {
        self.with(|m| m.cells())
    }

    /// The map's descriptors, one per axis.
    #[getter]
    fn descriptors(&self) -> Vec<&'static str> {
        self.with(|m| m.descriptors().iter().map(|d| d.name()).collect())
    }

    /// The map's axes: (descriptor, low, high, cells) each.
    #[getter]
    fn axes(&self) -> Vec<(&'static str, f64, f64, u32)> {
        self.with(|m| {
            m.descriptors()
                .iter()
                .zip(m.axes())
                .map(|(d, a)| (d.name(), a.min, a.max, a.cells))
                .collect()
        })
    }

    /// Names of the fitness terms.
    #[getter]
    fn term_names(&self) -> Vec<String> {
        self.with(|m| m.term_names().to_vec())
    }

    /// Breeds one generation and offers it to the map; returns its statistics row (see
    /// `stats`). Releases the GIL. Ctrl-C raises `KeyboardInterrupt` within one offspring's
    /// evaluation and leaves the map as it was before the generation.
    fn step<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let stats = interruptible(py, &self.stop, &self.serving, || {
            self.with(|m| m.step_until(&self.stop).cloned())
                .map_err(sylva::Error::from)
        })?;
        row(py, &stats)
    }

    /// Breeds `generations` generations (up to the config's `[run] generations` when left
    /// out), calling `on_generation(row)` after each when given. Releases the GIL while it
    /// breeds. Ctrl-C raises `KeyboardInterrupt` within one offspring's evaluation, leaving
    /// the map whole at the last generation it finished.
    #[pyo3(signature = (generations = None, on_generation = None))]
    fn run(
        &self,
        py: Python<'_>,
        generations: Option<Whole>,
        on_generation: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let generations: Option<u32> = whole::get(generations, "generations")?;
        let todo = generations.unwrap_or_else(|| {
            self.with(|m| m.config().run().generations.saturating_sub(m.generation()))
        });
        for _ in 0..todo {
            let row = self.step(py)?;
            if let Some(callback) = &on_generation {
                callback.call1((row,))?;
            }
        }
        Ok(())
    }

    /// Statistics of every generation so far, one dict each: generation, filled,
    /// coverage (share of cells filled), qd_score (the sum over elites of fitness less the
    /// map's `qd_offset`), best, mean, best_id, improved (offspring that filled a cell or
    /// beat its elite), evaluations, seconds.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let stats = self.with(|m| m.stats().to_vec());
        stats.iter().map(|s| row(py, s)).collect()
    }

    /// The filled cells as numpy arrays, in cell order (see `Archive`).
    fn archive(&self, py: Python<'_>) -> PyResult<Archive> {
        let (varieties, names, axes) =
            py.detach(|| self.with(|m| (m.varieties(), m.term_names().to_vec(), m.axes().len())));
        let n = varieties.len();
        let (mut cells, mut coordinates, mut descriptors) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n * axes),
            Vec::with_capacity(n * axes),
        );
        let (mut fitness, mut terms, mut ids, mut genomes) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n * names.len()),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for v in varieties {
            cells.push(v.cell as i64);
            coordinates.extend(v.coordinates.iter().map(|&c| i64::from(c)));
            descriptors.extend(&v.descriptors);
            fitness.push(v.member.total());
            let held = v.member.fitness.as_ref().map_or(&[][..], |f| f.terms());
            terms.extend((0..names.len()).map(|i| held.get(i).copied().unwrap_or(f64::NAN)));
            ids.push(v.member.id.0 as i64);
            genomes.push(Genome {
                inner: v.member.genome,
            });
        }
        Ok(Archive {
            cells: PyArray1::from_vec(py, cells).unbind(),
            coordinates: matrix(py, coordinates, axes)?,
            descriptors: matrix(py, descriptors, axes)?,
            fitness: PyArray1::from_vec(py, fitness).unbind(),
            terms: matrix(py, terms, names.len())?,
            term_names: names,
            ids: PyArray1::from_vec(py, ids).unbind(),
            genomes,
        })
    }

    /// The elite of `cell`, or None if the cell is empty.
    fn variety(&self, py: Python<'_>, cell: Whole) -> PyResult<Option<Variety>> {
        let cell: usize = cell.get("cell")?;
        let (variety, names) = self.with(|m| (m.variety(cell), m.term_names().to_vec()));
        variety.map(|v| Variety::of(py, v, &names)).transpose()
    }

    /// The fittest elite (ties go to the lower cell), or None while the map is empty.
    fn best(&self, py: Python<'_>) -> PyResult<Option<Variety>> {
        let (best, names) = self.with(|m| (m.best(), m.term_names().to_vec()));
        best.map(|v| Variety::of(py, v, &names)).transpose()
    }

    /// The checkpoint's text (JSON): everything needed to resume exactly.
    fn checkpoint(&self, py: Python<'_>) -> PyResult<String> {
        py.detach(|| self.with(|m| m.checkpoint())).py()
    }

    /// Writes the checkpoint file (atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| {
            let text = self.with(|m| m.checkpoint())?;
            sylva::files::write(&path, text.as_bytes())
        })
        .py()
    }

    /// Pickled through its checkpoint: unpickled, it resumes exactly where it was
    /// (`Varieties.resume(config, text=checkpoint)`), for multiprocessing and Ray.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let resume = py.get_type::<Varieties>().getattr("resume")?;
        let config = self.config();
        let text = self.checkpoint(py)?;
        Ok((resume, (config, None::<PathBuf>, text))
            .into_pyobject(py)?
            .into_any())
    }

    fn __repr__(&self) -> String {
        self.with(|m| {
            let filled = m.stats().last().map_or(0, |s| s.filled);
            format!(
                "<sylva.Varieties {} generation {}, {filled}/{} cells>",
                m.title(),
                m.generation(),
                m.cells()
            )
        })
    }
}

/// Starts a map of varieties (MAP-Elites) of `config`: a `Config`, a dict or the path of a
/// config file, with its `[map]` or the default map. The same as `Varieties(config, start,
/// threads)`.
#[pyfunction]
#[pyo3(pass_module, signature = (config, *, threads = None, start = None))]
pub fn varieties(
    module: &Bound<'_, PyModule>,
    py: Python<'_>,
    config: &Bound<'_, PyAny>,
    threads: Option<Whole>,
    start: Option<Vec<Genome>>,
) -> PyResult<Varieties> {
    Varieties::start(py, &Models::of(module.as_any())?, config, start, threads)
}
