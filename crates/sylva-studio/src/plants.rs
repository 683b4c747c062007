//! Plants: listed, shown with their genome, grown into GLB, OBJ and PNG, traced back
//! through their lineage, and branched from.
//!
//! A plant's GLB is the source of its other forms: grown again from its genome and seed
//! (growth is deterministic), or, for a garden specimen (whose shape depends on its
//! neighbours), read from the mesh stored when the garden grew. Recent GLBs stay in memory.

use std::collections::{HashSet, VecDeque};
use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::json;
use sylva::assets::Origin;
use sylva::core::Plant;
use sylva::evolution::outline::Outline;
use sylva::mesh::SceneNode;
use sylva::render::View;
use sylva::{Genome, GrowOptions, Grown, LodAssets, Preview, Registry};

use crate::Studio;
use crate::archive::{self, ParentRow, PlantRow};
use crate::cache::Bounded;
use crate::error::ApiError;
use crate::pruning::{grow_shown, pruned_to};

/// GLBs kept in memory, by plant and form: at most 256, and 128 MB (a view's preview is a
/// few hundred kB; a random PlantMaker plant's GLB in full, for an export, can be 40 MB).
pub type MeshCache = Bounded<(i64, Form), Vec<u8>>;

/// A mesh cache of the studio's size.
pub fn mesh_cache() -> MeshCache {
    Bounded::new(256, 128 << 20)
}

/// Pictures kept in memory, by plant, view and size: at most 4096, and 64 MB (a thumbnail is
/// a few kilobytes), so that a thumbnail asked for again is answered at once.
pub type PictureCache = Bounded<(i64, View, (u32, u32)), Vec<u8>>;

/// A picture cache of the studio's size.
pub fn picture_cache() -> PictureCache {
    Bounded::new(4096, 64 << 20)
}

/// Grown plants kept in memory, by plant (roots left out), so that a preview of any size is
/// simplified and meshed without growing the plant again: at most 256, and 64 MB. The two
/// caches together stay well under the studio's memory figure (docs/studio.md, "Memory").
pub type PlantCache = Bounded<i64, Plant>;

/// A plant cache of the studio's size.
pub fn plant_cache() -> PlantCache {
    Bounded::new(256, 64 << 20)
}

/// Roughly the bytes a plant holds.
pub fn plant_bytes(plant: &Plant) -> usize {
    std::mem::size_of_val(plant.segments())
        + std::mem::size_of_val(plant.organs())
        + std::mem::size_of_val(plant.materials())
}

/// Which GLB of a plant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Form {
    /// The plant in full, its roots left out or kept.
    Full {
        /// Whether the roots are kept.
        roots: bool,
    },
    /// A preview for views of up to this many pixels a side ([`PreviewSize`]).
    Preview(PreviewSize),
}

/// The size class of a preview: the longest side of the view it is for, in device pixels,
/// rounded up to a power of two from 128 to 2048. A class allows `side² / 8` triangles (at
/// most 400,000): one triangle for every eight pixels of a square view is more than the eye
/// can tell from the plant in full.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PreviewSize(u16);

impl PreviewSize {
    /// The class the breeding grid's cells are (up to 512 pixels a side), made with each
    /// plant a step breeds.
    pub const GRID: PreviewSize = PreviewSize(512);

    /// The class of a view `pixels` wide at most.
    pub fn of(pixels: u32) -> PreviewSize {
        PreviewSize(pixels.clamp(128, 2048).next_power_of_two() as u16)
    }

    /// Every class, the smallest first.
    fn all() -> impl Iterator<Item = PreviewSize> {
        (7..=11).map(|power| PreviewSize(1 << power))
    }

    /// The triangles a preview of this class may have.
    pub fn triangles(self) -> usize {
        (usize::from(self.0).pow(2) / 8).min(400_000)
    }
}

