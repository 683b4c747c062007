//! A grown plant as data: the skeleton export (`PLANT.skeleton.json`).
//!
//! [`Skeleton`] holds everything a [`Plant`] stores, in the words of its file: every segment
//! (start, end, both radii, branch order, parent, whether it starts a branch, its material
//! and whether it is wood), every organ (kind, position, orientation, its blade's axis and
//! normal, length and width, parent, material), the materials, and where the plant came
//! from (model, genome hash, seed, the genome itself, the pipe-model taper when one was
//! applied, whether the roots were kept). [`Skeleton::to_json`] writes it with a stable
//! field order, one segment or organ per line, floats in serde_json's shortest round-trip
//! form, so the same genome and seed give the same bytes. `docs/skeleton.md` documents the
//! format field by field.
//!
//! ```
//! use sylva::skeleton::Skeleton;
//! use sylva::{GrowOptions, Grown, Registry};
//!
//! let text = r#"{"model": "bintree", "format": 1, "depth": 3, "lower_radius": 0.2,
//!   "upper_radius": 0.15, "length": 1.5, "length_ratio": 0.8,
//!   "rotation1": {"angle": 30, "axis": [1, 0, 0]},
//!   "rotation2": {"angle": -30, "axis": [0, 0, 1]}, "min_radius": 0.02}"#;
//! let genome = Registry::standard().parse_genome(text)?;
//! let grown = Grown::grow(genome, &GrowOptions::default())?;
//! let skeleton = Skeleton::of_grown(&grown);
//! assert_eq!(skeleton.segments.len(), 7);
//! assert!(skeleton.to_json().starts_with("{\n  \"format\": 1,\n  \"kind\": \"sylva-skeleton\""));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sylva_core::species::Surface;
use sylva_core::taper::PipeTaper;
use sylva_core::{MaterialKind, OrganKind, Plant};
use sylva_gltf::export::Format;

use crate::assets::Grown;
use crate::error::{Error, InputError};
use crate::files::read_text;
use crate::genome::Genome;

/// The format's version, the file's `"format"`. Fields may be added within a version
/// (readers ignore what they do not know); anything else raises it.
pub const FORMAT: u32 = 1;

/// The file's `"kind"`, so readers can tell a skeleton from other JSON.
pub const KIND: &str = "sylva-skeleton";

/// How a skeleton file's name ends.
pub const SUFFIX: &str = ".skeleton.json";

/// A plant as data: a skeleton file's contents. Fields are in the file's order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Skeleton {
    /// [`FORMAT`].
    pub format: u32,
    /// [`KIND`].
    pub kind: String,
    /// The version of Sylva that wrote it.
    pub sylva_version: String,
    /// Where the plant came from.
    pub origin: SkeletonOrigin,
    /// The pipe-model taper applied before export, or `None` for the model's own radii.
    pub taper: Option<SkeletonTaper>,
    /// `false` when the roots were left out (`--hide-roots`).
    pub roots: bool,
    /// The materials that segments and organs name by index.
    pub materials: Vec<SkeletonMaterial>,
    /// The skeleton, parents before their children.
    pub segments: Vec<SkeletonSegment>,
    /// Leaves, flowers and root tips.
    pub organs: Vec<SkeletonOrgan>,
}

/// Where a plant came from: enough to grow it again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonOrigin {
    /// The model's name.
    pub model: String,
    /// The stable hash of the genome's compact JSON, as 16 hexadecimal digits (a string,
    /// since a 64-bit number does not survive JavaScript or jq).
    pub genome_hash: String,
    /// The seed it grew with.
    pub seed: u64,
    /// The genome, as its file's JSON.
    pub genome: serde_json::Value,
}

/// The pipe-model taper, as a GLB's extras record it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonTaper {
    /// `e` in `radius ∝ (tips above)^(1/e)`, from 2 to 3.
    pub pipe_exponent: f64,
}

/// A surface look.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonMaterial {
    /// Unique within the plant; the name exported meshes use.
    pub name: String,
    /// What it is for.
    pub kind: MaterialKind,
    /// Linear RGB, each from 0 to 1.
    pub color: [f32; 3],
    /// The model's texture id, if it uses textures.
    pub texture: Option<u16>,
    /// The surface Sylva draws (leaf cards of a kind, petals, bark), when the plant was
    /// dressed; left out otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<Surface>,
    /// For cards (leaves drawn as textured quads): the share of a card's area its picture
    /// covers, so readers can tell the leaf area from the card's; left out otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<f32>,
    /// For cards: a leaf's length over its card's (a card may carry a spray of leaves);
    /// left out otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leaf_of_card: Option<f32>,
}

