//! A module made with a registry of one's own (`_sylva::init`) reads, grows and evolves
//! that registry's models: here the toy fifth model of `sylva-testkit`, in an embedded
//! Python.

use std::ffi::CString;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use sylva::{ModelEntry, Registry};
use sylva_testkit::toy::Cylinder;

#[test]
fn a_module_made_with_a_registry_grows_and_evolves_its_models() {
    Python::initialize();
    Python::attach(|py| {
        let module = PyModule::new(py, "toy_sylva").unwrap();
        let models = Registry::standard()
            .clone()
            .with(ModelEntry::of::<Cylinder>());
        _sylva::init(&module, models).unwrap();
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("registry");
        std::fs::create_dir_all(&dir).unwrap();
        let errors = concat!(env!("CARGO_MANIFEST_DIR"), "/python/sylva/errors.py");
        let globals = PyDict::new(py);
        globals.set_item("sylva", &module).unwrap();
        globals.set_item("folder", &dir).unwrap();
        globals.set_item("errors_py", errors).unwrap();
        let code = CString::new(SCRIPT).unwrap();
        if let Err(e) = py.run(&code, Some(&globals), None) {
            let trace = e.traceback(py).and_then(|t| t.format().ok());
            panic!("{e}\n{}", trace.unwrap_or_default());
        }
        // The process holds one registry: a module with other models is refused.
        let other = PyModule::new(py, "standard_sylva").unwrap();
        let e = _sylva::init(&other, Registry::standard().clone()).unwrap_err();
        assert!(e.to_string().contains("cylinder"), "{e}");
    });
}

const SCRIPT: &str = r#"
import importlib.util
import os
import sys
import types

# Sylva's exception classes (the package's Python half, which this module's errors raise).
spec = importlib.util.spec_from_file_location("sylva.errors", errors_py)
errors = importlib.util.module_from_spec(spec)
spec.loader.exec_module(errors)
package = types.ModuleType("sylva")
package.errors = errors
sys.modules["sylva"] = package
sys.modules["sylva.errors"] = errors

# The module lists the fifth model beside the four.
assert sylva.models()["cylinder"], sylva.models()

# Its genome files are read, from text and from a file, with its own checks.
text = '{"model": "cylinder", "format": 1, "height": 2.5, "radius": 0.2}'
genome = sylva.Genome.from_json(text)
assert genome.model == "cylinder", genome.model
path = os.path.join(folder, "tall.json")
with open(path, "w") as f:
    f.write(text)
assert sylva.Genome.load(path) == genome
try:
    sylva.Genome.from_json(text.replace("2.5", "-1"))
    raise AssertionError("a negative height was read")
except errors.InputError as e:
    assert "`height` must be" in str(e), str(e)

# Random genomes, fields changed by hand, growing.
random = sylva.Genome.random("cylinder", 7)
assert random.model == "cylinder"
assert genome.with_field("height", 4.0)["height"] == 4.0
plant = genome.grow()
low, high = plant.bounds
# A cylinder 2.5 m tall, its bounds reaching a radius past each end at most.
assert 2.5 - 1e-3 < high[1] - low[1] < 2.5 + 2 * 0.2 + 1e-3, plant.bounds

# Configs of it, from a dict and from a file, evolve towards its target height.
config = sylva.Config.from_dict(
    {"model": "cylinder", "run": {"population": 12, "generations": 4, "seed": 3},
     "cylinder": {"target": 4.0, "start": ["tall.json"]}},
    base=folder,
)
run = sylva.Evolution(config)
for _ in range(4):
    run.step()
assert run.best().genome.model == "cylinder"
config_path = os.path.join(folder, "cylinder.toml")
with open(config_path, "w") as f:
    f.write(config.to_toml())
assert sylva.Evolution(config_path).best().genome.model == "cylinder"

# The module and its classes hold the one registry it was made with.
assert sylva.Genome._models is sylva._models and sylva.Config._models is sylva._models

# A studio archive reads its genomes with the same models.
db = os.path.join(folder, "studio.db")
if os.path.exists(db):
    os.remove(db)
with sylva.StudioArchive(db, create=True) as archive:
    ids = archive.add([{"genome": genome, "operator": "upload", "key": "tall"},
                       {"genome": random, "operator": "mutate", "parents": ["tall"]}])
    assert archive.genome(ids[1]) == random, archive.genome(ids[1])
    assert archive.parents(ids[1]) == [(ids[0], 1.0)]
"#;