/// A stored genome, read back.
pub fn genome_of(registry: &Registry, row: &PlantRow) -> Result<Genome, ApiError> {
    registry
        .parse_genome(&row.genome)
        .map_err(|e| ApiError::internal(format!("plant {}'s stored genome: {}", row.id, e.message)))
}

/// A plant by id, or 404.
pub fn plant_row(studio: &Studio, id: i64) -> Result<PlantRow, ApiError> {
    studio
        .archive
        .read(|c| archive::plant(c, id))?
        .ok_or_else(|| ApiError::not_found(format!("plant {id}")))
}

/// Grows a genome into a GLB whose node's extras carry its origin: genome, seed, parents
/// (archive ids) and operator.
pub fn grow_glb(
    genome: &Genome,
    seed: u64,
    roots: bool,
    pruned_to: Option<Arc<[Outline]>>,
    parents: &[ParentRow],
    operator: &str,
) -> Result<Vec<u8>, ApiError> {
    let options = GrowOptions {
        seed: Some(seed),
        roots,
        pruned_to,
        ..GrowOptions::default()
    };
    let grown =
        Grown::grow(genome.clone(), &options).map_err(|e| ApiError::library("genome", e))?;
    let mut node = SceneNode::new(genome.model(), &grown.mesh);
    node.extras = Some(extras(genome, seed, parents, operator));
    let scene = sylva::mesh::Scene::single(node);
    sylva::export::glb(&scene).map_err(|e| ApiError::library("genome", e))
}

/// A preview GLB of `size` of `plant` (grown from `genome` with `seed`, roots left out), for
/// the views. Its node's extras hold the plant's genome and seed and the preview's detail;
/// exports (`plant.glb`) carry the whole origin (parents, operator).
pub fn preview_glb(
    genome: &Genome,
    seed: u64,
    plant: &Plant,
    size: PreviewSize,
) -> Result<Vec<u8>, ApiError> {
    let preview = Preview::of(genome, seed, plant, size.triangles())
        .map_err(|e| ApiError::library("genome", e))?;
    preview.glb().map_err(|e| ApiError::library("genome", e))
}

/// A plant grown as the views show it (pruned to its match's outlines, if it grew inside
/// them): from memory, or grown again (and kept).
fn shown_plant(studio: &Studio, row: &PlantRow) -> Result<Arc<Plant>, ApiError> {
    if let Some(plant) = studio.plants.get(row.id) {
        return Ok(plant);
    }
    let outlines = pruned_to(studio, row)?;
    let genome = genome_of(&studio.registry, row)?;
    let plant = Arc::new(grow_shown(&genome, row.seed, outlines)?);
    studio
        .plants
        .put(row.id, plant.clone(), plant_bytes(&plant));
    Ok(plant)
}

/// What an exported node's extras hold in the studio.
pub fn extras(
    genome: &Genome,
    seed: u64,
    parents: &[ParentRow],
    operator: &str,
) -> serde_json::Value {
    let mut extras = Origin::of(genome, seed).extras();
    extras["parents"] = json!(parents.iter().map(|p| p.plant).collect::<Vec<_>>());
    extras["operator"] = json!(operator);
    extras
}

/// A plant's GLB: from memory, the stored mesh, or grown again.
pub fn plant_glb(studio: &Studio, id: i64, roots: bool) -> Result<Arc<Vec<u8>>, ApiError> {
    plant_form(studio, id, Form::Full { roots })
}