/// A tapered cylinder of the skeleton. Metres; Y is up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonSegment {
    /// Centre of the base.
    pub start: [f32; 3],
    /// Centre of the tip.
    pub end: [f32; 3],
    /// Radius at `start`.
    pub start_radius: f32,
    /// Radius at `end`.
    pub end_radius: f32,
    /// Branch order: 0 on the trunk's axis, one more on each branch off it.
    pub order: u16,
    /// Index of the segment it grows from (always smaller than its own), or `None`.
    pub parent: Option<u32>,
    /// `true` when it starts a branch from its parent, `false` when it continues its
    /// parent's axis.
    pub lateral: bool,
    /// Index into [`Skeleton::materials`].
    pub material: u16,
    /// Its material's kind.
    pub kind: MaterialKind,
    /// Whether it is wood (bark or root): what the pipe model thickens.
    pub woody: bool,
}

/// A leaf, flower or root tip. Metres; Y is up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonOrgan {
    /// What it is.
    pub kind: OrganKind,
    /// Where its base is attached.
    pub position: [f32; 3],
    /// Local to world, as a unit quaternion `[x, y, z, w]` (glTF's order).
    pub orientation: [f32; 4],
    /// The blade's direction from base to tip: local +Y turned by `orientation`.
    pub axis: [f32; 3],
    /// The blade's face normal: local +Z turned by `orientation`.
    pub normal: [f32; 3],
    /// Along `axis`.
    pub length: f32,
    /// Across the blade (local +X).
    pub width: f32,
    /// Index of the segment it grows on, or `None`.
    pub parent: Option<u32>,
    /// Index into [`Skeleton::materials`].
    pub material: u16,
}

impl Skeleton {
    /// The skeleton of `plant`, grown from `genome` (its `seed` and the model's name and
    /// genome hash come from the plant's metadata), tapered by `taper` and with its roots
    /// when `roots`.
    pub fn of(plant: &Plant, genome: &Genome, taper: Option<PipeTaper>, roots: bool) -> Skeleton {
        let materials = plant.materials();
        let kind_of = |m: sylva_core::MaterialId| {
            // Plants only hold materials that exist.
            materials
                .get(m.index())
                .map_or(MaterialKind::Bark, |m| m.kind)
        };
        let meta = plant.meta();
        Skeleton {
            format: FORMAT,
            kind: KIND.to_owned(),
            sylva_version: env!("CARGO_PKG_VERSION").to_owned(),
            origin: SkeletonOrigin {
                model: meta.model.clone(),
                genome_hash: format!("{:016x}", meta.genome_hash),
                seed: meta.seed,
                genome: genome.to_value(),
            },
            taper: taper.map(|t| SkeletonTaper {
                pipe_exponent: t.exponent,
            }),
            roots,
            materials: materials
                .iter()
                .map(|m| SkeletonMaterial {
                    name: m.name.clone(),
                    kind: m.kind,
                    color: m.color,
                    texture: m.texture,
                    surface: m.surface,
                    fill: m
                        .surface
                        .and_then(Surface::leaves)
                        .map(|(kind, card)| sylva_mesh::atlas::leaf_fill(kind, card)),
                    leaf_of_card: m
                        .surface
                        .and_then(Surface::leaves)
                        .map(|(kind, card)| kind.spec().leaf_of(card)),
                })
                .collect(),
            segments: plant
                .segments()
                .iter()
                .map(|s| {
                    let kind = kind_of(s.material);
                    SkeletonSegment {
                        start: s.start.to_array(),
                        end: s.end.to_array(),
                        start_radius: s.start_radius,
                        end_radius: s.end_radius,
                        order: s.order,
                        parent: s.parent.map(|p| p.0),
                        lateral: s.lateral,
                        material: s.material.0,
                        kind,
                        woody: kind.is_woody(),
                    }
                })
                .collect(),
            organs: plant
                .organs()
                .iter()
                .map(|o| SkeletonOrgan {
                    kind: o.kind,
                    position: o.position.to_array(),
                    orientation: o.orientation.to_array(),
                    axis: (o.orientation * sylva_core::glam::Vec3::Y).to_array(),
                    normal: (o.orientation * sylva_core::glam::Vec3::Z).to_array(),
                    length: o.size.x,
                    width: o.size.y,
                    parent: o.parent.map(|p| p.0),
                    material: o.material.0,
                })
                .collect(),
        }
    }

    /// The skeleton of a grown genome, with its taper and roots as grown.
    pub fn of_grown(grown: &Grown) -> Skeleton {
        Skeleton::of(&grown.plant, &grown.genome, grown.taper, grown.roots)
    }

    /// Bytes a file of `plant`'s skeleton needs, about (for the memory budget).
    pub fn estimated_bytes(plant: &Plant) -> u64 {
        // A segment's line is at most about 300 bytes, an organ's 400.
        (plant.segments().len() as u64 * 300)
            .saturating_add(plant.organs().len() as u64 * 400)
            .saturating_add(64 << 10)
    }

