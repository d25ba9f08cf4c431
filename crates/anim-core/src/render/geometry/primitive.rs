//! A shape placed in the world: either baked into world space (no matrix work per ray) or
//! kept in object space with its transform.

use crate::math::{
    gamma, relative_offset, spawn_origin_lifted, Aabb, Lift, Ray, Transform, UNIT_ROUNDOFF,
};
pub use crate::shape::Degenerate;
use crate::shape::{AaBox, Geometry, NearFaces, Shape, ShapeHit, Sphere};
use glam::{Affine3A, DVec3, Mat3A, Vec3A};

/// The kept hit of a closest-hit query, in world space.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Distance along the ray (world units).
    pub t: f32,
    /// The hit point, in world space.
    pub point: Vec3A,
    /// Unit geometric normal, outward for closed shapes (not flipped towards the ray).
    pub normal: Vec3A,
    /// How rays spawned from here leave the surface: outwards along the normal, inwards
    /// into every face around the point, by at least this hit's own error bound (see
    /// `Primitive::surface`).
    pub lift: Lift,
}

impl SurfaceHit {
    /// A hit on one face computed in world space, whose error the relative spawn bound covers.
    #[inline]
    pub fn on_face(t: f32, point: Vec3A, normal: Vec3A) -> SurfaceHit {
        SurfaceHit {
            t,
            point,
            normal,
            lift: Lift::normal(normal),
        }
    }

    /// Origin of a ray leaving this hit towards `dir`: on the side of the surface `dir`
    /// points into, clear of it by more than the hit's error bound.
    #[inline]
    pub fn spawn_origin(&self, dir: Vec3A) -> Vec3A {
        spawn_origin_lifted(self.point, self.normal, self.lift, dir)
    }

    /// A ray leaving this hit towards `dir` (see `spawn_origin`).
    #[inline]
    pub fn spawn_ray(&self, dir: Vec3A) -> Ray {
        Ray::new(self.spawn_origin(dir), dir)
    }
}

/// Least clearance per unit of offset a lift may leave a face with, 2⁻¹⁰: edges and corners
/// sharper than that (faces within a tenth of a degree of folding onto each other) are held to
/// it. No scene holds one, and the bound would exceed the shape.
const MIN_CLEARANCE: f32 = 1.0 / 1024.0;

/// The direction `d` with `nⱼ · d = 1` for every unit face normal `nⱼ` of `faces` and the
/// least length: moving by `s·d/|d|` clears each face's plane by `s/|d|`. One face: its
/// normal. Two (an edge): their bisector over cos(θ/2). Three (a corner): the solution of
/// the 3×3 Gram system, which for a corner the faces' normals span.
fn lift_direction(faces: &[Vec3A]) -> Vec3A {
    match *faces {
        [n] => n,
        [a, b] => (a + b) / (1.0 + a.dot(b)).max(MIN_CLEARANCE),
        [a, b, c] => {
            let gram = glam::Mat3::from_cols_array(&[
                a.dot(a),
                a.dot(b),
                a.dot(c),
                b.dot(a),
                b.dot(b),
                b.dot(c),
                c.dot(a),
                c.dot(b),
                c.dot(c),
            ]);
            let w = gram.inverse() * glam::Vec3::ONE;
            let d = a * w.x + b * w.y + c * w.z;
            if d.is_finite() && [a, b, c].iter().all(|n| n.dot(d) > 0.5) {
                d
            } else {
                lift_direction(&[a, b])
            }
        }
        _ => Vec3A::ZERO,
    }
}