/// A plant's GLB in `form`: from memory, the stored mesh (a garden specimen's, whatever
/// the form: it is small, and cannot be grown alone), or grown again.
pub fn plant_form(studio: &Studio, id: i64, form: Form) -> Result<Arc<Vec<u8>>, ApiError> {
    if let Some(glb) = studio.meshes.get((id, form)) {
        return Ok(glb);
    }
    let (row, parents, stored) = studio.archive.read(|c| {
        Ok((
            archive::plant(c, id)?,
            archive::parents(c, id)?,
            archive::mesh(c, id)?,
        ))
    })?;
    let row = row.ok_or_else(|| ApiError::not_found(format!("plant {id}")))?;
    let glb = match (stored, form) {
        (Some(glb), _) => glb,
        (None, Form::Full { roots }) => grow_glb(
            &genome_of(&studio.registry, &row)?,
            row.seed,
            roots,
            pruned_to(studio, &row)?,
            &parents,
            &row.operator,
        )?,
        (None, Form::Preview(size)) => {
            let plant = shown_plant(studio, &row)?;
            preview_glb(&genome_of(&studio.registry, &row)?, row.seed, &plant, size)?
        }
    };
    let glb = Arc::new(glb);
    studio.meshes.put((id, form), glb.clone(), glb.len());
    Ok(glb)
}

fn glb_response(glb: &[u8]) -> Response {
    ([(header::CONTENT_TYPE, "model/gltf-binary")], glb.to_vec()).into_response()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GlbQuery {
    #[serde(default)]
    roots: bool,
    /// A wind skin and its looping clip, as `sylva grow --wind`.
    #[serde(default)]
    wind: bool,
    /// Levels of detail, 2 to 8, as `sylva grow --lod N`: one scene of sibling nodes
    /// `NAME_LOD0`, `NAME_LOD1`, … with each level's screen coverage in its extras.
    lod: Option<usize>,
    /// Leaves or needles of a kind at their real size, as `sylva grow --foliage`.
    foliage: Option<String>,
    /// A tiling bark, as `sylva grow --bark`.
    bark: Option<String>,
    /// The height to scale to, metres, as `sylva grow --height`.
    height: Option<f32>,
}

impl GlbQuery {
    /// Its dress parameters.
    fn dress(&self) -> DressQuery {
        DressQuery {
            foliage: self.foliage.clone(),
            bark: self.bark.clone(),
            height: self.height,
        }
    }
}

/// The dress a request asks for: `foliage`, `bark` (kinds by name) and `height` (metres).
#[derive(Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DressQuery {
    foliage: Option<String>,
    bark: Option<String>,
    height: Option<f32>,
}

impl DressQuery {
    /// Whether it asks for anything.
    fn is_empty(&self) -> bool {
        self.foliage.is_none() && self.bark.is_none() && self.height.is_none()
    }

    /// The dress and height, each checked (a 400 naming the parameter and what it takes).
    fn options(&self) -> Result<(sylva::Dress, Option<f32>), ApiError> {
        let kind =
            |field: &'static str, e: sylva::core::species::UnknownKind| ApiError::bad(field, e);
        let mut dress = sylva::Dress::default();
        if let Some(name) = &self.foliage {
            dress.foliage = Some(name.parse().map_err(|e| kind("foliage", e))?);
        }
        if let Some(name) = &self.bark {
            dress.bark = Some(name.parse().map_err(|e| kind("bark", e))?);
        }
        let (lo, hi) = sylva::assets::HEIGHTS;
        if let Some(h) = self.height
            && !(lo..=hi).contains(&h)
        {
            return Err(ApiError::bad(
                "height",
                format!("expected {lo} to {hi} metres, got {h}"),
            ));
        }
        Ok((dress, self.height))
    }
}

/// `GET /api/plants/{id}/plant.glb[?roots=true][&wind=true][&lod=N][&foliage=KIND][&bark=KIND][&height=M]`:
/// the plant in full,
/// for exports; with wind or levels of detail, the game asset `sylva grow` writes.
pub(crate) async fn glb(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<GlbQuery>,
) -> Result<Response, ApiError> {
    if let Some(n) = q.lod
        && !(2..=sylva::lod::MAX_LEVELS).contains(&n)
    {
        return Err(ApiError::bad(
            "lod",
            format!("expected 2 to {} levels, got {n}", sylva::lod::MAX_LEVELS),
        ));
    }
    q.dress().options()?;
    let glb = tokio::task::spawn_blocking(move || {
        if q.wind || q.lod.is_some() || !q.dress().is_empty() {
            asset_glb(&studio, id, &q).map(Arc::new)
        } else {
            plant_glb(&studio, id, q.roots)
        }
    })
    .await??;
    Ok(glb_response(&glb))
}

