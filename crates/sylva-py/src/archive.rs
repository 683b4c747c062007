//! `StudioArchive`: the studio's archive (the SQLite file of `sylva studio --db FILE`) on the
//! library's [`sylva::archive`]: its plants listed and read, their genomes and parents, and
//! bred plants written back with their parents in one transaction, beside a running studio.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};
use sylva::archive::{AddedParent, Addition, Archive, Operator, ParentId};

use crate::errors::{archive_closed, archive_error, bad_value};
use crate::handle::Genome;
use crate::json::{from_py, to_py};
use crate::models::Models;
use crate::whole::Whole;

/// A studio archive, the SQLite file of `sylva studio --db FILE`: its plants (`plants`,
/// `plant`, `genome`, `parents`) and plants bred elsewhere written into it (`add`), which
/// the studio then shows beside its own. The file must be an archive already (`create=True`
/// makes one, or brings an older one up to date, as the studio does). It may be open in a
/// running studio meanwhile: reads never wait, and a write waits up to five seconds for the
/// studio's to finish. Errors are `ArchiveError`, naming the file. Use it in a `with` block,
/// or `close` it, to let the file go at once.
#[pyclass(module = "sylva", name = "StudioArchive", frozen)]
pub struct StudioArchive {
    archive: Mutex<Option<Arc<Archive>>>,
    models: Py<Models>,
    path: PathBuf,
}

/// A plant of a studio archive, as listed: everything but its genome, which
/// `StudioArchive.genome(id)` reads.
#[pyclass(module = "sylva", name = "ArchivedPlant", frozen, get_all)]
pub struct ArchivedPlant {
    /// Its id (row) in the archive.
    id: i64,
    /// Its model.
    model: String,
    /// The seed it grows with.
    seed: u64,
    /// How it was made: random, example, upload, cross, mutate, edit, regrow, mother,
    /// family, design, map, match, empty or branch.
    operator: String,
    /// The studio session it was made in, or None (plants written by `add`).
    session: Option<i64>,
    /// When it was written (UTC, `2025-11-25T09:30:00Z`).
    created: String,
    /// The settings of its operator, as the studio recorded them.
    settings: Py<PyAny>,
}

#[pymethods]
impl ArchivedPlant {
    fn __repr__(&self) -> String {
        format!(
            "<sylva.ArchivedPlant {} {} {}>",
            self.id, self.model, self.operator
        )
    }
}

/// What `add` takes of each plant.
const FIELDS: [&str; 7] = [
    "genome",
    "operator",
    "seed",
    "parents",
    "dominance",
    "key",
    "settings",
];

impl StudioArchive {
    /// The open archive, or `ArchiveError` once closed.
    fn open(&self) -> PyResult<Arc<Archive>> {
        let held = self.archive.lock().unwrap_or_else(|e| e.into_inner());
        held.clone().ok_or_else(|| archive_closed(&self.path))
    }

    fn listed(py: Python<'_>, row: sylva::archive::PlantSummary) -> PyResult<ArchivedPlant> {
        Ok(ArchivedPlant {
            id: row.id,
            model: row.model,
            seed: row.seed,
            operator: row.operator,
            session: row.session,
            created: row.created,
            settings: to_py(py, &row.settings)?.unbind(),
        })
    }
}

#[pymethods]
impl StudioArchive {
    /// Opens the studio archive at `path`: it must exist, be an archive and be of a schema
    /// this Sylva knows, and nothing in it changes but the plants `add` writes. With
    /// `create=True`, a missing file is made and an older schema brought up to date, as
    /// `sylva studio --db` does.
    #[new]
    #[classmethod]
    #[pyo3(signature = (path, create = false))]
    fn new(
        cls: &Bound<'_, PyType>,
        py: Python<'_>,
        path: PathBuf,
        create: bool,
    ) -> PyResult<StudioArchive> {
        let models = Models::of(cls)?.unbind();
        let path = std::path::absolute(&path).unwrap_or(path);
        let archive = py
            .detach(|| match create {
                true => Archive::open(&path),
                false => Archive::open_existing(&path),
            })
            .map_err(archive_error)?;
        Ok(StudioArchive {
            archive: Mutex::new(Some(Arc::new(archive))),
            models,
            path,
        })
    }

    /// The file, absolute.
    #[getter]
    fn path(&self) -> String {
        self.path.display().to_string()
    }

