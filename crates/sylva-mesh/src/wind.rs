//! Wind: a skin and a looping sway clip for a meshed plant, in core glTF 2.0.
//!
//! [`rig`] puts joints on the plant's skeleton: four along the trunk (each axis of order 0),
//! three along each first-order branch and one at the base of each second-order branch, at
//! most [`MAX_JOINTS`] in all (the trunk first, then branch bases, then the rest, in the
//! plant's order; the count left out is reported). Every joint hangs from the nearest joint
//! below it. A vertex follows the joint that owns its segment (the last joint at or below
//! it on its path to the root) and, near that joint, blends into the parent joint, so the
//! bend is smooth: at most two of the four glTF influences are used, and the weights (normalised bytes)
//! add up to one exactly. Higher orders, leaves and flowers ride on their nearest ancestor joint.
//!
//! The clip, `wind`, is one period long and loops seamlessly (its last key is its first):
//! each joint leans downwind and sways about a horizontal axis with an amplitude that falls
//! with its branch's radius (thin twigs sway more than the trunk) and with a phase of its own
//! (branches do not move in step; the trunk's joints lag a little going up). Wind blows
//! towards +X. Leaves and flowers also get a flutter weight, `_WIND` (0 at an organ's base
//! to 1 at its tip; 0 on wood), for engines that add shader flutter.
//!
//! ```
//! use sylva_core::{Plant, PlantMeta, glam::Vec3};
//! use sylva_mesh::mesher::{MeshOptions, Mesher};
//! use sylva_mesh::wind::{WindOptions, rig};
//!
//! let mut plant = Plant::new(PlantMeta::default());
//! let trunk = plant.add_segment(Vec3::ZERO, Vec3::Y * 2.0, (0.2, 0.1), None, false, Plant::BARK)?;
//! plant.add_segment(Vec3::Y * 2.0, Vec3::new(1.0, 3.0, 0.0), (0.05, 0.02), Some(trunk), true, Plant::BARK)?;
//! let (mesh, sources) = Mesher::new(MeshOptions::default())?.mesh_with_sources(&plant)?;
//! let rig = rig(&plant, &mesh, sources, &WindOptions::default());
//! assert_eq!(rig.joints.len(), 2);
//! assert_eq!(rig.rotations[0].first(), rig.rotations[0].last());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::f32::consts::TAU;

use sylva_core::Plant;
use sylva_core::glam::{Mat4, Quat, Vec3};

use crate::mesh::Mesh;
use crate::mesher::{NO_SEGMENT, ORGAN_SOURCE, VertexSources};

/// The most joints a rig has (glTF's unsigned-byte joint indices, and what game engines take
/// per skinned mesh).
pub const MAX_JOINTS: usize = 256;

/// Keys of the clip, the first and last equal.
pub const KEYS: usize = 33;

/// How the wind blows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindOptions {
    /// Sway, 0 to 10; 1 is a breeze (the trunk's base leans about 1°, twigs up to 15°).
    /// Default 1.
    pub strength: f32,
    /// Seconds the clip lasts (one sway), 0.5 to 60. Default 4.
    pub period: f32,
}

impl Default for WindOptions {
    fn default() -> Self {
        WindOptions {
            strength: 1.0,
            period: 4.0,
        }
    }
}

/// Why wind options were refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WindError {
    /// Strength out of range.
    #[error("wind strength must be a number from 0 to 10, got {0}")]
    Strength(f32),
    /// Period out of range.
    #[error("wind period must be a number from 0.5 to 60 seconds, got {0}")]
    Period(f32),
}

impl WindOptions {
    /// Checked options.
    pub fn new(strength: f32, period: f32) -> Result<WindOptions, WindError> {
        if !(strength.is_finite() && (0.0..=10.0).contains(&strength)) {
            return Err(WindError::Strength(strength));
        }
        if !(period.is_finite() && (0.5..=60.0).contains(&period)) {
            return Err(WindError::Period(period));
        }
        Ok(WindOptions { strength, period })
    }
}

/// A joint of a rig.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The joint it hangs from; joints come after their parents.
    pub parent: Option<usize>,
    /// Where it is in the plant at rest, metres (its rest rotation is the identity).
    pub position: Vec3,
    /// The branch order of the axis it sits on.
    pub order: u16,
    /// The branch's radius there, metres.
    pub radius: f32,
}

