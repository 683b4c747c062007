//! The crown's envelope: the space a tree grows into, filled with attraction points.
//!
//! An envelope is a stack of rows from the crown's base to its top; at each height it holds
//! stretches of x (seen from the front) and of z (seen from the side), and the ellipse
//! inscribed in the rectangle around them, as a tree's crown is round in plan: a point is
//! inside where it is in that ellipse, over a stretch of x and over a stretch of z. A crown
//! shape ([`CrownShape`]) makes centred rows of one stretch from its radius profile; a
//! picture's visual hull makes rows from the front and side outlines, each stretch where the
//! outline's ink is at that height, so the gaps a crown shows (beside the trunk under the
//! crown, between its lobes) stay empty.

use crate::genome::{CrownShape, Growth, Param};
use crate::profile::{EnvelopeError, Row, hull};
use glam::Vec3;
use rand::{Rng, RngExt};

/// Rows a shape's envelope is drawn with.
const SHAPE_ROWS: usize = 64;

/// The space a crown fills: rows of x and z stretches from `base` to `top`.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// Height of the lowest row, metres.
    pub base: f32,
    /// Height of the highest row, metres.
    pub top: f32,
    /// Per row, bottom to top: the stretches of x and of z, metres (an empty row has none,
    /// or stretches with left ≥ right).
    pub rows: Vec<Row>,
}

/// Whether `v` is over one of the stretches.
fn over(stretches: &[[f32; 2]], v: f32) -> bool {
    stretches.iter().any(|s| (s[0]..=s[1]).contains(&v))
}

/// The share of a view's rectangle its stretches cover.
fn coverage(stretches: &[[f32; 2]]) -> f32 {
    let [lo, hi] = hull(stretches);
    if lo >= hi {
        return 0.0;
    }
    let covered: f32 = stretches.iter().map(|s| (s[1] - s[0]).max(0.0)).sum();
    (covered / (hi - lo)).min(1.0)
}

impl Envelope {
    /// The envelope of a genome's crown: its profile, or its shape and proportions, drawn
    /// in by its `inset`.
    pub fn of(genome: &Growth) -> Envelope {
        let p = &genome.parameters;
        let inset = p.f(Param::Inset) * p.f(Param::Height);
        Envelope::outer(genome).inset(inset)
    }

    /// The envelope of a genome's crown before its inset.
    fn outer(genome: &Growth) -> Envelope {
        let p = &genome.parameters;
        let height = p.f(Param::Height);
        if let Some(profile) = &genome.envelope {
            return Envelope {
                base: profile.base * height,
                top: height,
                rows: (profile.rows.iter())
                    .map(|row| {
                        row.clone()
                            .map(|view| view.iter().map(|s| s.map(|v| v * height)).collect())
                    })
                    .collect(),
            };
        }
        let half_width = 0.5 * p.f(Param::Width) * height;
        let half_depth = half_width * p.f(Param::Depth);
        Envelope::of_shape(
            genome.crown,
            p.f(Param::CrownBase) * height,
            height,
            half_width,
            half_depth,
        )
    }

    /// A shape's envelope from `base` to `top`, `half_width` and `half_depth` at its widest.
    pub fn of_shape(
        shape: CrownShape,
        base: f32,
        top: f32,
        half_width: f32,
        half_depth: f32,
    ) -> Envelope {
        let rows = (0..SHAPE_ROWS)
            .map(|i| {
                let r = shape.radius((i as f32 + 0.5) / SHAPE_ROWS as f32);
                [
                    vec![[-r * half_width, r * half_width]],
                    vec![[-r * half_depth, r * half_depth]],
                ]
            })
            .collect();
        Envelope { base, top, rows }
    }

    /// This envelope drawn in by `by` metres at each stretch's ends and (to the nearest
    /// row) at its top; a stretch narrower than twice that is left out. Twigs stop short of the space
    /// they grow into while their leaves reach beyond them. Nothing changes for 0.
    pub fn inset(mut self, by: f32) -> Envelope {
        if by <= 0.0 || self.rows.is_empty() {
            return self;
        }
        for view in self.rows.iter_mut().flatten() {
            view.retain_mut(|s| {
                *s = [s[0] + by, s[1] - by];
                s[0] < s[1]
            });
        }
        // The top comes down by whole rows, so every row keeps its height.
        let dy = (self.top - self.base) / self.rows.len() as f32;
        let drop = ((by / dy) as usize).min(self.rows.len() - 1);
        self.rows.truncate(self.rows.len() - drop);
        self.top -= drop as f32 * dy;
        self
    }