/// A plant grown again with wind or levels of detail (not kept in memory: exports are
/// rare, and each asks its own).
fn asset_glb(studio: &Studio, id: i64, q: &GlbQuery) -> Result<Vec<u8>, ApiError> {
    let row = plant_row(studio, id)?;
    let genome = genome_of(&studio.registry, &row)?;
    let (dress, height) = q.dress().options()?;
    let options = GrowOptions {
        seed: Some(row.seed),
        roots: q.roots,
        wind: q.wind.then(sylva::mesh::wind::WindOptions::default),
        lod: q.lod,
        pruned_to: pruned_to(studio, &row)?,
        dress,
        height,
        ..GrowOptions::default()
    };
    let failed = |e: sylva::Error| ApiError::library("genome", e);
    let grown = Grown::grow(genome, &options).map_err(failed)?;
    let glb = if options.lod.is_some() {
        let chain = LodAssets::new(grown, &options).map_err(failed)?;
        sylva::export::glb(&chain.group_scene(&row.model))
    } else {
        sylva::export::glb(&grown.scene())
    };
    glb.map_err(failed)
}

/// `GET /api/plants/{id}/inspect[?foliage=KIND][&bark=KIND][&height=M]`: how the plant
/// (dressed and scaled as asked) measures against real trees, as `sylva inspect --json`.
pub(crate) async fn inspect(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<DressQuery>,
) -> Result<Response, ApiError> {
    let (dress, height) = q.options()?;
    let json = tokio::task::spawn_blocking(move || -> Result<String, ApiError> {
        let row = plant_row(&studio, id)?;
        let genome = genome_of(&studio.registry, &row)?;
        let options = GrowOptions {
            seed: Some(row.seed),
            pruned_to: pruned_to(&studio, &row)?,
            dress,
            height,
            ..GrowOptions::default()
        };
        let grown = Grown::grow(genome, &options).map_err(|e| ApiError::library("genome", e))?;
        let asset = sylva::inspect::AssetFacts::of_mesh(&grown.mesh);
        Ok(sylva::inspect::Report::of(&grown.plant, Some(asset)).to_json())
    })
    .await??;
    Ok(([(header::CONTENT_TYPE, "application/json")], json).into_response())
}

