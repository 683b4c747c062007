//! A scene: meshes placed in the world, each with where it came from.
//!
//! Exporters write one glTF node (or OBJ group, or VRML `Transform`) per [`SceneNode`], so a
//! garden of many plants is one scene of many nodes. Nodes borrow their meshes: a forest of
//! one genome can place the same mesh many times without copying it.

use sylva_core::{
    Aabb,
    glam::{Quat, Vec3},
};

use crate::mesh::Mesh;
use crate::wind::Rig;

/// One placed mesh.
#[derive(Clone, Debug)]
pub struct SceneNode<'a> {
    /// Node name (unique names read better in viewers, but are not required).
    pub name: String,
    /// The geometry.
    pub mesh: &'a Mesh,
    /// Where the mesh's origin goes, metres.
    pub translation: Vec3,
    /// Rotation applied before the translation.
    pub rotation: Quat,
    /// Origin data stored with the node (glTF `extras`): genome, seed, Sylva version.
    pub extras: Option<serde_json::Value>,
    /// A skin and wind clip for the mesh ([`crate::wind`]); GLB only.
    pub rig: Option<&'a Rig>,
}

impl<'a> SceneNode<'a> {
    /// A node at the origin with no rotation and no extras.
    pub fn new(name: impl Into<String>, mesh: &'a Mesh) -> Self {
        SceneNode {
            name: name.into(),
            mesh,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            extras: None,
            rig: None,
        }
    }

    /// Maps a mesh-space point into the world.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// World-space bounds of the node's vertices.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in &self.mesh.positions {
            b.grow(self.transform_point(Vec3::from_array(*p)), 0.0);
        }
        b
    }
}

/// Placed meshes, exported or rendered together.
#[derive(Clone, Debug, Default)]
pub struct Scene<'a> {
    /// The nodes, in export order.
    pub nodes: Vec<SceneNode<'a>>,
}

impl<'a> Scene<'a> {
    /// A scene of one node.
    pub fn single(node: SceneNode<'a>) -> Self {
        Scene { nodes: vec![node] }
    }

    /// World-space bounds of every node.
    pub fn bounds(&self) -> Aabb {
        self.nodes
            .iter()
            .fold(Aabb::EMPTY, |acc, n| acc.union(&n.bounds()))
    }

    /// Triangles over all nodes.
    pub fn triangle_count(&self) -> usize {
        self.nodes.iter().map(|n| n.mesh.triangle_count()).sum()
    }
}