    /// The file's schema version.
    #[getter]
    fn version(&self) -> PyResult<usize> {
        Ok(self.open()?.version())
    }

    /// The newest `limit` plants, newest first, of `model` or of every model.
    #[pyo3(signature = (model = None, limit = Whole(500)))]
    fn plants(
        &self,
        py: Python<'_>,
        model: Option<&str>,
        limit: Whole,
    ) -> PyResult<Vec<ArchivedPlant>> {
        let limit: u32 = limit.get("limit")?;
        let archive = self.open()?;
        let rows = py
            .detach(|| archive.newest_plants(model, limit))
            .map_err(archive_error)?;
        rows.into_iter()
            .map(|row| StudioArchive::listed(py, row))
            .collect()
    }

    /// The plant of `id`; `ArchiveError` if there is none.
    fn plant(&self, py: Python<'_>, id: i64) -> PyResult<ArchivedPlant> {
        let archive = self.open()?;
        let row = py.detach(|| archive.plant(id)).map_err(archive_error)?;
        StudioArchive::listed(
            py,
            sylva::archive::PlantSummary {
                id: row.id,
                session: row.session,
                model: row.model,
                seed: row.seed,
                operator: row.operator,
                settings: row.settings,
                created: row.created,
            },
        )
    }

    /// The genome of plant `id`, read with this module's models; a genome that does not
    /// read raises `InputError` naming the archive and the plant as its file
    /// (`studio.db plant 12`).
    fn genome(&self, py: Python<'_>, id: i64) -> PyResult<Genome> {
        let archive = self.open()?;
        let models = self.models.bind(py).get();
        let inner = py
            .detach(|| archive.genome(models.registry(), id))
            .map_err(archive_error)?;
        Ok(Genome { inner })
    }

    /// The parents of plant `id`, in order: `(id, dominance)` each.
    fn parents(&self, py: Python<'_>, id: i64) -> PyResult<Vec<(i64, f64)>> {
        let archive = self.open()?;
        let rows = py.detach(|| archive.parents(id)).map_err(archive_error)?;
        Ok(rows.into_iter().map(|p| (p.plant, p.dominance)).collect())
    }

    /// Writes plants made outside the studio, each after its parents, in one transaction
    /// (all or, on any error, none), in no session; returns their ids, in order. Each is a
    /// dict: `genome` (a `Genome`), `operator` (how it was made: `"mutate"`, `"cross"`,
    /// `"example"`, `"upload"`, `"random"`, ...), and optionally `seed` (the genome's own by
    /// default), `parents` (each the id of a plant in the archive, or the `key` of a plant
    /// given before it in this call), `dominance` (one weight per parent, 1 each by
    /// default), `key` (a name for later plants of this call to give as a parent) and
    /// `settings` (a dict of JSON values recorded with it, `{}` by default).
    fn add(&self, py: Python<'_>, plants: &Bound<'_, PyAny>) -> PyResult<Vec<i64>> {
        let additions = additions(plants)?;
        let archive = self.open()?;
        py.detach(|| archive.add_plants(&additions))
            .map_err(archive_error)
    }

    /// Lets the file go; the archive reads and writes no more.
    fn close(&self) {
        self.archive
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
    }

