//! Turning derived strings into geometry, kept apart from derivation (as L-Py does).
//!
//! The shoot's turtle starts at the plant's foot heading up (+Y); the root's starts at the same
//! point heading down. Every module symbol is a sphyll: a segment of the module's length and
//! radius along the heading. Rotations turn the frame by the genome's angles; `[` saves the
//! turtle and the current parent segment, `]` restores them. The first module after a `[`
//! starts a lateral branch; the modules after it continue that branch's axis. Apexes draw
//! nothing, but their places are recorded, since growth happens there.

use serde::{Deserialize, Serialize};
use sylva_core::glam::Vec3;
use sylva_core::{Frame, Material, MaterialId, MaterialKind, Plant, PlantError, SegmentId};

use crate::grammar::{Axis, Compartment, Module, Symbol};

/// Length and radius of a module's sphyll, metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuleShape {
    /// Length along the heading, 0.005 to 2 m.
    #[serde(deserialize_with = "module_length")]
    pub length: f64,
    /// Radius, 0.001 to 0.5 m.
    #[serde(deserialize_with = "module_radius")]
    pub radius: f64,
}

sylva_core::ranged!(module_length: f64, "length", 0.005, 2.0, " m");
sylva_core::ranged!(module_radius: f64, "radius", 0.001, 0.5, " m");

/// The three rotation angles, degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Angles {
    /// `+` and `-`, -180 to 180 degrees.
    #[serde(deserialize_with = "angle")]
    pub turn: f64,
    /// `>` and `<`, -180 to 180 degrees.
    #[serde(deserialize_with = "angle")]
    pub pitch: f64,
    /// `$` and `&`, -180 to 180 degrees.
    #[serde(deserialize_with = "angle")]
    pub roll: f64,
}

sylva_core::ranged!(angle: f64, "angle", -180.0, 180.0, " degrees");

/// Where an apex sits after interpretation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApexSite {
    /// Shoot or root.
    pub compartment: Compartment,
    /// Index of the apex symbol in its compartment's word.
    pub index: usize,
    /// Which rule would rewrite it.
    pub apex: u8,
    /// Its position, metres.
    pub position: Vec3,
    /// The segment it grows from, if any.
    pub parent: Option<SegmentId>,
}

/// What interpretation found besides the plant's segments.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layout {
    /// Every apex, shoot first.
    pub apexes: Vec<ApexSite>,
    /// For each segment of the plant (in order): its module.
    pub modules: Vec<Module>,
}

/// The materials interpretation uses, added to a fresh plant.
#[derive(Clone, Copy, Debug)]
pub struct ModuleMaterials {
    /// For `b`.
    pub branch: MaterialId,
    /// For `l`.
    pub leaf: MaterialId,
    /// For `r` and `c`.
    pub root: MaterialId,
}

impl ModuleMaterials {
    /// Bark and leaf from [`Plant::new`], plus a root material.
    pub fn add_to(plant: &mut Plant) -> Result<ModuleMaterials, PlantError> {
        let root = plant.add_material(Material::of_kind(MaterialKind::Root))?;
        Ok(ModuleMaterials {
            branch: Plant::BARK,
            leaf: Plant::LEAF,
            root,
        })
    }

    fn of(&self, m: Module) -> MaterialId {
        match m {
            Module::Branch => self.branch,
            Module::Leaf => self.leaf,
            Module::FineRoot | Module::RootBranch => self.root,
        }
    }
}

