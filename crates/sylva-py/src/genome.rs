//! `Genome`'s methods: a genome of any model, its fields, growth and breeding by hand (the
//! class's data is [`crate::handle::Genome`], which the classes that hold genomes share).

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};
use sylva::Registry;

use crate::errors::{IntoPy, bad_value};
use crate::handle::Genome;
use crate::json::{from_py, pointer, to_py};
use crate::models::Models;
use crate::plant::Plant;
use crate::whole::{self, Whole};

impl Genome {
    /// A genome file's text, read with `registry`; `source` names it in errors.
    fn parse(registry: &Registry, text: &str, source: &str) -> PyResult<Genome> {
        let inner = registry
            .parse_genome(text)
            .map_err(|e| sylva::InputError::genome(Path::new(source), text, e))
            .py()?;
        Ok(Genome { inner })
    }

    /// The genome file's JSON.
    fn value(&self) -> serde_json::Value {
        // A genome's own text always parses back.
        serde_json::from_str(&self.inner.to_json()).unwrap_or_default()
    }
}

#[pymethods]
impl Genome {
    /// Reads a genome file of any model.
    #[classmethod]
    fn load(cls: &Bound<'_, PyType>, path: PathBuf) -> PyResult<Genome> {
        let inner = Models::of(cls)?.get().registry().load_genome(&path).py()?;
        Ok(Genome { inner })
    }

    /// A genome from a dict shaped like a genome file (with its `model` and `format`).
    #[classmethod]
    fn from_dict(cls: &Bound<'_, PyType>, data: &Bound<'_, PyAny>) -> PyResult<Genome> {
        let value = from_py(data, "genome dict")?;
        let text = serde_json::to_string_pretty(&value).unwrap_or_default();
        Genome::parse(Models::of(cls)?.get().registry(), &text, "<genome dict>")
    }

    /// A genome from a genome file's JSON text; `source` names it in errors.
    #[classmethod]
    #[pyo3(signature = (text, source = "<json>"))]
    fn from_json(cls: &Bound<'_, PyType>, text: &str, source: &str) -> PyResult<Genome> {
        Genome::parse(Models::of(cls)?.get().registry(), text, source)
    }

    /// A random genome of `model` ("bintree", "automata", "plantmaker" or "lsystem"),
    /// made by the model with `settings` (a dict of its settings, or its defaults).
    #[classmethod]
    #[pyo3(signature = (model, seed, settings = None))]
    fn random(
        cls: &Bound<'_, PyType>,
        model: &str,
        seed: Whole,
        settings: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Genome> {
        let seed: u64 = seed.get("seed")?;
        let models = Models::of(cls)?;
        let registry = models.get().registry();
        let entry = registry.get(model).ok_or_else(|| {
            let names: Vec<&str> = registry.models().iter().map(|m| m.name()).collect();
            bad_value(
                "model",
                format!(
                    "unknown model `{model}`; expected one of: {}",
                    names.join(", ")
                ),
            )
        })?;
        let settings = settings.map(|s| from_py(s, "settings")).transpose()?;
        let inner = entry.random(settings.as_ref().into(), seed).py()?;
        Ok(Genome { inner })
    }

    /// The model's name: "bintree", "automata", "plantmaker" or "lsystem".
    #[getter]
    fn model(&self) -> &'static str {
        self.inner.model()
    }

