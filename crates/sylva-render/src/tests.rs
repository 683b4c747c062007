//! Renderer tests on hand-made meshes.

use image::RgbImage;
use sylva_core::{
    MaterialKind,
    glam::{Quat, Vec3},
};
use sylva_mesh::mesh::Mesh;
use sylva_mesh::scene::{Scene, SceneNode};

use super::test_meshes::{add_box, add_quad, empty, material, tree};
use super::*;

const RED: [f32; 3] = [0.8, 0.05, 0.05];
const BLUE: [f32; 3] = [0.05, 0.05, 0.8];
const GREEN: [f32; 3] = [0.05, 0.7, 0.05];

/// Small, plain options: no ground or shadows, so only the meshes differ from background.
fn plain(view: View) -> RenderOptions {
    RenderOptions {
        width: 96,
        height: 96,
        view,
        ground: false,
        shadows: false,
        supersample: 1,
        ..RenderOptions::default()
    }
}

fn scene(mesh: &Mesh) -> Scene<'_> {
    Scene::single(SceneNode::new("test", mesh))
}

/// Pixels that differ from the background: count, mean x, mean y, and bounding box.
struct Coverage {
    count: usize,
    mean: (f32, f32),
    min: (u32, u32),
    max: (u32, u32),
}

fn coverage(img: &RgbImage, bg: [u8; 3], keep: impl Fn([u8; 3]) -> bool) -> Coverage {
    let mut c = Coverage {
        count: 0,
        mean: (0.0, 0.0),
        min: (u32::MAX, u32::MAX),
        max: (0, 0),
    };
    for (x, y, p) in img.enumerate_pixels() {
        if p.0 != bg && keep(p.0) {
            c.count += 1;
            c.mean.0 += x as f32;
            c.mean.1 += y as f32;
            c.min = (c.min.0.min(x), c.min.1.min(y));
            c.max = (c.max.0.max(x), c.max.1.max(y));
        }
    }
    if c.count > 0 {
        c.mean = (c.mean.0 / c.count as f32, c.mean.1 / c.count as f32);
    }
    c
}

fn reddish(p: [u8; 3]) -> bool {
    u16::from(p[0]) > 2 * u16::from(p[1].max(p[2]).max(20))
}

fn greenish(p: [u8; 3]) -> bool {
    u16::from(p[1]) > 2 * u16::from(p[0].max(p[2]).max(20))
}

fn bluish(p: [u8; 3]) -> bool {
    u16::from(p[2]) > 2 * u16::from(p[0].max(p[1]).max(20))
}

#[test]
fn object_is_visible_centred_and_large() {
    let mut mesh = empty(RED);
    add_box(
        &mut mesh,
        0,
        Vec3::new(3.0, 5.0, -2.0),
        Vec3::new(0.5, 2.0, 0.5),
    );
    for view in View::ALL {
        let opts = plain(view);
        let img = render(&scene(&mesh), &opts).unwrap();
        let c = coverage(&img, opts.background, |_| true);
        assert!(c.count > 500, "{view}: {} pixels", c.count);
        assert!((c.mean.0 - 47.5).abs() < 6.0, "{view}: x {}", c.mean.0);
        assert!((c.mean.1 - 47.5).abs() < 6.0, "{view}: y {}", c.mean.1);
        // Framed with a 5 % margin on the longer projected side.
        let span = (c.max.0 - c.min.0).max(c.max.1 - c.min.1);
        assert!((80..=92).contains(&span), "{view}: span {span}");
    }
}

#[test]
fn tall_object_fills_the_height_in_front_view() {
    let mesh = tree(3, 8, 2);
    let opts = RenderOptions {
        width: 120,
        height: 120,
        view: View::Front,
        ..RenderOptions::default()
    };
    let img = render(&scene(&mesh), &opts).unwrap();
    let bark_or_leaf = |p: [u8; 3]| p[0] < 170 && p[1] < 200;
    let c = coverage(&img, opts.background, bark_or_leaf);
    assert!(
        c.max.1 - c.min.1 > 80,
        "plant spans {}..{}",
        c.min.1,
        c.max.1
    );
}

