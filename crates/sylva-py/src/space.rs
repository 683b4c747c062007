//! `GenomeSpace`: any model's genomes as numpy vectors, for optimisers outside Sylva
//! (pyribs, CMA-ES, a loop of one's own): bounds, decoding, encoding, and scoring batches
//! as the config's MAP-Elites run scores them.

use crate::varieties::interruptible;
use crate::work::Serving;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArray};
use numpy::{PyArrayDescrMethods, PyUntypedArrayMethods, dtype};
use pyo3::prelude::*;
use pyo3::types::PyType;
use sylva::core::par::Pool;
use sylva::evolution::Stop;
use sylva::evolution::{Coding, SpaceOptions};

use crate::errors::{IntoPy, bad_value};
use crate::evolution::{Config, Evolution};
use crate::handle::Genome;
use crate::models::Models;
use crate::whole::{self, Whole};

/// `value` as float64 numbers and their shape; anything but numbers (an array of another
/// kind, text, ragged lists) raises `TypeError` naming the argument `name`.
fn numbers(
    py: Python<'_>,
    value: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let refused = |what: String| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "`{name}` must be a numpy array (or a sequence) of numbers; {what}"
        ))
    };
    if let Ok(array) = value.cast::<PyUntypedArray>() {
        let kind = array.dtype().kind();
        if !matches!(kind, b'i' | b'u' | b'f') {
            return Err(refused(format!("got an array of dtype {}", array.dtype())));
        }
    }
    let numpy = py.import("numpy")?;
    let array = numpy
        .call_method1("asarray", (value, dtype::<f64>(py)))
        .map_err(|e| refused(format!("got {}", e.value(py))))?;
    let array = array
        .cast::<PyArrayDyn<f64>>()
        .map_err(|e| refused(e.to_string()))?
        .readonly();
    let shape = array.shape().to_vec();
    Ok((array.as_array().iter().copied().collect(), shape))
}

/// A shape as Python writes it.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// A model's genomes as vectors of numbers under a config (docs/python.md): `dim` entries,
/// each within `lower` and `upper`; `decode` makes the genome of a vector, `encode` the
/// vector of a genome (direct codings only), and `evaluate` scores a batch with the
/// config's own fitness (the model's terms and `[match]`, if any) and its `[map]`'s
/// descriptors, exactly as `sylva.varieties` scores its offspring, in parallel on
/// `threads` with the GIL released. `coding` is `"direct"` (an entry per parameter:
/// binary trees and PlantMaker) or `"codons"` (entries from 0 to 1 read as the draws of
/// the model's random genome generator: every model); by default direct where the model
/// has it. `seed` (the config's `[run] seed` by default) is what decoded genomes take for
/// anything the vector does not hold. The config's `start` genome files are read as a run
/// reads them (an L-system space's random genomes are mutants of its start genome).
#[pyclass(module = "sylva", name = "GenomeSpace", frozen)]
pub struct GenomeSpace {
    space: sylva::GenomeSpace,
    pool: Pool,
    config: Config,
    threads: Option<u32>,
}

impl GenomeSpace {
    /// `x` as one vector of this space.
    fn vector(&self, py: Python<'_>, x: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let (values, shape) = numbers(py, x, "x")?;
        if shape != [self.space.dim()] {
            return Err(bad_value(
                "x",
                format!(
                    "expected a vector of shape ({},) (this space's `dim`), got shape {}",
                    self.space.dim(),
                    shape_text(&shape)
                ),
            ));
        }
        Ok(values)
    }

    /// `xs` as rows of vectors of this space.
    fn rows(&self, py: Python<'_>, xs: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let (values, shape) = numbers(py, xs, "X")?;
        if !matches!(shape[..], [_, d] if d == self.space.dim()) {
            return Err(bad_value(
                "X",
                format!(
                    "expected an array of shape (n, {}), one vector per row, got shape {}",
                    self.space.dim(),
                    shape_text(&shape)
                ),
            ));
        }
        Ok(values)
    }

    fn bound(&self, py: Python<'_>, end: usize) -> Py<PyArray1<f64>> {
        let values = self.space.bounds().iter().map(|b| b[end]).collect();
        PyArray1::from_vec(py, values).unbind()
    }
}

#[pymethods]
impl GenomeSpace {
    /// The space of `config`'s genomes (a `Config`, a dict or a config file's path).
    #[new]
    #[classmethod]
    #[pyo3(signature = (config, dim = None, *, coding = None, seed = None, threads = None))]
    fn new(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        dim: Option<Whole>,
        coding: Option<&str>,
        seed: Option<Whole>,
        threads: Option<Whole>,
    ) -> PyResult<GenomeSpace> {
        let dim = whole::get(dim, "dim")?;
        let seed = whole::get(seed, "seed")?;
        let threads = whole::get(threads, "threads")?;
        let models = Models::of(cls)?;
        let registry = models.get().registry();
        let config = Config::from_any(registry, config)?;
        let coding = match coding {
            None => None,
            Some(name) => Some(Coding::from_name(name).ok_or_else(|| {
                bad_value(
                    "coding",
                    format!("expected \"direct\" or \"codons\", got {name:?}"),
                )
            })?),
        };
        let options = SpaceOptions { coding, dim, seed };
        let pool = Evolution::pool(&config.inner, threads)?;
        let start = config.inner.load_start(registry, &config.base).py()?;
        let inner = &config.inner;
        let space = py
            .detach(|| sylva::GenomeSpace::new(inner, start, &options))
            .py()?;
        Ok(GenomeSpace {
            space,
            pool,
            config,
            threads,
        })
    }