    /// The model's title.
    #[getter]
    fn title(&self) -> &'static str {
        self.inner.title()
    }

    /// The seed the genome grows with when none is given.
    #[getter]
    fn default_seed(&self) -> u64 {
        self.inner.default_seed()
    }

    /// The genome as a dict, exactly as its file holds it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.value())
    }

    /// The genome file's text: pretty JSON ending with a newline.
    fn to_json(&self) -> String {
        self.inner.to_json()
    }

    /// Writes the genome file (atomically: the file appears whole or not at all).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        sylva::files::write(&path, self.inner.to_json().as_bytes()).py()
    }

    /// The names of the genome's fields (`model` and `format` left out).
    fn fields(&self) -> Vec<String> {
        match self.value() {
            serde_json::Value::Object(map) => map
                .keys()
                .filter(|k| !matches!(k.as_str(), "model" | "format"))
                .cloned()
                .collect(),
            _ => Vec::new(),
        }
    }

    /// A field's value; dotted paths reach into nested fields and lists.
    fn __getitem__<'py>(&self, py: Python<'py>, field: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = self.value();
        let found = value.pointer(&pointer(field)).ok_or_else(|| {
            pyo3::exceptions::PyKeyError::new_err(format!(
                "`{}` genomes have no field `{field}`; fields: {}",
                self.inner.model(),
                self.fields().join(", ")
            ))
        })?;
        to_py(py, found)
    }

    /// A copy with `field` set to `value`, checked as the genome file would be: a value out
    /// of its range raises `InputError` naming the field.
    fn with_field(&self, field: &str, value: &Bound<'_, PyAny>) -> PyResult<Genome> {
        let new = from_py(value, field)?;
        let schema = self.inner.schema();
        if schema.field(field).is_some() {
            // Out of its range: named with the range and the value, before the model reads it.
            schema.check(field, &new).map_err(|e| bad_value(field, e))?;
        }
        let mut genome = self.value();
        let slot = genome.pointer_mut(&pointer(field)).ok_or_else(|| {
            bad_value(
                field,
                format!(
                    "`{}` genomes have no field `{field}`; fields: {}",
                    self.inner.model(),
                    self.fields().join(", ")
                ),
            )
        })?;
        *slot = new;
        let text = serde_json::to_string_pretty(&genome).unwrap_or_default();
        let inner = self
            .inner
            .reparse(&text)
            .map_err(|e| bad_value(field, e.message))?;
        Ok(Genome { inner })
    }

    /// Grows the plant with `seed` (the genome's own seed when none is given) and meshes it;
    /// `roots=False` leaves the roots out; `taper=E` thickens the branches by the pipe model,
    /// radius ∝ (tips above)^(1/E), E from 2 to 3; `wind=S` adds a wind skin and a looping
    /// clip named `wind` (strength S from 0 to 10, 1 a breeze; `wind_period` seconds a sway,
    /// 0.5 to 60, default 4), which the plant's GLB carries; `height=M` scales the plant so
    /// that it stands M metres tall (0.01 to 1000); `foliage="oak"` puts leaves or needles
    /// of a kind on it at their real size as alpha-cut cards, `bark="furrowed"` a tiling
    /// bark (the foliage's own by default), `density` cards per metre of twig (0.25 to 4).
    /// Releases the GIL.
    #[pyo3(signature = (seed = None, roots = true, taper = None, wind = None, wind_period = None, height = None, foliage = None, bark = None, density = None))]
    #[allow(clippy::too_many_arguments)]
    fn grow(
        &self,
        py: Python<'_>,
        seed: Option<Whole>,
        roots: bool,
        taper: Option<f64>,
        wind: Option<f32>,
        wind_period: Option<f32>,
        height: Option<f32>,
        foliage: Option<&str>,
        bark: Option<&str>,
        density: Option<f32>,
    ) -> PyResult<Plant> {
        let seed = whole::get(seed, "seed")?;
        let genome = self.inner.clone();
        let taper = taper
            .map(sylva::core::taper::PipeTaper::new)
            .transpose()
            .map_err(|e| bad_value("taper", e))?;
        let wind = wind_options(wind, wind_period)?;
        let options = sylva::GrowOptions {
            seed,
            roots,
            taper,
            wind,
            height: height_value(height)?,
            dress: dress_value(sylva::Dress::default(), foliage, bark, density)?,
            ..sylva::GrowOptions::default()
        };
        let grown = py.detach(|| sylva::Grown::grow(genome, &options)).py()?;
        Ok(Plant::with_wind(grown, wind))
    }

    /// Loads a species preset (`.toml`: a genome and how it grows, as
    /// `examples/species/oak.toml`) and grows it; the arguments given override the file's.
    #[classmethod]
    #[pyo3(signature = (path, seed = None, height = None, foliage = None, bark = None, density = None))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments.
    fn grow_preset(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        path: std::path::PathBuf,
        seed: Option<Whole>,
        height: Option<f32>,
        foliage: Option<&str>,
        bark: Option<&str>,
        density: Option<f32>,
    ) -> PyResult<Plant> {
        let seed: Option<u64> = whole::get(seed, "seed")?;
        let preset = sylva::preset::Preset::load(Models::of(cls)?.get().registry(), &path)
            .map_err(|e| crate::errors::input_error(&e))?;
        let options = sylva::GrowOptions {
            seed: seed.or(preset.options.seed),
            height: height_value(height)?.or(preset.options.height),
            dress: dress_value(preset.options.dress, foliage, bark, density)?,
            ..preset.options
        };
        let grown = py
            .detach(|| sylva::Grown::grow(preset.genome, &options))
            .py()?;
        Ok(Plant::new(grown))
    }

    /// A mutated copy, made by the model's own mutation with `settings` (a dict of the
    /// model's settings, or its defaults), drawing from the stream of `seed`.
    #[pyo3(signature = (seed, settings = None))]
    fn mutate(&self, seed: Whole, settings: Option<&Bound<'_, PyAny>>) -> PyResult<Genome> {
        let seed: u64 = seed.get("seed")?;
        let settings = settings.map(|s| from_py(s, "settings")).transpose()?;
        let inner = self.inner.mutate(settings.as_ref().into(), seed).py()?;
        Ok(Genome { inner })
    }

    /// Sets a field in place, checked as [`Genome::with_field`] checks it.
    fn __setitem__(&mut self, field: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        *self = self.with_field(field, value)?;
        Ok(())
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Genome>()
            .is_ok_and(|o| o.borrow().inner == self.inner)
    }

    /// The hash of its genome file's text: equal genomes hash alike, so genomes are set
    /// members and dict keys (do not set a field of one while it is).
    fn __hash__(&self) -> u64 {
        sylva::core::hash::stable_hash(self.inner.to_json().as_bytes())
    }

    fn __repr__(&self) -> String {
        let hash = sylva::core::hash::stable_hash(self.inner.to_json().as_bytes());
        format!("<sylva.Genome {} {hash:016x}>", self.inner.model())
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        // Pickled as its JSON text, so genomes cross process pools and Ray.
        let from_json = py.get_type::<Genome>().getattr("from_json")?;
        Ok((from_json, (self.inner.to_json(),))
            .into_pyobject(py)?
            .into_any())
    }
}

