//! `Plant` (a grown genome), `Mesh` (numpy arrays), `Scene` (many plants) and gardens.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use numpy::ndarray::{ArrayView, ArrayView1, ArrayView2, Dimension};
use numpy::npyffi::{_PyArray_GET_ITEM_DATA, NPY_ARRAY_WRITEABLE};
use numpy::{PyArray, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use sylva::assets::{Origin, Placed, SceneAssets};
use sylva::core::measures::TreeMeasures;
use sylva::files::Outputs;
use sylva::mesh::wind::WindOptions;
use sylva::render::View;

use crate::errors::{IntoPy, bad_value};
use crate::handle::Genome;
use crate::json::to_py;
use crate::models::Models;
use crate::pair::Pair;
use crate::whole::Whole;

/// A grown genome: its plant's measures, its mesh, and the files it exports to.
#[pyclass(module = "sylva", name = "Plant", frozen)]
pub struct Plant {
    grown: sylva::Grown,
    /// The mesh's triangles gathered from its primitives, the first time they are asked for.
    triangles: OnceLock<Triangles>,
    /// The wind it grew with, for its levels of detail.
    wind: Option<WindOptions>,
}

impl Plant {
    pub fn new(grown: sylva::Grown) -> Plant {
        Plant::with_wind(grown, None)
    }

    /// A plant grown with `wind` (its rig is in `grown`).
    pub fn with_wind(grown: sylva::Grown, wind: Option<WindOptions>) -> Plant {
        Plant {
            grown,
            triangles: OnceLock::new(),
            wind,
        }
    }
}

#[pymethods]
impl Plant {
    /// The genome it grew from.
    #[getter]
    fn genome(&self) -> Genome {
        Genome {
            inner: self.grown.genome.clone(),
        }
    }

    /// The seed it grew with.
    #[getter]
    fn seed(&self) -> u64 {
        self.grown.seed
    }

    /// The model's name.
    #[getter]
    fn model(&self) -> &'static str {
        self.grown.genome.model()
    }

    /// Segments of the skeleton (tapered cylinders).
    #[getter]
    fn segments(&self) -> usize {
        self.grown.plant.segments().len()
    }

    /// Organs: leaves, flowers, fruits.
    #[getter]
    fn organs(&self) -> usize {
        self.grown.plant.organs().len()
    }

    /// End points of the skeleton.
    #[getter]
    fn tips(&self) -> usize {
        self.grown.plant.tips().count()
    }

    /// Highest point of the skeleton above the ground, metres.
    #[getter]
    fn height(&self) -> f32 {
        self.grown.plant.height()
    }

    /// Bounds of the plant as meshed, what a scene shows and an exporter writes: ((min x,
    /// y, z), (max x, y, z)), metres, the mesh's vertices' (zeros for an empty plant).
    #[getter]
    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let b = self.grown.mesh.bounds();
        if b.is_empty() {
            ([0.0; 3], [0.0; 3])
        } else {
            (b.min.to_array(), b.max.to_array())
        }
    }

    /// How the plant measures against real trees (`sylva inspect`): a dict from each
    /// figure's name to its `value` (None when not measured), `unit`, `label`, the range
    /// real trees give (`real`), the band outside which it is implausible (`check`), its
    /// `verdict` ("real", "unusual", "implausible", "none") and `source`.
    fn inspect<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        use sylva::inspect::{AssetFacts, Report};
        let report = Report::of(
            &self.grown.plant,
            Some(AssetFacts::of_mesh(&self.grown.mesh)),
        );
        let out = PyDict::new(py);
        for f in &report.figures {
            let d = PyDict::new(py);
            d.set_item("value", f.value)?;
            d.set_item("unit", f.unit)?;
            d.set_item("label", f.label)?;
            d.set_item("real", f.real)?;
            d.set_item("check", f.check)?;
            let verdict = match f.verdict() {
                sylva::inspect::Verdict::Real => "real",
                sylva::inspect::Verdict::Unusual => "unusual",
                sylva::inspect::Verdict::Implausible => "implausible",
                sylva::inspect::Verdict::None => "none",
            };
            d.set_item("verdict", verdict)?;
            d.set_item("source", f.source)?;
            out.set_item(f.name, d)?;
        }
        Ok(out)
    }

    /// Lateral area of all segments, square metres.
    #[getter]
    fn surface_area(&self) -> f32 {
        self.grown.plant.surface_area()
    }

    /// Volume of all segments, cubic metres.
    #[getter]
    fn volume(&self) -> f32 {
        self.grown.plant.volume()
    }

    /// Length of the whole skeleton, metres.
    #[getter]
    fn total_length(&self) -> f32 {
        self.grown.plant.total_length()
    }

    /// The six measures of Susinno's paper (height, surface area, volume, symmetry,
    /// straightness, radius-to-length, pipe model, roundness), as a dict.
    fn measures<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = TreeMeasures::of_plant(&self.grown.plant);
        to_py(py, &serde_json::to_value(m).unwrap_or_default())
    }

    /// The plant as data: the fields `sylva grow -o PLANT.skeleton.json` writes (origin,
    /// taper, roots, materials), with its `segments` and `organs` as dicts of numpy arrays,
    /// one row per segment or organ and one array per field of the file (`start` is an
    /// (N, 3) array, `parent` holds -1 for none, `kind` a list of names). See
    /// docs/skeleton.md; [`Plant::skeleton_json`] gives the file's text.
    fn skeleton<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let skeleton = sylva::Skeleton::of_grown(&self.grown);
        let out = PyDict::new(py);
        out.set_item("format", skeleton.format)?;
        out.set_item("kind", &skeleton.kind)?;
        out.set_item("sylva_version", &skeleton.sylva_version)?;
        // Through JSON text, so the small parts' floats read as the file writes them (0.2,
        // not the f32's 0.20000000298...).
        let loads = py.import("json")?.getattr("loads")?;
        let json = |text: serde_json::Result<String>| loads.call1((text.unwrap_or_default(),));
        out.set_item("origin", json(serde_json::to_string(&skeleton.origin))?)?;
        out.set_item("taper", json(serde_json::to_string(&skeleton.taper))?)?;
        out.set_item("roots", skeleton.roots)?;
        out.set_item(
            "materials",
            json(serde_json::to_string(&skeleton.materials))?,
        )?;
        out.set_item("segments", segment_arrays(py, &skeleton.segments)?)?;
        out.set_item("organs", organ_arrays(py, &skeleton.organs)?)?;
        Ok(out)
    }

    /// The plant as data in the skeleton file's own text (JSON), as `sylva grow -o
    /// PLANT.skeleton.json` writes it.
    fn skeleton_json(&self) -> String {
        sylva::Skeleton::of_grown(&self.grown).to_json()
    }

    /// The mesh, as read-only numpy arrays that view the plant's own memory (no copy).
    #[getter]
    fn mesh(this: &Bound<'_, Self>) -> PyResult<Mesh> {
        let plant = this.get();
        let triangles = plant
            .triangles
            .get_or_init(|| Triangles::of(&plant.grown.mesh));
        Mesh::view(this.as_any(), &plant.grown.mesh, triangles)
    }

    /// Writes the plant as GLB, OBJ (with its MTL and textures), VRML97 or STL (binary, in
    /// millimetres), by the file's extension; every file appears whole or not at all (a
    /// folder that is not there raises `FileNotFoundError`). Releases the GIL.
    fn export(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| write_scene(&self.grown.scene(), &path)).py()
    }

    /// The plant as GLB bytes.
    fn glb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py.detach(|| glb_bytes(&self.grown.scene())).py()?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The wind it grew with (`grow(wind=...)`), or None: a dict of its `strength` and
    /// `period` (seconds), the skin's `joints`, the finer joints `left_out` past the skin's
    /// limit, and the clip's name (`clip`, "wind").
    #[getter]
    fn wind<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let (Some(wind), Some(rig)) = (self.wind, &self.grown.rig) else {
            return Ok(None);
        };
        let dict = PyDict::new(py);
        dict.set_item("strength", wind.strength)?;
        dict.set_item("period", wind.period)?;
        dict.set_item("joints", rig.joints.len())?;
        dict.set_item("left_out", rig.dropped)?;
        dict.set_item("clip", "wind")?;
        Ok(Some(dict))
    }

    /// Its levels of detail as GLB bytes: `levels` (2 to 8) meshes of falling detail and
    /// then an impostor (two crossed cards showing the plant's picture) as sibling nodes
    /// named `NAME_LOD0` (the plant in full) to `NAME_LOD{levels}` (the impostor), each with
    /// its triangles and screen coverage in its extras, and the wind skin and clip on every
    /// meshed level when the plant has wind (as `sylva grow --lod` writes them). Grows the
    /// plant again. Releases the GIL.
    #[pyo3(signature = (levels, name = "plant"))]
    fn lod_glb<'py>(
        &self,
        py: Python<'py>,
        levels: Whole,
        name: &str,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let levels: usize = levels.get("levels")?;
        let most = sylva::lod::MAX_LEVELS;
        if !(2..=most).contains(&levels) {
            return Err(bad_value(
                "levels",
                format!("expected an int from 2 to {most}, got {levels}"),
            ));
        }
        if name.is_empty() {
            return Err(bad_value("name", "expected a name for the nodes, got \"\""));
        }
        let g = &self.grown;
        let options = sylva::GrowOptions {
            seed: Some(g.seed),
            roots: g.roots,
            taper: g.taper,
            wind: self.wind,
            lod: Some(levels),
            height: g.height,
            ..sylva::GrowOptions::default()
        };
        let genome = g.genome.clone();
        let bytes = py
            .detach(|| {
                let grown = sylva::Grown::grow(genome, &options)?;
                let chain = sylva::LodAssets::new(grown, &options)?;
                glb_bytes(&chain.group_scene(name))
            })
            .py()?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Renders a picture of the plant: PNG bytes, also written to `path` when given.
    /// `view` is "front", "side", "top" or "iso"; `size` is (width, height) in pixels, each
    /// 16 to 8192.
    #[pyo3(signature = (path = None, view = "iso", size = Pair(Whole(800), Whole(800))))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        path: Option<PathBuf>,
        view: &str,
        size: Pair<Whole>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        render(py, &self.grown.scene(), path, view, size.into())
    }

    /// The plant grown again from what it grew from (`Plant._regrow`): the same genome,
    /// seed, roots, taper and height give the same bytes.
    #[staticmethod]
    #[pyo3(signature = (genome, seed, roots, taper, height = None))]
    fn _regrow(
        py: Python<'_>,
        genome: &Genome,
        seed: u64,
        roots: bool,
        taper: Option<f64>,
        height: Option<f32>,
    ) -> PyResult<Plant> {
        let taper = taper
            .map(sylva::core::taper::PipeTaper::new)
            .transpose()
            .map_err(|e| bad_value("taper", e))?;
        let options = sylva::GrowOptions {
            seed: Some(seed),
            roots,
            taper,
            height,
            ..sylva::GrowOptions::default()
        };
        let genome = genome.inner.clone();
        let grown = py.detach(|| sylva::Grown::grow(genome, &options)).py()?;
        Ok(Plant::new(grown))
    }

    /// Pickled as what it grew from (genome, seed, roots, taper), so it grows again to the
    /// same bytes when unpickled: a few bytes for multiprocessing and Ray rather than its
    /// mesh.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        if self.grown.rig.is_some() {
            return Err(pyo3::exceptions::PyTypeError::new_err(
                "a plant grown with wind does not pickle",
            ));
        }
        let regrow = py.get_type::<Plant>().getattr("_regrow")?;
        let g = &self.grown;
        let args = (
            self.genome(),
            g.seed,
            g.roots,
            g.taper.map(|t| t.exponent),
            g.height,
        );
        Ok((regrow, args).into_pyobject(py)?.into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "<sylva.Plant {} seed {}: {} segments, {} organs, {} triangles>",
            self.grown.genome.model(),
            self.grown.seed,
            self.grown.plant.segments().len(),
            self.grown.plant.organs().len(),
            self.grown.mesh.triangle_count()
        )
    }
}