    /// The row at height `y`, if `y` is within the envelope.
    fn row(&self, y: f32) -> Option<&Row> {
        if !(self.base..self.top).contains(&y) {
            return None;
        }
        let t = (y - self.base) / (self.top - self.base);
        let i = ((t * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        Some(&self.rows[i])
    }

    /// Whether `p` lies inside.
    pub fn contains(&self, p: Vec3) -> bool {
        let Some([xs, zs]) = self.row(p.y) else {
            return false;
        };
        let ([x0, x1], [z0, z1]) = (hull(xs), hull(zs));
        if x0 >= x1 || z0 >= z1 {
            return false;
        }
        let u = (2.0 * p.x - (x0 + x1)) / (x1 - x0);
        let v = (2.0 * p.z - (z0 + z1)) / (z1 - z0);
        u * u + v * v <= 1.0 && over(xs, p.x) && over(zs, p.z)
    }

    /// The box around it: least and greatest corners.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::new(f32::MAX, self.base, f32::MAX);
        let mut hi = Vec3::new(f32::MIN, self.top, f32::MIN);
        for [xs, zs] in &self.rows {
            let ([x0, x1], [z0, z1]) = (hull(xs), hull(zs));
            if x0 < x1 && z0 < z1 {
                lo = lo.min(Vec3::new(x0, self.base, z0));
                hi = hi.max(Vec3::new(x1, self.top, z1));
            }
        }
        (lo, hi)
    }

    /// The volume it holds, cubic metres: exact for rows of one stretch a view; for more,
    /// each row's ellipse times the shares of its rectangle the stretches cover.
    pub fn volume(&self) -> f32 {
        let dy = (self.top - self.base) / self.rows.len() as f32;
        let area = |[xs, zs]: &Row| {
            let ([x0, x1], [z0, z1]) = (hull(xs), hull(zs));
            std::f32::consts::FRAC_PI_4
                * (x1 - x0).max(0.0)
                * (z1 - z0).max(0.0)
                * coverage(xs)
                * coverage(zs)
        };
        self.rows.iter().map(area).sum::<f32>() * dy
    }

    /// `count` points drawn uniformly inside, from `rng`. At most 64 draws a point are
    /// made; an envelope too thin to take a tenth of the points is an error.
    pub fn attraction_points<R: Rng + ?Sized>(
        &self,
        count: usize,
        rng: &mut R,
    ) -> Result<Vec<Vec3>, EnvelopeError> {
        let empty = EnvelopeError::Empty {
            base: self.base,
            top: self.top,
        };
        let volume = self.volume();
        if !(self.top > self.base && volume.is_finite() && volume > 1e-6) {
            return Err(empty);
        }
        let (lo, hi) = self.bounds();
        let mut points = Vec::with_capacity(count);
        for _ in 0..count * 64 {
            if points.len() == count {
                break;
            }
            let p = Vec3::new(
                rng.random_range(lo.x..=hi.x),
                rng.random_range(lo.y..hi.y),
                rng.random_range(lo.z..=hi.z),
            );
            if self.contains(p) {
                points.push(p);
            }
        }
        if points.len() * 10 < count {
            return Err(EnvelopeError::TooThin {
                placed: points.len(),
                asked: count,
            });
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::genome::{Growth, Param};
    use crate::profile::{GAP, Profile, Stretches};
    use sylva_model::TargetProfile;

    /// `e`'s volume as the share of `samples` random points of its bounding box inside it.
    fn sampled_volume(e: &Envelope, samples: u32, rng: &mut impl Rng) -> f32 {
        let (lo, hi) = e.bounds();
        let inside = (0..samples)
            .filter(|_| {
                e.contains(Vec3::new(
                    rng.random_range(lo.x..hi.x),
                    rng.random_range(lo.y..hi.y),
                    rng.random_range(lo.z..hi.z),
                ))
            })
            .count();
        (hi - lo).element_product() * inside as f32 / samples as f32
    }

    #[test]
    fn points_fill_the_shape_and_nothing_else() {
        let e = Envelope::of_shape(CrownShape::Cone, 2.0, 10.0, 3.0, 3.0);
        let mut rng = sylva_core::rng::seeded(1);
        let points = e.attraction_points(2000, &mut rng).unwrap();
        assert_eq!(points.len(), 2000);
        assert!(points.iter().all(|&p| e.contains(p)));
        // A cone holds a third of its cylinder, most of it low down.
        let low = points.iter().filter(|p| p.y < 6.0).count();
        assert!(low > 1400, "{low}");
        // The volume is what a box's share of random points says it is.
        let measured = sampled_volume(&e, 20_000, &mut rng);
        assert!(
            (e.volume() / measured - 1.0).abs() < 0.05,
            "{} {measured}",
            e.volume()
        );
    }

    /// A lollipop: a trunk a tenth as wide as the crown for 30 rows, then a round crown.
    fn lollipop() -> TargetProfile {
        let rows: Vec<Stretches> = (0..100)
            .map(|i| {
                if i < 30 {
                    vec![[-0.02, 0.02]]
                } else {
                    let t = (i as f32 - 65.0) / 35.0;
                    let r = 0.35 * (1.0 - t * t).max(0.0).sqrt();
                    vec![[-r.max(0.02), r.max(0.02)]]
                }
            })
            .collect();
        TargetProfile {
            front: rows.clone(),
            side: rows,
        }
    }

    #[test]
    fn a_target_s_crown_is_its_hull_above_the_trunk() {
        let profile = Profile::from_target(&lollipop()).unwrap();
        assert!((profile.base - 0.3).abs() < 0.03, "{}", profile.base);
        let genome = Growth {
            envelope: Some(profile),
            ..Growth::default()
        };
        let e = Envelope::of(&genome);
        let height = genome.parameters.f(Param::Height);
        assert_eq!(e.top, height);
        assert!(e.contains(Vec3::new(0.0, 0.65 * height, 0.0)));
        assert!(
            !e.contains(Vec3::new(0.0, 0.2 * height, 0.0)),
            "the trunk is no crown"
        );
        assert!(!e.contains(Vec3::new(0.4 * height, 0.65 * height, 0.0)));
        // The tree grows into it: its leaves stay about the crown's rows.
        let (plant, report) = crate::grow(&genome, 1).unwrap();
        assert!(report.internodes > 200, "{report:?}");
        let low = plant
            .organs()
            .iter()
            .filter(|o| o.position.y < 0.2 * height)
            .count();
        assert_eq!(low, 0);
        let far = (plant.organs().iter())
            .filter(|o| o.position.x.abs() > 0.5 * height)
            .count();
        assert_eq!(far, 0);
    }

    #[test]
    fn a_genome_s_envelope_is_checked_as_it_is_read() {
        let text = |envelope: &str| {
            format!(
                r#"{{"model":"grown","format":1,"seed":1,"crown":"cone","foliage":"oak","envelope":{envelope}}}"#
            )
        };
        let read = |envelope: &str| sylva_model::file::parse::<Growth>(&text(envelope));
        assert!(read(r#"{"base":0.3,"rows":[[[-0.2,0.2],[-0.2,0.2]]]}"#).is_ok());
        for (bad, says) in [
            (
                r#"{"base":2,"rows":[[[-0.2,0.2],[-0.2,0.2]]]}"#,
                "envelope.base",
            ),
            (r#"{"base":0.3,"rows":[]}"#, "1 to 256 rows"),
            (
                r#"{"base":0.3,"rows":[[[-1e9,0.2],[-0.2,0.2]]]}"#,
                "envelope.rows[0]",
            ),
            (r#"{"base":0.3,"rows":[[[-0.2,0.2]]]}"#, "invalid length"),
            (
                r#"{"base":0.3,"rows":[[[0.2,-0.2],[-0.2,0.2]]]}"#,
                "left ≤ right",
            ),
            (
                r#"{"base":0.3,"rows":[[[-0.2,0.2],"wide"]]}"#,
                "a view's stretches",
            ),
            (
                r#"{"base":0.3,"rows":[[[-0.2,0.2],[-0.2,0.2]]],"extra":1}"#,
                "extra",
            ),
        ] {
            let e = read(bad).unwrap_err();
            assert!(e.message.contains(says), "{bad}: {e}");
        }
    }

    /// Two lobes of a crown beside a trunk, over a gap under the crown as wide as a third of
    /// the crown, in rows 30 to 50; a round crown above.
    fn two_lobes() -> TargetProfile {
        let mut target = lollipop();
        for (i, row) in target.front.iter_mut().enumerate().take(50).skip(30) {
            let r = row[0][1];
            *row = if i % 2 == 0 {
                vec![[-r, -0.1], [-0.02, 0.02], [0.1, r]]
            } else {
                // Gaps narrower than `GAP` in a lobe are closed.
                vec![
                    [-r, -0.2],
                    [-0.2 + 0.5 * GAP, -0.1],
                    [-0.02, 0.02],
                    [0.1, r],
                ]
            };
        }
        target
    }

    #[test]
    fn a_target_s_gaps_stay_empty() {
        let profile = Profile::from_target(&two_lobes()).unwrap();
        let low = &profile.rows[2];
        assert_eq!(low[0].len(), 3, "{low:?}");
        assert_eq!(low[1].len(), 1, "the side view has no gap: {low:?}");
        let genome = Growth {
            envelope: Some(profile),
            ..Growth::default()
        };
        let e = Envelope::of(&genome);
        let height = genome.parameters.f(Param::Height);
        let at = |x: f32, y: f32| Vec3::new(x * height, y * height, 0.0);
        assert!(e.contains(at(-0.15, 0.4)), "over a lobe");
        assert!(e.contains(at(0.0, 0.4)), "over the trunk");
        assert!(!e.contains(at(0.06, 0.4)), "over the gap");
        assert!(e.contains(at(0.06, 0.6)), "in the crown above");
        // The volume counts the gaps out (within the sampling error).
        let mut rng = sylva_core::rng::seeded(2);
        let measured = sampled_volume(&e, 40_000, &mut rng);
        assert!(
            (e.volume() / measured - 1.0).abs() < 0.05,
            "{} {measured}",
            e.volume()
        );
        let points = e.attraction_points(3000, &mut rng).unwrap();
        let gap = (points.iter())
            .filter(|p| p.y < 0.5 * height && (0.03..0.09).contains(&(p.x / height)))
            .count();
        assert_eq!(gap, 0);
    }

    #[test]
    fn an_inset_draws_the_envelope_in() {
        let e = Envelope::of_shape(CrownShape::Cylinder, 2.0, 10.0, 3.0, 3.0);
        let inner = e.clone().inset(0.5);
        assert_eq!(e.clone().inset(0.0), e);
        assert!((inner.top - 9.5).abs() < 0.2, "{}", inner.top);
        assert!(e.contains(Vec3::new(2.7, 5.0, 0.0)));
        assert!(!inner.contains(Vec3::new(2.7, 5.0, 0.0)));
        assert!(inner.contains(Vec3::new(2.3, 5.0, 0.0)));
        // A stretch narrower than twice the inset goes.
        let lobes = Envelope::of(&Growth {
            envelope: Profile::from_target(&two_lobes()).ok(),
            ..Growth::default()
        });
        let (before, after) = (&lobes.rows[2][0], &lobes.clone().inset(0.3).rows[2][0]);
        assert_eq!((before.len(), after.len()), (3, 2), "{before:?} {after:?}");
        // A genome's inset is its envelope's.
        let mut genome = Growth::default();
        genome.parameters.set_at(Param::Inset as usize, 0.05);
        let height = genome.parameters.f(Param::Height);
        let drawn_in = Envelope::of(&genome);
        let whole = Envelope::of(&Growth::default());
        assert!(drawn_in.volume() < 0.8 * whole.volume());
        assert!((whole.top - drawn_in.top - 0.05 * height).abs() < height / 64.0);
    }

    #[test]
    fn genomes_written_before_stretches_still_read() {
        let text = r#"{"base":0.3,"rows":[[[-0.2,0.2],[-0.1,0.1]],[[[-0.2,-0.1],[0.1,0.2]],[]]]}"#;
        let profile: Profile = serde_json::from_str(text).unwrap();
        assert_eq!(profile.rows[0], [vec![[-0.2, 0.2]], vec![[-0.1, 0.1]]]);
        assert_eq!(profile.rows[1], [vec![[-0.2, -0.1], [0.1, 0.2]], vec![]]);
        let again: Profile =
            serde_json::from_str(&serde_json::to_string(&profile).unwrap()).unwrap();
        assert_eq!(again, profile);
    }

    #[test]
    fn a_target_with_no_crown_is_refused() {
        let blank = TargetProfile {
            front: vec![Vec::new(); 50],
            side: vec![vec![[0.0, 0.0]]; 50],
        };
        let e = Profile::from_target(&blank).unwrap_err();
        assert!(e.to_string().contains("empty or flat"), "{e}");
    }

    #[test]
    fn a_flat_envelope_is_refused() {
        let e = Envelope::of_shape(CrownShape::Ellipsoid, 2.0, 10.0, 3.0, 0.0);
        let mut rng = sylva_core::rng::seeded(1);
        let err = e.attraction_points(100, &mut rng).unwrap_err();
        assert!(err.to_string().contains("empty or flat"), "{err}");
    }
}