/// How rays leave a hit with reported unit normal `normal`, world point `point`, error bound
/// `error + per_offset·s` once moved by `s`, near the `faces` given as (world unit normal,
/// world distance of the point from the face's plane).
///
/// The faces the point lies on (within its error) are cleared first; a face it only passes
/// near joins them when the move inwards would bring the origin within the error of it:
/// moving by `s` along `−dir` leaves a point `dist` inside a face with normal `n` at
/// `dist + s·(dir · n)` inside, which on an acute edge (n₁ · n₂ < 0) is less than `dist`.
/// (Outwards, the origin leaves the reported normal's half-space, which holds the solid.) On one face of no edge the lift is the normal, by the larger of the relative bound
/// and the error.
fn lift_off(normal: Vec3A, point: Vec3A, faces: &[(Vec3A, f32)], error: f32, per: f32) -> Lift {
    let rel = relative_offset(point);
    let mut on = [false; 3];
    for (i, &(_, dist)) in faces.iter().enumerate() {
        on[i] = dist <= error;
    }
    let mut lift = Lift {
        outward_min: error / (1.0 - per),
        inward: normal,
        inward_min: error / (1.0 - per),
    };
    for _ in 0..3 {
        let mut chosen = [Vec3A::ZERO; 3];
        let mut count = 0;
        for (f, _) in faces.iter().zip(on).filter(|(_, on)| *on) {
            chosen[count] = f.0;
            count += 1;
        }
        if count > 1 {
            let d = lift_direction(&chosen[..count]);
            let clearance = (1.0 / d.length()).max(MIN_CLEARANCE);
            lift.inward = d.normalize_or_zero();
            lift.inward_min = error / (clearance - per).max(MIN_CLEARANCE);
        }
        let s = rel.max(lift.inward_min);
        let mut grew = false;
        for (i, &(n, dist)) in faces.iter().enumerate() {
            if !on[i] && dist + s * lift.inward.dot(n) < error + per * s {
                on[i] = true;
                grew = true;
            }
        }
        if !grew {
            break;
        }
    }
    lift
}

/// How rays leave a cone's apex: outwards along the reported normal (its half-space holds
/// the cone), inwards along `axis`, the world image of the object axis into
/// the solid (an affine map keeps it inside the image of the cone, where the world normal,
/// under a shear, can point out through the side), far enough to clear every generator's
/// plane by the error bound `error + per·s`. Moving by `s` along `axis / |axis|` moves the
/// object point `s / |axis|` along the unit object axis, `sin · s / |axis|` from each
/// generator's object plane; a plane of object normal `n` is `|N·n| ≤ ‖N‖_F` times nearer in
/// world space (`N` = `normal_norm`'s matrix; see `world_faces`).
fn apex_lift(axis: Vec3A, sin: f32, normal_norm: f32, error: f32, per: f32) -> Lift {
    let len = axis.length();
    let clearance = (sin / (len * normal_norm)).max(MIN_CLEARANCE);
    Lift {
        outward_min: error / (1.0 - per),
        inward: axis / len,
        inward_min: error / (clearance - per).max(MIN_CLEARANCE),
    }
}

/// How a primitive's shape space maps to the world, for `Primitive::clear_of_apex`:
/// shape-space directions to the world, and the Frobenius norm of the normal matrix.
struct Placement<'a> {
    to_world: &'a dyn Fn(Vec3A) -> Vec3A,
    normal_norm: f32,
}

/// `near`'s faces in world space: unit normals (mapped by `to_world`, which for a plane
/// `n · x = c` of unit `n` gives the world plane's normal with length 1 / (world distance per
/// object distance)) and the point's world distances from them.
fn world_faces(near: &NearFaces, to_world: impl Fn(Vec3A) -> Vec3A) -> [(Vec3A, f32); 3] {
    let mut out = [(Vec3A::ZERO, 0.0); 3];
    for (slot, (n, dist)) in out.iter_mut().zip(near.iter()) {
        let w = to_world(n);
        let len = w.length();
        *slot = (w / len, dist / len);
    }
    out
}

/// Error bound of a hit point computed in world space: the f64 solve rounded to f32 (u·|p|
/// per coordinate), the rounding of the spawned origin (u·(|p| + s)) and the f64 solve of
/// the next ray (far below u; counted as one more u). Returns (bound at s = 0, growth per s).
fn world_space_error(p: Vec3A) -> (f32, f32) {
    let u = UNIT_ROUNDOFF;
    ((p.abs() * (3.0 * u)).length(), (Vec3A::ONE * u).length())
}

