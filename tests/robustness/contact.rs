//! Contact shadows: the spawn offset is small enough for resting objects.

use super::*;

// ------------------------------------------------------------------------------------------
// Contact shadows
// ------------------------------------------------------------------------------------------

/// A sphere of radius r resting on a support whose top surface is the plane y = 0 at the
/// contact point c: from the support's surface a distance ε from c, a shadow ray towards a
/// light straight above c must hit the sphere, whose underside is only ≈ ε²/2r above the
/// surface there. An offset larger than that gap would light the contact region.
#[test]
fn contact_shadows_reach_the_resting_sphere() {
    let mut worst_gap_over_offset = f64::INFINITY;
    for scale in [1e-3, 1e-1, 1.0, 1e2, 1e4] {
        // Off the origin, so the offset (relative to the point's magnitude) is not trivially
        // small.
        let c = DVec3::new(3.0, 0.0, -2.0) * scale;
        let r = scale;
        let sphere = Primitive::new(
            &Geometry::Sphere {
                center: c + DVec3::Y * r,
                radius: r,
            },
            &Transform::IDENTITY,
            0,
        )
        .unwrap();
        let plane = Primitive::new(
            &Geometry::Plane {
                point: c,
                normal: DVec3::Y,
            },
            &Transform::IDENTITY,
            0,
        )
        .unwrap();
        let flat_box = Primitive::new(
            &Geometry::Box {
                p1: c + DVec3::new(-2.0, -1.0, -2.0) * r,
                p2: c + DVec3::new(2.0, 0.0, 2.0) * r,
            },
            &Transform::IDENTITY,
            0,
        )
        .unwrap();
        // The same box rotated about the vertical through c: kept in object space, so the
        // matrix round trip is part of the test.
        let about_c = Transform::translate(c)
            .then_after(&Transform::rotate(30.0, DVec3::Y).unwrap())
            .then_after(&Transform::translate(-c));
        let turned_box = Primitive::new(
            &Geometry::Box {
                p1: c + DVec3::new(-2.0, -1.0, -2.0) * r,
                p2: c + DVec3::new(2.0, 0.0, 2.0) * r,
            },
            &about_c,
            0,
        )
        .unwrap();
        let light = c + DVec3::Y * (100.0 * r);
        for (name, support) in [
            ("plane", &plane),
            ("box", &flat_box),
            ("rotated box", &turned_box),
        ] {
            for eps in [0.02, 0.05, 0.1, 0.3] {
                for k in 0..8 {
                    let phi = k as f64 * TAU / 8.0 + 0.1;
                    let q = c + DVec3::new(phi.cos(), 0.0, phi.sin()) * (eps * r);
                    // The surface point as the renderer would find it: a camera-like ray
                    // from below (the plane is two-sided; the box is entered from inside).
                    let from = q - DVec3::Y * (0.5 * r) + DVec3::new(0.1, 0.0, 0.05) * r;
                    let hit = support
                        .intersect(&world_ray(from, q - from), f32::INFINITY)
                        .unwrap_or_else(|| panic!("{name} at scale {scale}: no surface point"));
                    assert!(
                        hit.normal.y > 0.99,
                        "{name}: top face normal {:?}",
                        hit.normal
                    );
                    let to_light = v32(light) - hit.point;
                    let shadow = hit.spawn_ray(to_light);
                    assert!(
                        support.intersect(&shadow, 1.0).is_none(),
                        "{name} at scale {scale}: the shadow ray hit its own surface"
                    );
                    let blocker = sphere.intersect(&shadow, 1.0);
                    assert!(
                        blocker.is_some(),
                        "{name} at scale {scale}, ε = {eps}·r, φ = {phi:.2}: the shadow ray \
                         from {:?} (offset to {:?}) misses the sphere resting 1 − √(1 − ε²) = \
                         {:.2e}·r above it",
                        hit.point,
                        shadow.origin,
                        1.0 - (1.0 - eps * eps).sqrt()
                    );
                    let gap = r * (1.0 - (1.0 - eps * eps).sqrt());
                    let offset = (shadow.origin - hit.point).length() as f64;
                    worst_gap_over_offset = worst_gap_over_offset.min(gap / offset);
                }
            }
        }
    }
    eprintln!(
        "contact: smallest (sphere gap above the surface) / (spawn offset) = {worst_gap_over_offset:.1}"
    );
}