/// A triangle mesh as numpy arrays: `positions` and `normals` (n, 3) float32, `uvs` (n, 2)
/// float32, `indices` (t, 3) uint32, `triangle_materials` (t,) uint32 (an index into
/// `materials`), and `materials`, a list of dicts (name, kind, color, texture; picture and
/// normal_map, the names of the pictures it shows for `picture_png`, and cut_out). The arrays
/// are read-only views of the plant's (or scene's) memory, which they keep alive.
#[pyclass(module = "sylva", name = "Mesh", frozen, get_all)]
pub struct Mesh {
    positions: Py<PyArray2<f32>>,
    normals: Py<PyArray2<f32>>,
    uvs: Py<PyArray2<f32>>,
    indices: Py<PyArray2<u32>>,
    triangle_materials: Py<PyArray1<u32>>,
    materials: Py<PyAny>,
}

/// A mesh's triangles in one list, as numpy wants them: the mesher keeps one list per
/// material.
struct Triangles {
    corners: Vec<[u32; 3]>,
    materials: Vec<u32>,
}

impl Triangles {
    fn of(mesh: &sylva::mesh::Mesh) -> Triangles {
        let count = mesh.triangle_count();
        let mut corners = Vec::with_capacity(count);
        let mut materials = Vec::with_capacity(count);
        for p in &mesh.primitives {
            let (triangles, _) = p.indices.as_chunks::<3>();
            corners.extend_from_slice(triangles);
            materials.extend(std::iter::repeat_n(p.material as u32, triangles.len()));
        }
        Triangles { corners, materials }
    }
}

