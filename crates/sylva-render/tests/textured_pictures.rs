//! Pictures of the generated textures and of textured plants, to look at:
//! `cargo test -p sylva-render --test textured_pictures -- --ignored`, then open
//! `$TMPDIR/textured-*.png` (the flat textures tiled 2 × 2, the textures on quads, trees,
//! trunks, and leaves and flowers).
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::f32::consts::{FRAC_PI_2, TAU};
use std::path::PathBuf;

use image::{GrayImage, imageops};
use sylva_core::glam::{Quat, Vec2, Vec3};
use sylva_core::{Material, MaterialId, MaterialKind, Organ, OrganKind, Plant, PlantMeta};
use sylva_mesh::mesher::{MeshOptions, mesh_plant};
use sylva_mesh::texture::{TEXTURE_COUNT, TEXTURE_SIZE, TextureFamily, texture, texture_info};
use sylva_mesh::{Mesh, Primitive, Scene, SceneNode};
use sylva_render::{
    RenderOptions, SheetCell, SheetOptions, View, contact_sheet, render, write_png,
};

fn out(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("textured-{name}.png"))
}

/// A material of the texture's family, in that family's default colour.
fn material_for(id: u16) -> Material {
    let kind = match texture_info(id).family {
        TextureFamily::Bark => MaterialKind::Bark,
        TextureFamily::Leaf => MaterialKind::Leaf,
        TextureFamily::Petal => MaterialKind::Flower,
    };
    Material {
        texture: Some(id),
        ..Material::of_kind(kind)
    }
}

/// An upright 2 m square facing +Z, showing its texture once, v = 0 at the top.
fn quad(id: u16) -> Mesh {
    Mesh {
        positions: vec![
            [-1.0, 0.2, 0.0],
            [1.0, 0.2, 0.0],
            [1.0, 2.2, 0.0],
            [-1.0, 2.2, 0.0],
        ],
        normals: vec![[0.0, 0.0, 1.0]; 4],
        uvs: vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
        primitives: vec![Primitive {
            material: 0,
            indices: vec![0, 1, 2, 0, 2, 3],
        }],
        materials: vec![material_for(id)],
        impostor: None,
    }
}

fn caption(id: u16) -> String {
    format!("{id} {}", texture_info(id).name)
}

fn sheet(cells: &[SheetCell], view: View, title: &str, name: &str) {
    let options = SheetOptions {
        columns: 3,
        cell_width: 360,
        cell_height: 380,
        view,
        title: Some(title.to_owned()),
    };
    write_png(
        &out(name),
        &contact_sheet(cells, &options, &sylva_core::par::Pool::Serial).unwrap(),
    )
    .unwrap();
}

