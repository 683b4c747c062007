//! The colours a run's fans may take. In the paper a fan's colours are genes like any other,
//! chosen by the person who breeds: [`Palette::Any`], the default. A run whose fitness cannot
//! see colour (a match of an outline) would leave them to drift, and its trees would come
//! out with blue, purple and red leaves; [`Palette::Foliage`] keeps a leaf fan's colours
//! among leaf greens and a twig fan's among bark browns, without changing the plant's form.

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_evolve::{Crossover, Mutate};

use crate::{PlantMaker, Rgb};

/// The colours a run's random genomes and offspring may give their fans.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Palette {
    /// Any colour the genes give (the paper's).
    #[default]
    Any,
    /// A leaf fan's colours are leaf greens (hue 80° to 150°, saturation 0.35 to 0.85,
    /// value 0.2 to 0.65) and a twig fan's bark browns (hue 15° to 40°, saturation 0.25 to
    /// 0.6, value 0.15 to 0.45): each colour moved to the nearest such one, so a colour
    /// within them stays as it is and mutation still varies it.
    Foliage,
}

/// The hue (degrees), saturation and value a palette keeps a colour within.
struct Band {
    hue: (f32, f32),
    saturation: (f32, f32),
    value: (f32, f32),
}

const LEAF: Band = Band {
    hue: (80.0, 150.0),
    saturation: (0.35, 0.85),
    value: (0.2, 0.65),
};

const BARK: Band = Band {
    hue: (15.0, 40.0),
    saturation: (0.25, 0.6),
    value: (0.15, 0.45),
};

impl Palette {
    /// Moves `genome`'s fan colours into the palette (nothing for [`Palette::Any`]). Whether
    /// a fan is of leaves or twigs is its prototype's ([`crate::Branch::is_leaf`]); a fan
    /// naming no branch is left alone. Draws nothing at random.
    pub fn apply(self, genome: &mut PlantMaker) {
        if self == Palette::Any {
            return;
        }
        for fan in &mut genome.fans {
            let Some(proto) = genome.branches.get(usize::from(fan.branch).wrapping_sub(1)) else {
                continue;
            };
            let band = if proto.is_leaf() { &LEAF } else { &BARK };
            fan.min_color = band.nearest(fan.min_color);
            fan.max_color = band.nearest(fan.max_color);
        }
    }
}

impl Band {
    /// The colour of this band nearest `color` in hue, saturation and value, each clamped
    /// into the band (hue the short way round the circle).
    fn nearest(&self, color: Rgb) -> Rgb {
        let (h, s, v) = hsv(color);
        let hue = if (self.hue.0..=self.hue.1).contains(&h) {
            h
        } else {
            let around = |a: f32, b: f32| {
                let d = (a - b).abs();
                d.min(360.0 - d)
            };
            if around(h, self.hue.0) <= around(h, self.hue.1) {
                self.hue.0
            } else {
                self.hue.1
            }
        };
        let s = s.clamp(self.saturation.0, self.saturation.1);
        let v = v.clamp(self.value.0, self.value.1);
        rgb(hue, s, v)
    }
}

/// Hue (0 to 360 degrees; 0 for a grey), saturation and value (0 to 1) of `color`.
fn hsv(color: Rgb) -> (f32, f32, f32) {
    let [r, g, b] = color.0.map(|c| f32::from(c) / 255.0);
    let (max, min) = (r.max(g).max(b), r.min(g).min(b));
    let d = max - min;
    let hue = if d <= 0.0 {
        0.0
    } else if max == r {
        60.0 * ((g - b) / d).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    let saturation = if max > 0.0 { d / max } else { 0.0 };
    (hue, saturation, max)
}

/// The colour of hue `h` (degrees), saturation `s` and value `v`.
fn rgb(h: f32, s: f32, v: f32) -> Rgb {
    let c = v * s;
    let x = c * (1.0 - ((h / 60.0).rem_euclid(2.0) - 1.0).abs());
    let (r, g, b) = match (h / 60.0) as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    Rgb([r, g, b].map(|t| ((t + m) * 255.0).round().clamp(0.0, 255.0) as u8))
}

/// An operator whose children then take their colours from a palette.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Painted<O> {
    /// The operator.
    pub operator: O,
    /// The palette.
    pub palette: Palette,
}

impl<O: Mutate<PlantMaker>> Mutate<PlantMaker> for Painted<O> {
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut PlantMaker, rng: &mut R) {
        self.operator.mutate(genome, rng);
        self.palette.apply(genome);
    }
}

impl<O: Crossover<PlantMaker>> Crossover<PlantMaker> for Painted<O> {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &PlantMaker,
        b: &PlantMaker,
        rng: &mut R,
    ) -> PlantMaker {
        let mut child = self.operator.crossover(a, b, rng);
        self.palette.apply(&mut child);
        child
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::develop::is_green;

    #[test]
    fn foliage_greens_leaves_and_browns_twigs_and_keeps_what_fits() {
        for code in (0..0x100_0000u32).step_by(0x01_0307) {
            let c = Rgb::from_code(code);
            let leaf = LEAF.nearest(c);
            assert!(is_green(leaf), "{c} became {leaf}");
            // What is in the band stays (to rounding): mutation still varies it.
            let again = LEAF.nearest(leaf).0.map(i32::from);
            assert!(
                again
                    .iter()
                    .zip(leaf.0)
                    .all(|(a, b)| (a - i32::from(b)).abs() <= 1)
            );
            // Dark browns' hue moves a few degrees in rounding to whole channels.
            let (h, s, v) = hsv(BARK.nearest(c));
            assert!(
                (10.0..=45.0).contains(&h) && (0.22..=0.63).contains(&s),
                "{c}: {h} {s}"
            );
            assert!((0.14..=0.46).contains(&v), "{c}: {v}");
        }
        let moss = Rgb([0x3d, 0x7a, 0x25]);
        assert_eq!(LEAF.nearest(moss), moss);
    }

    #[test]
    fn any_leaves_a_genome_as_it_is_and_foliage_changes_only_colours() {
        let mut rng = sylva_core::rng::seeded(7);
        for _ in 0..20 {
            let genome = PlantMaker::random(5, 5, 5, &mut rng);
            let mut any = genome.clone();
            Palette::Any.apply(&mut any);
            assert_eq!(any, genome);
            let mut foliage = genome.clone();
            Palette::Foliage.apply(&mut foliage);
            let (a, b) = (genome.develop(genome.seed), foliage.develop(foliage.seed));
            let (Ok(a), Ok(b)) = (a, b) else { continue };
            let form = |p: &sylva_core::Plant| {
                let segments = p
                    .segments()
                    .iter()
                    .map(|s| (s.start, s.end, s.start_radius));
                let organs = p.organs().iter().map(|o| (o.kind, o.position, o.size));
                (segments.collect::<Vec<_>>(), organs.collect::<Vec<_>>())
            };
            assert_eq!(form(&a), form(&b), "the form is the genome's");
            for o in b.organs() {
                let m = &b.materials()[o.material.index()];
                assert_eq!(m.kind, sylva_core::plant::MaterialKind::Leaf, "{m:?}");
            }
        }
    }
}