/// A plant's skin and wind clip, for one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    /// The joints, parents first.
    pub joints: Vec<Joint>,
    /// Per vertex of the mesh, where it came from ([`Mesher::mesh_with_sources`]).
    ///
    /// [`Mesher::mesh_with_sources`]: crate::mesher::Mesher::mesh_with_sources
    sources: VertexSources,
    /// Per segment of the plant, the joint that owns it (at most [`MAX_JOINTS`]: a byte).
    owner: Vec<u8>,
    /// Per joint, what weighing a vertex needs of it, packed for the per-vertex loop.
    blends: Vec<Blend>,
    /// The clip's key times, seconds: [`KEYS`] from 0 to the period.
    pub times: Vec<f32>,
    /// Per joint, its rotation at each key (relative to its parent).
    pub rotations: Vec<Vec<Quat>>,
    /// Joints the plant would have had beyond [`MAX_JOINTS`].
    pub dropped: usize,
}

/// A joint as the per-vertex weighing reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Blend {
    position: Vec3,
    /// How far from the joint a vertex blends into its parent joint.
    reach: f32,
    /// The parent joint, if any.
    parent: Option<u8>,
}

/// How one vertex follows the joints: what glTF's `JOINTS_0`, `WEIGHTS_0` and Sylva's
/// `_WIND` hold for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Influence {
    /// Four joint indices (unused ones 0).
    pub joints: [u8; 4],
    /// Four weights in 255ths adding up to exactly 255 (unused ones 0): glTF's normalised
    /// unsigned bytes, a quarter of the size of floats.
    pub weights: [u8; 4],
    /// The leaf flutter weight, 0 to 1 (0 on wood).
    pub flutter: f32,
}

/// Joints each axis gets, by order, as fractions of its length from its start.
fn joint_places(order: u16) -> &'static [f32] {
    match order {
        0 => &[0.0, 0.25, 0.5, 0.75],
        1 => &[0.0, 1.0 / 3.0, 2.0 / 3.0],
        2 => &[0.0],
        _ => &[],
    }
}

