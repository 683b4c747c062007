//! Hand-made meshes for the renderer's tests: boxes, quads, tubes and a small tree.
//!
//! These build [`Mesh`]es directly (the real mesher lives elsewhere), so the renderer is
//! tested on its own.

use sylva_core::{
    Material, MaterialKind,
    glam::{Quat, Vec3},
};
use sylva_mesh::mesh::{Mesh, Primitive};

/// A material of a given linear colour.
pub fn material(kind: MaterialKind, color: [f32; 3]) -> Material {
    Material {
        color,
        ..Material::of_kind(kind)
    }
}

/// Appends a vertex and returns its index.
fn vertex(mesh: &mut Mesh, p: Vec3, n: Vec3) -> u32 {
    mesh.positions.push(p.to_array());
    mesh.normals.push(n.to_array());
    (mesh.positions.len() - 1) as u32
}

/// The primitive of material `m`, created if missing.
fn prim(mesh: &mut Mesh, m: usize) -> &mut Vec<u32> {
    let k = match mesh.primitives.iter().position(|p| p.material == m) {
        Some(k) => k,
        None => {
            mesh.primitives.push(Primitive {
                material: m,
                indices: Vec::new(),
            });
            mesh.primitives.len() - 1
        }
    };
    &mut mesh.primitives[k].indices
}

/// A mesh with one material and nothing else.
pub fn empty(color: [f32; 3]) -> Mesh {
    Mesh {
        materials: vec![material(MaterialKind::Bark, color)],
        ..Mesh::default()
    }
}

/// A flat quad facing `normal` (counter-clockwise seen from that side), centred at `c`,
/// spanning `u` and `v` (half extents) with `u x v` along `normal`.
pub fn add_quad(mesh: &mut Mesh, m: usize, c: Vec3, u: Vec3, v: Vec3) {
    let n = u.cross(v).normalize();
    let i: Vec<u32> = [c - u - v, c + u - v, c + u + v, c - u + v]
        .into_iter()
        .map(|p| vertex(mesh, p, n))
        .collect();
    prim(mesh, m).extend([i[0], i[1], i[2], i[0], i[2], i[3]]);
}

/// An axis-aligned box with outward faces.
pub fn add_box(mesh: &mut Mesh, m: usize, c: Vec3, half: Vec3) {
    let (x, y, z) = (Vec3::X * half.x, Vec3::Y * half.y, Vec3::Z * half.z);
    add_quad(mesh, m, c + z, x, y);
    add_quad(mesh, m, c - z, -x, y);
    add_quad(mesh, m, c + x, -z, y);
    add_quad(mesh, m, c - x, z, y);
    add_quad(mesh, m, c + y, x, -z);
    add_quad(mesh, m, c - y, x, z);
}

/// A closed tapered tube from `a` (radius `ra`) to `b` (radius `rb`) with `sides` sides.
pub fn add_tube(mesh: &mut Mesh, m: usize, a: Vec3, b: Vec3, ra: f32, rb: f32, sides: u32) {
    let d = (b - a).normalize();
    let any = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let u = d.cross(any).normalize();
    let v = d.cross(u);
    let dir = |i: u32| {
        let t = i as f32 * std::f32::consts::TAU / sides as f32;
        u * t.cos() + v * t.sin()
    };
    // The normal leans along the axis by the taper, so shading matches the cone.
    let slope = (ra - rb) / (b - a).length();
    let base = mesh.positions.len() as u32;
    for i in 0..sides {
        let n = (dir(i) + d * slope).normalize();
        vertex(mesh, a + dir(i) * ra, n);
        vertex(mesh, b + dir(i) * rb, n);
    }
    let ca = vertex(mesh, a, -d);
    let cb = vertex(mesh, b, d);
    let cap = mesh.positions.len() as u32;
    for i in 0..sides {
        vertex(mesh, a + dir(i) * ra, -d);
        vertex(mesh, b + dir(i) * rb, d);
    }
    let idx = prim(mesh, m);
    for i in 0..sides {
        let j = (i + 1) % sides;
        let (a0, b0, a1, b1) = (
            base + 2 * i,
            base + 2 * i + 1,
            base + 2 * j,
            base + 2 * j + 1,
        );
        idx.extend([a0, a1, b1, a0, b1, b0]);
        idx.extend([ca, cap + 2 * j, cap + 2 * i]);
        idx.extend([cb, cap + 2 * i + 1, cap + 2 * j + 1]);
    }
}

