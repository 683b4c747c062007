//! A plausibility report: how a plant measures against real trees.
//!
//! [`Report::of`] measures a [`Plant`] (and, when given, the triangles and texture bytes of
//! its asset): height, crown width, trunk diameter at the base and at breast height,
//! slenderness, the pipe-model (Leonardo) exponent at forks, leaf size, leaf area over the
//! crown's projection (leaf area index), the share of leaves on the last twigs, whether stems
//! are thicker below than above, triangles and texture bytes. Each [`Figure`] carries the
//! range real trees give, with its source, and a wider band outside which `--check` calls it
//! implausible; `docs/realism.md` gives the sources in full. The bands describe trees, not
//! Sylva: another generator's trees pass them too (tested on ez-tree's).
//!
//! Figures that need what a plant does not have (a trunk, forks, leaves) are left out
//! (`value: None`), never guessed.
//!
//! ```
//! use sylva::inspect::Report;
//! use sylva::{GrowOptions, Grown, Registry};
//!
//! let genome = Registry::standard().parse_genome(&std::fs::read_to_string("../../examples/bintree/oak.json")?)?;
//! let options = GrowOptions { dress: sylva::Dress::foliage(sylva::LeafKind::Oak), height: Some(14.0), ..Default::default() };
//! let grown = Grown::grow(genome, &options)?;
//! let report = Report::of(&grown.plant, None);
//! assert!(report.failures().is_empty(), "{}", report.table());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt::Write as _;

use serde::Serialize;
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::species::Surface;
use sylva_core::{MaterialKind, OrganKind, Plant};

/// What the asset of a plant weighs, when it was meshed: its triangles and the bytes of its
/// textures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct AssetFacts {
    /// Triangles drawn.
    pub triangles: u64,
    /// Bytes of the textures it carries (encoded, as stored in the file).
    pub texture_bytes: u64,
}

impl AssetFacts {
    /// The weight of a mesh Sylva made: its triangles, and the PNG bytes of every picture its
    /// drawn materials show (base pictures and normal maps, as a GLB embeds them).
    pub fn of_mesh(mesh: &sylva_mesh::Mesh) -> AssetFacts {
        use sylva_mesh::picture::Picture;
        let mut pictures = std::collections::BTreeSet::new();
        for p in mesh.primitives.iter().filter(|p| !p.indices.is_empty()) {
            if let Some(m) = mesh.materials.get(p.material) {
                pictures.extend(Picture::base_of(m));
                pictures.extend(Picture::normal_of(m));
            }
        }
        let texture_bytes = pictures
            .into_iter()
            .filter_map(|p| p.png().ok())
            .map(|png| png.len() as u64)
            .sum();
        AssetFacts {
            triangles: mesh.triangle_count() as u64,
            texture_bytes,
        }
    }

    /// The weight of a GLB file (any generator's): the triangles of its scene as read, and
    /// the bytes of the images it embeds.
    pub fn of_glb(bytes: &[u8]) -> Result<AssetFacts, sylva_gltf::import::ImportError> {
        let scene = sylva_gltf::import::read_glb(bytes)?;
        Ok(AssetFacts {
            triangles: scene.scene().triangle_count() as u64,
            texture_bytes: sylva_gltf::import::texture_bytes(bytes)?,
        })
    }
}

/// What a material's leaf organs are when they are cards: the share of a card's area its
/// picture covers, and a leaf's length over the card's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cards {
    /// The share of a card's area that is leaf.
    pub fill: f64,
    /// A leaf's length over its card's.
    pub leaf_of_card: f64,
}

/// One measured figure and the ranges it is judged by.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figure {
    /// A short name, as `--check` and JSON give it (`slenderness`).
    pub name: &'static str,
    /// What it is, in words.
    pub label: &'static str,
    /// The value, in `unit`; `None` when the plant has nothing to measure it on.
    pub value: Option<f64>,
    /// The unit (`m`, `` for ratios).
    pub unit: &'static str,
    /// What real trees give: outside it the report warns.
    pub real: (f64, f64),
    /// Outside this the figure is implausible: `--check` fails.
    pub check: (f64, f64),
    /// Where the real range comes from (docs/realism.md has the references).
    pub source: &'static str,
}