/// A read-only numpy array viewing `data`, which lives inside `owner`: the array holds
/// `owner` as its base, so the memory outlives it. numpy refuses to make such an array
/// writeable again (it does not own its data), so the exporters read what the mesher made.
///
/// The one `unsafe` in Sylva: `owner` must be a frozen pyclass whose `data` never changes or
/// moves while it lives. Every caller passes a field of `Plant` or `Scene`, both frozen and
/// never mutated after they are made.
#[allow(unsafe_code)]
fn view<'py, T: numpy::Element, D: Dimension>(
    owner: &Bound<'py, PyAny>,
    data: &ArrayView<'_, T, D>,
) -> PyResult<Py<PyArray<T, D>>> {
    // SAFETY: as above: `data` belongs to the frozen `owner`, the array's base. The new
    // array is ours alone, so clearing its flag directly (as `make_nonwriteable` does, without
    // numpy-rs's borrow tracking, a fifth of the cost of `plant.mesh`) invalidates no borrow.
    let array = unsafe {
        let array = PyArray::borrow_from_array(data, owner.clone());
        (*_PyArray_GET_ITEM_DATA(array.as_array_ptr())).flags &= !NPY_ARRAY_WRITEABLE;
        array
    };
    Ok(array.unbind())
}

/// `rows` of `N` values each, inside `owner`, as an (n, N) read-only array (no copy).
fn rows<T: numpy::Element, const N: usize>(
    owner: &Bound<'_, PyAny>,
    rows: &[[T; N]],
) -> PyResult<Py<PyArray2<T>>> {
    let data = ArrayView2::from_shape((rows.len(), N), rows.as_flattened())
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    view(owner, &data)
}