#[test]
#[ignore = "writes pictures to look at"]
fn write_textured_pictures() {
    // Every texture flat, tiled 2 x 2 so seams would show, three to a row.
    let s = TEXTURE_SIZE;
    let cell = 2 * s + 8;
    let mut flat = GrayImage::from_pixel(3 * cell, 3 * cell, image::Luma([90]));
    for id in 0..TEXTURE_COUNT {
        let t = texture(id);
        std::fs::write(out(&format!("tex{id}")), t.png().unwrap()).unwrap();
        let (x, y) = (u32::from(id % 3) * cell, u32::from(id / 3) * cell);
        for (dx, dy) in [(0, 0), (s, 0), (0, s), (s, s)] {
            imageops::replace(&mut flat, &t.image, i64::from(x + dx), i64::from(y + dy));
        }
    }
    flat.save(out("flat")).unwrap();

    // The textures on quads, in their family's default colour.
    let quads: Vec<Mesh> = (0..TEXTURE_COUNT).map(quad).collect();
    let cells: Vec<SheetCell> = quads
        .iter()
        .zip(0..)
        .map(|(m, id)| SheetCell {
            scene: Scene::single(SceneNode::new("quad", m)),
            caption: caption(id),
        })
        .collect();
    sheet(&cells, View::Front, "Sylva textures on quads", "quads");

    // Trees: bark, leaf and petal textures of one row each.
    let trees: Vec<(String, Mesh)> = (0..3)
        .map(|k| {
            let mut plant = sylva_testkit::binary_tree(4, 6);
            for (m, id) in [k, 3 + k, 6 + k].into_iter().enumerate() {
                plant.set_texture(MaterialId(m as u16), Some(id)).unwrap();
            }
            let label = format!("textures {k}, {}, {}", 3 + k, 6 + k);
            (label, mesh_plant(&plant, &MeshOptions::default()).unwrap())
        })
        .collect();
    let cells: Vec<SheetCell> = trees
        .iter()
        .map(|(label, m)| SheetCell {
            scene: Scene::single(SceneNode::new("tree", m)),
            caption: label.clone(),
        })
        .collect();
    sheet(&cells, View::Iso, "Textured trees", "trees");
    let one = Scene::single(SceneNode::new("tree", &trees[0].1));
    let options = RenderOptions::default();
    write_png(&out("tree"), &render(&one, &options).unwrap()).unwrap();

    // Trunks close up: one tapering, slightly bent axis per bark.
    let trunks: Vec<Mesh> = (0..3u16)
        .map(|id| {
            let mut plant = Plant::new(PlantMeta::default());
            let mut parent = None;
            for i in 0..8 {
                let y = |i: i32| Vec3::new(0.05 * (i as f32 * 0.7).sin(), 0.4 * i as f32, 0.0);
                let r = |i: i32| 0.35 - 0.02 * i as f32;
                parent = Some(
                    plant
                        .add_segment(y(i), y(i + 1), (r(i), r(i + 1)), parent, false, Plant::BARK)
                        .unwrap(),
                );
            }
            plant.set_texture(MaterialId(0), Some(id)).unwrap();
            mesh_plant(&plant, &MeshOptions::default()).unwrap()
        })
        .collect();
    let cells: Vec<SheetCell> = trunks
        .iter()
        .zip(0..)
        .map(|(m, id)| SheetCell {
            scene: Scene::single(SceneNode::new("trunk", m)),
            caption: caption(id),
        })
        .collect();
    sheet(&cells, View::Front, "Bark on trunks", "trunks");

    // Leaves lying flat in a fan, and flowers facing up, seen from above.
    let organs: Vec<Mesh> = (3..TEXTURE_COUNT)
        .map(|id| {
            let mut plant = Plant::new(PlantMeta::default());
            let m = plant.add_material(material_for(id)).unwrap();
            let leaf = texture_info(id).family == TextureFamily::Leaf;
            for k in 0..5 {
                let turn = Quat::from_rotation_y(TAU * k as f32 / 5.0);
                let (kind, orientation, size) = if leaf {
                    (
                        OrganKind::Leaf,
                        turn * Quat::from_rotation_x(-FRAC_PI_2),
                        Vec2::new(1.0, 0.45),
                    )
                } else {
                    (OrganKind::Flower, turn, Vec2::new(2.0, 0.7))
                };
                let position = if leaf {
                    Vec3::new(0.0, 0.1, 0.0)
                } else {
                    Vec3::new(0.0, 0.1 + 0.01 * k as f32, 0.0)
                };
                plant
                    .add_organ(Organ {
                        kind,
                        position,
                        orientation,
                        size,
                        material: m,
                        parent: None,
                    })
                    .unwrap();
                if !leaf {
                    break;
                }
            }
            let options = MeshOptions {
                leaf_stations: 12,
                flower_petals: 6,
                ..MeshOptions::default()
            };
            mesh_plant(&plant, &options).unwrap()
        })
        .collect();
    let cells: Vec<SheetCell> = organs
        .iter()
        .zip(3..)
        .map(|(m, id)| SheetCell {
            scene: Scene::single(SceneNode::new("organs", m)),
            caption: caption(id),
        })
        .collect();
    sheet(&cells, View::Top, "Leaves and flowers", "organs");

    // An untextured tree, to compare with the pictures before textures existed.
    let plain = mesh_plant(&sylva_testkit::binary_tree(4, 6), &MeshOptions::default()).unwrap();
    let plain = Scene::single(SceneNode::new("tree", &plain));
    write_png(&out("untextured-tree"), &render(&plain, &options).unwrap()).unwrap();
}