/// How a figure stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Within what real trees give.
    Real,
    /// Outside what real trees give, within the check band.
    Unusual,
    /// Outside the check band.
    Implausible,
    /// Not measured.
    None,
}

impl Figure {
    /// How it stands against its ranges.
    pub fn verdict(&self) -> Verdict {
        match self.value {
            None => Verdict::None,
            Some(v) if !(self.check.0..=self.check.1).contains(&v) => Verdict::Implausible,
            Some(v) if !(self.real.0..=self.real.1).contains(&v) => Verdict::Unusual,
            Some(_) => Verdict::Real,
        }
    }
}

/// Every figure of one plant.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The figures, in the order of the table.
    pub figures: Vec<Figure>,
}

/// Breast height, metres.
const BREAST: f32 = 1.3;

impl Report {
    /// Measures `plant`, and the asset's weight when `asset` is given. Leaf cards are known
    /// by their materials' surfaces ([`Surface::Leaves`], [`Surface::Branchlets`]).
    pub fn of(plant: &Plant, asset: Option<AssetFacts>) -> Report {
        Report::of_cards(plant, &[], asset)
    }

    /// [`Report::of`], with what each material's leaf organs are when they are cards of
    /// another generator's (`cards` by material index, as a skeleton file's materials say;
    /// [`crate::Skeleton::cards`]).
    pub fn of_cards(plant: &Plant, cards: &[Option<Cards>], asset: Option<AssetFacts>) -> Report {
        let m = Measures::of(plant, cards);
        let f = |name, label, value: Option<f64>, unit, real, check, source| Figure {
            name,
            label,
            value: value.filter(|v| v.is_finite()),
            unit,
            real,
            check,
            source,
        };
        let tree = m.height >= 3.0;
        let figures = vec![
            f(
                "height",
                "height",
                Some(m.height),
                "m",
                (0.3, 60.0),
                (0.05, 130.0),
                "Koch et al. 2004 (tallest trees 112.7 m, limit 122-130 m)",
            ),
            f(
                "crown_width_ratio",
                "crown width ÷ height",
                (m.height > 0.0).then(|| m.crown_width / m.height),
                "",
                (0.15, 2.0),
                (0.05, 5.0),
                "Coombes et al. 2019; Hemery et al. 2005 (crown ÷ stem diameter) with slenderness",
            ),
            f(
                "trunk_base",
                "trunk diameter at the base",
                m.base_diameter,
                "m",
                (0.0, 15.0),
                (0.0, 20.0),
                "the plant's own trunk (judged below as slenderness and flare)",
            ),
            f(
                "base_ratio",
                "trunk at its foot ÷ at 1.3 m",
                m.base_diameter
                    .zip(m.dbh)
                    .filter(|_| tree)
                    .map(|(b, d)| b / d),
                "",
                (1.0, 2.0),
                (0.9, 3.0),
                "butt swell of the root collar (DeYoung, Forest Measurements)",
            ),
            f(
                "slenderness",
                "slenderness (height ÷ trunk at 1.3 m)",
                m.dbh.filter(|_| tree).map(|d| m.height / d),
                "",
                (15.0, 100.0),
                (5.0, 180.0),
                "Wonn & O'Hara 2001; Orzeł 2007; Akhavan & Namiranian 2007",
            ),
            f(
                "pipe_exponent",
                "pipe-model exponent at forks (median)",
                m.pipe_exponent,
                "",
                (1.6, 3.0),
                (1.2, 8.0),
                "Eloy 2011 (1.8-2.3 measured); Bentley et al. 2013",
            ),
            f(
                "leaf_length",
                "median leaf length",
                m.leaf_length,
                "m",
                (0.01, 0.4),
                (0.002, 1.0),
                "floras (Stace 2010; Flora of North America): needles 1 cm to ash leaves 35 cm",
            ),
            f(
                "leaf_to_height",
                "median leaf length ÷ height",
                m.leaf_length
                    .filter(|_| m.height > 0.0)
                    .map(|l| l / m.height),
                "",
                (0.0005, 0.15),
                (0.0002, 0.25),
                "leaf sizes by species over tree heights (docs/realism.md)",
            ),
            f(
                "leaf_area_index",
                "leaf area ÷ crown projection (LAI)",
                m.leaf_area_index,
                "",
                (1.5, 10.0),
                (0.5, 15.0),
                "Asner et al. 2003; Körner 2013; an isolated blue oak 4.4 (Karlik & McKay)",
            ),
            f(
                "leaves_on_twigs",
                "leaves on the last twigs (share, Strahler 1-2)",
                m.leaves_on_twigs,
                "",
                (0.8, 1.0),
                (0.5, 1.0),
                "leaves grow on current shoots (Pollard 1970: 87% on short shoots in aspen)",
            ),
            f(
                "thicker_below",
                "stems no thicker than their parents (share)",
                m.thicker_below,
                "",
                (0.95, 1.0),
                (0.7, 1.0),
                "secondary growth thickens stems from the tips down",
            ),
            f(
                "triangles",
                "triangles",
                asset.map(|a| a.triangles as f64),
                "",
                (0.0, 40_000.0),
                (0.0, 150_000.0),
                "game trees 1k-23k (SpeedTree, ez-tree 4.8k-22.6k); 40k for a tree in leaf",
            ),
            f(
                "texture_bytes",
                "texture bytes",
                asset.map(|a| a.texture_bytes as f64),
                "B",
                (0.0, 2_000_000.0),
                (0.0, 2_000_000.0),
                "one 1024-pixel atlas and a bark pair per tree: 2 MB at most",
            ),
        ];
        Report { figures }
    }