impl Mesh {
    /// The arrays of `mesh` and its `triangles`, both held by the frozen `owner`.
    fn view(
        owner: &Bound<'_, PyAny>,
        mesh: &sylva::mesh::Mesh,
        triangles: &Triangles,
    ) -> PyResult<Mesh> {
        let py = owner.py();
        let uvs = if mesh.uvs.len() == mesh.positions.len() {
            rows(owner, &mesh.uvs)?
        } else {
            PyArray2::zeros(py, [mesh.positions.len(), 2], false).unbind()
        };
        let list = PyList::empty(py);
        for m in &mesh.materials {
            let d = PyDict::new(py);
            d.set_item(intern!(py, "name"), &m.name)?;
            d.set_item(intern!(py, "kind"), m.kind.name())?;
            d.set_item(intern!(py, "color"), m.color)?;
            d.set_item(intern!(py, "texture"), m.texture)?;
            // Realism surfaces: the pictures to show (by name, for `picture_png`), and
            // whether the picture's alpha cuts the organ's shape out (drawn from both sides).
            use sylva::mesh::picture::Picture;
            d.set_item(
                intern!(py, "picture"),
                Picture::base_of(m).map(Picture::name),
            )?;
            d.set_item(
                intern!(py, "normal_map"),
                Picture::normal_of(m).map(Picture::name),
            )?;
            let cut = m.surface.is_some_and(|s| s.is_cut_out());
            d.set_item(intern!(py, "cut_out"), cut)?;
            list.append(d)?;
        }
        Ok(Mesh {
            positions: rows(owner, &mesh.positions)?,
            normals: rows(owner, &mesh.normals)?,
            uvs,
            indices: rows(owner, &triangles.corners)?,
            triangle_materials: view(owner, &ArrayView1::from(&triangles.materials[..]))?,
            materials: list.into_any().unbind(),
        })
    }
}

