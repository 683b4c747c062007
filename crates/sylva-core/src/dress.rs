//! Dressing a grown plant for realism: leaves or needles of a kind at their real size, a
//! tiling bark, and a trunk that flares at its foot.
//!
//! [`dress`] takes any plant, whatever model grew it, and returns a copy dressed as a
//! [`Dress`] says:
//!
//! - **Foliage.** The plant's own leaves stay where they grew: each (a blade, or a leaf drawn
//!   as a segment as the L-system model draws them) becomes one or more cards of the kind
//!   (sprays of a few leaves, branchlets of a few dozen, or tufts of needles, see
//!   [`crate::species`]) spread along the blade, as many as cover its area. Twigs bare of
//!   leaves (every twig of a binary tree or most automata trees) get them too: cards along
//!   the outer stretch of every axis that ends in a tip, turned about the twig by the kind's
//!   phyllotaxis (the golden angle for alternate leaves, 90° for opposite pairs), each
//!   leaving the twig at 40 to 65° and drooping as the species does; spruce and fir splay
//!   theirs level in pairs, with shoots along the twig, as their branches lie in flat
//!   layers. A card's size follows from a leaf length drawn from the kind's real range (in
//!   metres, whatever the plant's size), and its colour from a few shades around the kind's
//!   summer colour. Petals keep their colours and texture, cut to a petal's outline
//!   ([`Surface::Petals`]).
//! - **Bark.** Every bark material shows the bark kind's tiling texture and normal map
//!   ([`Surface::Bark`]) in its colour; the foliage kind's own bark when none is given.
//! - **Wood.** Straight runs of a stem are joined into one segment, and stems are thickened
//!   by the pipe model, each leaf a pipe (exponent [`Dress::taper`]): a stem is as thick as
//!   the leaves and twig tips it carries, so twigs are thin, branches taper as their leaves
//!   leave them, and limbs thicken towards the trunk. Then the whole tree is scaled so that
//!   its trunk (or the stems from the ground together, by their basal area) is as thick at
//!   breast height (1.3 m, or a tenth of the height on a small plant) as an open-grown tree
//!   of the species (height ÷ [`LeafSpec::slenderness`](crate::species::LeafSpec)). Each
//!   trunk (a woody segment with no parent) flares at its root collar: its first stretch,
//!   about two and a half radii high, is split into rings that widen to 1.5 times the radius
//!   at the ground. Along every axis a stem never thickens towards its tip, so a stem is one
//!   smooth tube from its base, not a stack of discs.
//!
//! Every choice is drawn from the seed's own stream, so the same plant, dress and seed give
//! the same plant. At most [`Dress::max_cards`] cards are placed; more are thinned evenly
//! and the count dropped is reported in [`Dressed`], never hidden.
//!
//! ```
//! use sylva_core::{Plant, PlantMeta, glam::Vec3};
//! use sylva_core::dress::{Dress, dress};
//! use sylva_core::species::LeafKind;
//!
//! let mut plant = Plant::new(PlantMeta::default());
//! let trunk = plant.add_segment(Vec3::ZERO, 2.0 * Vec3::Y, (0.1, 0.05), None, false, Plant::BARK)?;
//! plant.add_segment(2.0 * Vec3::Y, Vec3::new(0.5, 3.0, 0.0), (0.05, 0.01), Some(trunk), true, Plant::BARK)?;
//! let (dressed, report) = dress(&plant, &Dress::foliage(LeafKind::Oak), 1)?;
//! assert!(report.cards > 0);
//! assert_eq!(dressed.organs().len(), report.cards as usize);
//! # Ok::<(), sylva_core::PlantError>(())
//! ```

use glam::{Mat3, Quat, Vec2, Vec3};
use rand::{Rng, RngExt};

use crate::plant::{Material, MaterialId, MaterialKind, Organ, OrganKind, Plant, PlantError};
use crate::rng;
use crate::species::{Arrangement, BarkKind, Card, LeafKind, Surface};
use crate::taper::PipeTaper;

/// Shades of a foliage kind's colour given to its cards.
pub const SHADES: usize = 5;

/// Most cards a dress places by default: 12,000 flat cards are 24,000 triangles (one-sided
/// cards drawn from both sides by their material), which with the wood keeps a tree in
/// leaf under a game's budget of 40,000; kinds of crossed cards (conifers) place a third as
/// many, 16,000 triangles, for a budget of 30,000.
pub const DEFAULT_MAX_CARDS: u32 = 12_000;

/// How to dress a plant. Every field says its default ([`Dress::default`] changes nothing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dress {
    /// Leaves or needles of this kind. Default `None`: the plant's own leaves, as grown.
    pub foliage: Option<LeafKind>,
    /// The bark. Default `None`: the foliage kind's own bark when foliage is set, else the
    /// plant's own look.
    pub bark: Option<BarkKind>,
    /// Cards per metre of twig, as a multiple of the kind's own spacing, 0.25 to 4.
    /// Default 1.
    pub density: f32,
    /// Most flat cards placed (a third as many of crossed ones); beyond, cards are thinned
    /// evenly. Default [`DEFAULT_MAX_CARDS`].
    pub max_cards: u32,
    /// The card size. Default `None`: branchlets on plants at least [`BRANCHLET_HEIGHT`]
    /// tall, sprays on smaller ones.
    pub card: Option<Card>,
    /// The pipe model the wood is thickened by when bark is dressed. Default exponent 2.5.
    pub taper: PipeTaper,
}

/// Height over breast-height diameter of a trunk dressed without a foliage kind.
pub const DEFAULT_SLENDERNESS: f32 = 40.0;

/// Plants at least this tall (metres) wear branchlets rather than sprays by default: a
/// crown of sprays would need more cards than an engine's budget allows.
pub const BRANCHLET_HEIGHT: f32 = 4.0;