    /// The report as pretty JSON: each figure with its value, ranges, source and verdict.
    pub fn to_json(&self) -> String {
        let figures: Vec<serde_json::Value> = self
            .figures
            .iter()
            .map(|f| {
                let mut v = serde_json::to_value(f).unwrap_or_default();
                v["verdict"] = serde_json::to_value(f.verdict()).unwrap_or_default();
                v
            })
            .collect();
        serde_json::to_string_pretty(&serde_json::json!({ "figures": figures })).unwrap_or_default()
    }

    /// The figures outside their check band.
    pub fn failures(&self) -> Vec<&Figure> {
        self.figures
            .iter()
            .filter(|f| f.verdict() == Verdict::Implausible)
            .collect()
    }

    /// The report as a table of text, a figure a line: value, what real trees give, and
    /// the verdict.
    pub fn table(&self) -> String {
        let mut out = String::new();
        for f in &self.figures {
            let value = match f.value {
                Some(v) => number(v, f.unit),
                None => "—".to_owned(),
            };
            let verdict = match f.verdict() {
                Verdict::Real => "",
                Verdict::Unusual => "  unusual",
                Verdict::Implausible => "  IMPLAUSIBLE",
                Verdict::None => "  not measured",
            };
            let _ = writeln!(
                out,
                "{:<42} {:>12}   real {} to {}{verdict}",
                f.label,
                value,
                number(f.real.0, f.unit),
                number(f.real.1, f.unit)
            );
        }
        out
    }
}

/// A number with its unit, to three significant figures or so.
fn number(v: f64, unit: &str) -> String {
    let text = if v != 0.0 && v.abs() < 0.01 {
        format!("{v:.5}")
    } else if v.abs() < 10.0 {
        format!("{v:.3}")
    } else if v.abs() < 1000.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.0}")
    };
    if unit.is_empty() {
        text
    } else {
        format!("{text} {unit}")
    }
}