#[pymethods]
impl Mesh {
    /// A mesh of these arrays (`Mesh._from_arrays`, as a mesh unpickles): they are made
    /// read-only, as a plant's are.
    #[staticmethod]
    fn _from_arrays(
        positions: Bound<'_, PyArray2<f32>>,
        normals: Bound<'_, PyArray2<f32>>,
        uvs: Bound<'_, PyArray2<f32>>,
        indices: Bound<'_, PyArray2<u32>>,
        triangle_materials: Bound<'_, PyArray1<u32>>,
        materials: Bound<'_, PyList>,
    ) -> PyResult<Mesh> {
        for array in [
            positions.as_any(),
            normals.as_any(),
            uvs.as_any(),
            indices.as_any(),
            triangle_materials.as_any(),
        ] {
            array.call_method1("setflags", (false,))?;
        }
        Ok(Mesh {
            positions: positions.unbind(),
            normals: normals.unbind(),
            uvs: uvs.unbind(),
            indices: indices.unbind(),
            triangle_materials: triangle_materials.unbind(),
            materials: materials.into_any().unbind(),
        })
    }

    /// Pickled as its arrays (copied: an unpickled mesh owns its memory, read-only).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let make = py.get_type::<Mesh>().getattr("_from_arrays")?;
        let args = (
            self.positions.bind(py),
            self.normals.bind(py),
            self.uvs.bind(py),
            self.indices.bind(py),
            self.triangle_materials.bind(py),
            self.materials.bind(py),
        );
        Ok((make, args).into_pyobject(py)?.into_any())
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<sylva.Mesh {} vertices, {} triangles>",
            self.positions.bind(py).shape()[0],
            self.indices.bind(py).shape()[0]
        )
    }
}

/// Many plants in one scene (a garden): export it, picture it, read its meshes.
#[pyclass(module = "sylva", name = "Scene", frozen)]
pub struct Scene {
    assets: SceneAssets,
    garden: Option<String>,
    /// Each mesh's triangles, gathered the first time they are asked for.
    triangles: OnceLock<Vec<Triangles>>,
}

impl Scene {
    fn new(assets: SceneAssets, garden: Option<String>) -> Scene {
        Scene {
            assets,
            garden,
            triangles: OnceLock::new(),
        }
    }
}

#[pymethods]
impl Scene {
    /// Plants in the scene.
    #[getter]
    fn plants(&self) -> usize {
        self.assets.placed()
    }

    /// Triangles of all plants.
    #[getter]
    fn triangles(&self) -> usize {
        self.assets.scene().triangle_count()
    }

    /// The garden file's text (JSON) that grows this scene again, for gardens.
    #[getter]
    fn garden(&self) -> Option<&str> {
        self.garden.as_deref()
    }

    /// Each distinct plant's mesh, in its own coordinates (read-only views, as `Plant.mesh`);
    /// plants placed more than once (a garden's variants) share one.
    fn meshes(this: &Bound<'_, Self>) -> PyResult<Vec<Mesh>> {
        let scene = this.get();
        let meshes = scene.assets.meshes();
        let triangles = scene
            .triangles
            .get_or_init(|| meshes.iter().map(Triangles::of).collect());
        meshes
            .iter()
            .zip(triangles)
            .map(|(m, t)| Mesh::view(this.as_any(), m, t))
            .collect()
    }