impl Default for Dress {
    fn default() -> Self {
        Dress {
            foliage: None,
            bark: None,
            density: 1.0,
            max_cards: DEFAULT_MAX_CARDS,
            card: None,
            taper: PipeTaper { exponent: 2.5 },
        }
    }
}

impl Dress {
    /// Foliage of `kind` and its species' bark.
    pub fn foliage(kind: LeafKind) -> Dress {
        Dress {
            foliage: Some(kind),
            ..Dress::default()
        }
    }

    /// The bark this dress puts on: the one given, else the foliage's.
    pub fn bark_kind(&self) -> Option<BarkKind> {
        self.bark.or(self.foliage.map(LeafKind::bark))
    }

    /// Whether it changes anything at all.
    pub fn is_plain(&self) -> bool {
        self.foliage.is_none() && self.bark.is_none()
    }
}

/// What [`dress`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dressed {
    /// Leaf or needle cards placed.
    pub cards: u32,
    /// The plant's own leaves replaced by cards.
    pub leaves_replaced: u32,
    /// Cards left out to stay within [`Dress::max_cards`].
    pub dropped: u32,
    /// The most cards this plant could take ([`Dress::max_cards`], a third of it for
    /// crossed cards).
    pub most: u32,
    /// Trunks given a flared root collar.
    pub collars: u32,
}

/// The plant dressed as `dress` says (see the [module docs](self)), and what was done.
pub fn dress(plant: &Plant, dress: &Dress, seed: u64) -> Result<(Plant, Dressed), PlantError> {
    let mut report = Dressed::default();
    let mut out = Plant::bare(plant.meta().clone());
    for m in plant.materials() {
        out.add_material(m.clone())?;
    }
    if dress.is_plain() {
        for s in plant.segments() {
            out.add_segment(
                s.start,
                s.end,
                (s.start_radius, s.end_radius),
                s.parent,
                s.lateral,
                s.material,
            )?;
        }
        for o in plant.organs() {
            out.add_organ(*o)?;
        }
        return Ok((out, report));
    }
    let woody = |m: MaterialId| {
        plant
            .materials()
            .get(m.index())
            .is_some_and(|m| m.kind.is_woody())
    };
    let bark = dress.bark_kind();
    let wood;
    let plant = if bark.is_some() {
        let slenderness = dress
            .foliage
            .map_or(DEFAULT_SLENDERNESS, |k| k.spec().slenderness);
        wood = thicken(&join_straight_runs(plant)?, dress.taper, slenderness);
        &wood
    } else {
        plant
    };
    if let Some(kind) = bark {
        for (i, m) in plant.materials().iter().enumerate() {
            if m.kind == MaterialKind::Bark {
                out.replace_material(
                    MaterialId(i as u16),
                    Material {
                        color: kind.spec().color,
                        surface: Some(Surface::Bark(kind)),
                        texture: None,
                        ..m.clone()
                    },
                )?;
            }
        }
    }

    // The skeleton, each trunk's foot split into a flared collar when bark is dressed, and
    // radii that never grow along an axis.
    // Leaves a model draws as segments (the L-system's) become leaf sites when foliage is
    // dressed: they leave the skeleton, with anything growing from them.
    let leaf_segment = |m: MaterialId| {
        dress.foliage.is_some()
            && plant
                .materials()
                .get(m.index())
                .is_some_and(|m| m.kind == MaterialKind::Leaf)
    };
    // A leaf segment bearing a blade of its own (PlantMaker's midribs) is that blade's,
    // not a leaf of its own.
    let mut bears_blade = vec![false; plant.segments().len()];
    for o in plant.organs() {
        if let Some(p) = o.parent
            && is_leaf(plant, o)
        {
            bears_blade[p.index()] = true;
        }
    }
    let mut sites = Vec::new();
    let mut new_id: Vec<Option<crate::plant::SegmentId>> =
        Vec::with_capacity(plant.segments().len());
    // Each segment's nearest kept ancestor-or-self: where what grew on a gone one goes.
    let mut host: Vec<Option<crate::plant::SegmentId>> = Vec::with_capacity(plant.segments().len());
    for (i, s) in plant.segments().iter().enumerate() {
        let up = s.parent.and_then(|p| host[p.index()]);
        let parent = match s.parent {
            Some(p) => match new_id[p.index()] {
                Some(id) => Some(id),
                None => {
                    new_id.push(None);
                    host.push(up);
                    continue;
                }
            },
            None => None,
        };
        if leaf_segment(s.material) {
            if !bears_blade[i] {
                sites.push(leaf_site(s, parent));
            }
            new_id.push(None);
            host.push(up);
            continue;
        }
        let mut end_radius = s.end_radius;
        let mut start_radius = s.start_radius;
        if bark.is_some()
            && woody(s.material)
            && let Some(p) = parent
            && !s.lateral
        {
            let up = out.segment(p);
            start_radius = start_radius.min(up.end_radius);
            end_radius = end_radius.min(start_radius);
        }
        let is_trunk = s.parent.is_none()
            && woody(s.material)
            && plant
                .materials()
                .get(s.material.index())
                .is_some_and(|m| m.kind == MaterialKind::Bark);
        let id = if bark.is_some() && is_trunk && s.length() > 4.0 * s.start_radius {
            report.collars += 1;
            collar(&mut out, s, start_radius, end_radius)?
        } else {
            out.add_segment(
                s.start,
                s.end,
                (start_radius, end_radius),
                parent,
                s.lateral,
                s.material,
            )?
        };
        new_id.push(Some(id));
        host.push(Some(id));
    }

    let mut rng = rng::seeded(seed ^ 0x5e1a_d7e5_5d2e_55ed);
    let card = dress.card.unwrap_or(if plant.height() >= BRANCHLET_HEIGHT {
        Card::Branchlet
    } else {
        Card::Spray
    });
    let foliage = match dress.foliage {
        Some(kind) => Some((
            Foliage { kind, card },
            shades(&mut out, kind, card, &mut rng)?,
        )),
        None => None,
    };
    let mut cards = Vec::new();
    // Where leaves grow, by segment of the dressed plant, and then whether any grow above
    // each: twigs bare of leaves get cards of their own.
    let mut leafy = vec![false; out.segments().len()];
    let leaf_hosts = sites.iter().map(|site| site.parent).chain(
        plant
            .organs()
            .iter()
            .filter(|o| is_leaf(plant, o))
            .map(|o| o.parent.and_then(|p| host[p.index()])),
    );
    for h in leaf_hosts.flatten() {
        leafy[h.index()] = true;
    }
    for (i, s) in out.segments().iter().enumerate().rev() {
        if let Some(p) = s.parent
            && leafy[i]
        {
            leafy[p.index()] = true;
        }
    }
    for site in &sites {
        if let Some((foliage, shades)) = &foliage {
            report.leaves_replaced += 1;
            leaf_to_cards(
                site,
                site.parent,
                *foliage,
                shades,
                dress.density,
                &mut rng,
                &mut cards,
            );
        }
    }
    for o in plant.organs() {
        // On a segment that went (a leaf drawn as a segment): on its nearest kept ancestor.
        let parent = o.parent.and_then(|p| host[p.index()]);
        match (&foliage, o.kind) {
            (Some((foliage, shades)), OrganKind::Leaf) if is_leaf(plant, o) => {
                report.leaves_replaced += 1;
                leaf_to_cards(
                    o,
                    parent,
                    *foliage,
                    shades,
                    dress.density,
                    &mut rng,
                    &mut cards,
                );
            }
            (Some(_), OrganKind::Flower) => {
                let m = &plant.materials()[o.material.index()];
                let mut petals = m.clone();
                petals.surface = Some(Surface::Petals);
                out.replace_material(o.material, petals)?;
                out.add_organ(Organ { parent, ..*o })?;
            }
            _ => out.add_organ(Organ { parent, ..*o })?,
        }
    }
    if let Some((foliage, shades)) = &foliage {
        twig_cards(
            &out,
            &leafy,
            *foliage,
            shades,
            dress.density,
            &mut rng,
            &mut cards,
        );
    }
    let most = match foliage {
        Some((f, _)) if f.kind.spec().crossed => dress.max_cards / 3,
        _ => dress.max_cards,
    };
    report.most = most;
    let kept = thin(cards, most as usize, &mut report);
    for card in kept {
        out.add_organ(card)?;
    }
    Ok((out, report))
}