/// The object-space side of a transformed primitive. Rays are moved relative to `anchor`
/// (the centre of the world bounds) before the f32 matrix is applied: for a small object far
/// from the origin, `o − anchor` is small and exact where `o` alone would lose the digits
/// that matter.
#[derive(Clone, Debug)]
struct ObjectSpace {
    anchor: Vec3A,
    /// `object_from_world` with its translation re-based on the anchor: `L·(o − a) + (L·a + t)`.
    object_from_world: Affine3A,
    world_from_object: Affine3A,
    normal_to_world: Mat3A,
    /// Absolute values of both matrices' entries, for the error bound of `Primitive::surface`.
    abs_world: Affine3A,
    abs_object: Affine3A,
    /// Growth of that bound per unit of spawn offset (see `ObjectSpace::error`).
    error_per_offset: f32,
}

impl ObjectSpace {
    fn new(
        anchor: Vec3A,
        object_from_world: Affine3A,
        world_from_object: Affine3A,
        n: Mat3A,
    ) -> Self {
        let abs = |a: &Affine3A| Affine3A {
            matrix3: Mat3A::from_cols(
                a.matrix3.x_axis.abs(),
                a.matrix3.y_axis.abs(),
                a.matrix3.z_axis.abs(),
            ),
            translation: a.translation.abs(),
        };
        let (abs_world, abs_object) = (abs(&world_from_object), abs(&object_from_world));
        let u = UNIT_ROUNDOFF;
        let per = abs_world.matrix3 * (abs_object.matrix3 * Vec3A::ONE) * gamma(5)
            + Vec3A::splat(2.0 * u);
        ObjectSpace {
            anchor,
            object_from_world,
            world_from_object,
            normal_to_world: n,
            abs_world,
            abs_object,
            error_per_offset: per.length(),
        }
    }

    /// World-space bound on how far a spawned origin, as the next ray's transform into object
    /// space sees it, can be from where exact arithmetic puts it, for a hit at object point
    /// `p` shown at world point `pw`: (bound for a zero offset, growth per unit of offset).
    /// The steps, each bounded per coordinate by γₙ times the sum of the absolute values of
    /// the terms it adds (`crate::math::gamma`; pbrt-v4 carries the same terms as its
    /// `pError` through `Transform::operator()(Point3fi)`):
    /// - `p` itself, solved in f64 and rounded to f32: u·|p| in object space (and as much
    ///   for the f64 solve of the next ray);
    /// - `pw = W·p + t_W` in f32 (three products, three sums): γ₄·(|W|·|p| + |t_W|);
    /// - the origin `o = pw ± s·lift` and `o − a` rounded: u·(|pw| + |pw − a| + 2s);
    /// - `M·(o − a) + t'` in f32: γ₅·(|M|·|o − a| + |t'|) in object space (γ₅: one more u
    ///   for M's entries rounded to f32), and the mismatch of the two f32 matrices, which
    ///   are each other's inverse only to u: 2u·(|M|·(|W|·|p| + |t_W|) + |t'|).
    ///
    /// Errors made in object space reach the world through |W|. The sum's length bounds the
    /// error along any unit direction.
    fn error(&self, p: Vec3A, pw: Vec3A) -> (f32, f32) {
        let u = UNIT_ROUNDOFF;
        let (w, m) = (&self.abs_world, &self.abs_object);
        let ap = p.abs();
        let forward = w.matrix3 * ap + w.translation;
        let pa = (pw - self.anchor).abs();
        let back = m.matrix3 * pa + m.translation;
        let mismatch = m.matrix3 * forward + m.translation;
        let object = back * gamma(5) + (ap + mismatch) * (2.0 * u);
        let world = forward * gamma(4) + (pw.abs() + pa) * u + w.matrix3 * object;
        (world.length(), self.error_per_offset)
    }
}

#[derive(Clone, Debug)]
/// A shape placed in the world: baked into world space, or kept in its own space with
/// the transform that places it (see the module doc).
pub struct Primitive {
    /// The shape, in world space when baked, else in its own space.
    pub shape: Shape,
    object: Option<Box<ObjectSpace>>,
    /// Index of its material in the compiled scene.
    pub material: u32,
    /// World bounds (infinite for a plane).
    pub bounds: Aabb,
}

fn f(v: DVec3) -> Vec3A {
    v.as_vec3().into()
}