/// The measures behind the figures.
struct Measures {
    height: f64,
    crown_width: f64,
    base_diameter: Option<f64>,
    dbh: Option<f64>,
    pipe_exponent: Option<f64>,
    leaf_length: Option<f64>,
    leaf_area_index: Option<f64>,
    leaves_on_twigs: Option<f64>,
    thicker_below: Option<f64>,
}

/// A leaf organ's leaf length and one-sided leaf area: a card's from its kind and size (its
/// leaves fill [`sylva_mesh::atlas::leaf_fill`] of it, crossed cards counted twice) or from
/// what `cards` says of its material, a plain blade's from its box (a blade fills about two
/// thirds of it).
fn leaf_of(plant: &Plant, cards: &[Option<Cards>], o: &sylva_core::Organ) -> Option<(f64, f64)> {
    let m = plant.materials().get(o.material.index())?;
    if o.kind != OrganKind::Leaf || m.kind != MaterialKind::Leaf {
        return None;
    }
    let (length, width) = (f64::from(o.size.x), f64::from(o.size.y));
    if let Some(Some(c)) = cards.get(o.material.index()) {
        return Some((length * c.leaf_of_card, length * width * c.fill));
    }
    Some(match m.surface.and_then(Surface::leaves) {
        Some((kind, card)) => {
            let spec = kind.spec();
            let faces = if spec.crossed { 2.0 } else { 1.0 };
            let fill = f64::from(sylva_mesh::atlas::leaf_fill(kind, card));
            (
                length * f64::from(spec.leaf_of(card)),
                length * width * fill * faces,
            )
        }
        None => (length, length * width * 2.0 / 3.0),
    })
}

impl Measures {
    fn of(plant: &Plant, cards: &[Option<Cards>]) -> Measures {
        let segments = plant.segments();
        let bark = |i: usize| {
            plant
                .materials()
                .get(segments[i].material.index())
                .is_some_and(|m| m.kind == MaterialKind::Bark)
        };
        // The trunk: the thickest bark segment without a parent; the ground at its foot.
        let foot = (0..segments.len())
            .filter(|&i| segments[i].parent.is_none() && bark(i))
            .max_by(|&a, &b| {
                segments[a]
                    .start_radius
                    .total_cmp(&segments[b].start_radius)
            });
        let ground = foot.map_or(0.0, |i| segments[i].start.y);

        // What stands above the ground: bark segments' ends and leaf and flower corners.
        let mut points: Vec<Vec3> = Vec::new();
        for (i, s) in segments.iter().enumerate() {
            if bark(i) {
                points.extend([s.start, s.end]);
            }
        }
        for o in plant.organs() {
            if o.kind == OrganKind::RootTip {
                continue;
            }
            let q = o.orientation;
            let (x, y) = (q * Vec3::X * (0.5 * o.size.y), q * Vec3::Y * o.size.x);
            points.extend([
                o.position - x,
                o.position + x,
                o.position + y - x,
                o.position + y + x,
            ]);
        }
        points.retain(|p| p.y >= ground - 1e-4);
        let height = points
            .iter()
            .map(|p| f64::from(p.y - ground))
            .fold(0.0, f64::max);
        let flat: Vec<Vec2> = points.iter().map(|p| Vec2::new(p.x, p.z)).collect();
        // Widths and the projection are the hull's: a few dozen corners of tens of thousands
        // of points (a match scores every plant it grows by this report).
        let hull = hull(&flat);
        let crown_width = spread(&hull);

        // Trunk diameters.
        let (base_diameter, dbh) = match foot {
            None => (None, None),
            Some(foot) => {
                let base = 2.0 * f64::from(segments[foot].start_radius);
                (
                    Some(base),
                    trunk_radius_at(plant, foot, ground + BREAST).map(|r| 2.0 * r),
                )
            }
        };

        // Leaves.
        let leaves: Vec<(f64, f64, Option<usize>)> = plant
            .organs()
            .iter()
            .filter_map(|o| {
                leaf_of(plant, cards, o).map(|(l, a)| (l, a, o.parent.map(|p| p.index())))
            })
            .collect();
        let leaf_length = median(leaves.iter().map(|l| l.0).collect());
        let area: f64 = leaves.iter().map(|l| l.1).sum();
        let projection = polygon_area(&hull);
        let leaf_area_index = (!leaves.is_empty() && projection > 0.0).then(|| area / projection);
        let strahler = strahler(plant);
        let placed: Vec<usize> = leaves.iter().filter_map(|l| l.2).collect();
        let leaves_on_twigs = (!placed.is_empty()).then(|| {
            let on = placed.iter().filter(|&&p| strahler[p] <= 2).count();
            on as f64 / placed.len() as f64
        });

        Measures {
            height,
            crown_width,
            base_diameter,
            dbh,
            pipe_exponent: pipe_exponent(plant),
            leaf_length,
            leaf_area_index,
            leaves_on_twigs,
            thicker_below: thicker_below(plant),
        }
    }
}

