//! Lean materials for glTF: one material per organ kind and texture, with per-organ colour
//! variation moved into vertex colours.
//!
//! Models such as PlantMaker give each colour shade a material of its own (the flowering
//! bush has 29), and an engine draws each material separately. When a mesh has several
//! colours of one kind and texture, the GLB writer merges them: one primitive and one
//! material per (kind, texture), named after the kind (`leaf`, or `leaf-t3` with texture 3),
//! whose base colour is the per-channel maximum of the merged colours, and a `COLOR_0`
//! attribute (normalised `u8` RGBA) holding each vertex's colour divided by that maximum,
//! so that base colour × vertex colour gives the original colour back to within 1/510 of
//! the maximum (glTF multiplies them, and the texture, by definition). Dividing by the
//! maximum rather than writing colours against a white base keeps dark greens precise in
//! eight bits and shows plausible colours in a viewer that ignores vertex colours.
//!
//! A mesh that already has one colour per kind and texture (every automata, bintree and
//! L-system plant) is written as before, without `COLOR_0`; so is a mesh in which a vertex
//! is shared by triangles of two colours, whose colour a vertex attribute could not hold.

use sylva_core::species::Surface;
use sylva_core::{Material, MaterialKind};
use sylva_mesh::mesh::Mesh;

/// A merged material's name for a surface: `leaf-oak`, `bark-furrowed`, `flower-petals-t7`.
fn surface_name(kind: MaterialKind, surface: Surface, texture: Option<u16>) -> String {
    let what = match surface {
        Surface::Leaves(k) => k.name(),
        Surface::Branchlets(k) => return format!("{}-{}-branchlets", kind.name(), k.name()),
        Surface::Bark(k) => k.name(),
        Surface::Petals => "petals",
        Surface::Impostor => "impostor",
    };
    match texture {
        Some(t) if surface == Surface::Petals => format!("{}-{what}-t{t}", kind.name()),
        _ => format!("{}-{what}", kind.name()),
    }
}

/// No primitive has claimed this vertex yet.
const UNCLAIMED: u32 = u32::MAX;

/// How one mesh's primitives are merged.
pub(super) struct LeanPlan {
    /// The merged materials, in order of first use.
    pub materials: Vec<Material>,
    /// For each merged material, the indices of `mesh.primitives` it takes, in order.
    pub members: Vec<Vec<usize>>,
    /// RGBA per vertex, normalised to 255: the vertex's colour over its material's base.
    pub colors: Vec<[u8; 4]>,
}

impl LeanPlan {
    /// The plan for `mesh`, or `None` when merging would change nothing or is impossible.
    pub fn of(mesh: &Mesh) -> Option<LeanPlan> {
        let mut keys: Vec<(MaterialKind, Option<u16>, Option<Surface>)> = Vec::new();
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut merges = false;
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if prim.indices.is_empty() {
                continue;
            }
            let m = &mesh.materials[prim.material];
            let key = (m.kind, m.texture, m.surface);
            match keys.iter().position(|k| *k == key) {
                Some(g) => {
                    let first = &mesh.materials[mesh.primitives[members[g][0]].material];
                    merges |= colour_bits(first) != colour_bits(m);
                    members[g].push(p);
                }
                None => {
                    keys.push(key);
                    members.push(vec![p]);
                }
            }
        }
        if !merges {
            return None;
        }

        let materials: Vec<Material> = keys
            .iter()
            .zip(&members)
            .map(|(&(kind, texture, surface), group)| {
                let mut color = [0.0f32; 3];
                for &p in group {
                    let c = mesh.materials[mesh.primitives[p].material].color;
                    for (acc, c) in color.iter_mut().zip(c) {
                        *acc = acc.max(c.clamp(0.0, 1.0));
                    }
                }
                Material {
                    name: match (surface, texture) {
                        (Some(s), _) => surface_name(kind, s, texture),
                        (None, Some(t)) => format!("{}-t{t}", kind.name()),
                        (None, None) => kind.name().to_owned(),
                    },
                    kind,
                    color,
                    texture,
                    surface,
                }
            })
            .collect();

