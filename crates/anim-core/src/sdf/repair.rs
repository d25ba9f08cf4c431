//! Repairs of material values, shared by the reader (which warns about each one it makes) and
//! the scene builder (which makes them silently, or with one warning, for statements made by
//! programs), so both read a file's numbers the same way.

/// The index of refraction of air, the medium outside every object: used for a material
/// without a usable one.
pub const AIR_IOR: f32 = 1.0;

/// The Phong exponent a material's `m` stands for: its sign carries no meaning, and a
/// negative exponent would send the highlight to infinity where R·V = 0. (An `m` of 0 is kept:
/// pow(x, 0) = 1 is well defined.)
pub fn phong_exponent(m: f32) -> f32 {
    m.abs()
}

/// An index of refraction as given, if it can be used (it must be positive).
pub fn usable_ior(ior: f64) -> Option<f64> {
    if ior <= 0.0 {
        None
    } else {
        Some(ior)
    }
}