    /// The file's text: the fields in their order, objects and lists down to the second
    /// level one entry per line (so each segment, organ and material has its own line),
    /// deeper ones compact; floats in their shortest round-trip form; a final newline.
    pub fn to_json(&self) -> String {
        let mut bytes = Vec::new();
        let mut writer = serde_json::Serializer::with_formatter(&mut bytes, Lines::default());
        // Plain data (strings, numbers, lists; a JSON genome) always serialises.
        if self.serialize(&mut writer).is_ok() {
            bytes.push(b'\n');
        }
        String::from_utf8(bytes).unwrap_or_default()
    }

    /// What its materials say of their cards (`fill`, `leaf_of_card`), by material index:
    /// for [`crate::inspect::Report::of_cards`].
    pub fn cards(&self) -> Vec<Option<crate::inspect::Cards>> {
        self.materials
            .iter()
            .map(|m| {
                m.fill.map(|fill| crate::inspect::Cards {
                    fill: f64::from(fill),
                    leaf_of_card: f64::from(m.leaf_of_card.unwrap_or(1.0)),
                })
            })
            .collect()
    }

    /// The plant it holds, every part checked as a grown plant's are: a segment or organ
    /// that breaks a rule (a parent after its child, a material that is not there, a radius
    /// that is negative or not a number) is refused, naming it.
    pub fn to_plant(&self, path: &Path) -> Result<Plant, InputError> {
        use sylva_core::glam::{Quat, Vec2, Vec3};
        use sylva_core::{Material, MaterialId, Organ, PlantMeta, SegmentId};
        let mut plant = Plant::bare(PlantMeta {
            model: self.origin.model.clone(),
            genome_hash: u64::from_str_radix(&self.origin.genome_hash, 16).unwrap_or(0),
            seed: self.origin.seed,
        });
        let bad = |what: String, e: sylva_core::PlantError| {
            InputError::file(path, format!("{what}: {e}"))
        };
        for (i, m) in self.materials.iter().enumerate() {
            plant
                .add_material(Material {
                    name: m.name.clone(),
                    kind: m.kind,
                    color: m.color,
                    texture: m.texture,
                    surface: m.surface,
                })
                .map_err(|e| bad(format!("materials[{i}]"), e))?;
        }
        for (i, s) in self.segments.iter().enumerate() {
            if s.parent.is_some_and(|p| p as usize >= i) {
                return Err(InputError::file(
                    path,
                    format!(
                        "segments[{i}]: its parent must come before it (parents first), got {}",
                        s.parent.unwrap_or(0)
                    ),
                ));
            }
            plant
                .add_segment(
                    Vec3::from_array(s.start),
                    Vec3::from_array(s.end),
                    (s.start_radius, s.end_radius),
                    s.parent.map(SegmentId),
                    s.lateral,
                    MaterialId(s.material),
                )
                .map_err(|e| bad(format!("segments[{i}]"), e))?;
        }
        for (i, o) in self.organs.iter().enumerate() {
            let q = Quat::from_array(o.orientation);
            // Files hold four decimals' worth of rounding: renormalise a near-unit one.
            let orientation = if (q.length() - 1.0).abs() < 1e-3 {
                q.normalize()
            } else {
                q
            };
            plant
                .add_organ(Organ {
                    kind: o.kind,
                    position: Vec3::from_array(o.position),
                    orientation,
                    size: Vec2::new(o.length, o.width),
                    material: MaterialId(o.material),
                    parent: o.parent.map(SegmentId),
                })
                .map_err(|e| bad(format!("organs[{i}]"), e))?;
        }
        Ok(plant)
    }

    /// Reads a skeleton file, checking its `kind` and `format`.
    pub fn read(path: &Path) -> Result<Skeleton, InputError> {
        let text = read_text(path)?;
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| InputError::json(path, &text, &e))?;
        if value.get("kind").and_then(|k| k.as_str()) != Some(KIND) {
            return Err(InputError::file(
                path,
                format!("not a skeleton file (expected \"kind\": \"{KIND}\")"),
            ));
        }
        if value.get("format").and_then(serde_json::Value::as_u64) != Some(u64::from(FORMAT)) {
            return Err(InputError::file(
                path,
                format!("a skeleton of another format (this Sylva reads \"format\": {FORMAT})"),
            ));
        }
        serde_json::from_str(&text).map_err(|e| InputError::json(path, &text, &e))
    }
}

/// What an output path of one grown plant names: a 3D asset, by its extension, or the
/// skeleton as data (a name ending in `.skeleton.json`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GrowOutput {
    /// A mesh, as GLB, OBJ or VRML97.
    Asset(Format),
    /// The skeleton, as [`Skeleton::to_json`] writes it.
    Skeleton,
}