    /// Writes the scene as GLB, OBJ, VRML97 or STL, by the file's extension (one node per plant,
    /// each carrying its genome and seed); every file appears whole or not at all.
    fn export(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| write_scene(&self.assets.scene(), &path)).py()
    }

    /// The scene as GLB bytes.
    fn glb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py.detach(|| glb_bytes(&self.assets.scene())).py()?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Renders a picture of the scene: PNG bytes, also written to `path` when given.
    #[pyo3(signature = (path = None, view = "iso", size = Pair(Whole(1200), Whole(800))))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        path: Option<PathBuf>,
        view: &str,
        size: Pair<Whole>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        render(py, &self.assets.scene(), path, view, size.into())
    }

    fn __repr__(&self) -> String {
        format!("<sylva.Scene {} plants>", self.plants())
    }
}

fn write_scene(scene: &sylva::mesh::Scene<'_>, path: &Path) -> Result<(), sylva::Error> {
    sylva::export::format(path)?;
    let mut out = Outputs::new();
    out.add_scene(path, scene)?;
    out.commit()
}

fn glb_bytes(scene: &sylva::mesh::Scene<'_>) -> Result<Vec<u8>, sylva::Error> {
    sylva::export::glb(scene)
}

fn render<'py>(
    py: Python<'py>,
    scene: &sylva::mesh::Scene<'_>,
    path: Option<PathBuf>,
    view: &str,
    size: (Whole, Whole),
) -> PyResult<Bound<'py, PyBytes>> {
    let view: View = view.parse().map_err(|e| bad_value("view", e))?;
    let size = picture_size(size)?;
    if let Some(path) = &path {
        sylva::assets::check_png(path).py()?;
    }
    let png = py
        .detach(|| -> Result<Vec<u8>, sylva::Error> {
            let png = sylva::assets::picture(scene, view, size)?;
            if let Some(path) = &path {
                sylva::files::write(path, &png)?;
            }
            Ok(png)
        })
        .py()?;
    Ok(PyBytes::new(py, &png))
}

/// A picture's (width, height), each side checked against the renderer's range, named `size`.
fn picture_size((width, height): (Whole, Whole)) -> PyResult<(u32, u32)> {
    use sylva::render::{MAX_SIZE, MIN_SIZE};
    let side = |w: Whole| {
        u32::try_from(w.0)
            .ok()
            .filter(|s| (MIN_SIZE..=MAX_SIZE).contains(s))
    };
    match (side(width), side(height)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(bad_value(
            "size",
            format!(
                "expected (width, height), each {MIN_SIZE} to {MAX_SIZE} pixels, got ({}, {})",
                width.0, height.0
            ),
        )),
    }
}