/// A child of two or more parents of one model, made by the model's own crossover with
/// `settings`, drawing from the stream of `seed`. `dominance` gives each parent's weight
/// (all equal when left out). Returns the child and the positions of the parents that
/// gave it genes.
#[pyfunction]
#[pyo3(signature = (parents, seed, dominance = None, settings = None))]
pub fn cross(
    parents: Vec<Genome>,
    seed: Whole,
    dominance: Option<Vec<f64>>,
    settings: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Genome, Vec<usize>)> {
    let seed: u64 = seed.get("seed")?;
    let dominance = dominance.unwrap_or_else(|| vec![1.0; parents.len()]);
    if dominance.len() != parents.len() {
        return Err(bad_value(
            "dominance",
            format!(
                "{} weights for {} parents; give one per parent",
                dominance.len(),
                parents.len()
            ),
        ));
    }
    if let Some(d) = dominance.iter().find(|d| !d.is_finite() || **d < 0.0) {
        return Err(bad_value(
            "dominance",
            format!("{d} is not a weight; expected a finite number of 0 or more"),
        ));
    }
    let settings = settings.map(|s| from_py(s, "settings")).transpose()?;
    let pairs: Vec<(&sylva::Genome, f64)> =
        parents.iter().map(|g| &g.inner).zip(dominance).collect();
    let (child, used) = sylva::Genome::cross(&pairs, settings.as_ref().into(), seed).py()?;
    Ok((Genome { inner: child }, used))
}

