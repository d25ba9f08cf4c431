//! Seeded, smooth, deterministic one-dimensional gradient noise (Perlin's, in one dimension),
//! and `wiggle`'s sum of its octaves.
//!
//! At each whole number `i` the noise is 0 with a slope `g(i)` drawn from the seed: `g(i)` is
//! the 53 high bits of `mix64(mix64(seed) ^ i)` mapped to [−1, 1). Between `i` and `i + 1`,
//! with `f = x − i` and the quintic fade `u(f) = 6f⁵ − 15f⁴ + 10f³`,
//!
//! ```text
//! noise(x) = 2 · ( g(i)·f + u(f)·( g(i+1)·(f − 1) − g(i)·f ) )
//! ```
//!
//! which is smooth to the second derivative (the fade's first and second derivatives vanish
//! at whole numbers), lies in [−1, 1] (`(1 − u)·f + u·(1 − f)` is at most ½), and is the
//! same for the same `x` and seed on every machine (integer hashing and a fixed formula).

use anim_core::util::mix64;

/// The slope at whole number `i` for `seed`, in [−1, 1).
fn gradient(i: i64, seed: u64) -> f64 {
    let bits = mix64(mix64(seed) ^ i as u64) >> 11;
    bits as f64 / (1u64 << 52) as f64 - 1.0
}

/// Gradient noise at `x` for `seed`: in [−1, 1], 0 at whole numbers, smooth.
pub fn noise(x: f64, seed: u64) -> f64 {
    if !x.is_finite() {
        return f64::NAN;
    }
    let i = x.floor();
    let f = x - i;
    let i = i as i64;
    let a = gradient(i, seed) * f;
    let b = gradient(i.wrapping_add(1), seed) * (f - 1.0);
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    2.0 * (a + u * (b - a))
}

/// `octaves` (a whole number, at least 1) of noise at `x`, each at twice the frequency of the
/// one before and `falloff` times its amplitude, each from its own seed: After Effects'
/// `wiggle` before it is scaled by the amplitude.
pub fn wiggle(x: f64, octaves: f64, falloff: f64, seed: u64) -> f64 {
    let octaves = if octaves.is_finite() {
        octaves.clamp(1.0, 16.0) as u32
    } else {
        1
    };
    let mut sum = 0.0;
    let mut amp = 1.0;
    let mut freq = 1.0;
    for k in 0..octaves {
        sum += amp * noise(x * freq, seed.wrapping_add(u64::from(k) << 32));
        amp *= falloff;
        freq *= 2.0;
    }
    sum
}