#[test]
fn near_quad_hides_far_quad_in_any_order() {
    let mut near_first = Mesh {
        materials: vec![
            material(MaterialKind::Bark, RED),
            material(MaterialKind::Bark, BLUE),
        ],
        ..Mesh::default()
    };
    let mut far_first = near_first.clone();
    let near = |m: &mut Mesh| add_quad(m, 0, Vec3::new(0.0, 0.0, 1.0), Vec3::X, Vec3::Y);
    let far = |m: &mut Mesh| add_quad(m, 1, Vec3::new(0.3, 0.3, 0.0), Vec3::X, Vec3::Y);
    near(&mut near_first);
    far(&mut near_first);
    far(&mut far_first);
    near(&mut far_first);
    for mesh in [&near_first, &far_first] {
        let opts = plain(View::Front);
        let img = render(&scene(mesh), &opts).unwrap();
        let red = coverage(&img, opts.background, reddish);
        let blue = coverage(&img, opts.background, bluish);
        assert!(
            reddish(img.get_pixel(48, 48).0),
            "{:?}",
            img.get_pixel(48, 48)
        );
        // Blue shows only as the L-shaped rim the red quad does not cover.
        assert!(blue.count > 0 && blue.count < red.count / 2);
        assert!(
            blue.mean.0 > red.mean.0 && blue.mean.1 < red.mean.1,
            "up and right"
        );
    }
    let a = render(&scene(&near_first), &plain(View::Iso)).unwrap();
    let b = render(&scene(&far_first), &plain(View::Iso)).unwrap();
    assert_eq!(a, b, "triangle order does not matter");
}

#[test]
fn back_faces_are_culled() {
    let mut facing = empty(RED);
    add_quad(&mut facing, 0, Vec3::ZERO, Vec3::X, Vec3::Y);
    let mut away = empty(RED);
    add_quad(&mut away, 0, Vec3::ZERO, -Vec3::X, Vec3::Y);
    let opts = plain(View::Front);
    let seen = render(&scene(&facing), &opts).unwrap();
    assert!(coverage(&seen, opts.background, reddish).count > 1000);
    let hidden = render(&scene(&away), &opts).unwrap();
    assert_eq!(coverage(&hidden, opts.background, |_| true).count, 0);
}

/// A grey pillar at the origin with a red marker at +X and a green one at +Z.
fn markers() -> Mesh {
    let mut mesh = Mesh {
        materials: vec![
            material(MaterialKind::Bark, [0.4, 0.4, 0.4]),
            material(MaterialKind::Bark, RED),
            material(MaterialKind::Bark, GREEN),
        ],
        ..Mesh::default()
    };
    add_box(&mut mesh, 0, Vec3::Y, Vec3::new(0.3, 1.0, 0.3));
    add_box(&mut mesh, 1, Vec3::new(1.5, 0.3, 0.0), Vec3::splat(0.3));
    add_box(&mut mesh, 2, Vec3::new(0.0, 0.3, 1.5), Vec3::splat(0.3));
    mesh
}

#[test]
fn views_differ_and_are_not_mirrored() {
    let mesh = markers();
    let mut images = Vec::new();
    for view in View::ALL {
        let opts = plain(view);
        let img = render(&scene(&mesh), &opts).unwrap();
        let red = coverage(&img, opts.background, reddish);
        let green = coverage(&img, opts.background, greenish);
        match view {
            View::Front => assert!(red.mean.0 > 60.0, "+X on the right"),
            // From +X, +Z is on the left and the red marker faces the camera in the middle.
            View::Side => assert!(green.mean.0 + 20.0 < red.mean.0, "+Z on the left"),
            View::Top => {
                assert!(red.mean.0 > 60.0, "+X on the right");
                assert!(green.mean.1 > 60.0, "+Z at the bottom");
            }
            View::Iso => {
                assert!(red.mean.0 > 55.0 && green.mean.0 < 40.0);
                assert!(red.count > 0 && green.count > 0);
            }
        }
        images.push(img);
    }
    for i in 0..images.len() {
        for j in i + 1..images.len() {
            assert_ne!(images[i], images[j], "{} vs {}", View::ALL[i], View::ALL[j]);
        }
    }
}