/// The median of `values` (`None` for none).
fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let middle = values.len() / 2;
    Some(*values.select_nth_unstable_by(middle, f64::total_cmp).1)
}

/// The crown's spread as foresters take it: the widest extent over the ground, and the extent
/// square to it, averaged (both over whole degrees).
fn spread(points: &[Vec2]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let extent = |deg: f64| {
        let a = deg.to_radians();
        let d = Vec2::new(a.cos() as f32, a.sin() as f32);
        let (lo, hi) = points.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            let t = p.dot(d);
            (lo.min(t), hi.max(t))
        });
        f64::from(hi - lo)
    };
    let (widest, at) = (0..180)
        .map(|k| (extent(f64::from(k)), k))
        .fold((0.0, 0), |best, e| if e.0 > best.0 { e } else { best });
    0.5 * (widest + extent(f64::from(at + 90)))
}

/// The corners of the convex hull of `points` (monotone chain), counter-clockwise.
fn hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .map(|v| (f64::from(v.x), f64::from(v.y)))
        .collect();
    // Unstable is the same order: equal points are the same point, and are merged next.
    p.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    p.dedup();
    if p.len() < 3 {
        return p
            .iter()
            .map(|&(x, y)| Vec2::new(x as f32, y as f32))
            .collect();
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    // Exact: the corners are points given as f32.
    hull.iter()
        .map(|&(x, y)| Vec2::new(x as f32, y as f32))
        .collect()
}

/// The area of a convex polygon given by its corners (`hull`), square metres.
fn polygon_area(corners: &[Vec2]) -> f64 {
    let n = corners.len();
    if n < 3 {
        return 0.0;
    }
    let xy = |v: Vec2| (f64::from(v.x), f64::from(v.y));
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (xy(corners[i]), xy(corners[(i + 1) % n]));
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        .abs()
}