/// The PNG of Sylva's texture `id` (what a material of `plant.mesh.materials` names in
/// `texture`): 8-bit grey, 256 × 256, to multiply the material's colour by, the picture the
/// GLB and OBJ exports embed. Made once per process; releases the GIL while it is made.
#[pyfunction]
pub fn texture_png(py: Python<'_>, id: Whole) -> PyResult<Bound<'_, PyBytes>> {
    let id: u16 = id.get("id")?;
    let png = py
        .detach(|| sylva::mesh::texture::texture_png(id))
        .map_err(|e| {
            pyo3::exceptions::PyRuntimeError::new_err(format!("encoding texture {id} as PNG: {e}"))
        })?;
    Ok(PyBytes::new(py, &png))
}

/// The PNG of one of Sylva's pictures by name (what a material of `plant.mesh.materials`
/// names in `picture` or `normal_map`: `sylva-texture-3`, `sylva-leaves-oak`,
/// `sylva-bark-furrowed-normal`, …). Made once per process; releases the GIL.
#[pyfunction]
pub fn picture_png<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyBytes>> {
    let picture = sylva::mesh::picture::Picture::from_name(name)
        .ok_or_else(|| bad_value("name", format!("no picture of Sylva's is named {name:?}")))?;
    let png = py.detach(|| picture.png()).map_err(|e| {
        pyo3::exceptions::PyRuntimeError::new_err(format!("encoding {name} as PNG: {e}"))
    })?;
    Ok(PyBytes::new(py, &png))
}

/// Grows a PlantMaker garden: `count` plants of each genome, on a plot `area` = (width,
/// depth) metres centred on the origin, their seeds, places and turns drawn from `seed`.
/// Or give `path`, a garden file (`*.garden.json`), to grow the garden it describes.
/// Releases the GIL.
#[pyfunction]
#[pyo3(pass_module, signature = (genomes = Vec::new(), count = Whole(20), area = Pair(20.0, 20.0), seed = Whole(1), path = None))]
pub fn garden(
    module: &Bound<'_, PyModule>,
    genomes: Vec<Genome>,
    count: Whole,
    area: Pair<f64>,
    seed: Whole,
    path: Option<PathBuf>,
) -> PyResult<Scene> {
    let py = module.py();
    let models = Models::of(module.as_any())?;
    let registry = models.get().registry();
    let count: u32 = count.get("count")?;
    let seed: u64 = seed.get("seed")?;
    let area: (f64, f64) = area.into();
    let (garden, source) = match path {
        Some(path) => {
            if !genomes.is_empty() {
                return Err(bad_value(
                    "genomes",
                    "a garden file is grown on its own; give either genomes or a garden file",
                ));
            }
            let text = sylva::files::read_text(&path).py()?;
            let garden = sylva::garden::read(registry, &path, &text).py()?;
            (garden, path)
        }
        None => {
            if !(1..=100_000).contains(&count) {
                return Err(bad_value(
                    "count",
                    format!("{count} plants per genome; expected 1 to 100000"),
                ));
            }
            let valid = |v: f64| v.is_finite() && (0.1..=1e6).contains(&v);
            if !valid(area.0) || !valid(area.1) {
                return Err(bad_value(
                    "area",
                    format!(
                        "{} x {} m; each side must be 0.1 to 1000000 m",
                        area.0, area.1
                    ),
                ));
            }
            let genomes: Vec<sylva::Genome> = genomes.iter().map(|g| g.inner.clone()).collect();
            let garden =
                sylva::garden::plant(registry, &genomes, count as usize, [area.0, area.1], seed)
                    .map_err(|e| match e {
                        sylva::garden::PlanError::WrongModel { index, .. } => {
                            bad_value(format!("genomes[{index}]"), e)
                        }
                        sylva::garden::PlanError::NoGenomes => bad_value("genomes", e),
                    })?;
            (garden, PathBuf::from("<garden>"))
        }
    };
    let assets = py
        .detach(|| sylva::garden::garden_assets(&garden, &source, None))
        .py()?;
    Ok(Scene::new(assets, Some(garden.to_json())))
}

/// Puts grown plants in one scene: each at (x, z) on the ground, turned by `turns`
/// (radians about the vertical axis, 0 when left out).
#[pyfunction]
#[pyo3(signature = (plants, positions, turns = None))]
pub fn scene(
    py: Python<'_>,
    plants: Vec<Py<Plant>>,
    positions: Vec<(f32, f32)>,
    turns: Option<Vec<f32>>,
) -> PyResult<Scene> {
    if positions.len() != plants.len() {
        return Err(bad_value(
            "positions",
            format!("{} positions for {} plants", positions.len(), plants.len()),
        ));
    }
    let turns = turns.unwrap_or_else(|| vec![0.0; plants.len()]);
    if turns.len() != plants.len() {
        return Err(bad_value(
            "turns",
            format!("{} turns for {} plants", turns.len(), plants.len()),
        ));
    }
    if positions
        .iter()
        .flat_map(|(x, z)| [x, z])
        .chain(&turns)
        .any(|v| !v.is_finite() || v.abs() > 1e6)
    {
        return Err(bad_value(
            "positions",
            "positions and turns must be finite numbers within ±1000000",
        ));
    }
    let grown: Vec<&sylva::Grown> = plants.iter().map(|p| &p.get().grown).collect();
    let placed: Vec<Placed> = grown
        .iter()
        .zip(positions.iter().zip(&turns))
        .enumerate()
        .map(|(i, (g, ((x, z), turn)))| Placed {
            translation: sylva::core::glam::Vec3::new(*x, 0.0, *z),
            rotation: sylva::core::glam::Quat::from_rotation_y(*turn),
            extras: Some(Origin::of(&g.genome, g.seed).extras()),
            ..Placed::new(format!("plant-{i}"), &g.plant, g.genome.mesh_hint())
        })
        .collect();
    let assets = py.detach(|| SceneAssets::mesh(&placed, None)).py()?;
    Ok(Scene::new(assets, None))
}

/// A column of `rows`: one value each.
fn column<'py, R, T: numpy::Element>(
    py: Python<'py>,
    rows: &[R],
    value: impl Fn(&R) -> T,
) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_vec(py, rows.iter().map(value).collect())
}