impl Primitive {
    /// Places `geometry` with world transform `xf`. Shapes whose class survives the
    /// transform are baked into world space; the rest keep the matrix.
    pub fn new(
        geometry: &Geometry,
        xf: &Transform,
        material: u32,
    ) -> Result<Primitive, Degenerate> {
        let baked = geometry.keeps_kind_under(xf);
        let shape = geometry.shape_under(if baked { xf } else { &Transform::IDENTITY })?;
        let object = (!baked).then(|| {
            let local = shape.bounds();
            let anchor = if local.is_finite() {
                xf.point(local.centroid().as_dvec3())
            } else {
                xf.point(DVec3::ZERO)
            };
            let mut rebased = xf.object_from_world;
            // Composed in f64, so the object-space anchor keeps its precision.
            rebased.w_axis = xf.object_from_world.transform_point3(anchor).extend(1.0);
            Box::new(ObjectSpace::new(
                f(anchor),
                Affine3A::from_mat4(rebased.as_mat4()),
                Affine3A::from_mat4(xf.world_from_object.as_mat4()),
                Mat3A::from(xf.normal_matrix().as_mat3()),
            ))
        });
        let local = shape.bounds();
        let bounds = match &object {
            Some(o) if local.is_finite() => Aabb::from_points(
                local
                    .corners()
                    .map(|c| o.world_from_object.transform_point3a(c)),
            ),
            _ => local,
        };
        Ok(Primitive {
            shape,
            object,
            material,
            bounds,
        })
    }