#[test]
fn bad_sizes_are_errors() {
    let mesh = markers();
    for (w, h, s) in [
        (0, 100, 2),
        (15, 100, 2),
        (100, 8193, 2),
        (u32::MAX, u32::MAX, 1),
        (100, 100, 0),
        (100, 100, 5),
    ] {
        let opts = RenderOptions {
            width: w,
            height: h,
            supersample: s,
            ..RenderOptions::default()
        };
        let err = render(&scene(&mesh), &opts).unwrap_err();
        assert!(matches!(
            err,
            RenderError::InvalidSize { .. } | RenderError::InvalidSupersample(_)
        ));
        assert!(!err.to_string().is_empty());
    }
    // The largest legal size with the largest supersampling stays within MAX_SAMPLES.
    let huge = RenderOptions {
        width: 8192,
        height: 8192,
        supersample: 4,
        ..RenderOptions::default()
    };
    assert_eq!(huge.validate().ok(), Some(()));
    assert_eq!(huge.effective_supersample(), 1);
    let ok = RenderOptions {
        width: 16,
        height: 8192,
        supersample: 4,
        ..RenderOptions::default()
    };
    assert_eq!(ok.effective_supersample(), 4);
    assert_eq!(render(&scene(&mesh), &ok).unwrap().dimensions(), (16, 8192));
}

#[test]
fn empty_scene_gives_ground_or_background() {
    let nothing = Scene::default();
    let opts = RenderOptions {
        width: 64,
        height: 48,
        ..RenderOptions::default()
    };
    let img = render(&nothing, &opts).unwrap();
    assert_eq!(img.dimensions(), (64, 48));
    assert!(
        coverage(&img, opts.background, |_| true).count > 500,
        "ground"
    );
    let bare = RenderOptions {
        ground: false,
        ..opts.clone()
    };
    let img = render(&nothing, &bare).unwrap();
    assert!(img.pixels().all(|p| p.0 == bare.background));
    // A mesh with no triangles, or a node whose mesh is all NaN, is just as empty.
    let mut nan = empty(RED);
    nan.positions = vec![[f32::NAN; 3]; 3];
    nan.normals = vec![[0.0, 1.0, 0.0]; 3];
    nan.primitives = vec![sylva_mesh::mesh::Primitive {
        material: 0,
        indices: vec![0, 1, 2],
    }];
    let img = render(&scene(&nan), &bare).unwrap();
    assert!(img.pixels().all(|p| p.0 == bare.background));
}

