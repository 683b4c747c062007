//! The `Genome` class's data: a handle on a genome of the library's, which plants, members,
//! varieties and genome spaces hold and hand out. Its methods are `genome.rs`'s, which grow
//! genomes into `plant.rs`'s plants; so `plant.rs` depends on this, not on `genome.rs`, and
//! the modules' imports run one way.

use pyo3::prelude::*;

/// A genome of any of Sylva's models. Load it from a file (`Genome.load`), a dict
/// (`Genome.from_dict`) or JSON text (`Genome.from_json`); read and set its fields with
/// `genome["field"]` (dotted paths reach into nested fields: `genome["rotation1.angle"]`);
/// grow it with `grow`; breed it with `mutate` and `sylva.cross`.
#[pyclass(module = "sylva", name = "Genome", from_py_object)]
#[derive(Clone)]
pub struct Genome {
    pub inner: sylva::Genome,
}