impl GrowOutput {
    /// Tells what `path` names, before any work is done; refuses unknown extensions and a
    /// path that is a folder.
    pub fn of(path: &Path) -> Result<GrowOutput, InputError> {
        let output = GrowOutput::by_name(path)?;
        if path.is_dir() {
            return Err(InputError::file(path, "is a folder, not a file"));
        }
        Ok(output)
    }

    /// What the name of `path` asks for.
    fn by_name(path: &Path) -> Result<GrowOutput, InputError> {
        if is_skeleton_path(path) {
            return Ok(GrowOutput::Skeleton);
        }
        Format::from_path(path).map(GrowOutput::Asset).map_err(|_| {
            let found = path.extension().map_or_else(
                || "no extension".to_owned(),
                |e| format!("\".{}\"", e.to_string_lossy()),
            );
            InputError::file(
                path,
                format!(
                    "unknown output format ({found}); expected .glb, .obj, .wrl or .stl for a mesh, \
                     or {SUFFIX} for the skeleton as data"
                ),
            )
        })
    }
}

/// Whether a file name ends in [`SUFFIX`] (in any case).
pub fn is_skeleton_path(path: &Path) -> bool {
    path.file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .is_some_and(|n| n.ends_with(SUFFIX))
}

/// Grows a genome into its skeleton, unmeshed: the roots left out when `roots` is false,
/// then the pipe model's radii with a `taper`; refused when its file would not fit the
/// memory budget.
pub fn grow_skeleton(
    genome: &Genome,
    seed: u64,
    roots: bool,
    taper: Option<PipeTaper>,
) -> Result<Skeleton, Error> {
    let plant = crate::assets::grow_plant(genome, seed, roots, taper)?;
    check_budget(&plant)?;
    Ok(Skeleton::of(&plant, genome, taper, roots))
}

/// Refuses a skeleton whose file would not fit the memory budget.
pub fn check_budget(plant: &Plant) -> Result<(), Error> {
    sylva_core::budget::check(
        Skeleton::estimated_bytes(plant),
        format_args!(
            "the skeleton file of {} segments and {} organs",
            plant.segments().len(),
            plant.organs().len()
        ),
        "grow a smaller plant",
    )?;
    Ok(())
}

/// serde_json's layout for skeleton files: objects and lists down to [`Lines::DEPTH`] one
/// entry per line, indented by two spaces a level; deeper ones compact.
#[derive(Debug, Default)]
struct Lines {
    /// Containers open.
    depth: usize,
    /// Whether the innermost open container has an entry yet.
    has_value: bool,
}

impl Lines {
    /// The deepest level laid out one entry per line: the file's fields (1) and the entries
    /// of its objects and lists (2).
    const DEPTH: usize = 2;

    fn spread(&self) -> bool {
        self.depth <= Self::DEPTH
    }

    fn open<W: ?Sized + io::Write>(&mut self, writer: &mut W, bracket: &[u8]) -> io::Result<()> {
        self.depth += 1;
        self.has_value = false;
        writer.write_all(bracket)
    }

    fn close<W: ?Sized + io::Write>(&mut self, writer: &mut W, bracket: &[u8]) -> io::Result<()> {
        let spread = self.spread();
        self.depth -= 1;
        if spread && self.has_value {
            self.newline(writer)?;
        }
        self.has_value = true;
        writer.write_all(bracket)
    }

    fn entry<W: ?Sized + io::Write>(&mut self, writer: &mut W, first: bool) -> io::Result<()> {
        if !first {
            writer.write_all(b",")?;
        }
        if self.spread() {
            self.newline(writer)?;
        }
        Ok(())
    }

    /// A new line, indented to the depth.
    fn newline<W: ?Sized + io::Write>(&self, writer: &mut W) -> io::Result<()> {
        writer.write_all(b"\n")?;
        for _ in 0..self.depth {
            writer.write_all(b"  ")?;
        }
        Ok(())
    }
}

impl serde_json::ser::Formatter for Lines {
    fn begin_array<W: ?Sized + io::Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.open(writer, b"[")
    }

    fn end_array<W: ?Sized + io::Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.close(writer, b"]")
    }

    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.entry(writer, first)
    }

    fn end_array_value<W: ?Sized + io::Write>(&mut self, _writer: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }

    fn begin_object<W: ?Sized + io::Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.open(writer, b"{")
    }

    fn end_object<W: ?Sized + io::Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.close(writer, b"}")
    }

    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.entry(writer, first)
    }

    fn begin_object_value<W: ?Sized + io::Write>(&mut self, writer: &mut W) -> io::Result<()> {
        writer.write_all(if self.spread() { b": " } else { b":" })
    }

    fn end_object_value<W: ?Sized + io::Write>(&mut self, _writer: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }
}