#[test]
fn bad_vertices_and_indices_are_skipped() {
    let mut clean = empty(RED);
    add_quad(&mut clean, 0, Vec3::ZERO, Vec3::X, Vec3::Y);
    let mut dirty = clean.clone();
    for bad in [f32::NAN, f32::INFINITY, 1e30] {
        let k = dirty.positions.len() as u32;
        dirty.positions.push([bad, 0.0, 0.0]);
        dirty.normals.push([0.0, 0.0, 1.0]);
        dirty.primitives[0].indices.extend([0, 1, k]);
    }
    // Out-of-range indices, a dangling material and a NaN normal and colour.
    dirty.primitives[0].indices.extend([0, 1, 999]);
    dirty.primitives.push(sylva_mesh::mesh::Primitive {
        material: 7,
        indices: vec![0, 1],
    });
    let opts = plain(View::Front);
    let a = render(&scene(&clean), &opts).unwrap();
    let b = render(&scene(&dirty), &opts).unwrap();
    assert_eq!(a, b);

    let mut odd = clean.clone();
    odd.normals[0] = [f32::NAN; 3];
    odd.normals.truncate(2);
    odd.materials[0].color = [f32::NAN, 2.0, -1.0];
    let img = render(&scene(&odd), &opts).unwrap();
    assert!(coverage(&img, opts.background, |_| true).count > 1000);

    // Degenerate triangles draw nothing; huge but valid coordinates still frame.
    let mut flat = empty(RED);
    flat.positions = vec![[0.0; 3], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
    flat.normals = vec![[0.0, 0.0, 1.0]; 3];
    flat.primitives = vec![sylva_mesh::mesh::Primitive {
        material: 0,
        indices: vec![0, 1, 2, 0, 0, 0],
    }];
    let img = render(&scene(&flat), &opts).unwrap();
    assert!(img.pixels().all(|p| p.0 == opts.background));
    let mut far = empty(RED);
    add_quad(
        &mut far,
        0,
        Vec3::splat(1e12),
        Vec3::X * 1e11,
        Vec3::Y * 1e11,
    );
    let img = render(&scene(&far), &RenderOptions::default()).unwrap();
    assert!(coverage(&img, [221, 232, 242], reddish).count > 1000);
}

#[test]
fn node_placement_moves_and_turns_the_mesh() {
    let mut mesh = empty(RED);
    add_quad(&mut mesh, 0, Vec3::ZERO, Vec3::X, Vec3::Y);
    // Turned half round, the quad faces away from the front camera and is culled.
    let mut node = SceneNode::new("turned", &mesh);
    node.rotation = Quat::from_rotation_y(std::f32::consts::PI);
    let opts = plain(View::Front);
    let img = render(&Scene::single(node.clone()), &opts).unwrap();
    assert_eq!(coverage(&img, opts.background, |_| true).count, 0);
    // Two copies side by side: the right-hand one is at +X.
    let mut blue = empty(BLUE);
    add_quad(&mut blue, 0, Vec3::ZERO, Vec3::X, Vec3::Y);
    let mut right = SceneNode::new("right", &blue);
    right.translation = Vec3::new(3.0, 0.0, 0.0);
    let two = Scene {
        nodes: vec![SceneNode::new("left", &mesh), right],
    };
    let img = render(&two, &opts).unwrap();
    let r = coverage(&img, opts.background, reddish);
    let b = coverage(&img, opts.background, bluish);
    assert!(r.mean.0 < 40.0 && b.mean.0 > 56.0);
}

#[test]
fn same_input_same_bytes_and_renderer_reuse() {
    let mesh = tree(2, 6, 2);
    let opts = RenderOptions {
        width: 100,
        height: 80,
        ..RenderOptions::default()
    };
    let a = render(&scene(&mesh), &opts).unwrap();
    let mut r = Renderer::new();
    r.render(&scene(&markers()), &RenderOptions::default())
        .unwrap();
    let b = r.render(&scene(&mesh), &opts).unwrap();
    assert_eq!(a, b);
    assert_eq!(encode_png(&a).unwrap(), encode_png(&b).unwrap());
    assert!(
        format!("{r:?}").len() < 200,
        "Debug shows sizes, not samples"
    );
}

#[test]
fn ground_hides_roots_and_receives_shadow() {
    // A box standing on the ground and one buried under it, seen from above.
    let mut mesh = Mesh {
        materials: vec![
            material(MaterialKind::Bark, RED),
            material(MaterialKind::Root, BLUE),
        ],
        ..Mesh::default()
    };
    add_box(
        &mut mesh,
        0,
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.2, 1.0, 0.2),
    );
    add_box(&mut mesh, 1, Vec3::new(0.4, -0.3, 0.0), Vec3::splat(0.15));
    let opts = RenderOptions {
        width: 96,
        height: 96,
        view: View::Top,
        supersample: 1,
        ..RenderOptions::default()
    };
    let img = render(&scene(&mesh), &opts).unwrap();
    assert!(coverage(&img, opts.background, reddish).count > 50);
    assert_eq!(coverage(&img, opts.background, bluish).count, 0);
    let bare = RenderOptions {
        ground: false,
        ..opts.clone()
    };
    let img = render(&scene(&mesh), &bare).unwrap();
    assert!(coverage(&img, opts.background, bluish).count > 0);
    // Shadows darken some of the ground.
    let dark = |o: &RenderOptions| {
        let img = render(&scene(&mesh), o).unwrap();
        img.pixels()
            .filter(|p| p.0[0] < 150 && p.0[1] < 150 && p.0[2] < 150)
            .count()
    };
    let unshadowed = RenderOptions {
        shadows: false,
        ..opts.clone()
    };
    assert!(dark(&opts) > dark(&unshadowed) + 20);
}