/// `GET /api/kinds`: the foliage and bark kinds a plant can be dressed in, by name.
pub(crate) async fn kinds() -> Response {
    let names = |it: &mut dyn Iterator<Item = &'static str>| it.collect::<Vec<_>>();
    axum::Json(serde_json::json!({
        "foliage": names(&mut sylva::LeafKind::ALL.iter().map(|k| k.name())),
        "bark": names(&mut sylva::BarkKind::ALL.iter().map(|k| k.name())),
    }))
    .into_response()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PreviewQuery {
    px: Option<u32>,
}

/// `GET /api/plants/{id}/preview.glb?px=N`: the plant at the detail a view of `N` device
/// pixels a side needs (320 by default), for the grid's cells; `plant.glb` is the plant in
/// full, for exports.
pub(crate) async fn preview(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<PreviewQuery>,
) -> Result<Response, ApiError> {
    let px = q.px.unwrap_or(320);
    if !(16..=16384).contains(&px) {
        return Err(ApiError::bad(
            "px",
            format!("expected 16 to 16384 pixels, got {px}"),
        ));
    }
    let form = Form::Preview(PreviewSize::of(px));
    let glb = tokio::task::spawn_blocking(move || plant_form(&studio, id, form)).await??;
    Ok(glb_response(&glb))
}

pub(crate) fn imported(glb: &[u8]) -> Result<sylva::import::ImportedScene, ApiError> {
    sylva::import::read_glb(glb).map_err(|e| ApiError::internal(format!("reading a GLB back: {e}")))
}

/// `GET /api/plants/{id}/plant.obj`.
pub(crate) async fn obj(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let (obj, _) = tokio::task::spawn_blocking(move || obj_files(&studio, id)).await??;
    Ok(([(header::CONTENT_TYPE, "text/plain; charset=utf-8")], obj).into_response())
}

/// `GET /api/plants/{id}/plant.mtl`.
pub(crate) async fn mtl(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let (_, mtl) = tokio::task::spawn_blocking(move || obj_files(&studio, id)).await??;
    Ok(([(header::CONTENT_TYPE, "text/plain; charset=utf-8")], mtl).into_response())
}

fn obj_files(studio: &Studio, id: i64) -> Result<(String, String), ApiError> {
    let glb = plant_glb(studio, id, false)?;
    let scene = imported(&glb)?;
    sylva::export::obj(&scene.scene(), "plant.mtl").map_err(ApiError::internal)
}

/// `GET /api/plants/{id}/plant.zip`: the OBJ export in one download: `plant-ID.obj`, the
/// `plant-ID.mtl` it names and the `plant-ID_texN.png` textures the MTL names, so the folder
/// it unpacks to opens in any OBJ viewer.
pub(crate) async fn obj_zip(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let zip = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, ApiError> {
        let glb = plant_glb(&studio, id, false)?;
        let scene = imported(&glb)?;
        let obj = format!("plant-{id}.obj");
        let files = sylva::export::files(&scene.scene(), std::path::Path::new(&obj))
            .map_err(|e| ApiError::internal(format!("exporting OBJ: {e}")))?;
        zip_files(&files).map_err(|e| ApiError::internal(format!("writing the zip: {e}")))
    })
    .await??;
    Ok(download(zip, "application/zip", &format!("plant-{id}.zip")))
}

/// A zip of `(name, bytes)` files, in order: text deflated, PNGs stored (they are
/// compressed already), every date 1980-01-01 so the same files give the same bytes.
fn zip_files(files: &[(std::path::PathBuf, Vec<u8>)]) -> zip::result::ZipResult<Vec<u8>> {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (path, bytes) in files {
        let name = path.to_string_lossy();
        let method = if name.ends_with(".png") {
            zip::CompressionMethod::Stored
        } else {
            zip::CompressionMethod::Deflated
        };
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(method)
            .last_modified_time(zip::DateTime::default());
        zip.start_file(name, options)?;
        zip.write_all(bytes)?;
    }
    Ok(zip.finish()?.into_inner())
}

/// `GET /api/plants/{id}/plant.stl`: the plant for 3D printing, binary STL in millimetres.
pub(crate) async fn stl(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let stl = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, ApiError> {
        let glb = plant_glb(&studio, id, false)?;
        sylva::export::stl(&imported(&glb)?.scene()).map_err(ApiError::internal)
    })
    .await??;
    Ok(download(stl, "model/stl", &format!("plant-{id}.stl")))
}