/// A column of `rows` with `N` numbers each, as an (rows, N) array.
fn columns<'py, R, const N: usize>(
    py: Python<'py>,
    rows: &[R],
    value: impl Fn(&R) -> [f32; N],
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat: Vec<f32> = rows.iter().flat_map(value).collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), N])
}

/// Names of enum values (`"bark"`, `"leaf"`) as a list, each name made once.
fn names<'py, K: Copy + PartialEq + serde::Serialize>(
    py: Python<'py>,
    kinds: impl Iterator<Item = K>,
) -> PyResult<Bound<'py, PyList>> {
    let mut made: Vec<(K, Bound<'py, PyAny>)> = Vec::new();
    let list = PyList::empty(py);
    for kind in kinds {
        let name = match made.iter().find(|(k, _)| *k == kind) {
            Some((_, name)) => name.clone(),
            None => {
                let name = match serde_json::to_value(kind) {
                    Ok(serde_json::Value::String(s)) => s.into_pyobject(py)?.into_any(),
                    _ => py.None().into_bound(py),
                };
                made.push((kind, name.clone()));
                name
            }
        };
        list.append(name)?;
    }
    Ok(list)
}

/// A parent index, or -1 for none.
fn parent_index(parent: Option<u32>) -> i64 {
    parent.map_or(-1, i64::from)
}

fn segment_arrays<'py>(
    py: Python<'py>,
    segments: &[sylva::skeleton::SkeletonSegment],
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("start", columns(py, segments, |s| s.start)?)?;
    out.set_item("end", columns(py, segments, |s| s.end)?)?;
    out.set_item("start_radius", column(py, segments, |s| s.start_radius))?;
    out.set_item("end_radius", column(py, segments, |s| s.end_radius))?;
    out.set_item("order", column(py, segments, |s| s.order))?;
    out.set_item("parent", column(py, segments, |s| parent_index(s.parent)))?;
    out.set_item("lateral", column(py, segments, |s| s.lateral))?;
    out.set_item("material", column(py, segments, |s| s.material))?;
    out.set_item("kind", names(py, segments.iter().map(|s| s.kind))?)?;
    out.set_item("woody", column(py, segments, |s| s.woody))?;
    Ok(out)
}

fn organ_arrays<'py>(
    py: Python<'py>,
    organs: &[sylva::skeleton::SkeletonOrgan],
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("kind", names(py, organs.iter().map(|o| o.kind))?)?;
    out.set_item("position", columns(py, organs, |o| o.position)?)?;
    out.set_item("orientation", columns(py, organs, |o| o.orientation)?)?;
    out.set_item("axis", columns(py, organs, |o| o.axis)?)?;
    out.set_item("normal", columns(py, organs, |o| o.normal)?)?;
    out.set_item("length", column(py, organs, |o| o.length))?;
    out.set_item("width", column(py, organs, |o| o.width))?;
    out.set_item("parent", column(py, organs, |o| parent_index(o.parent)))?;
    out.set_item("material", column(py, organs, |o| o.material))?;
    Ok(out)
}