/// A leaf: a double-sided diamond from `base` along `dir`, opening towards `side`.
pub fn add_leaf(mesh: &mut Mesh, m: usize, base: Vec3, dir: Vec3, side: Vec3, len: f32) {
    let n = dir.cross(side).normalize();
    let side = n.cross(dir).normalize();
    let pts = [
        base,
        base + dir * (0.45 * len) + side * (0.22 * len),
        base + dir * len,
        base + dir * (0.45 * len) - side * (0.22 * len),
    ];
    // (p1 - p0) x (p2 - p0) points along -n, so 0-1-2 is the -n face.
    for (normal, order) in [(-n, [0usize, 1, 2, 0, 2, 3]), (n, [0, 2, 1, 0, 3, 2])] {
        let i: Vec<u32> = pts.iter().map(|&p| vertex(mesh, p, normal)).collect();
        prim(mesh, m).extend(order.map(|k| i[k]));
    }
}

/// A small tree: a trunk that forks `depth` times into three tapered branches each
/// (golden-angle phyllotaxis), leaves at the tips and two roots below ground.
pub fn tree(depth: u32, sides: u32, leaves_per_tip: u32) -> Mesh {
    let mut mesh = Mesh {
        materials: vec![
            Material::of_kind(MaterialKind::Bark),
            Material::of_kind(MaterialKind::Leaf),
            Material::of_kind(MaterialKind::Root),
        ],
        ..Mesh::default()
    };
    branch(
        &mut mesh,
        Vec3::ZERO,
        Vec3::Y,
        2.2,
        0.22,
        depth,
        sides,
        leaves_per_tip,
        0,
    );
    for (k, d) in [Vec3::new(0.8, -0.6, 0.3), Vec3::new(-0.5, -0.7, -0.6)]
        .into_iter()
        .enumerate()
    {
        let d = d.normalize();
        let mid = d * 0.9;
        add_tube(&mut mesh, 2, Vec3::Y * 0.05, mid, 0.12, 0.07, sides);
        let d2 = (d + Vec3::new(0.3 * k as f32, -0.5, 0.2)).normalize();
        add_tube(&mut mesh, 2, mid, mid + d2 * 0.7, 0.07, 0.02, sides);
    }
    mesh
}

#[allow(clippy::too_many_arguments)]
fn branch(
    mesh: &mut Mesh,
    a: Vec3,
    d: Vec3,
    len: f32,
    r: f32,
    depth: u32,
    sides: u32,
    leaves: u32,
    serial: u32,
) {
    let b = a + d * len;
    let rb = r * 0.68;
    add_tube(mesh, 0, a, b, r, rb, sides);
    if depth == 0 {
        let any = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        let side = d.cross(any).normalize();
        for k in 0..leaves {
            let q = Quat::from_axis_angle(d, k as f32 * 2.4 + serial as f32);
            let out = q * side;
            let dir = (out + d * 0.6 + Vec3::Y * 0.2).normalize();
            add_leaf(
                mesh,
                1,
                b - d * (0.1 * k as f32 * len),
                dir,
                d.cross(out),
                0.45,
            );
        }
        return;
    }
    let any = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let side = d.cross(any).normalize();
    for k in 0..3 {
        let spin = Quat::from_axis_angle(d, 2.4 * (k + serial) as f32);
        let tilt = Quat::from_axis_angle(spin * side, 0.55 + 0.1 * k as f32);
        // Branches bend slightly upwards, like a real crown.
        let nd = (tilt * d + Vec3::Y * 0.15).normalize();
        let nl = len * (0.72 - 0.05 * k as f32);
        branch(
            mesh,
            b,
            nd,
            nl,
            rb,
            depth - 1,
            sides,
            leaves,
            serial * 3 + k + 1,
        );
    }
}
