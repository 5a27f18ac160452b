//! Entities on one surface: a CAD face is a patch of its surface, and a modeller may write
//! one surface once per face (a hub's cone split into a dozen faces, each with a patch over
//! its own extent or its seam turned; the fillet faces round one torus). Mesh edges between
//! such faces are on one surface, not where two surfaces meet.

use std::collections::BTreeMap;

use crate::groups::Groups;
use crate::model::{EntityGeometry, GeometricEntity};
use crate::shapes::AnalyticShape;
use crate::vec3::norm;

/// Relative distance within which two shapes are one (as the STEP converter's round-off).
const SAME: f64 = 1e-9;

/// For each entity, the surface entities on the same surface (itself included, ascending;
/// none for a curve): the same B-spline, or the same closed form — each one's patch holds
/// 3 × 3 samples of the other's within 1e-9 (relative), both ways.
pub(crate) fn same_surfaces(entities: &[GeometricEntity]) -> Vec<Vec<usize>> {
    let n = entities.len();
    let mut groups = Groups::new(n);
    let surface = |k: usize| match &entities[k].geometry {
        EntityGeometry::Surface(s) => Some(s),
        EntityGeometry::Curve(_) => None,
    };
    // The same B-spline: grouped by a cheap key first (the net's size and corners), then
    // compared in full.
    let mut by_net: BTreeMap<(usize, [u64; 6]), Vec<usize>> = BTreeMap::new();
    for k in 0..n {
        let Some(s) = surface(k) else { continue };
        let (Some(a), Some(b)) = (s.control_points.first(), s.control_points.last()) else {
            continue;
        };
        let key = (
            s.control_points.len(),
            [a[0], a[1], a[2], b[0], b[1], b[2]].map(f64::to_bits),
        );
        let bucket = by_net.entry(key).or_default();
        if let Some(&j) = bucket
            .iter()
            .find(|&&j| entities[j].geometry == entities[k].geometry)
        {
            groups.join(j, k);
        } else {
            bucket.push(k);
        }
    }
    // The same closed form: each one's samples on the other's shape, among shapes of one
    // kind whose sizes agree (sorted by size, so only neighbours are compared).
    let mut analytic: Vec<(u8, f64, usize)> = (0..n)
        .filter(|&k| surface(k).is_some())
        .filter_map(|k| {
            let (kind, size) = match entities[k].analytic? {
                AnalyticShape::Sphere { radius, .. } => (0, radius),
                AnalyticShape::Cylinder { radius, .. } => (1, radius),
                AnalyticShape::Cone { half_angle, .. } => (2, half_angle),
                AnalyticShape::Torus { major_radius, .. } => (3, major_radius),
                AnalyticShape::Circle { .. } => return None,
            };
            Some((kind, size, k))
        })
        .collect();
    analytic.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    let on_shape_of = |k: usize, other: usize| -> bool {
        let (Some(s), Some(shape)) = (surface(k), entities[other].analytic.as_ref()) else {
            return false;
        };
        let ((u0, u1), (v0, v1)) = s.domain();
        (0..3).all(|i| {
            (0..3).all(|j| {
                let x = s.point(
                    u0 + (u1 - u0) * i as f64 / 2.0,
                    v0 + (v1 - v0) * j as f64 / 2.0,
                );
                shape.closest_point(x).distance <= SAME * (1.0 + norm(x))
            })
        })
    };
    for (i, &(kind, size, k)) in analytic.iter().enumerate() {
        for &(other_kind, other_size, other) in &analytic[i + 1..] {
            if other_kind != kind || other_size - size > SAME * (1.0 + size.abs()) {
                break;
            }
            if on_shape_of(k, other) && on_shape_of(other, k) {
                groups.join(k, other);
            }
        }
    }
    let mut twins = vec![Vec::new(); n];
    for group in groups.of(|k| surface(k).is_some()) {
        for &k in &group {
            twins[k] = group.clone();
        }
    }
    twins
}

#[cfg(test)]
#[path = "tests/surface_groups.rs"]
mod tests;