/// Breast height, metres: where a trunk's diameter is measured.
const BREAST_HEIGHT: f32 = 1.3;

/// The plant with its bark thickened by the pipe model, each leaf a pipe: a stem's
/// cross-section is the sum of those of the leaves and twig tips it carries, so a branch
/// tapers along its length as its leaves leave it, and a twig is thin whatever grew it.
/// Then the whole is scaled so that the trunk (or the stems from the ground together, by
/// their basal area) is `height / slenderness` thick at breast height (at a tenth of the
/// height on plants under 13 m, whose breast height lies too low to tell a trunk by).
fn thicken(plant: &Plant, taper: PipeTaper, slenderness: f32) -> Plant {
    let mut plant = plant.clone();
    let kind = |m: MaterialId| plant.materials().get(m.index()).map(|m| m.kind);
    let segments = plant.segments();
    let n = segments.len();
    let bark: Vec<bool> = segments
        .iter()
        .map(|s| kind(s.material) == Some(MaterialKind::Bark))
        .collect();
    // Pipes each bark segment carries: its own leaves (organs, and leaves drawn as
    // segments), its tip if nothing woody grows from it, and all its children's.
    let mut own = vec![0u32; n];
    for o in plant.organs() {
        if o.kind == OrganKind::Leaf
            && let Some(p) = o.parent
        {
            own[p.index()] += 1;
        }
    }
    let mut bears_wood = vec![false; n];
    for (i, s) in segments.iter().enumerate() {
        if let Some(p) = s.parent.map(|p| p.index()) {
            if bark[i] {
                bears_wood[p] = true;
            } else if kind(s.material) == Some(MaterialKind::Leaf) {
                own[p] += 1;
            }
        }
    }
    // Children come after their parents: one pass from the last segment gathers them.
    let mut pipes = vec![0u32; n];
    let mut continuation: Vec<Option<usize>> = vec![None; n];
    for i in (0..n).rev() {
        if !bark[i] {
            continue;
        }
        pipes[i] += own[i] + u32::from(!bears_wood[i]);
        let s = &segments[i];
        if let Some(p) = s.parent.map(|p| p.index()) {
            pipes[p] += pipes[i];
            if !s.lateral && continuation[p].is_none_or(|c| pipes[c] < pipes[i]) {
                continuation[p] = Some(i);
            }
        }
    }
    // Radii in units of one pipe's.
    let inv = 1.0 / taper.exponent;
    let radius = |k: u32| (f64::from(k.max(1))).powf(inv) as f32;
    let unit: Vec<(f32, f32)> = (0..n)
        .map(|i| {
            let start = radius(pipes[i]);
            let end = continuation[i].map_or(radius(pipes[i].saturating_sub(own[i])), |c| {
                radius(pipes[c])
            });
            (start, end.min(start))
        })
        .collect();
    // The stems from the ground: bark skeleton roots, judged together by basal area.
    let roots: Vec<usize> = (0..n)
        .filter(|&i| segments[i].parent.is_none() && bark[i])
        .collect();
    let Some(ground) = roots
        .iter()
        .map(|&i| segments[i].start.y)
        .min_by(f32::total_cmp)
    else {
        return plant;
    };
    let height = plant.height() - ground;
    if height.is_nan() || height <= 0.0 {
        return plant;
    }
    let at = BREAST_HEIGHT.min(0.1 * height);
    let area: f64 = roots
        .iter()
        .filter_map(|&r| radius_up_axis(segments, &continuation, &unit, r, ground + at))
        .map(|r| f64::from(r) * f64::from(r))
        .sum();
    let factor = (0.5 * height / slenderness) / area.sqrt() as f32;
    if !(factor.is_finite() && factor > 0.0) || factor > crate::plant::MAX_COORD {
        return plant;
    }
    for ((s, u), _) in plant
        .segments_mut()
        .iter_mut()
        .zip(&unit)
        .zip(&bark)
        .filter(|(_, b)| **b)
    {
        (s.start_radius, s.end_radius) = (u.0 * factor, u.1 * factor);
    }
    plant
}