    /// The model's name.
    #[getter]
    fn model(&self) -> &'static str {
        self.space.model()
    }

    /// "direct" or "codons".
    #[getter]
    fn coding(&self) -> &'static str {
        self.space.coding().name()
    }

    /// Entries per vector.
    #[getter]
    fn dim(&self) -> usize {
        self.space.dim()
    }

    /// Each entry's lower bound, (dim,) float64.
    #[getter]
    fn lower(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.bound(py, 0)
    }

    /// Each entry's upper bound, (dim,) float64.
    #[getter]
    fn upper(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.bound(py, 1)
    }

    /// The seed decoded genomes take for what the vector does not hold.
    #[getter]
    fn seed(&self) -> u64 {
        self.space.seed()
    }

    /// The descriptors `evaluate` measures (the config's `[map]`), in column order.
    #[getter]
    fn descriptors(&self) -> Vec<&'static str> {
        self.space.descriptors().iter().map(|d| d.name()).collect()
    }

    /// Names of the fitness terms the config scores.
    #[getter]
    fn term_names(&self) -> Vec<String> {
        self.space.term_names().to_vec()
    }

    /// The genome of vector `x` ((dim,) numbers, each finite; entries beyond the bounds
    /// are clamped to them).
    fn decode(&self, py: Python<'_>, x: &Bound<'_, PyAny>) -> PyResult<Genome> {
        let x = self.vector(py, x)?;
        let inner = py.detach(|| self.space.decode(&x)).py()?;
        Ok(Genome { inner })
    }

    /// The genomes of the rows of `X` ((n, dim) numbers), in order. Releases the GIL.
    #[allow(non_snake_case)] // `X`: a batch of vectors, as pyribs and scikit-learn name it.
    fn decode_many(&self, py: Python<'_>, X: &Bound<'_, PyAny>) -> PyResult<Vec<Genome>> {
        let xs = self.rows(py, X)?;
        let genomes = py.detach(|| self.space.decode_many(&xs, &self.pool)).py()?;
        Ok(genomes.into_iter().map(|inner| Genome { inner }).collect())
    }

    /// The vector of `genome` ((dim,) float64), for a direct coding; raises `InputError`
    /// for a codon space, or a genome of another model or shape.
    fn encode(&self, py: Python<'_>, genome: &Genome) -> PyResult<Py<PyArray1<f64>>> {
        let x = self.space.encode(&genome.inner).py()?;
        Ok(PyArray1::from_vec(py, x).unbind())
    }

    /// Scores the rows of `X` ((n, dim) numbers): `(objective, descriptors)`, an (n,)
    /// float64 array of each row's fitness and an (n, k) one of its descriptors (NaN for a
    /// genome that cannot be grown, which a native map leaves out). Runs on the space's
    /// threads with the GIL released; the same numbers for any number of threads.
    #[allow(clippy::type_complexity)] // The pair of arrays Python receives.
    #[allow(non_snake_case)] // `X`, as in `decode_many`.
    fn evaluate(
        &self,
        py: Python<'_>,
        X: &Bound<'_, PyAny>,
    ) -> PyResult<(Py<PyArray1<f64>>, Py<PyArray2<f64>>)> {
        let xs = self.rows(py, X)?;
        // Ctrl-C stops the batch within one row's evaluation (`KeyboardInterrupt`).
        let (stop, serving) = (Stop::new(), Serving::default());
        let scores = interruptible(py, &stop, &serving, || self.space.evaluate(&xs, &self.pool))?;
        let (n, k) = (scores.fitness.len(), self.space.descriptors().len());
        let objective = PyArray1::from_vec(py, scores.fitness).unbind();
        let descriptors = PyArray1::from_vec(py, scores.descriptors)
            .reshape([n, k])?
            .unbind();
        Ok((objective, descriptors))
    }

    /// Pickled as the arguments that make it again.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let class = py.get_type::<GenomeSpace>();
        let kwargs = pyo3::types::PyDict::new(py);
        kwargs.set_item("coding", self.space.coding().name())?;
        kwargs.set_item("seed", self.space.seed())?;
        kwargs.set_item("threads", self.threads)?;
        let make = py
            .import("functools")?
            .getattr("partial")?
            .call((class,), Some(&kwargs))?;
        Ok((make, (self.config.clone(), self.space.dim()))
            .into_pyobject(py)?
            .into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "<sylva.GenomeSpace {} {} dim {}>",
            self.space.model(),
            self.space.coding().name(),
            self.space.dim()
        )
    }
}