/// Builds the rig of `plant` for its `mesh`, whose vertices came from `sources`
/// ([`crate::mesher::Mesher::mesh_with_sources`]). Each vertex's influence is worked out when
/// it is asked for ([`Rig::influence`]), as the GLB writer streams it, rather than stored.
pub fn rig(plant: &Plant, mesh: &Mesh, sources: VertexSources, options: &WindOptions) -> Rig {
    let segs = plant.segments();
    let n = segs.len();
    // Each segment's axis, its distance along it, and each axis's length and order.
    let mut continues = vec![false; n];
    let mut taken = vec![false; n];
    for (i, s) in segs.iter().enumerate() {
        if let Some(p) = s.parent
            && !s.lateral
            && !taken[p.index()]
        {
            taken[p.index()] = true;
            continues[i] = true;
        }
    }
    let mut axis_of = vec![0usize; n];
    let mut along = vec![0f32; n];
    let mut axes: Vec<Vec<usize>> = Vec::new();
    let mut axis_len: Vec<f32> = Vec::new();
    for (i, s) in segs.iter().enumerate() {
        match s.parent {
            Some(p) if continues[i] => {
                let p = p.index();
                axis_of[i] = axis_of[p];
                along[i] = along[p] + segs[p].length();
            }
            _ => {
                axis_of[i] = axes.len();
                axes.push(Vec::new());
                axis_len.push(0.0);
            }
        }
        axes[axis_of[i]].push(i);
        axis_len[axis_of[i]] += s.length();
    }
    // Candidate joints: (priority, segment): each axis's first segment, and for each further
    // place the segment that starts nearest to it.
    let mut candidates: Vec<(u8, usize)> = Vec::new();
    for (a, members) in axes.iter().enumerate() {
        let first = members[0];
        let order = segs[first].order;
        let places = joint_places(order);
        let root = segs[first].parent.is_none();
        if places.is_empty() && !root {
            continue;
        }
        let priority = |k: usize| match (root, order, k) {
            (true, _, _) | (_, 0, _) => 0u8,
            (_, 1, 0) => 1,
            (_, 1, _) => 2,
            _ => 3,
        };
        candidates.push((priority(0), first));
        let mut last = first;
        for (k, &f) in places.iter().enumerate().skip(1) {
            let at = f * axis_len[a];
            let nearest = members
                .iter()
                .copied()
                .min_by(|&x, &y| (along[x] - at).abs().total_cmp(&(along[y] - at).abs()))
                .unwrap_or(first);
            if nearest > last {
                candidates.push((priority(k), nearest));
                last = nearest;
            }
        }
    }
    candidates.sort();
    let dropped = candidates.len().saturating_sub(MAX_JOINTS);
    let mut opens = vec![false; n];
    for &(_, i) in candidates.iter().take(MAX_JOINTS) {
        opens[i] = true;
    }
    // Joints in segment order, so parents come first; each segment's owning joint.
    let mut owner: Vec<Option<usize>> = vec![None; n];
    let mut joints: Vec<Joint> = Vec::new();
    for (i, s) in segs.iter().enumerate() {
        let below = s.parent.and_then(|p| owner[p.index()]);
        owner[i] = if opens[i] {
            joints.push(Joint {
                parent: below,
                position: s.start,
                order: s.order,
                radius: s.start_radius.max(1e-4),
            });
            Some(joints.len() - 1)
        } else {
            below
        };
    }
    if joints.is_empty() {
        // No segments: one joint at the origin carries the organs.
        joints.push(Joint {
            parent: None,
            position: Vec3::ZERO,
            order: 0,
            radius: 1.0,
        });
    }
    // Weights: the owner, blended into its parent near the joint, over a quarter of the
    // span between them.
    let blends = joints
        .iter()
        .map(|joint| Blend {
            position: joint.position,
            reach: joint.parent.map_or(0.0, |p| {
                (0.25 * joint.position.distance(joints[p].position)).max(1e-3)
            }),
            // Joint indices fit a byte: there are at most MAX_JOINTS.
            parent: joint.parent.map(|p| p as u8),
        })
        .collect();
    let owner = owner.iter().map(|o| o.unwrap_or(0) as u8).collect();
    debug_assert!(sources.len() <= mesh.positions.len() || mesh.positions.is_empty());

    // The clip.
    let times: Vec<f32> = (0..KEYS)
        .map(|k| options.period * k as f32 / (KEYS - 1) as f32)
        .collect();
    let thickest = joints
        .iter()
        .map(|j| j.radius)
        .fold(0.0f32, f32::max)
        .max(1e-4);
    let rotations = joints
        .iter()
        .enumerate()
        .map(|(i, joint)| {
            let amplitude = (options.strength * 0.02 * (thickest / joint.radius).sqrt()).min(0.35);
            let phase = if joint.order == 0 {
                0.4 * i as f32
            } else {
                TAU * unit_hash(i as u32)
            };
            (0..KEYS)
                .map(|k| {
                    // Whole turns: the last key equals the first exactly.
                    let turn = if k + 1 == KEYS {
                        0.0
                    } else {
                        TAU * k as f32 / (KEYS - 1) as f32
                    };
                    let sway = 0.8 * (turn + phase).sin() + 0.2 * (2.0 * turn + 1.7 * phase).sin();
                    let across = 0.35 * (turn + phase + 1.3).sin();
                    let lean = 0.5 + 0.5 * sway;
                    (Quat::from_rotation_z(-amplitude * lean)
                        * Quat::from_rotation_x(amplitude * across))
                    .normalize()
                })
                .collect()
        })
        .collect();
    Rig {
        joints,
        sources,
        owner,
        blends,
        times,
        rotations,
        dropped,
    }
}

impl Rig {
    /// Vertices the rig was made for (its mesh's).
    pub fn vertices(&self) -> usize {
        self.sources.len()
    }

    /// How vertex `v` of `mesh` (the mesh the rig was made for) follows the joints.
    pub fn influence(&self, mesh: &Mesh, v: usize) -> Influence {
        let source = self.sources.get(v).unwrap_or(ORGAN_SOURCE | NO_SEGMENT);
        self.influence_from(mesh, v, source)
    }