/// The radius (from `unit`) of the axis from `foot` at height `y`, following each
/// segment's `continuation`; the last segment's end radius when the axis ends lower.
fn radius_up_axis(
    segments: &[crate::plant::Segment],
    continuation: &[Option<usize>],
    unit: &[(f32, f32)],
    foot: usize,
    y: f32,
) -> Option<f32> {
    let mut i = foot;
    loop {
        let s = &segments[i];
        match continuation[i] {
            Some(c) if s.end.y < y => i = c,
            _ => {
                let t = if s.end.y > s.start.y {
                    ((y - s.start.y) / (s.end.y - s.start.y)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                return Some(unit[i].0 + (unit[i].1 - unit[i].0) * t);
            }
        }
    }
}

/// Straight runs of a stem joined into one segment when they bend less than this (radians)
/// at each joint: a tube's rings there show nothing.
const JOIN_BEND: f32 = 0.1;

/// The plant with each straight run of bark joined: a segment whose parent it continues
/// (its only child, bearing no organ, of the same material) within [`JOIN_BEND`] of its
/// direction extends that parent, as long as the run stays shorter than a tenth of the
/// plant's height, so long curves keep their shape.
fn join_straight_runs(plant: &Plant) -> Result<Plant, PlantError> {
    let segments = plant.segments();
    let n = segments.len();
    let mut children = vec![0u32; n];
    for s in segments {
        if let Some(p) = s.parent {
            children[p.index()] += 1;
        }
    }
    let mut bears = vec![false; n];
    for o in plant.organs() {
        if let Some(p) = o.parent {
            bears[p.index()] = true;
        }
    }
    let bark = |i: usize| {
        plant
            .materials()
            .get(segments[i].material.index())
            .is_some_and(|m| m.kind == MaterialKind::Bark)
    };
    let most = 0.1 * plant.height();
    // The joined segments, and for each original one the joined one it became.
    let mut joined: Vec<crate::plant::Segment> = Vec::with_capacity(n);
    let mut into = Vec::with_capacity(n);
    let mut run_start: Vec<Vec3> = Vec::with_capacity(n);
    for (i, s) in segments.iter().enumerate() {
        if let Some(p) = s.parent.map(|p| p.index())
            && !s.lateral
            && children[p] == 1
            && !bears[p]
            && bark(i)
            && bark(p)
            && s.material == segments[p].material
        {
            let j: usize = into[p];
            let run = &joined[j];
            let (a, b) = (
                run.vector().normalize_or(Vec3::Y),
                s.vector().normalize_or(Vec3::Y),
            );
            if a.dot(b) >= JOIN_BEND.cos() && run_start[j].distance(s.end) <= most {
                joined[j].end = s.end;
                joined[j].end_radius = s.end_radius;
                into.push(j);
                continue;
            }
        }
        let mut seg = *s;
        seg.parent = s
            .parent
            .map(|p| crate::plant::SegmentId(into[p.index()] as u32));
        run_start.push(s.start);
        joined.push(seg);
        into.push(joined.len() - 1);
    }
    if joined.len() == n {
        return Ok(plant.clone());
    }
    let mut out = Plant::bare(plant.meta().clone());
    for m in plant.materials() {
        out.add_material(m.clone())?;
    }
    for s in &joined {
        out.add_segment(
            s.start,
            s.end,
            (s.start_radius, s.end_radius),
            s.parent,
            s.lateral,
            s.material,
        )?;
    }
    for o in plant.organs() {
        let parent = o
            .parent
            .map(|p| crate::plant::SegmentId(into[p.index()] as u32));
        out.add_organ(Organ { parent, ..*o })?;
    }
    Ok(out)
}

/// A kind of leaves on cards of a size.
#[derive(Clone, Copy, Debug)]
struct Foliage {
    kind: LeafKind,
    card: Card,
}

impl Foliage {
    /// A card's size: a leaf length from the kind's range, and the card around it.
    fn card_size(self, rng: &mut impl Rng) -> f32 {
        let spec = self.kind.spec();
        let (lo, hi) = spec.length;
        rng.random_range(lo..=hi) / spec.leaf_of(self.card)
    }

    /// A card's mean size.
    fn typical(self) -> f32 {
        let spec = self.kind.spec();
        0.5 * (spec.length.0 + spec.length.1) / spec.leaf_of(self.card)
    }
}

/// A leaf drawn as a segment, as a leaf organ along it: as long as the segment, as wide as
/// its thickest end, facing up as far as it can.
fn leaf_site(s: &crate::plant::Segment, parent: Option<crate::plant::SegmentId>) -> Organ {
    let along = s.vector().normalize_or(Vec3::Y);
    Organ {
        kind: OrganKind::Leaf,
        position: s.start,
        orientation: card_rotation(along, Vec3::Y),
        size: Vec2::new(s.length(), 2.0 * s.start_radius.max(s.end_radius)),
        material: s.material,
        parent,
    }
}

/// Whether an organ is a leaf blade of a leaf material.
fn is_leaf(plant: &Plant, o: &Organ) -> bool {
    o.kind == OrganKind::Leaf
        && plant
            .materials()
            .get(o.material.index())
            .is_some_and(|m| m.kind == MaterialKind::Leaf)
}

/// Adds the [`SHADES`] materials of a foliage kind: its summer colour made lighter or
/// darker and a little yellower or bluer, each by up to the kind's variation.
fn shades(
    plant: &mut Plant,
    kind: LeafKind,
    card: Card,
    rng: &mut impl Rng,
) -> Result<Vec<MaterialId>, PlantError> {
    let spec = kind.spec();
    let mut ids = Vec::with_capacity(SHADES);
    for i in 0..SHADES {
        // Evenly spread brightness, a random warm or cool tilt.
        let light = 1.0 + spec.variation * (2.0 * i as f32 / (SHADES - 1) as f32 - 1.0);
        let warm = spec.variation * rng.random_range(-1.0f32..=1.0);
        let [r, g, b] = spec.color;
        let color = [
            (r * light * (1.0 + warm)).clamp(0.0, 1.0),
            (g * light).clamp(0.0, 1.0),
            (b * light * (1.0 - warm)).clamp(0.0, 1.0),
        ];
        ids.push(plant.add_material(Material {
            name: format!("leaf-{}-{i}", spec.name),
            kind: MaterialKind::Leaf,
            color,
            texture: None,
            surface: Some(match card {
                Card::Spray => Surface::Leaves(kind),
                Card::Branchlet => Surface::Branchlets(kind),
            }),
        })?);
    }
    Ok(ids)
}

/// Adds a trunk's first segment as a flared collar and the rest of it; returns the last
/// piece, which stands for the segment (its children grow from it).
fn collar(
    out: &mut Plant,
    s: &crate::plant::Segment,
    r0: f32,
    r1: f32,
) -> Result<crate::plant::SegmentId, PlantError> {
    let length = s.length();
    let height = (2.5 * r0).min(0.4 * length);
    let radius = |d: f32| {
        let base = r0 + (r1 - r0) * d / length;
        let t = (1.0 - d / height).max(0.0);
        base * (1.0 + 0.5 * t * t)
    };
    let at = |d: f32| s.start + s.vector() * (d / length);
    let mut parent = None;
    let mut from = 0.0;
    for f in [0.12, 0.35, 1.0] {
        let to = height * f;
        let id = out.add_segment(
            at(from),
            at(to),
            (radius(from), radius(to)),
            parent,
            false,
            s.material,
        )?;
        parent = Some(id);
        from = to;
    }
    out.add_segment(
        at(from),
        s.end,
        (radius(from), r1),
        parent,
        false,
        s.material,
    )
}

/// The rotation whose +Y is `along` and whose +Z (the card's face) is as near to `face`
/// as a direction square to `along` can be.
fn card_rotation(along: Vec3, face: Vec3) -> Quat {
    let y = along.normalize_or(Vec3::Y);
    let z = (face - y * face.dot(y))
        .try_normalize()
        .unwrap_or_else(|| y.any_orthonormal_vector());
    let x = y.cross(z);
    Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize()
}

/// A direction square to `dir`, turned `angle` radians about it from a fixed reference.
fn radial(dir: Vec3, angle: f32) -> Vec3 {
    let dir = dir.normalize_or(Vec3::Y);
    // The reference is the horizontal square to the twig (or X for an upright one), so
    // the phyllotaxis turns from the same side whichever way the twig points.
    let a = Vec3::Y.cross(dir).try_normalize().unwrap_or(Vec3::X);
    let b = dir.cross(a);
    a * angle.cos() + b * angle.sin()
}

/// How far a kind's cards droop towards the ground (0: not at all).
fn droop(kind: LeafKind) -> f32 {
    match kind {
        LeafKind::Willow => 1.6,
        LeafKind::Birch => 0.6,
        LeafKind::Aspen | LeafKind::Ash => 0.25,
        LeafKind::Spruce => 0.2,
        _ => 0.1,
    }
}

/// A broadleaf spray leaving a twig at `base` going along `dir`, turned `turn` radians
/// about it.
fn spray(
    foliage: Foliage,
    base: Vec3,
    dir: Vec3,
    turn: f32,
    parent: Option<crate::plant::SegmentId>,
    material: MaterialId,
    rng: &mut impl Rng,
) -> Organ {
    let out = radial(dir, turn);
    let tilt = rng.random_range(0.70f32..=1.13); // 40 to 65 degrees from the twig
    let mut along = dir.normalize_or(Vec3::Y) * tilt.cos() + out * tilt.sin();
    along = (along - Vec3::Y * droop(foliage.kind)).normalize_or(along);
    // Leaves turn their faces up to the light, a little outwards.
    let face = Vec3::Y + 0.35 * out;
    let size = foliage.card_size(rng);
    Organ {
        kind: OrganKind::Leaf,
        position: base,
        orientation: card_rotation(along, face),
        size: Vec2::splat(size),
        material,
        parent,
    }
}

/// A needle card laid along a shoot from `base` towards `dir`, rolled `turn` radians.
fn shoot(
    kind: LeafKind,
    base: Vec3,
    dir: Vec3,
    turn: f32,
    size: f32,
    parent: Option<crate::plant::SegmentId>,
    material: MaterialId,
) -> Organ {
    let mut along = dir.normalize_or(Vec3::Y);
    along = (along - Vec3::Y * droop(kind)).normalize_or(along);
    let face = Vec3::Y + 0.5 * radial(along, turn);
    Organ {
        kind: OrganKind::Leaf,
        position: base,
        orientation: card_rotation(along, face),
        size: Vec2::splat(size),
        material,
        parent,
    }
}

/// Cards for one of the plant's own leaves: as many as cover its blade, along it.
fn leaf_to_cards(
    leaf: &Organ,
    parent: Option<crate::plant::SegmentId>,
    foliage: Foliage,
    shades: &[MaterialId],
    density: f32,
    rng: &mut impl Rng,
    cards: &mut Vec<Organ>,
) {
    let kind = foliage.kind;
    let spec = kind.spec();
    let q = leaf.orientation.normalize();
    let (axis, side) = (q * Vec3::Y, q * Vec3::X);
    let (length, width) = (leaf.size.x, leaf.size.y);
    let typical = foliage.typical();
    // A blade fills about half its box, a card about 40% of its own: as many cards as
    // cover the blade, in rows along it and columns across it (at most 64).
    let n = ((0.5 * length * width * density) / (0.4 * typical * typical)).round();
    let n = n.clamp(1.0, 64.0) as u32;
    let rows = ((n as f32 * length / width.max(1e-6)).sqrt().round() as u32).clamp(1, n);
    let cols = n.div_ceil(rows);
    for i in 0..rows * cols {
        let (row, col) = (i / cols, i % cols);
        let along = (row as f32 + 0.5) / rows as f32;
        // Across the blade, within its outline there (widest a third of the way up).
        let half = 0.5 * width * (2.6 * along.sqrt() * (1.0 - along)).min(1.0);
        let across = half * (2.0 * (col as f32 + 0.5) / cols as f32 - 1.0);
        let material = shades[rng.random_range(0..shades.len())];
        let at = leaf.position + axis * (length * (row as f32 / rows as f32)) + side * across;
        if spec.needles {
            let size = foliage.card_size(rng);
            let turn = rng.random_range(0.0..std::f32::consts::TAU);
            cards.push(shoot(kind, at, axis, turn, size, parent, material));
        } else {
            // Cards fan out about the blade's line, alternately to each side.
            let sign = if (row + col) % 2 == 0 { 1.0 } else { -1.0 };
            let dir = (axis + side * (0.4 * sign)).normalize_or(axis);
            let mut card = spray(foliage, at, dir, 0.0, parent, material, rng);
            card.orientation = card_rotation(dir, q * Vec3::Z + Vec3::Y * 0.5);
            cards.push(card);
        }
    }
}

/// Cards along the outer stretch of every axis that ends in a tip, but on stems where the
/// plant's own leaves grow (`leafy`: leaves on them or above them), which wear those.
fn twig_cards(
    plant: &Plant,
    leafy: &[bool],
    foliage: Foliage,
    shades: &[MaterialId],
    density: f32,
    rng: &mut impl Rng,
    cards: &mut Vec<Organ>,
) {
    let kind = foliage.kind;
    let spec = kind.spec();
    let segments = plant.segments();
    let woody: Vec<bool> = segments
        .iter()
        .map(|s| plant.materials()[s.material.index()].kind == MaterialKind::Bark)
        .collect();
    // Distance from each segment's end to the nearest tip above it (0 for a tip), found
    // children first; f32::MAX where no tip lies above.
    let n = segments.len();
    let mut to_tip = vec![f32::MAX; n];
    let mut bears = vec![false; n];
    for i in (0..n).rev() {
        if !woody[i] {
            continue;
        }
        if !bears[i] {
            to_tip[i] = 0.0;
        }
        if let Some(p) = segments[i].parent.map(|p| p.index())
            && woody[p]
        {
            bears[p] = true;
            to_tip[p] = to_tip[p].min(to_tip[i] + segments[i].length());
        }
    }
    let typical = foliage.typical();
    let density = density.clamp(0.25, 4.0);
    // Broadleaves: sprays every 0.3 card along the outer stretch of each axis, the last
    // 2.5 cards or a fifth of the plant's height if more (a large crown's twigs stand for
    // many more than the model grew). Spruce and fir: a pair of shoots splayed flat every
    // half card, and one along the twig every other station, along the last 6 cards or 40%
    // of the height (a conifer keeps its needles for years, in flat layers). Pine: tufts
    // radiating from the outer 3 cards or sixth of the height (its needles crowd the ends
    // of its shoots).
    let height = plant.height();
    let layered = matches!(
        spec.arrangement,
        Arrangement::Spiral | Arrangement::TwoRanked
    );
    let (spacing, zone) = if layered {
        (0.5 * typical / density, (6.0 * typical).max(0.4 * height))
    } else if spec.needles {
        (0.35 * typical / density, (3.0 * typical).max(height / 6.0))
    } else {
        (0.3 * typical / density, (2.5 * typical).max(height / 5.0))
    };
    let divergence = spec.arrangement.divergence_deg().to_radians();
    for (i, s) in segments.iter().enumerate() {
        if !woody[i] || to_tip[i] >= zone || leafy[i] {
            continue;
        }
        let length = s.length();
        let dir = s.vector().normalize_or(Vec3::Y);
        let id = Some(crate::plant::SegmentId(i as u32));
        // Stations from the segment's end backwards while within the zone.
        let mut d = rng.random_range(0.0..spacing);
        let mut turn = rng.random_range(0.0..std::f32::consts::TAU);
        let mut node = 0u32;
        while d <= length && to_tip[i] + d < zone {
            let at = s.end - dir * d;
            let material = shades[rng.random_range(0..shades.len())];
            if layered {
                // Left and right in the twig's own level plane (radial's angle 0 is level).
                for side in [0.0, std::f32::consts::PI] {
                    let t = side + rng.random_range(-0.35..=0.35);
                    cards.push(spray(foliage, at, dir, t, id, material, rng));
                }
                if node.is_multiple_of(2) {
                    let size = foliage.card_size(rng);
                    let from = at - dir * (0.5 * size);
                    cards.push(shoot(kind, from, dir, turn, size, id, material));
                }
            } else if spec.needles {
                cards.push(spray(foliage, at, dir, turn, id, material, rng));
            } else {
                let r = s.end_radius + (s.start_radius - s.end_radius) * (d / length.max(1e-6));
                for k in 0..spec.arrangement.per_node() {
                    let t = turn + std::f32::consts::PI * k as f32;
                    let base = at + radial(dir, t) * r;
                    cards.push(spray(foliage, base, dir, t, id, material, rng));
                }
            }
            node += 1;
            turn += divergence + rng.random_range(-0.2..=0.2);
            d += spacing * rng.random_range(0.8..=1.2);
        }
        // A tip ends in a spray (or shoot) carrying on its line.
        if !bears[i] && node > 0 {
            let material = shades[rng.random_range(0..shades.len())];
            let size = foliage.card_size(rng);
            let face = Vec3::Y + 0.3 * radial(dir, turn);
            cards.push(Organ {
                kind: OrganKind::Leaf,
                position: s.end,
                orientation: card_rotation((dir - Vec3::Y * droop(kind)).normalize_or(dir), face),
                size: Vec2::splat(size),
                material,
                parent: id,
            });
        }
    }
}

/// At most `max` cards, thinned evenly (every k-th kept) when there are more.
fn thin(cards: Vec<Organ>, max: usize, report: &mut Dressed) -> Vec<Organ> {
    let n = cards.len();
    if n <= max {
        report.cards = n as u32;
        return cards;
    }
    let kept: Vec<Organ> = cards
        .into_iter()
        .enumerate()
        .filter(|(i, _)| (i * max) / n != ((i + 1) * max) / n)
        .map(|(_, c)| c)
        .collect();
    report.cards = kept.len() as u32;
    report.dropped = (n - kept.len()) as u32;
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlantMeta;

    /// A trunk forking twice: four tips, 3 m tall.
    fn tree() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let t = p
            .add_segment(
                Vec3::ZERO,
                1.5 * Vec3::Y,
                (0.12, 0.08),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        for x in [-1.0f32, 1.0] {
            let top = Vec3::new(0.5 * x, 2.3, 0.0);
            let b = p
                .add_segment(1.5 * Vec3::Y, top, (0.06, 0.04), Some(t), true, Plant::BARK)
                .unwrap();
            for z in [-1.0f32, 1.0] {
                let tip = top + Vec3::new(0.3 * x, 0.7, 0.4 * z);
                p.add_segment(top, tip, (0.03, 0.01), Some(b), true, Plant::BARK)
                    .unwrap();
            }
        }
        p
    }

    #[test]
    fn plain_dress_changes_nothing() {
        let p = tree();
        let (d, report) = dress(&p, &Dress::default(), 1).unwrap();
        assert_eq!(d, p);
        assert_eq!(report, Dressed::default());
    }

    #[test]
    fn twigs_get_cards_of_real_size_near_their_tips() {
        let p = tree();
        let (d, report) = dress(&p, &Dress::foliage(LeafKind::Oak), 7).unwrap();
        assert!(report.cards >= 8, "{report:?}");
        assert_eq!(report.collars, 1);
        let spec = LeafKind::Oak.spec();
        for o in d.organs() {
            let m = &d.materials()[o.material.index()];
            // A 3 m plant wears sprays.
            assert_eq!(m.surface, Some(Surface::Leaves(LeafKind::Oak)));
            let leaf = o.size.x * spec.leaf_of_spray;
            assert!((0.08 - 1e-4..=0.12 + 1e-4).contains(&leaf), "{leaf}");
            // Cards sit on the crown's twigs, not on the trunk.
            assert!(o.position.y > 2.0, "{:?}", o.position);
        }
        // Bark, a trunk as thick as an open-grown oak's (3 m ÷ 32 at a tenth of its height,
        // its breast height being too low on a 3 m plant), and a flared foot.
        assert_eq!(
            d.materials()[0].surface,
            Some(Surface::Bark(BarkKind::Furrowed))
        );
        let trunk = d.segments()[3];
        assert!(trunk.start.y < 0.3 && trunk.end.y > 0.3, "{trunk:?}");
        let t = (0.3 - trunk.start.y) / (trunk.end.y - trunk.start.y);
        let r = trunk.start_radius + (trunk.end_radius - trunk.start_radius) * t;
        assert!((2.0 * r - 3.0 / 32.0).abs() < 1e-4, "{r}");
        let foot = d.segments()[0];
        assert!(foot.start_radius > 1.4 * trunk.start_radius);
        // Twigs are as thick as the pipe model says: four tips on the trunk, so a twig is
        // the trunk's radius over 4^(1/2.5).
        let twig = d.segments().last().unwrap();
        let want = trunk.end_radius / 4f32.powf(0.4);
        assert!((twig.start_radius - want).abs() < 1e-4 * want.max(1.0));
        // The same seed gives the same plant; another seed another.
        assert_eq!(dress(&p, &Dress::foliage(LeafKind::Oak), 7).unwrap().0, d);
        assert_ne!(dress(&p, &Dress::foliage(LeafKind::Oak), 8).unwrap().0, d);
    }

    #[test]
    fn leaf_size_does_not_scale_with_the_plant() {
        let mut big = tree();
        big.scale(8.0).unwrap();
        let (d, _) = dress(&big, &Dress::foliage(LeafKind::Oak), 7).unwrap();
        let spec = LeafKind::Oak.spec();
        // A 24 m tree wears branchlets, whose leaves are as long as a sapling's.
        let b = spec.leaf_of_branchlet;
        let (lo, hi) = (spec.length.0 / b, spec.length.1 / b);
        let m = &d.materials()[d.organs()[0].material.index()];
        assert_eq!(m.surface, Some(Surface::Branchlets(LeafKind::Oak)));
        assert!(
            d.organs()
                .iter()
                .all(|o| (lo - 1e-4..=hi + 1e-4).contains(&o.size.x))
        );
        // A larger crown carries more cards (of the same size).
        let branchlets = Dress {
            card: Some(Card::Branchlet),
            ..Dress::foliage(LeafKind::Oak)
        };
        let small = dress(&tree(), &branchlets, 7).unwrap().1.cards;
        assert!(
            d.organs().len() as u32 > 2 * small,
            "{} vs {small}",
            d.organs().len()
        );
    }

    #[test]
    fn own_leaves_become_cards_where_they_were() {
        let mut p = tree();
        let leaf = Organ {
            kind: OrganKind::Leaf,
            position: Vec3::new(0.0, 2.0, 0.0),
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.6, 0.3),
            material: Plant::LEAF,
            parent: Some(crate::SegmentId(0)),
        };
        p.add_organ(leaf).unwrap();
        let (d, report) = dress(&p, &Dress::foliage(LeafKind::Birch), 1).unwrap();
        assert_eq!(report.leaves_replaced, 1);
        // The trunk's first segment was split into a collar: its last piece carries the
        // leaf's cards, along the blade; the bare twigs carry cards of their own.
        let on_trunk: Vec<&Organ> = d
            .organs()
            .iter()
            .filter(|o| o.parent == Some(crate::SegmentId(3)))
            .collect();
        assert!(on_trunk.len() >= 2, "{report:?}");
        for o in on_trunk {
            assert!(o.position.distance(leaf.position) <= 0.6 + 1e-5);
        }
        assert!(
            d.organs().iter().any(|o| o.position.y > 2.5),
            "twigs wear leaves too"
        );
    }

    #[test]
    fn leaves_drawn_as_segments_become_cards_and_blades_on_them_stay() {
        // A twig with a leaf drawn as a segment (the L-system's), and another whose
        // leaf segment bears a blade of its own (PlantMaker's midrib): both leaves become
        // cards, once each, the blade's where it was.
        let mut p = Plant::new(PlantMeta::default());
        let t = p
            .add_segment(
                Vec3::ZERO,
                2.0 * Vec3::Y,
                (0.05, 0.04),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        let top = 2.0 * Vec3::Y;
        p.add_segment(
            top,
            top + Vec3::new(0.3, 0.1, 0.0),
            (0.02, 0.0),
            Some(t),
            true,
            Plant::LEAF,
        )
        .unwrap();
        let midrib = p
            .add_segment(
                top,
                top + Vec3::new(-0.3, 0.1, 0.0),
                (0.005, 0.0),
                Some(t),
                true,
                Plant::LEAF,
            )
            .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Leaf,
            position: top,
            orientation: Quat::from_rotation_z(0.7),
            size: Vec2::new(0.3, 0.15),
            material: Plant::LEAF,
            parent: Some(midrib),
        })
        .unwrap();
        let (d, report) = dress(&p, &Dress::foliage(LeafKind::Beech), 1).unwrap();
        assert_eq!(report.leaves_replaced, 2, "{report:?}");
        // No leaf segment is left, every card sits on the trunk (the collar's last piece).
        assert!(d.segments().iter().all(|s| s.material == Plant::BARK));
        let last = crate::SegmentId(d.segments().len() as u32 - 1);
        assert!(
            d.organs().iter().all(|o| o.parent == Some(last)),
            "{:?}",
            d.organs()
        );
    }

    #[test]
    fn cards_beyond_the_budget_are_thinned_and_reported() {
        let mut big = tree();
        big.scale(10.0).unwrap();
        let dress_all = Dress::foliage(LeafKind::Willow);
        let all = dress(&big, &dress_all, 3).unwrap().1.cards;
        let (d, report) = dress(
            &big,
            &Dress {
                max_cards: all / 3,
                ..dress_all
            },
            3,
        )
        .unwrap();
        assert!(report.cards <= all / 3);
        assert_eq!(report.cards + report.dropped, all);
        assert_eq!(d.organs().len() as u32, report.cards);
    }

    #[test]
    fn needles_run_along_and_beside_the_shoots_and_bark_can_stand_alone() {
        let (d, _) = dress(&tree(), &Dress::foliage(LeafKind::Spruce), 2).unwrap();
        assert!(d.materials()[0].surface == Some(Surface::Bark(BarkKind::Plated)));
        let mut along_twig = 0;
        for o in d.organs() {
            let along = o.orientation * Vec3::Y;
            let twig = d.segment(o.parent.unwrap()).vector().normalize();
            assert!(along.dot(twig) > 0.2, "shoots lean forward from their twig");
            along_twig += usize::from(along.dot(twig) > 0.9);
        }
        // Shoots along the twig every other station, a level pair at every one.
        assert!(
            5 * along_twig >= d.organs().len(),
            "{along_twig} of {}",
            d.organs().len()
        );
        let bark_only = Dress {
            bark: Some(BarkKind::Birch),
            ..Dress::default()
        };
        let (d, report) = dress(&tree(), &bark_only, 2).unwrap();
        assert_eq!(report.cards, 0);
        assert!(d.organs().is_empty());
        assert_eq!(
            d.materials()[0].surface,
            Some(Surface::Bark(BarkKind::Birch))
        );
    }

    #[test]
    fn stems_never_thicken_along_an_axis() {
        let mut p = Plant::new(PlantMeta::default());
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.05), None, false, Plant::BARK)
            .unwrap();
        // A "stacked tyre": the next segment starts thicker than the last ended.
        p.add_segment(
            Vec3::Y,
            2.0 * Vec3::Y,
            (0.09, 0.08),
            Some(a),
            false,
            Plant::BARK,
        )
        .unwrap();
        let bark = Dress {
            bark: Some(BarkKind::Smooth),
            ..Dress::default()
        };
        let (d, _) = dress(&p, &bark, 1).unwrap();
        let s = d.segments();
        for w in s.windows(2) {
            assert!(w[1].start_radius <= w[0].end_radius + 1e-6);
            assert!(w[1].end_radius <= w[1].start_radius + 1e-6);
        }
    }
}