    /// Cheap stage: nearest hit as the shape reports it (object space for transformed shapes;
    /// `t` is in world units either way).
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        match &self.object {
            None => self.shape.intersect(ray, t_max),
            Some(o) => {
                let local = Ray::new(
                    o.object_from_world.transform_point3a(ray.origin - o.anchor),
                    o.object_from_world.transform_vector3a(ray.dir),
                );
                self.shape.intersect(&local, t_max)
            }
        }
    }

    /// Full stage, for the one hit that is kept: world-space point, unit normal, and how
    /// rays spawned from it leave the surface.
    ///
    /// A shape baked into world space keeps the relative spawn bound on its faces (it covers
    /// world-space rounding many times over: `crate::math::spawn_origin`). A shape traced
    /// through its matrix carries its own bound (`ObjectSpace::error`): the next ray sees
    /// the spawned origin through two more f32 transforms, whose error the relative bound
    /// does not know (for an object far from its own origin, it exceeds it). Rays spawned
    /// inwards from a rim leave along the bisector of the two faces' world normals: the object-space bisector,
    /// mapped by a non-uniform scale, may point out of one face while into the solid, so a
    /// ray spawned inwards by it started outside that face (tests/robustness
    /// `quadric_apex_and_rims_are_watertight`).
    #[inline]
    pub fn surface(&self, hit: &ShapeHit) -> SurfaceHit {
        if let Some(lift) = self.world_box_face_lift(hit) {
            return SurfaceHit {
                t: hit.t,
                point: hit.point,
                normal: lift.inward,
                lift,
            };
        }
        let mut near = self.shape.faces_near(hit);
        let (point, normal, lift) = match &self.object {
            None => {
                let normal = hit.normal.normalize_or_zero();
                if near.apex.is_none() {
                    near.apex = self.thin_tip(hit.point, hit.point, Lift::normal(normal), |v| v);
                }
                let lift = if near.len == 0 && near.apex.is_none() {
                    Lift::normal(normal)
                } else {
                    let (error, per) = world_space_error(hit.point);
                    let faces = world_faces(&near, |n| n);
                    let lift = lift_off(normal, hit.point, &faces[..near.len], error, per);
                    let space = Placement {
                        to_world: &|v| v,
                        normal_norm: 1.0,
                    };
                    self.clear_of_apex(&near, lift, (error, per), &space)
                };
                (hit.point, normal, lift)
            }
            Some(o) => {
                let point = o.world_from_object.transform_point3a(hit.point);
                let normal = (o.normal_to_world * hit.normal).normalize_or_zero();
                let (error, per) = o.error(hit.point, point);
                let faces = world_faces(&near, |n| o.normal_to_world * n);
                let lift = lift_off(normal, point, &faces[..near.len], error, per);
                if near.apex.is_none() {
                    near.apex =
                        self.thin_tip(hit.point, point, lift, |v| o.object_from_world.matrix3 * v);
                }
                let m = &o.normal_to_world;
                let space = Placement {
                    to_world: &|v| o.world_from_object.matrix3 * v,
                    normal_norm: (m.x_axis.length_squared()
                        + m.y_axis.length_squared()
                        + m.z_axis.length_squared())
                    .sqrt(),
                };
                let lift = self.clear_of_apex(&near, lift, (error, per), &space);
                (point, normal, lift)
            }
        };
        SurfaceHit {
            t: hit.t,
            point,
            normal,
            lift,
        }
    }

    /// The lift `surface` gives a hit on a world-space box away from its edges, without the
    /// general path's work (most hits of a room's walls). There every face normal is a unit
    /// axis, so `world_faces` maps them exactly and the normal of the hit face is
    /// perpendicular to the others: `lift_off` keeps the hit face alone, its normal both ways
    /// by the error bound, as long as each other face lies farther than `error` and does not
    /// join on the inward move (`dist < error + per·s`). Then it returns the same `Lift`;
    /// otherwise `None`, and the general path decides.
    #[inline]
    fn world_box_face_lift(&self, hit: &ShapeHit) -> Option<Lift> {
        let (Shape::Box(b), None) = (&self.shape, &self.object) else {
            return None;
        };
        let normal = hit.normal.normalize_or_zero();
        let (error, per) = world_space_error(hit.point);
        let min = error / (1.0 - per);
        let s = relative_offset(hit.point).max(min);
        let clear = |axis: usize| {
            let p = hit.point[axis];
            let dist = (p - b.min[axis]).min(b.max[axis] - p).max(0.0);
            hit.normal[axis] != 0.0 || (dist > error && dist >= error + per * s)
        };
        (clear(0) && clear(1) && clear(2)).then_some(Lift {
            outward_min: min,
            inward: normal,
            inward_min: min,
        })
    }

    /// The apex's way out for a hit at shape-space point `at` (world point `world`) next to a
    /// cone's apex, where the inward move `lift` makes (mapped to shape space by `to_shape`)
    /// would cross the thin tip (`Shape::apex_escape_near`).
    fn thin_tip(
        &self,
        at: Vec3A,
        world: Vec3A,
        lift: Lift,
        to_shape: impl Fn(Vec3A) -> Vec3A,
    ) -> Option<(Vec3A, f32)> {
        if !self.shape.has_apex() {
            return None;
        }
        let step = -lift.inward * relative_offset(world).max(lift.inward_min);
        self.shape.apex_escape_near(at, to_shape(step))
    }

    /// `lift`, or at a cone's apex the lift along its axis (`apex_lift`).
    fn clear_of_apex(
        &self,
        near: &NearFaces,
        lift: Lift,
        (error, per): (f32, f32),
        space: &Placement,
    ) -> Lift {
        match near.apex {
            Some((axis, sin)) => {
                apex_lift((space.to_world)(axis), sin, space.normal_norm, error, per)
            }
            None => lift,
        }
    }

    /// Both stages at once (tests and tools).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        self.hit(ray, t_max).map(|h| self.surface(&h))
    }

    /// Whether its bounds are finite (a plane's are not).
    pub fn is_bounded(&self) -> bool {
        self.bounds.is_finite()
    }

    /// The sphere, when this is one baked into world space (the render scene keeps those
    /// packed, four to a SIMD test).
    pub fn world_sphere(&self) -> Option<&Sphere> {
        match (&self.shape, &self.object) {
            (Shape::Sphere(s), None) => Some(s),
            _ => None,
        }
    }

    /// The shape, when it is baked into world space.
    pub fn world_shape(&self) -> Option<&Shape> {
        self.object.is_none().then_some(&self.shape)
    }

    /// The box, when this is one baked into world space (the render scene slab-tests those
    /// four at a time).
    pub fn world_box(&self) -> Option<&AaBox> {
        match (&self.shape, &self.object) {
            (Shape::Box(b), None) => Some(b),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3A::from(o), Vec3A::from(d))
    }

    #[test]
    fn scaled_sphere_is_baked_and_hit_in_world_space() {
        let xf = Transform::translate(DVec3::new(0.0, 0.0, -10.0))
            .then_after(&Transform::scale(DVec3::splat(2.0)).unwrap());
        let prim = Primitive::new(
            &Geometry::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            &xf,
            0,
        )
        .unwrap();
        assert!(prim.object.is_none(), "similarity transforms are baked");
        let h = prim
            .intersect(&ray([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]), f32::INFINITY)
            .unwrap();
        assert!((h.t - 8.0).abs() < 1e-5);
        assert!((h.normal - Vec3A::Z).length() < 1e-6);
    }

    #[test]
    fn ellipsoid_normal_uses_the_inverse_transpose() {
        // Sphere scaled by (2,1,1) is x²/4 + y² + z² = 1; a ray down −z at (1, 0.5) meets it
        // at z = √0.5, where the normal is ∝ (x/4, y, z).
        let xf = Transform::scale(DVec3::new(2.0, 1.0, 1.0)).unwrap();
        let prim = Primitive::new(
            &Geometry::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            &xf,
            0,
        )
        .unwrap();
        assert!(prim.object.is_some());
        let z = 0.5f32.sqrt();
        let h = prim
            .intersect(&ray([1.0, 0.5, 5.0], [0.0, 0.0, -1.0]), f32::INFINITY)
            .unwrap();
        let expected = Vec3A::new(0.25, 0.5, z).normalize();
        assert!((h.normal - expected).length() < 1e-5, "{:?}", h.normal);
        assert!((h.t - (5.0 - z)).abs() < 1e-5);
    }

    #[test]
    fn object_space_error_bounds_the_round_trip_of_a_spawned_origin() {
        // Sheared (turned, then stretched), far from the origin and from the object's own
        // origin: world point of an object point, the origin moved off it, and that origin
        // as the next ray's transform sees it, against f64. The error the next ray sees,
        // mapped back to world, must stay within the bound; the bound must not be loose by
        // more than a few hundred times either, or the offset would outgrow contact shadows.
        let xf = Transform::translate(DVec3::new(3.0e4, -2.0e3, 5.0e4))
            .then_after(&Transform::rotate(50.0, DVec3::new(1.0, 2.0, -0.5)).unwrap())
            .then_after(&Transform::scale(DVec3::new(40.0, 3.0, 11.0)).unwrap())
            .then_after(&Transform::rotate(-35.0, DVec3::new(0.3, -1.0, 0.8)).unwrap());
        let geometry = Geometry::Box {
            p1: DVec3::new(90.0, -1.0, 40.0),
            p2: DVec3::new(92.0, 1.5, 41.0),
        };
        let prim = Primitive::new(&geometry, &xf, 0).unwrap();
        let o = prim.object.as_deref().unwrap();
        let mut rng = crate::util::SplitMix64::new(0x2545_F491_4F6C_DD1D);
        let mut unit = || rng.unit_f64();
        let mut worst = 0.0f64;
        for _ in 0..20_000 {
            let p = Vec3A::new(
                (90.0 + 2.0 * unit()) as f32,
                (-1.0 + 2.5 * unit()) as f32,
                (40.0 + unit()) as f32,
            );
            let pw = o.world_from_object.transform_point3a(p);
            let (error, per) = o.error(p, pw);
            let dir = Vec3A::new(unit() as f32 - 0.5, unit() as f32 - 0.5, 0.3).normalize();
            let s = (unit() * 0.05) as f32;
            let origin = pw + dir * s;
            let seen = o
                .object_from_world
                .transform_point3a(origin - o.anchor)
                .as_dvec3();
            let meant = xf.point(p.as_dvec3()) + dir.as_dvec3() * s as f64;
            let off = (xf.point(seen) - meant).length();
            let bound = (error + per * s) as f64;
            worst = worst.max(off / bound);
        }
        assert!(worst <= 1.0, "the error reached {worst} of the bound");
        assert!(
            worst > 1.0 / 400.0,
            "the bound is {:.0}x the worst error",
            1.0 / worst
        );
    }

    #[test]
    fn a_rim_hit_that_reports_a_face_normal_still_lifts_off_both_faces() {
        // The showcase's cylinder at scale 1e4 (`anim bench --stress`): a hit snapped onto the
        // bottom rim reports the side's normal (its crossing told the halfway normal wrong).
        // Moved along that normal alone, an origin spawned inwards stayed on the cap's plane
        // and a ray heading in through the cap met it again at t = 1.7e-3.
        let prim = Primitive::new(
            &Geometry::Cylinder {
                p1: DVec3::new(-24000.0, -17500.0, -85000.0),
                p2: Vec3A::new(-24000.0, -6624.3066, -79928.58).as_dvec3(),
                radius: 6000.0,
            },
            &Transform::IDENTITY,
            0,
        )
        .unwrap();
        let shape_hit = ShapeHit {
            t: 1.0,
            point: Vec3A::new(-28362.574, -19240.857, -81266.73),
            normal: Vec3A::new(-0.7270958, -0.2901428, 0.6222129),
        };
        let dir = Vec3A::new(0.7149914, 0.647_381_4, 0.263_978_7);
        let hit = prim.surface(&shape_hit);
        assert!(hit.normal.dot(dir) < 0.0, "spawned inwards");
        let old = crate::math::spawn_ray(hit.point, hit.normal, dir);
        let again = prim.intersect(&old, f32::INFINITY).unwrap();
        assert!(again.normal.dot(dir) < 0.0 && again.t < 0.01, "{again:?}");
        // Now: lifted along the bisector of side and cap, it meets the cylinder only leaving
        // it through the far side.
        let again = prim.intersect(&hit.spawn_ray(dir), f32::INFINITY).unwrap();
        assert!(again.normal.dot(dir) > 0.0 && again.t > 1000.0, "{again:?}");
        assert!(hit.lift.inward.dot(hit.normal) < 0.9, "{:?}", hit.lift);
    }

    #[test]
    fn lift_clears_every_face_it_is_given_by_the_bound() {
        let faces = [
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(-0.9, 0.4358899, 0.0),
            Vec3A::new(0.2, 0.3, -0.9327379),
        ];
        for count in 1..=3 {
            let d = lift_direction(&faces[..count]);
            for n in &faces[..count] {
                assert!((n.dot(d) - 1.0).abs() < 1e-5, "{count}: {}", n.dot(d));
            }
        }
        // An acute edge (faces 154° apart) next to a point on one face only: the other face
        // joins once the inward move would come within the error of it.
        let point = Vec3A::new(100.0, 0.0, 0.0);
        let near = [(faces[0], 0.0), (faces[1], relative_offset(point) * 0.5)];
        let lift = lift_off(faces[0], point, &near, 1e-6, 0.0);
        assert!(lift.inward.dot(faces[1]) > 0.0, "{lift:?}");
        let s = relative_offset(point).max(lift.inward_min);
        for (n, dist) in near {
            assert!(dist + s * lift.inward.dot(n) >= 1e-6, "{lift:?}");
        }
        // Far from the edge the normal alone is kept, by the relative bound.
        let far = [(faces[0], 0.0), (faces[1], 1.0)];
        assert_eq!(lift_off(faces[0], point, &far, 1e-6, 0.0).inward, faces[0]);
    }

    #[test]
    fn rotated_box_keeps_its_matrix_and_bounds_cover_it() {
        let xf = Transform::rotate(45.0, DVec3::Z).unwrap();
        let prim = Primitive::new(
            &Geometry::Box {
                p1: DVec3::splat(-1.0),
                p2: DVec3::splat(1.0),
            },
            &xf,
            0,
        )
        .unwrap();
        assert!(prim.object.is_some());
        assert!((prim.bounds.max.x - 2.0f32.sqrt()).abs() < 1e-5);
        // The rotated corner sits on the +x axis at √2.
        let h = prim
            .intersect(&ray([5.0, 0.0, 0.0], [-1.0, 0.0, 0.0]), f32::INFINITY)
            .unwrap();
        assert!((h.t - (5.0 - 2.0f32.sqrt())).abs() < 1e-4);
    }
}