/// The radius of the trunk's axis from `foot` at height `y` (its continuation the thickest
/// non-lateral child at each joint); `None` when the axis ends lower.
fn trunk_radius_at(plant: &Plant, foot: usize, y: f32) -> Option<f64> {
    let segments = plant.segments();
    let mut next: Vec<Option<usize>> = vec![None; segments.len()];
    for (i, s) in segments.iter().enumerate() {
        if let Some(p) = s.parent
            && !s.lateral
            && next[p.index()].is_none_or(|n: usize| segments[n].start_radius < s.start_radius)
        {
            next[p.index()] = Some(i);
        }
    }
    let mut i = foot;
    loop {
        let s = &segments[i];
        let (y0, y1) = (s.start.y.min(s.end.y), s.start.y.max(s.end.y));
        if y1 >= y && y0 <= y {
            let t = if s.end.y != s.start.y {
                ((y - s.start.y) / (s.end.y - s.start.y)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return Some(f64::from(
                s.start_radius + (s.end_radius - s.start_radius) * t,
            ));
        }
        i = next[i]?;
    }
}

/// Woody segments' Strahler orders: 1 for a tip, and at a joint the children's largest,
/// one more when two children share it (a segment continuing its axis counts as a child).
fn strahler(plant: &Plant) -> Vec<u32> {
    let segments = plant.segments();
    let n = segments.len();
    let woody = |i: usize| {
        plant
            .materials()
            .get(segments[i].material.index())
            .is_some_and(|m| m.kind.is_woody())
    };
    let (mut top, mut ties) = (vec![0u32; n], vec![0u32; n]);
    let mut order = vec![1u32; n];
    for i in (0..n).rev() {
        if woody(i) {
            order[i] = match (top[i], ties[i]) {
                (0, _) => 1,
                (t, k) if k >= 2 => t + 1,
                (t, _) => t,
            };
        }
        if let Some(p) = segments[i].parent.map(|p| p.index())
            && woody(i)
        {
            let o = order[i];
            if o > top[p] {
                (top[p], ties[p]) = (o, 1);
            } else if o == top[p] {
                ties[p] += 1;
            }
        }
    }
    order
}

/// The median exponent `e` solving `r_m^e = Σ r_d^e` over the forks that have one (a fork:
/// a woody segment with a woody lateral child at least a fifth as thick as it; the mother's
/// radius below the node, each child's at its start).
fn pipe_exponent(plant: &Plant) -> Option<f64> {
    let segments = plant.segments();
    let woody = |i: usize| {
        plant
            .materials()
            .get(segments[i].material.index())
            .is_some_and(|m| m.kind.is_woody())
    };
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); segments.len()];
    for (i, s) in segments.iter().enumerate() {
        if let Some(p) = s.parent
            && woody(i)
            && woody(p.index())
        {
            children[p.index()].push(i);
        }
    }
    let mut exponents = Vec::new();
    for (m, kids) in children.iter().enumerate() {
        let mother = f64::from(segments[m].start_radius);
        let lateral = kids
            .iter()
            .filter(|&&k| segments[k].lateral)
            .map(|&k| f64::from(segments[k].start_radius))
            .fold(0.0, f64::max);
        if mother <= 0.0 || lateral < 0.2 * mother {
            continue;
        }
        let ratios: Vec<f64> = kids
            .iter()
            .map(|&k| f64::from(segments[k].start_radius) / mother)
            .filter(|&r| r >= 0.05)
            .collect();
        if ratios.iter().any(|&r| r >= 1.0) {
            continue;
        }
        let f = |e: f64| ratios.iter().map(|r| r.powf(e)).sum::<f64>() - 1.0;
        let (mut lo, mut hi) = (0.5, 8.0);
        if f(lo) < 0.0 || f(hi) > 0.0 {
            continue;
        }
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        exponents.push(0.5 * (lo + hi));
    }
    (exponents.len() >= 3).then(|| median(exponents)).flatten()
}

/// The share of joints (a woody segment growing from a woody one) where the child starts
/// no thicker than 1.05 times the parent's radius where it leaves it.
fn thicker_below(plant: &Plant) -> Option<f64> {
    let segments = plant.segments();
    let woody = |i: usize| {
        plant
            .materials()
            .get(segments[i].material.index())
            .is_some_and(|m| m.kind.is_woody())
    };
    let (mut joints, mut fine) = (0usize, 0usize);
    for (i, s) in segments.iter().enumerate() {
        let Some(p) = s.parent.map(|p| p.index()) else {
            continue;
        };
        if !(woody(i) && woody(p)) {
            continue;
        }
        joints += 1;
        // A branch may leave anywhere along its parent: judge it by the parent's thicker end.
        let parent = &segments[p];
        fine += usize::from(s.start_radius <= 1.05 * parent.start_radius.max(parent.end_radius));
    }
    (joints > 0).then(|| fine as f64 / joints as f64)
}