/// Seconds per call of the library's grow-and-mesh (`sylva::Grown::grow`) of `genome`,
/// timed in Rust over `repeats` calls: the baseline `benches/overhead.py` compares
/// `Genome.grow` with.
#[pyfunction]
pub fn _rust_grow_seconds(
    py: Python<'_>,
    genome: &Genome,
    seed: u64,
    repeats: u32,
) -> PyResult<f64> {
    let genome = genome.inner.clone();
    py.detach(|| {
        let start = std::time::Instant::now();
        for _ in 0..repeats.max(1) {
            let options = sylva::GrowOptions {
                seed: Some(seed),
                ..sylva::GrowOptions::default()
            };
            std::hint::black_box(sylva::Grown::grow(genome.clone(), &options)?);
        }
        Ok::<_, sylva::Error>(start.elapsed().as_secs_f64() / f64::from(repeats.max(1)))
    })
    .py()
}

/// The models Sylva knows: a dict of name to title.
#[pyfunction]
#[pyo3(pass_module)]
pub fn models<'py>(module: &Bound<'py, PyModule>) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(module.py());
    for m in Models::of(module.as_any())?.get().registry().models() {
        dict.set_item(m.name(), m.title())?;
    }
    Ok(dict)
}

/// A model's genome field by field: a dict of `fields` (each field's `path`, `group`,
/// `meaning`, `kind` with its range, `unit`, `shapes`, `optional`), `lists` and
/// `structures`. The studio's panel and docs/genomes.md show the same.
#[pyfunction]
#[pyo3(pass_module)]
pub fn schema<'py>(module: &Bound<'py, PyModule>, model: &str) -> PyResult<Bound<'py, PyAny>> {
    let models = Models::of(module.as_any())?;
    let registry = models.get().registry();
    let entry = registry.get(model).ok_or_else(|| {
        let known: Vec<_> = registry.models().iter().map(|m| m.name()).collect();
        bad_value(
            "model",
            format!(
                "no model is named {model:?}; expected one of {}",
                known.join(", ")
            ),
        )
    })?;
    to_py(module.py(), &serde_json::json!(entry.schema()))
}

/// The wind `grow` asks for: none without a strength, a period only with one.
fn wind_options(
    strength: Option<f32>,
    period: Option<f32>,
) -> PyResult<Option<sylva::mesh::wind::WindOptions>> {
    use sylva::mesh::wind::{WindError, WindOptions};
    let Some(strength) = strength else {
        return match period {
            Some(_) => Err(bad_value(
                "wind_period",
                "a period needs wind: give `wind`, a strength from 0 to 10, too",
            )),
            None => Ok(None),
        };
    };
    let period = period.unwrap_or(WindOptions::default().period);
    WindOptions::new(strength, period).map(Some).map_err(|e| {
        let argument = match e {
            WindError::Strength(_) => "wind",
            WindError::Period(_) => "wind_period",
        };
        bad_value(argument, e)
    })
}

/// A height for `grow`, checked.
fn height_value(height: Option<f32>) -> PyResult<Option<f32>> {
    let (lo, hi) = sylva::assets::HEIGHTS;
    match height {
        Some(h) if !(lo..=hi).contains(&h) => Err(bad_value(
            "height",
            format!("expected metres from {lo} to {hi}, got {h}"),
        )),
        h => Ok(h),
    }
}

/// `base` with the dress arguments given: kinds by name, density checked.
fn dress_value(
    base: sylva::Dress,
    foliage: Option<&str>,
    bark: Option<&str>,
    density: Option<f32>,
) -> PyResult<sylva::Dress> {
    let mut dress = base;
    if let Some(name) = foliage {
        dress.foliage = Some(
            name.parse()
                .map_err(|e: sylva::core::species::UnknownKind| bad_value("foliage", e))?,
        );
    }
    if let Some(name) = bark {
        dress.bark = Some(
            name.parse()
                .map_err(|e: sylva::core::species::UnknownKind| bad_value("bark", e))?,
        );
    }
    if let Some(d) = density {
        if !(0.25..=4.0).contains(&d) {
            return Err(bad_value(
                "density",
                format!("expected a multiple from 0.25 to 4, got {d}"),
            ));
        }
        dress.density = d;
    }
    Ok(dress)
}