/// A file to save, under `name`.
fn download(bytes: Vec<u8>, content_type: &'static str, name: &str) -> Response {
    let disposition = format!("attachment; filename=\"{name}\"");
    (
        [
            (header::CONTENT_TYPE, content_type.to_owned()),
            (header::CONTENT_DISPOSITION, disposition),
        ],
        bytes,
    )
        .into_response()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PngQuery {
    view: Option<String>,
    size: Option<String>,
}

/// The largest picture edge.
const MAX_PICTURE: u32 = 2048;

/// `GET /api/plants/{id}/plant.png`.
pub(crate) async fn png(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<PngQuery>,
) -> Result<Response, ApiError> {
    let view: View = match q.view.as_deref() {
        None => View::Iso,
        Some(v) => v.parse().map_err(|_| {
            ApiError::bad(
                "view",
                format!("expected iso, front, side or top; got {v:?}"),
            )
        })?,
    };
    let size = match q.size.as_deref() {
        None => (512, 512),
        Some(s) => parse_size(s)?,
    };
    let key = (id, view, size);
    let png = match studio.pictures.get(key) {
        Some(png) => png,
        None => {
            tokio::task::spawn_blocking(move || -> Result<Arc<Vec<u8>>, ApiError> {
                let glb = picture_glb(&studio, id, size)?;
                let scene = imported(&glb)?;
                let png = sylva::assets::picture(&scene.scene(), view, size)
                    .map_err(ApiError::internal)?;
                let png = Arc::new(png);
                studio.pictures.put(key, png.clone(), png.len());
                Ok(png)
            })
            .await??
        }
    };
    Ok(([(header::CONTENT_TYPE, "image/png")], png.to_vec()).into_response())
}

/// The cheapest GLB a picture of `size` is drawn from: the smallest preview in memory that
/// has the detail the picture needs (a step's grid previews are), else a preview of just
/// that detail. A preview has all the eye can tell at its size, and a thumbnail drawn from
/// one takes a fraction of the plant in full.
fn picture_glb(studio: &Studio, id: i64, size: (u32, u32)) -> Result<Arc<Vec<u8>>, ApiError> {
    let needed = PreviewSize::of(size.0.max(size.1));
    let kept = PreviewSize::all()
        .filter(|class| *class >= needed)
        .find_map(|class| studio.meshes.get((id, Form::Preview(class))));
    match kept {
        Some(glb) => Ok(glb),
        None => plant_form(studio, id, Form::Preview(needed)),
    }
}

/// `WxH`, each 16 to [`MAX_PICTURE`].
pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), ApiError> {
    let bad = || {
        ApiError::bad(
            "size",
            format!("expected WIDTHxHEIGHT, each from 16 to {MAX_PICTURE}; got {s:?}"),
        )
    };
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if (16..=MAX_PICTURE).contains(&w) && (16..=MAX_PICTURE).contains(&h) {
        Ok((w, h))
    } else {
        Err(bad())
    }
}

/// `GET /api/plants/{id}/plant_tex{N}.png`: a texture the plant's materials name, beside
/// its `.mtl`. Anything else is 404, and nothing is made or kept for it: a request (an
/// `<img>` on any page) cannot fill a cache with made-up ids.
pub(crate) async fn texture(
    State(studio): State<Studio>,
    Path((id, file)): Path<(i64, String)>,
) -> Result<Response, ApiError> {
    let not_found = || ApiError::not_found(format!("`/api/plants/{id}/{file}`"));
    let texture = file
        .strip_prefix("plant_tex")
        .and_then(|f| f.strip_suffix(".png"))
        .filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|n| n.parse::<u16>().ok())
        .ok_or_else(not_found)?;
    let named = tokio::task::spawn_blocking(move || -> Result<bool, ApiError> {
        let glb = plant_glb(&studio, id, false)?;
        let ids = sylva::import::texture_ids(&glb)
            .map_err(|e| ApiError::internal(format!("reading a GLB back: {e}")))?;
        Ok(ids.contains(&texture))
    })
    .await??;
    if !named {
        return Err(not_found());
    }
    let png = tokio::task::spawn_blocking(move || sylva::mesh::texture::texture_png(texture))
        .await?
        .map_err(ApiError::internal)?;
    Ok(([(header::CONTENT_TYPE, "image/png")], png.to_vec()).into_response())
}