    fn __enter__(slf: Bound<'_, Self>) -> Bound<'_, Self> {
        slf
    }

    fn __exit__(
        &self,
        _kind: Option<&Bound<'_, PyAny>>,
        _error: Option<&Bound<'_, PyAny>>,
        _trace: Option<&Bound<'_, PyAny>>,
    ) -> bool {
        self.close();
        false
    }

    fn __repr__(&self) -> String {
        format!("<sylva.StudioArchive {}>", self.path.display())
    }
}

/// `add`'s plants, checked, each error naming its place (`plants[2].parents[0]`).
fn additions(plants: &Bound<'_, PyAny>) -> PyResult<Vec<Addition>> {
    let mut keys: Vec<Option<String>> = Vec::new();
    let mut out = Vec::new();
    let items: Vec<Bound<'_, PyAny>> = plants
        .try_iter()
        .map_err(|_| bad_value("plants", "expected a list of dicts"))?
        .collect::<PyResult<_>>()?;
    for (i, item) in items.iter().enumerate() {
        let at = |field: &str| format!("plants[{i}].{field}");
        let dict = item.cast::<PyDict>().map_err(|_| {
            bad_value(
                format!("plants[{i}]"),
                "expected a dict with `genome` and `operator`",
            )
        })?;
        for key in dict.keys() {
            let name: String = key.extract().unwrap_or_else(|_| key.to_string());
            if !FIELDS.contains(&name.as_str()) {
                return Err(bad_value(
                    at(&name),
                    format!("unknown field; expected {}", FIELDS.join(", ")),
                ));
            }
        }
        let genome: Genome = dict
            .get_item("genome")?
            .ok_or_else(|| bad_value(at("genome"), "missing: give the plant's sylva.Genome"))?
            .extract()
            .map_err(|_| bad_value(at("genome"), "expected a sylva.Genome"))?;
        let operator: String = dict
            .get_item("operator")?
            .ok_or_else(|| bad_value(at("operator"), "missing: say how the plant was made"))?
            .extract()
            .map_err(|_| bad_value(at("operator"), "expected a str"))?;
        let operator = Operator::parse(&operator).ok_or_else(|| {
            bad_value(
                at("operator"),
                format!(
                    "unknown operator `{operator}`; expected {}",
                    Operator::expected()
                ),
            )
        })?;
        let seed = match dict.get_item("seed")? {
            None => genome.inner.default_seed(),
            Some(s) if s.is_none() => genome.inner.default_seed(),
            Some(s) => s
                .extract()
                .map_err(|_| bad_value(at("seed"), "expected an int from 0 to 2**64 - 1"))?,
        };
        let settings = match dict.get_item("settings")? {
            None => serde_json::json!({}),
            Some(s) => from_py(&s, &at("settings"))?,
        };
        let key: Option<String> = match dict.get_item("key")? {
            None => None,
            Some(k) if k.is_none() => None,
            Some(k) => {
                let k: String = k
                    .extract()
                    .map_err(|_| bad_value(at("key"), "expected a str"))?;
                if keys.iter().flatten().any(|earlier| *earlier == k) {
                    return Err(bad_value(
                        at("key"),
                        format!("`{k}` is the key of an earlier plant; give each its own"),
                    ));
                }
                Some(k)
            }
        };
        let given: Vec<Bound<'_, PyAny>> = match dict.get_item("parents")? {
            None => Vec::new(),
            Some(p) => p
                .try_iter()
                .map_err(|_| bad_value(at("parents"), "expected a list"))?
                .collect::<PyResult<_>>()?,
        };
        let mut parents = Vec::with_capacity(given.len());
        for (j, parent) in given.iter().enumerate() {
            let place = format!("plants[{i}].parents[{j}]");
            let plant = if let Ok(k) = parent.extract::<String>() {
                let earlier = keys.iter().position(|e| e.as_deref() == Some(k.as_str()));
                ParentId::Earlier(earlier.ok_or_else(|| {
                    bad_value(
                        &place,
                        format!("no plant before this one has the key `{k}`"),
                    )
                })?)
            } else if let Ok(id) = parent.extract::<i64>() {
                ParentId::Row(id)
            } else {
                return Err(bad_value(
                    &place,
                    "expected the id of an archived plant (int) or the key of an earlier one (str)",
                ));
            };
            parents.push(AddedParent {
                plant,
                dominance: 1.0,
            });
        }
        if let Some(d) = dict.get_item("dominance")?
            && !d.is_none()
        {
            let weights: Vec<f64> = d
                .extract()
                .map_err(|_| bad_value(at("dominance"), "expected a list of floats"))?;
            if weights.len() != parents.len() {
                return Err(bad_value(
                    at("dominance"),
                    format!(
                        "{} weights for {} parents; give one per parent",
                        weights.len(),
                        parents.len()
                    ),
                ));
            }
            for (j, (parent, w)) in parents.iter_mut().zip(weights).enumerate() {
                if !(w.is_finite() && w >= 0.0) {
                    return Err(bad_value(
                        format!("plants[{i}].dominance[{j}]"),
                        format!("{w}; expected a number, 0 or more"),
                    ));
                }
                parent.dominance = w;
            }
        }
        keys.push(key);
        out.push(Addition {
            genome: genome.inner,
            seed,
            operator,
            settings,
            parents,
        });
    }
    Ok(out)
}