    /// Every vertex's influence, in order.
    pub fn influences<'a>(&'a self, mesh: &'a Mesh) -> impl Iterator<Item = Influence> + 'a {
        let n = self.vertices().min(mesh.positions.len());
        self.sources
            .iter()
            .take(n)
            .enumerate()
            .map(|(v, source)| self.influence_from(mesh, v, source))
    }

    /// Calls `f` with every vertex's influence, in order: as [`Rig::influences`], run by run
    /// of vertices from one source (the GLB writer's loop).
    pub fn for_each_influence(&self, mesh: &Mesh, mut f: impl FnMut(Influence)) {
        let n = self.vertices().min(mesh.positions.len());
        let mut v = 0;
        for (end, source) in self.sources.runs() {
            let end = (end as usize).min(n);
            while v < end {
                f(self.influence_from(mesh, v, source));
                v += 1;
            }
        }
    }

    /// How vertex `v`, which came from `source`, follows the joints.
    #[inline]
    fn influence_from(&self, mesh: &Mesh, v: usize, source: u32) -> Influence {
        let organ = source & ORGAN_SOURCE != 0;
        let j = self
            .owner
            .get((source & !ORGAN_SOURCE) as usize)
            .copied()
            .unwrap_or(0);
        let joint = &self.blends[usize::from(j)];
        let (joints, weights) = match joint.parent {
            // Beyond the blend (most vertices) the joint takes it all, as t = 1 would give;
            // at the edge the share rounds to 255 either way.
            Some(p)
                if !organ
                    && Vec3::from_array(mesh.positions[v]).distance_squared(joint.position)
                        < joint.reach * joint.reach =>
            {
                let d = Vec3::from_array(mesh.positions[v]).distance(joint.position);
                let t = (d / joint.reach).clamp(0.0, 1.0);
                let w = 0.5 + 0.5 * t * t * (3.0 - 2.0 * t);
                // w·255 lies in 127.5..=255, where this truncation is `round` without a
                // call to libm.
                let own = (w * 255.0 + 0.5) as u8;
                if own < 255 {
                    ([j, p, 0, 0], [own, 255 - own, 0, 0])
                } else {
                    ([j, 0, 0, 0], [255, 0, 0, 0])
                }
            }
            _ => ([j, 0, 0, 0], [255, 0, 0, 0]),
        };
        // Only organs flutter: wood never reads its texture coordinates.
        let flutter = if organ {
            mesh.uvs.get(v).map_or(0.0, |uv| uv[1].clamp(0.0, 1.0))
        } else {
            0.0
        };
        Influence {
            joints,
            weights,
            flutter,
        }
    }

    /// Each joint's rotation at `time` seconds (wrapped into the clip), keys interpolated
    /// as glTF's LINEAR does (spherically for rotations).
    pub fn rotations_at(&self, time: f32) -> Vec<Quat> {
        let period = self.times.last().copied().unwrap_or(0.0);
        let t = if period > 0.0 {
            time.rem_euclid(period)
        } else {
            0.0
        };
        let step = period / (KEYS - 1) as f32;
        let (k, f) = if step > 0.0 {
            let x = t / step;
            ((x.floor() as usize).min(KEYS - 2), x - x.floor())
        } else {
            (0, 0.0)
        };
        self.rotations
            .iter()
            .map(|keys| keys[k].slerp(keys[k + 1], f).normalize())
            .collect()
    }

    /// `mesh` posed at `time` seconds: each vertex moved by its joints as a glTF viewer
    /// skins it (linear blend skinning), for pictures of the wind.
    pub fn pose(&self, mesh: &Mesh, time: f32) -> Mesh {
        let rotations = self.rotations_at(time);
        let mut world: Vec<Mat4> = Vec::with_capacity(self.joints.len());
        for (joint, q) in self.joints.iter().zip(&rotations) {
            let local = match joint.parent {
                Some(p) => joint.position - self.joints[p].position,
                None => joint.position,
            };
            let m = Mat4::from_rotation_translation(*q, local);
            let w = match joint.parent {
                Some(p) => world[p] * m,
                None => m,
            };
            world.push(w);
        }
        let skin: Vec<Mat4> = world
            .iter()
            .zip(&self.joints)
            .map(|(w, j)| *w * Mat4::from_translation(-j.position))
            .collect();
        let mut posed = mesh.clone();
        for (
            v,
            Influence {
                joints, weights, ..
            },
        ) in self.influences(mesh).enumerate()
        {
            let mut m = Mat4::ZERO;
            for (&j, &w) in joints.iter().zip(&weights) {
                if w > 0 {
                    m += skin[j as usize] * (f32::from(w) / 255.0);
                }
            }
            posed.positions[v] = m
                .transform_point3(Vec3::from_array(mesh.positions[v]))
                .to_array();
            if let Some(n) = mesh.normals.get(v) {
                posed.normals[v] = m
                    .transform_vector3(Vec3::from_array(*n))
                    .normalize_or(Vec3::Y)
                    .to_array();
            }
        }
        posed
    }
}