/// `GET /api/plants/{id}/genome.json`.
pub(crate) async fn genome(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Response, ApiError> {
    let row = plant_row(&studio, id)?;
    Ok(([(header::CONTENT_TYPE, "application/json")], row.genome).into_response())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ListQuery {
    session: Option<i64>,
    #[serde(default)]
    offset: u32,
    limit: Option<u32>,
}

#[derive(Serialize)]
pub(crate) struct PlantSummary {
    id: i64,
    model: String,
    operator: String,
    seed: u64,
    session: Option<i64>,
    parents: Vec<i64>,
}

#[derive(Serialize)]
pub(crate) struct PlantList {
    total: u64,
    plants: Vec<PlantSummary>,
}

/// `GET /api/plants`.
pub(crate) async fn list(
    State(studio): State<Studio>,
    Query(q): Query<ListQuery>,
) -> Result<Json<PlantList>, ApiError> {
    let limit = q.limit.unwrap_or(100);
    if !(1..=1000).contains(&limit) {
        return Err(ApiError::bad(
            "limit",
            format!("expected 1 to 1000, got {limit}"),
        ));
    }
    let (total, plants) = studio.archive.read(|c| {
        let (total, rows) = archive::plants(c, q.session, q.offset, limit)?;
        let mut plants = Vec::with_capacity(rows.len());
        for r in rows {
            let parents = archive::parents(c, r.id)?.iter().map(|p| p.plant).collect();
            plants.push(PlantSummary {
                id: r.id,
                model: r.model,
                operator: r.operator,
                seed: r.seed,
                session: r.session,
                parents,
            });
        }
        Ok((total, plants))
    })?;
    Ok(Json(PlantList { total, plants }))
}

#[derive(Serialize)]
pub(crate) struct Field {
    path: String,
    value: serde_json::Value,
}

#[derive(Serialize)]
pub(crate) struct PlantView {
    id: i64,
    model: String,
    title: &'static str,
    genome: serde_json::Value,
    genome_text: String,
    packed: Option<String>,
    fields: Vec<Field>,
    seed: u64,
    operator: String,
    settings: serde_json::Value,
    parents: Vec<ParentRow>,
    session: Option<i64>,
    created: String,
}

/// The leaves of a JSON value with their paths (`branches[0].length`).
fn fields(value: &serde_json::Value, path: &str, out: &mut Vec<Field>) {
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                fields(v, &p, out);
            }
        }
        serde_json::Value::Array(items) if items.iter().any(|v| v.is_object() || v.is_array()) => {
            for (i, v) in items.iter().enumerate() {
                fields(v, &format!("{path}[{i}]"), out);
            }
        }
        leaf => out.push(Field {
            path: path.to_owned(),
            value: leaf.clone(),
        }),
    }
}