        // Each vertex takes the colour of the primitive that uses it; two colours refuse.
        let mut owner = vec![UNCLAIMED; mesh.positions.len()];
        let mut colors = vec![[255u8; 4]; mesh.positions.len()];
        for (group, base) in members.iter().zip(&materials) {
            for &p in group {
                let prim = &mesh.primitives[p];
                let rgba = ratio(mesh.materials[prim.material].color, base.color);
                for &i in &prim.indices {
                    let i = i as usize;
                    match owner[i] {
                        UNCLAIMED => {
                            owner[i] = p as u32;
                            colors[i] = rgba;
                        }
                        o if o as usize == p => {}
                        o => {
                            let other = &mesh.materials[mesh.primitives[o as usize].material];
                            let this = &mesh.materials[prim.material];
                            if colour_bits(other) != colour_bits(this)
                                || (other.kind, other.texture, other.surface)
                                    != (this.kind, this.texture, this.surface)
                            {
                                return None;
                            }
                        }
                    }
                }
            }
        }
        Some(LeanPlan {
            materials,
            members,
            colors,
        })
    }
}

fn colour_bits(m: &Material) -> [u32; 3] {
    m.color.map(|c| c.clamp(0.0, 1.0).to_bits())
}

/// `color / base` per channel as normalised bytes, opaque; a zero base channel gives 255
/// (the product is zero either way).
fn ratio(color: [f32; 3], base: [f32; 3]) -> [u8; 4] {
    let mut out = [255u8; 4];
    for ((o, c), b) in out.iter_mut().zip(color).zip(base) {
        if b > 0.0 {
            *o = (c.clamp(0.0, 1.0) / b * 255.0).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_mesh::mesh::Primitive;

    fn material(kind: MaterialKind, color: [f32; 3], texture: Option<u16>) -> Material {
        Material {
            name: format!("{}-{color:?}", kind.name()),
            kind,
            color,
            texture,
            surface: None,
        }
    }

    /// Four one-triangle primitives over their own vertices.
    fn mesh(materials: Vec<Material>) -> Mesh {
        let n = materials.len();
        Mesh {
            positions: vec![[0.0; 3]; 3 * n],
            normals: vec![[0.0, 1.0, 0.0]; 3 * n],
            uvs: Vec::new(),
            primitives: (0..n)
                .map(|m| Primitive {
                    material: m,
                    indices: vec![3 * m as u32, 3 * m as u32 + 1, 3 * m as u32 + 2],
                })
                .collect(),
            materials,
            impostor: None,
        }
    }

    #[test]
    fn shades_of_a_kind_merge_into_one_material_with_vertex_colours() {
        let m = mesh(vec![
            material(MaterialKind::Leaf, [0.1, 0.4, 0.05], Some(3)),
            material(MaterialKind::Bark, [0.2, 0.1, 0.05], None),
            material(MaterialKind::Leaf, [0.05, 0.2, 0.1], Some(3)),
            material(MaterialKind::Leaf, [0.1, 0.4, 0.05], Some(4)),
        ]);
        let plan = LeanPlan::of(&m).unwrap();
        let names: Vec<&str> = plan.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["leaf-t3", "bark", "leaf-t4"]);
        assert_eq!(plan.members, vec![vec![0, 2], vec![1], vec![3]]);
        assert_eq!(plan.materials[0].color, [0.1, 0.4, 0.1]);
        assert_eq!(plan.colors[0], [255, 255, 128, 255]);
        assert_eq!(plan.colors[6], [128, 128, 255, 255]);
        assert_eq!(plan.colors[3], [255; 4]);
        // Base colour × vertex colour is the original colour, to a byte.
        for (v, original) in [(0, [0.1f32, 0.4, 0.05]), (6, [0.05, 0.2, 0.1])] {
            for ((base, byte), want) in plan.materials[0]
                .color
                .iter()
                .zip(plan.colors[v])
                .zip(original)
            {
                let back = base * f32::from(byte) / 255.0;
                assert!((back - want).abs() <= base / 510.0);
            }
        }
    }

    #[test]
    fn one_colour_per_kind_or_shared_vertices_change_nothing() {
        let one = mesh(vec![
            material(MaterialKind::Bark, [0.2, 0.1, 0.05], None),
            material(MaterialKind::Leaf, [0.1, 0.4, 0.05], None),
        ]);
        assert!(LeanPlan::of(&one).is_none());
        let mut shared = mesh(vec![
            material(MaterialKind::Leaf, [0.1, 0.4, 0.05], None),
            material(MaterialKind::Leaf, [0.05, 0.2, 0.1], None),
        ]);
        shared.primitives[1].indices[0] = 0;
        assert!(LeanPlan::of(&shared).is_none());
    }
}
