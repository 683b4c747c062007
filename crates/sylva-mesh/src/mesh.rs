//! The triangle mesh every exporter and the renderer read.
//!
//! One vertex buffer (positions, unit normals and texture coordinates) shared by several
//! [`Primitive`]s, one per material, each a list of counter-clockwise triangles (front faces
//! wind counter-clockwise seen from outside). A material whose `texture` is set shows that
//! [`texture`](crate::texture) through the coordinates, multiplied by its colour. Leaves are double-sided by geometry: each blade is emitted twice with
//! opposite windings and normals, so every exporter and viewer shows both faces correctly.

use sylva_core::{Aabb, Material, glam::Vec3};

/// Triangles of one material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Primitive {
    /// Index into [`Mesh::materials`].
    pub material: usize,
    /// Three vertex indices per triangle, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
}

/// An indexed triangle mesh with per-material primitives.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, metres.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates `[u, v]`, one per position (`v` runs down the texture picture, as
    /// in glTF). May be empty for a mesh built by hand without them: exporters then write
    /// `(0, 0)` and the renderer samples there. The mesher always fills them.
    pub uvs: Vec<[f32; 2]>,
    /// Triangle lists, one per material that has triangles.
    pub primitives: Vec<Primitive>,
    /// The materials primitives refer to.
    pub materials: Vec<Material>,
    /// The picture (a PNG, colour and alpha) a material whose surface is
    /// [`Surface::Impostor`](sylva_core::species::Surface::Impostor) shows: an impostor card's
    /// picture of its plant. `None` for every other mesh.
    pub impostor: Option<std::sync::Arc<Vec<u8>>>,
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles over all primitives.
    pub fn triangle_count(&self) -> usize {
        self.primitives.iter().map(|p| p.indices.len() / 3).sum()
    }

    /// Bounds of the vertex positions.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in &self.positions {
            b.grow(Vec3::from_array(*p), 0.0);
        }
        b
    }

    /// Empties the buffers but keeps their capacity, so a reused mesh does not allocate.
    pub fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.uvs.clear();
        for p in &mut self.primitives {
            p.indices.clear();
        }
        self.primitives.clear();
        self.materials.clear();
        self.impostor = None;
    }
}
