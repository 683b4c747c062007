//! Guides drawn beside a plant in pictures: a fitness's target surface as a wire frame, and
//! its forbidden grid cells as red outlines ([`of`]). They are built as plants of thin
//! segments, so the ordinary mesher and renderer draw them; they never go into exported
//! assets.

use std::f32::consts::TAU;

use sylva_core::glam::Vec3;
use sylva_core::{Material, MaterialId, MaterialKind, Plant, PlantError, PlantMeta};

use super::{PoncinFitness, TargetShape};

/// The target surface and the forbidden grid cells of `fitness`, as wire frames in metres.
pub fn of(fitness: &PoncinFitness) -> Option<Plant> {
    let unit = fitness.unit as f32;
    let (mut plant, surface) = guide_plant([0.35, 0.42, 0.55]).ok()?;
    let wire = 0.4 * unit;
    match fitness.target {
        TargetShape::Sphere { center, radius } => ellipsoid_wire(
            &mut plant,
            center.as_vec3() * unit,
            Vec3::splat(radius as f32 * unit),
            wire,
            surface,
        ),
        TargetShape::Ellipsoid { center, radii } => ellipsoid_wire(
            &mut plant,
            center.as_vec3() * unit,
            radii.as_vec3() * unit,
            wire,
            surface,
        ),
        TargetShape::Box { center, size } => box_wire(
            &mut plant,
            (center - size * 0.5).as_vec3() * unit,
            (center + size * 0.5).as_vec3() * unit,
            wire,
            surface,
        ),
        _ => Ok(()),
    }
    .ok()?;
    if let Some(grid) = &fitness.grid {
        let forbidden = plant
            .add_material(Material {
                name: "forbidden".into(),
                kind: MaterialKind::Bark,
                color: [0.8, 0.08, 0.05],
                texture: None,
                surface: None,
            })
            .ok()?;
        for i in 0..grid.len() {
            if grid.weight(i) < 0.0 {
                let (lo, hi) = grid.cell_bounds(i);
                box_wire(
                    &mut plant,
                    lo.as_vec3() * unit,
                    hi.as_vec3() * unit,
                    wire,
                    forbidden,
                )
                .ok()?;
            }
        }
    }
    Some(plant)
}

/// A plant to hold guide wires, with one material of the given colour.
pub fn guide_plant(color: [f32; 3]) -> Result<(Plant, MaterialId), PlantError> {
    let mut plant = Plant::new(PlantMeta {
        model: "guide".into(),
        ..PlantMeta::default()
    });
    let material = plant.add_material(Material {
        name: "guide".into(),
        kind: MaterialKind::Bark,
        color,
        texture: None,
        surface: None,
    })?;
    Ok((plant, material))
}

/// Adds a closed polyline as one axis of segments.
fn polyline(
    plant: &mut Plant,
    points: &[Vec3],
    radius: f32,
    material: MaterialId,
) -> Result<(), PlantError> {
    let mut parent = None;
    for pair in points.windows(2) {
        parent =
            Some(plant.add_segment(pair[0], pair[1], (radius, radius), parent, false, material)?);
    }
    Ok(())
}

/// An ellipsoid (a sphere when the radii are equal) as 6 meridians and 5 parallels.
pub fn ellipsoid_wire(
    plant: &mut Plant,
    center: Vec3,
    radii: Vec3,
    wire: f32,
    material: MaterialId,
) -> Result<(), PlantError> {
    const STEPS: usize = 48;
    let point = |lat: f32, lon: f32| {
        center + radii * Vec3::new(lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin())
    };
    for m in 0..6 {
        let lon = m as f32 * TAU / 12.0;
        let pts: Vec<Vec3> = (0..=STEPS)
            .map(|i| point(i as f32 * TAU / STEPS as f32, lon))
            .collect();
        polyline(plant, &pts, wire, material)?;
    }
    for p in 1..=5 {
        let lat = (p as f32 / 6.0 - 0.5) * std::f32::consts::PI;
        let pts: Vec<Vec3> = (0..=STEPS)
            .map(|i| point(lat, i as f32 * TAU / STEPS as f32))
            .collect();
        polyline(plant, &pts, wire, material)?;
    }
    Ok(())
}

/// The 12 edges of an axis-aligned box.
pub fn box_wire(
    plant: &mut Plant,
    min: Vec3,
    max: Vec3,
    wire: f32,
    material: MaterialId,
) -> Result<(), PlantError> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    for a in 0..8 {
        for bit in [1, 2, 4] {
            if a & bit == 0 {
                polyline(plant, &[corner(a), corner(a | bit)], wire, material)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wires_have_the_expected_segments() {
        let (mut p, m) = guide_plant([0.5; 3]).unwrap();
        box_wire(&mut p, Vec3::ZERO, Vec3::ONE, 0.01, m).unwrap();
        assert_eq!(p.segments().len(), 12);
        let (mut p, m) = guide_plant([0.5; 3]).unwrap();
        ellipsoid_wire(&mut p, Vec3::Y * 2.0, Vec3::splat(1.5), 0.01, m).unwrap();
        assert_eq!(p.segments().len(), 11 * 48);
        for s in p.segments() {
            let d = (s.start - Vec3::Y * 2.0).length();
            assert!((d - 1.5).abs() < 1e-4);
        }
    }
}