/// A number in [0, 1) from `i` (a 32-bit integer hash).
fn unit_hash(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesher::{MeshOptions, Mesher};
    use sylva_core::{Organ, OrganKind, PlantMeta, glam::Vec2};

    /// A trunk of four segments, a first-order branch of three with a second-order twig and a
    /// leaf on the twig.
    fn tree() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let mut parent = None;
        for k in 0..4 {
            let (y0, y1) = (k as f32, k as f32 + 1.0);
            let r = 0.3 - 0.05 * k as f32;
            parent = Some(
                p.add_segment(
                    Vec3::Y * y0,
                    Vec3::Y * y1,
                    (r, r - 0.05),
                    parent,
                    false,
                    Plant::BARK,
                )
                .unwrap(),
            );
        }
        let mut b = Some(sylva_core::SegmentId(1));
        let mut lateral = true;
        let mut at = Vec3::Y * 2.0;
        for _ in 0..3 {
            let next = at + Vec3::new(0.6, 0.3, 0.0);
            let seg = p
                .add_segment(at, next, (0.06, 0.05), b, lateral, Plant::BARK)
                .unwrap();
            (b, lateral, at) = (Some(seg), false, next);
        }
        let twig = p
            .add_segment(
                at,
                at + Vec3::new(0.2, 0.3, 0.1),
                (0.02, 0.01),
                b,
                true,
                Plant::BARK,
            )
            .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Leaf,
            position: at + Vec3::new(0.2, 0.3, 0.1),
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.3, 0.1),
            material: Plant::LEAF,
            parent: Some(twig),
        })
        .unwrap();
        p
    }

    fn rigged(p: &Plant) -> (Mesh, Rig) {
        let (mesh, sources) = Mesher::new(MeshOptions::default())
            .unwrap()
            .mesh_with_sources(p)
            .unwrap();
        let rig = rig(p, &mesh, sources, &WindOptions::default());
        (mesh, rig)
    }

    #[test]
    fn joints_follow_the_skeleton_by_order() {
        let (_, rig) = rigged(&tree());
        let orders: Vec<u16> = rig.joints.iter().map(|j| j.order).collect();
        // Four on the trunk, three on the branch, one on the twig.
        assert_eq!(orders.iter().filter(|&&o| o == 0).count(), 4);
        assert_eq!(orders.iter().filter(|&&o| o == 1).count(), 3);
        assert_eq!(orders.iter().filter(|&&o| o == 2).count(), 1);
        for (i, j) in rig.joints.iter().enumerate() {
            assert!(j.parent.is_none_or(|p| p < i), "parents first");
        }
        assert_eq!(rig.joints.iter().filter(|j| j.parent.is_none()).count(), 1);
        assert_eq!(rig.dropped, 0);
    }

    #[test]
    fn weights_are_normalised_and_use_at_most_two_joints() {
        let (mesh, rig) = rigged(&tree());
        assert_eq!(rig.vertices(), mesh.positions.len());
        let all: Vec<Influence> = rig.influences(&mesh).collect();
        assert_eq!(all.len(), mesh.positions.len());
        for Influence {
            joints: j,
            weights: w,
            ..
        } in &all
        {
            assert_eq!(w.iter().map(|&x| u32::from(x)).sum::<u32>(), 255);
            assert_eq!(w[2..], [0, 0]);
            assert!((j[0] as usize) < rig.joints.len() && (j[1] as usize) < rig.joints.len());
        }
        assert!(all.iter().any(|i| i.weights[1] > 0), "some vertices blend");
        let leafy = all.iter().filter(|i| i.flutter > 0.0).count();
        assert!(leafy > 0 && all.iter().all(|i| (0.0..=1.0).contains(&i.flutter)));
    }

    #[test]
    fn the_clip_loops_and_twigs_sway_more_than_the_trunk() {
        let (_, rig) = rigged(&tree());
        assert_eq!(rig.times.len(), KEYS);
        assert_eq!(*rig.times.last().unwrap(), 4.0);
        let swing = |j: usize| {
            let r = &rig.rotations[j];
            assert_eq!(r.first(), r.last(), "seamless");
            assert!(r.iter().all(|q| q.is_normalized()));
            r.iter()
                .map(|q| q.angle_between(r[0]))
                .fold(0.0f32, f32::max)
        };
        let trunk = swing(0);
        let twig = swing(rig.joints.len() - 1);
        assert!(
            trunk > 0.0 && twig > 2.0 * trunk,
            "trunk {trunk}, twig {twig}"
        );
        let calm = rig_with(&tree(), 0.0);
        assert!(
            calm.rotations
                .iter()
                .flatten()
                .all(|q| q.angle_between(Quat::IDENTITY) < 1e-6)
        );
    }

    fn rig_with(p: &Plant, strength: f32) -> Rig {
        let (mesh, sources) = Mesher::new(MeshOptions::default())
            .unwrap()
            .mesh_with_sources(p)
            .unwrap();
        rig(p, &mesh, sources, &WindOptions::new(strength, 4.0).unwrap())
    }

    #[test]
    fn joints_are_capped_and_the_cap_reported() {
        let mut p = Plant::new(PlantMeta::default());
        let trunk = p
            .add_segment(
                Vec3::ZERO,
                Vec3::Y * 10.0,
                (0.5, 0.4),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        for k in 0..400 {
            let a = k as f32 * 0.1;
            let at = Vec3::Y * (1.0 + k as f32 * 0.02);
            p.add_segment(
                at,
                at + Vec3::new(a.cos(), 0.2, a.sin()),
                (0.02, 0.01),
                Some(trunk),
                true,
                Plant::BARK,
            )
            .unwrap();
        }
        let rig = rig_with(&p, 1.0);
        assert_eq!(rig.joints.len(), MAX_JOINTS);
        // The trunk's one segment, then 400 branch bases.
        assert_eq!(rig.dropped, 1 + 400 - MAX_JOINTS);
    }

    #[test]
    fn posing_at_rest_changes_nothing_and_the_wind_bends_twigs_downwind() {
        let p = tree();
        let (mesh, rig) = rigged(&p);
        let calm = rig_with(&p, 0.0);
        let still = calm.pose(&mesh, 1.3);
        for (a, b) in still.positions.iter().zip(&mesh.positions) {
            assert!(Vec3::from_array(*a).distance(Vec3::from_array(*b)) < 1e-4);
        }
        // The leaf at the twig's tip moves, and on average towards +X (downwind).
        let leaf = rig.influences(&mesh).position(|i| i.flutter > 0.0).unwrap();
        let mean_x: f32 = (0..KEYS - 1)
            .map(|k| rig.pose(&mesh, rig.times[k]).positions[leaf][0] - mesh.positions[leaf][0])
            .sum::<f32>()
            / (KEYS - 1) as f32;
        assert!(
            mean_x > 0.01,
            "the leaf moves {mean_x} m downwind on average"
        );
        let a = rig.pose(&mesh, 0.0).positions[leaf];
        let b = rig.pose(&mesh, 4.0).positions[leaf];
        assert!(
            Vec3::from_array(a).distance(Vec3::from_array(b)) < 1e-5,
            "the loop closes"
        );
    }

    #[test]
    fn options_are_checked() {
        assert!(WindOptions::new(f32::NAN, 4.0).is_err());
        assert!(WindOptions::new(11.0, 4.0).is_err());
        assert!(WindOptions::new(1.0, 0.1).is_err());
        assert!(WindOptions::new(1.0, f32::INFINITY).is_err());
        assert_eq!(WindOptions::new(1.0, 4.0), Ok(WindOptions::default()));
    }
}