/// Interprets one compartment's word from `foot`, adding segments to `plant` and recording
/// apexes and modules in `layout`.
#[allow(clippy::too_many_arguments)]
pub fn interpret(
    word: &[Symbol],
    compartment: Compartment,
    foot: Vec3,
    shapes: &[ModuleShape; 4],
    angles: &Angles,
    materials: &ModuleMaterials,
    plant: &mut Plant,
    layout: &mut Layout,
) -> Result<(), PlantError> {
    let mut frame = match compartment {
        Compartment::Shoot => Frame::UPRIGHT,
        Compartment::Root => Frame {
            heading: Vec3::NEG_Y,
            left: Vec3::X,
            up: Vec3::Z,
        },
    };
    let mut position = foot;
    let mut parent: Option<SegmentId> = None;
    // True when the next module starts a new axis.
    let mut lateral = false;
    let mut stack: Vec<(Vec3, Frame, Option<SegmentId>, bool)> = Vec::new();
    let radians = |deg: f64| deg.to_radians() as f32;
    for (index, symbol) in word.iter().enumerate() {
        match *symbol {
            Symbol::Module(m) => {
                let shape = shapes[m.index()];
                let end = position + frame.heading * shape.length as f32;
                let r = shape.radius as f32;
                let id =
                    plant.add_segment(position, end, (r, r), parent, lateral, materials.of(m))?;
                layout.modules.push(m);
                parent = Some(id);
                position = end;
                lateral = false;
            }
            Symbol::Apex(apex) => layout.apexes.push(ApexSite {
                compartment,
                index,
                apex,
                position,
                parent,
            }),
            Symbol::Push => {
                stack.push((position, frame, parent, lateral));
                lateral = parent.is_some();
            }
            Symbol::Pop => {
                if let Some(saved) = stack.pop() {
                    (position, frame, parent, lateral) = saved;
                }
            }
            Symbol::Rotate(axis, plus) => {
                let sign = if plus { 1.0 } else { -1.0 };
                match axis {
                    Axis::Turn => frame.rotate_u(sign * radians(angles.turn)),
                    Axis::Pitch => frame.rotate_l(sign * radians(angles.pitch)),
                    Axis::Roll => frame.rotate_h(sign * radians(angles.roll)),
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::{RuleSet, derive, parse_word};
    use sylva_core::PlantMeta;

    fn shapes() -> [ModuleShape; 4] {
        [ModuleShape {
            length: 0.1,
            radius: 0.01,
        }; 4]
    }

    const ANGLES: Angles = Angles {
        turn: 30.0,
        pitch: 30.0,
        roll: 30.0,
    };

    #[test]
    fn the_bush_grows_three_branches_around_the_axis() {
        let rules = RuleSet::parse(
            &[
                "A -> [>b[B]A]$$$$[>b[B]A]$$$$[>b[B]A]".into(),
                "B -> >>l".into(),
            ],
            Compartment::Shoot,
        )
        .unwrap();
        let mut word = parse_word("[A]", Compartment::Shoot).unwrap();
        for _ in 0..2 {
            word = derive(&word, &rules, 10_000).unwrap();
        }
        let mut plant = Plant::new(PlantMeta::default());
        let materials = ModuleMaterials::add_to(&mut plant).unwrap();
        let mut layout = Layout::default();
        interpret(
            &word,
            Compartment::Shoot,
            Vec3::ZERO,
            &shapes(),
            &ANGLES,
            &materials,
            &mut plant,
            &mut layout,
        )
        .unwrap();
        // Two steps: 3 branches, each with a leaf (B) and 3 sub-branches with B apexes.
        let leaves = layout
            .modules
            .iter()
            .filter(|m| **m == Module::Leaf)
            .count();
        assert_eq!(leaves, 3);
        assert_eq!(layout.modules.len(), 3 + 3 + 9);
        assert_eq!(layout.apexes.len(), 9 + 9);
        // The three first branches lean out in directions 120 degrees apart.
        let firsts: Vec<Vec3> = plant
            .segments()
            .iter()
            .filter(|s| s.parent.is_none())
            .map(|s| Vec3::new(s.vector().x, 0.0, s.vector().z).normalize())
            .collect();
        assert_eq!(firsts.len(), 3);
        for pair in [(0, 1), (1, 2), (0, 2)] {
            let cos = firsts[pair.0].dot(firsts[pair.1]);
            assert!((cos + 0.5).abs() < 1e-4, "{cos}");
        }
    }

    #[test]
    fn roots_grow_down() {
        let word = parse_word("c[r]c", Compartment::Root).unwrap();
        let mut plant = Plant::new(PlantMeta::default());
        let materials = ModuleMaterials::add_to(&mut plant).unwrap();
        let mut layout = Layout::default();
        interpret(
            &word,
            Compartment::Root,
            Vec3::ZERO,
            &shapes(),
            &ANGLES,
            &materials,
            &mut plant,
            &mut layout,
        )
        .unwrap();
        assert_eq!(plant.segments().len(), 3);
        assert!(plant.segments().iter().all(|s| s.end.y < 0.0));
        assert!(plant.segments()[1].lateral && !plant.segments()[2].lateral);
        assert_eq!(plant.segments()[2].parent, Some(SegmentId(0)));
    }
}