#[test]
fn views_parse_and_print() {
    for v in View::ALL {
        assert_eq!(v.to_string().parse::<View>().unwrap(), v);
    }
    assert_eq!(" ISO ".parse::<View>().unwrap(), View::Iso);
    let err = "back".parse::<View>().unwrap_err();
    assert!(matches!(err, RenderError::UnknownView(ref s) if s == "back"));
    let msg = err.to_string();
    for v in View::ALL {
        assert!(msg.contains(v.name()), "{msg}");
    }
    assert_eq!(View::default(), View::Iso);
}

#[test]
fn png_round_trip_and_atomic_write() {
    let img = render(&scene(&markers()), &plain(View::Iso)).unwrap();
    let png = encode_png(&img).unwrap();
    let back = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(back, img);
    let dir = std::env::temp_dir().join(format!("sylva-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("markers.png");
    write_png(&path, &img).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), png);
    let err = write_png(&dir.join("missing/x.png"), &img).unwrap_err();
    assert!(matches!(err, RenderError::Io { .. }));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn contact_sheet_layout_and_captions() {
    let meshes = [markers(), tree(2, 6, 2), markers()];
    let mut cells: Vec<SheetCell> = (0..5)
        .map(|i| SheetCell {
            scene: scene(&meshes[i % 3]),
            caption: format!("#{i}  fit {:.2}", i as f32 * 1.37),
        })
        .collect();
    cells[4].caption = "a caption much too long for a small cell, with é".into();
    let opts = SheetOptions {
        cell_width: 80,
        cell_height: 100,
        view: View::Front,
        title: Some("generation 7".into()),
        ..SheetOptions::default()
    };
    let sheet = contact_sheet(&cells, &opts, &sylva_core::par::Pool::Serial).unwrap();
    let title = 28;
    assert_eq!(sheet.dimensions(), (3 * 80, title + 2 * 100));
    let dark = |x0: u32, y0: u32, w: u32, h: u32| {
        (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .filter(|&(x, y)| sheet.get_pixel(x, y).0.iter().all(|&c| c < 80))
            .count()
    };
    assert!(dark(0, 0, 240, title) > 50, "title");
    for k in 0..5u32 {
        let (x0, y0) = ((k % 3) * 80, title + (k / 3) * 100);
        let strip = y0 + 100 - CAPTION_HEIGHT;
        assert!(dark(x0 + 1, strip, 79, CAPTION_HEIGHT) > 30, "caption {k}");
        // Each picture is exactly the cell rendered alone (parallel = serial).
        let alone = render(
            &cells[k as usize].scene,
            &RenderOptions {
                width: 80,
                height: 100 - CAPTION_HEIGHT,
                view: View::Front,
                ..RenderOptions::default()
            },
        )
        .unwrap();
        for (x, y, p) in alone.enumerate_pixels() {
            if x > 0 && y > 0 {
                assert_eq!(sheet.get_pixel(x0 + x, y0 + y), p, "cell {k} at {x},{y}");
            }
        }
    }
    // The empty sixth slot stays blank paper.
    assert_eq!(dark(160, title + 100, 80, 100), 0);

    let explicit = SheetOptions {
        columns: 5,
        title: None,
        ..opts.clone()
    };
    assert_eq!(
        contact_sheet(&cells, &explicit, &sylva_core::par::Pool::Serial)
            .unwrap()
            .dimensions(),
        (400, 100)
    );
    let too_many_columns = SheetOptions {
        columns: 50,
        ..explicit.clone()
    };
    assert_eq!(
        contact_sheet(&cells, &too_many_columns, &sylva_core::par::Pool::Serial)
            .unwrap()
            .dimensions(),
        (400, 100)
    );
}

#[test]
fn contact_sheet_errors() {
    let cells = [SheetCell {
        scene: Scene::default(),
        caption: String::new(),
    }];
    assert!(matches!(
        contact_sheet(
            &[],
            &SheetOptions::default(),
            &sylva_core::par::Pool::Serial
        ),
        Err(RenderError::EmptySheet)
    ));
    for (w, h) in [(8, 100), (100, 20), (9000, 100), (100, 9000)] {
        let opts = SheetOptions {
            cell_width: w,
            cell_height: h,
            ..SheetOptions::default()
        };
        assert!(matches!(
            contact_sheet(&cells, &opts, &sylva_core::par::Pool::Serial),
            Err(RenderError::InvalidCell { .. })
        ));
    }
    let many: Vec<SheetCell> = (0..2000)
        .map(|_| SheetCell {
            scene: Scene::default(),
            caption: String::new(),
        })
        .collect();
    let big = SheetOptions {
        cell_width: 8000,
        cell_height: 8000,
        ..SheetOptions::default()
    };
    assert!(matches!(
        contact_sheet(&many, &big, &sylva_core::par::Pool::Serial),
        Err(RenderError::SheetTooLarge { .. })
    ));
}

/// Renders a procedural tree in every view to the temp directory (`render-<view>.png`)
/// and the contact sheet to `render-sheet.png`, for people to look at.
#[test]
fn tree_pictures() {
    let mesh = tree(4, 10, 3);
    let dir = std::env::temp_dir();
    for view in View::ALL {
        let opts = RenderOptions {
            view,
            width: 480,
            height: 480,
            ..RenderOptions::default()
        };
        let img = render(&scene(&mesh), &opts).unwrap();
        write_png(&dir.join(format!("render-{view}.png")), &img).unwrap();
        let c = coverage(&img, opts.background, |_| true);
        assert!(c.count > 480 * 480 / 10, "{view}: {}", c.count);
    }
    let small = tree(2, 8, 3);
    let cells: Vec<SheetCell> = (0..6)
        .map(|i| SheetCell {
            scene: scene(if i % 2 == 0 { &mesh } else { &small }),
            caption: format!("#{i}  fit {:.2}", 3.41 - i as f32 * 0.25),
        })
        .collect();
    let opts = SheetOptions {
        title: Some("Sylva contact sheet".into()),
        ..SheetOptions::default()
    };
    let sheet = contact_sheet(&cells, &opts, &sylva_core::par::Pool::Serial).unwrap();
    write_png(&dir.join("render-sheet.png"), &sheet).unwrap();
}

/// Two upright quads side by side facing the camera, both of one colour: the left one
/// untextured, the right one showing texture `id` once across.
fn textured_pair(id: u16) -> Mesh {
    let mut mesh = Mesh {
        materials: vec![
            material(MaterialKind::Bark, [0.6, 0.6, 0.6]),
            sylva_core::Material {
                texture: Some(id),
                ..material(MaterialKind::Bark, [0.6, 0.6, 0.6])
            },
        ],
        ..Mesh::default()
    };
    add_quad(&mut mesh, 0, Vec3::new(-1.1, 0.0, 0.0), Vec3::X, Vec3::Y);
    add_quad(&mut mesh, 1, Vec3::new(1.1, 0.0, 0.0), Vec3::X, Vec3::Y);
    // add_quad's corners run (-u-v, +u-v, +u+v, -u+v); v points down the picture.
    let corners = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    mesh.uvs = corners.iter().chain(&corners).copied().collect();
    mesh
}

/// Distinct grey levels (red channel) and their spread over the pixels of columns `xs`,
/// rows `ys`.
fn variety(img: &RgbImage, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> (usize, u8) {
    let mut seen = std::collections::BTreeSet::new();
    for y in ys {
        for x in xs.clone() {
            seen.insert(img.get_pixel(x, y)[0]);
        }
    }
    let spread = seen.last().copied().unwrap_or(0) - seen.first().copied().unwrap_or(0);
    (seen.len(), spread)
}

#[test]
fn textures_show_on_textured_materials_only() {
    let opts = RenderOptions {
        width: 200,
        height: 100,
        ..plain(View::Front)
    };
    for id in [0, 3, 8] {
        let mesh = textured_pair(id);
        let img = render(&scene(&mesh), &opts).unwrap();
        // Inside each quad, away from its edges.
        let (flat, _) = variety(&img, 30..80, 35..65);
        let (textured, spread) = variety(&img, 120..170, 35..65);
        assert_eq!(flat, 1, "an untextured flat quad is one colour");
        assert!(
            textured > 20 && spread > 40,
            "texture {id}: {textured} levels, spread {spread}"
        );
    }
}

#[test]
fn untextured_pictures_ignore_texture_coordinates() {
    // Texture coordinates alone change nothing: only a material's texture id does.
    let mut with_uvs = textured_pair(0);
    with_uvs.materials[1].texture = None;
    let mut without = with_uvs.clone();
    without.uvs.clear();
    let opts = RenderOptions::default();
    assert_eq!(
        render(&scene(&with_uvs), &opts).unwrap(),
        render(&scene(&without), &opts).unwrap()
    );
}

#[test]
fn textures_are_made_once_per_renderer() {
    let mesh = textured_pair(5);
    let mut r = Renderer::new();
    let opts = plain(View::Front);
    let first = r.render(&scene(&mesh), &opts).unwrap();
    assert_eq!(r.textures.len(), 1);
    assert_eq!(r.render(&scene(&mesh), &opts).unwrap(), first);
    assert_eq!(r.textures.len(), 1);
    assert_eq!(
        render(&scene(&mesh), &opts).unwrap(),
        first,
        "a fresh renderer agrees"
    );
}

/// A one-sided upright card facing +Z (or away, `-Z`) showing the first spray cell of a
/// leaf kind's atlas, cut out by its alpha.
fn card(facing_away: bool) -> Mesh {
    use sylva_core::species::{Card, LeafKind, Surface};
    let mut mesh = Mesh {
        materials: vec![sylva_core::Material {
            surface: Some(Surface::Leaves(LeafKind::Maple)),
            ..material(MaterialKind::Leaf, [0.1, 0.5, 0.1])
        }],
        ..Mesh::default()
    };
    let u = if facing_away { -Vec3::X } else { Vec3::X };
    add_quad(&mut mesh, 0, Vec3::ZERO, u, Vec3::Y);
    let cell = sylva_mesh::atlas::card_uvs(Card::Spray, 0);
    mesh.uvs = if facing_away {
        vec![cell[1], cell[0], cell[3], cell[2]]
    } else {
        cell.to_vec()
    };
    mesh
}

#[test]
fn cut_out_cards_show_their_shape_from_both_sides_and_cast_it() {
    let opts = plain(View::Front);
    let mut solid = card(false);
    solid.materials[0].surface = None;
    let full = coverage(
        &render(&scene(&solid), &opts).unwrap(),
        opts.background,
        greenish,
    );
    let front = coverage(
        &render(&scene(&card(false)), &opts).unwrap(),
        opts.background,
        greenish,
    );
    let back = coverage(
        &render(&scene(&card(true)), &opts).unwrap(),
        opts.background,
        greenish,
    );
    // The leaf's outline is cut out of the square: far less than the square, but a good
    // part of it; the back of a one-sided card is drawn too (a plain quad's is culled).
    assert!(
        front.count * 10 < full.count * 8,
        "{} of {}",
        front.count,
        full.count
    );
    assert!(
        front.count * 10 > full.count,
        "{} of {}",
        front.count,
        full.count
    );
    assert_eq!(front.count, back.count);
    // Its shadow on the ground is its shape, not a square.
    let lit = RenderOptions {
        ground: true,
        shadows: true,
        ..plain(View::Iso)
    };
    let with = render(&scene(&card(false)), &lit).unwrap();
    let without = render(
        &scene(&card(false)),
        &RenderOptions {
            shadows: false,
            ..lit.clone()
        },
    )
    .unwrap();
    assert_ne!(with, without, "the card casts a shadow");
}

/// A cut-out's edges are its frame: a red square filling the left half of the frame fills
/// the left half of the picture, opaque, and leaves the right half clear.
#[test]
fn cut_outs_are_framed_exactly_on_a_clear_background() {
    let mut mesh = empty(RED);
    add_quad(
        &mut mesh,
        0,
        Vec3::new(0.5, 1.0, 0.0),
        Vec3::X * 0.5,
        Vec3::Y * 1.0,
    );
    let frame = Frame {
        left: 0.0,
        right: 2.0,
        bottom: 0.0,
        top: 2.0,
    };
    let picture = Renderer::new()
        .cut_out(&scene(&mesh), View::Front, frame, (64, 64), 2)
        .unwrap();
    for (x, _, p) in picture.enumerate_pixels() {
        match x {
            0..=30 => assert!(
                p.0[3] == 255 && reddish([p.0[0], p.0[1], p.0[2]]),
                "{x}: {p:?}"
            ),
            33.. => assert_eq!(p.0[3], 0, "{x}"),
            _ => {}
        }
    }
}

/// An impostor's crossed cards, seen from the front and the side, show the markers where
/// the plant has them, for a plant wider than tall (views one above the other in the
/// picture) and one taller than wide (side by side); the cards hold the plant.
#[test]
fn impostor_cards_show_the_plant_as_it_stands() {
    for tall in [false, true] {
        let mut plant = markers();
        if tall {
            add_box(&mut plant, 0, Vec3::Y * 3.0, Vec3::new(0.3, 2.0, 0.3));
        }
        let cards = impostor::impostor(&scene(&plant)).unwrap().unwrap();
        assert_eq!((cards.positions.len(), cards.triangle_count()), (8, 4));
        let (p, c) = (scene(&plant).bounds(), scene(&cards).bounds());
        assert!(
            c.min.cmple(p.min).all() && c.max.cmpge(p.max).all(),
            "{c:?} holds {p:?}"
        );
        assert_eq!(c.min.y, p.min.y, "the cards stand where the plant does");
        let (u, v) = cards.uvs[..4]
            .iter()
            .fold((0f32, 0f32), |(u, v), t| (u.max(t[0]), v.max(t[1])));
        assert_eq!((u, v), if tall { (0.5, 1.0) } else { (1.0, 0.5) });

        let png = cards.impostor.as_deref().unwrap();
        let picture = image::load_from_memory(png).unwrap().to_rgba8();
        assert_eq!(picture.dimensions(), (512, 512));
        let clear = picture.pixels().filter(|p| p.0[3] == 0).count();
        assert!(clear > 512 * 512 / 2 && clear < 512 * 512, "{clear} clear");

        for view in [View::Front, View::Side] {
            let opts = plain(view);
            let seen = render(&scene(&cards), &opts).unwrap();
            let red = coverage(&seen, opts.background, reddish);
            let green = coverage(&seen, opts.background, greenish);
            assert!(red.count > 20 && green.count > 20, "{view}, tall {tall}");
            match view {
                View::Front => assert!(red.mean.0 > 55.0, "+X on the right"),
                _ => assert!(green.mean.0 + 10.0 < red.mean.0, "+Z on the left"),
            }
        }
        let again = impostor::impostor(&scene(&plant)).unwrap().unwrap();
        assert_eq!(
            again.impostor, cards.impostor,
            "the same picture, byte for byte"
        );
    }
    assert!(impostor::impostor(&scene(&empty(RED))).unwrap().is_none());
}