/// `GET /api/plants/{id}`.
pub(crate) async fn get(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
) -> Result<Json<PlantView>, ApiError> {
    let (row, parents) = studio
        .archive
        .read(|c| Ok((archive::plant(c, id)?, archive::parents(c, id)?)))?;
    let row = row.ok_or_else(|| ApiError::not_found(format!("plant {id}")))?;
    let genome = genome_of(&studio.registry, &row)?;
    let value = genome.to_value();
    let mut list = Vec::new();
    fields(&value, "", &mut list);
    let packed = genome.packed();
    Ok(Json(PlantView {
        id: row.id,
        title: genome.title(),
        model: row.model,
        genome: value,
        genome_text: row.genome,
        packed,
        fields: list,
        seed: row.seed,
        operator: row.operator,
        settings: row.settings,
        parents,
        session: row.session,
        created: row.created,
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LineageQuery {
    depth: Option<u32>,
}

#[derive(Serialize)]
pub(crate) struct LineageNode {
    id: i64,
    model: String,
    operator: String,
    settings: serde_json::Value,
    seed: u64,
    depth: u32,
}

#[derive(Serialize)]
pub(crate) struct LineageEdge {
    child: i64,
    parent: i64,
    dominance: f64,
}

#[derive(Serialize)]
pub(crate) struct Lineage {
    nodes: Vec<LineageNode>,
    edges: Vec<LineageEdge>,
    /// True when the walk stopped at the node limit before reaching `depth`.
    truncated: bool,
}

/// The most nodes a lineage answer holds.
const MAX_LINEAGE: usize = 500;

/// `GET /api/plants/{id}/lineage`.
pub(crate) async fn lineage(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Query(q): Query<LineageQuery>,
) -> Result<Json<Lineage>, ApiError> {
    let depth = q.depth.unwrap_or(8);
    if !(1..=64).contains(&depth) {
        return Err(ApiError::bad(
            "depth",
            format!("expected 1 to 64, got {depth}"),
        ));
    }
    plant_row(&studio, id)?;
    let lineage = studio.archive.read(|c| {
        let mut nodes = Vec::new();
        let mut edges = Vec::new();
        let mut seen = HashSet::from([id]);
        let mut queue = VecDeque::from([(id, 0u32)]);
        let mut truncated = false;
        while let Some((plant, d)) = queue.pop_front() {
            let Some(row) = archive::plant(c, plant)? else {
                continue;
            };
            nodes.push(LineageNode {
                id: row.id,
                model: row.model,
                operator: row.operator,
                settings: row.settings,
                seed: row.seed,
                depth: d,
            });
            if d == depth {
                continue;
            }
            for p in archive::parents(c, plant)? {
                edges.push(LineageEdge {
                    child: plant,
                    parent: p.plant,
                    dominance: p.dominance,
                });
                if seen.insert(p.plant) {
                    if seen.len() > MAX_LINEAGE {
                        truncated = true;
                        continue;
                    }
                    queue.push_back((p.plant, d + 1));
                }
            }
        }
        let kept: HashSet<i64> = nodes.iter().map(|n| n.id).collect();
        edges.retain(|e| kept.contains(&e.parent));
        Ok(Lineage {
            nodes,
            edges,
            truncated,
        })
    })?;
    Ok(Json(lineage))
}

/// Reads a genome file's text, naming `field` and the line and column of any error.
pub fn parse_genome(registry: &Registry, text: &str, field: &str) -> Result<Genome, ApiError> {
    // A file that is not JSON at all (a picture chosen by mistake) is said to be no genome,
    // rather than where the JSON reader gave up on it.
    if serde_json::from_str::<serde::de::IgnoredAny>(text)
        .is_err_and(|e| e.is_syntax() || e.is_eof())
    {
        return Err(ApiError::unprocessable(
            field,
            "the file is not a genome (a JSON genome file was expected)",
        ));
    }
    registry.parse_genome(text).map_err(|e| {
        ApiError::unprocessable(
            field,
            format!("line {}, column {}: {}", e.line, e.column, e.message),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_that_is_not_json_is_said_to_be_no_genome() {
        let registry = Registry::standard();
        let png = String::from_utf8_lossy(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").into_owned();
        for text in [png.as_str(), "", "not json", "{\"model\": \"bintree\""] {
            let e = parse_genome(&registry, text, "genomes[0]").unwrap_err();
            assert_eq!(e.field, "genomes[0]");
            assert_eq!(
                e.error, "the file is not a genome (a JSON genome file was expected)",
                "{text:?}"
            );
        }
        // JSON that is not a genome still says what is wrong with it.
        let e = parse_genome(&registry, r#"{"model": "bintree"}"#, "genome").unwrap_err();
        assert!(!e.error.contains("not a genome (a JSON"), "{e}");
    }

    #[test]
    fn preview_sizes_are_few_and_bounded() {
        assert_eq!(PreviewSize::of(0), PreviewSize(128));
        assert_eq!(PreviewSize::of(300), PreviewSize(512));
        assert_eq!(PreviewSize::of(512), PreviewSize::GRID);
        assert_eq!(PreviewSize::of(u32::MAX), PreviewSize(2048));
        let classes: HashSet<PreviewSize> = (0..20_000).map(PreviewSize::of).collect();
        assert_eq!(classes.len(), 5);
        assert_eq!(PreviewSize::GRID.triangles(), 32_768);
        assert_eq!(PreviewSize(2048).triangles(), 400_000);
    }
}
