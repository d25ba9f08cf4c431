//! Adaptive anti-aliasing: where each pixel's samples go and when a pixel has enough.
//!
//! Sub-pixel positions come from the first two dimensions of the Sobol sequence, a
//! (0,2)-sequence in base 2: every prefix of 2^m points is a (0,m,2)-net, so any 4^k points
//! put one sample in each cell of the 2^k×2^k grid, and doubling the count keeps that true.
//! Each pixel gets its own nested uniform (Owen-style) scramble, keyed only by its position:
//! the scramble decorrelates neighbouring pixels (no structured aliasing), keeps the net
//! property, and is the same in every frame of an animation and for any thread count.
//!
//! The error of a pixel is estimated for its tone-mapped mean in 8-bit levels, the quantity
//! the output is judged in, so the target `--error` means the same on dark and bright pixels.
//!
//! A sample's other dimensions (the instant of the exposure, the point of the lens, the
//! point of each spherical light) come from the same pixel's sequence: the instant is the
//! third Sobol dimension, and each 2D pair is the first two dimensions again at a shuffled
//! index ([`PixelPattern::pair`]), as Burley ("Practical hash-based Owen scrambling", 2020)
//! pads a sequence: stratified like the pixel position, and not correlated with it.

use crate::util::mix64;
use glam::Vec3A;

/// Fewest samples of a refined pixel: the first count at which two nested nets (2 and 4
/// points) can be compared, one sample per quadrant.
pub const MIN_SAMPLES: u32 = 4;

/// Samples of a refined pixel that take the lights every shadow ray of the centres around it
/// saw fully as visible at their camera hits, without shadow rays (`PixelPrior`): those of
/// its first error check. A pixel that goes on has a feature its first samples disagree
/// about, and a shadow smaller than the spacing of the centres, which all nine missed, would
/// otherwise be taken as lit by every one of its samples: over a floor under many small
/// spheres that left converged renders 0.8 levels too bright on average and up to 30 levels
/// off (docs/benchmarks-history.md §4.8).
pub const PRIOR_SAMPLES: u32 = MIN_SAMPLES;

/// Fewest samples of a pixel that motion touches. Its instants are stratified, one in each
/// 1/n of the exposure, so n samples all miss only what covers the pixel for less than about
/// 1/n of it: at 4, a moving shadow's blurred end went unseen often enough to leave the
/// blurred frames of animations/blur.ron visibly off the mean of many instants, and 8 with
/// the adaptive sampler's third pass (which looks in the neighbours for what 8 still miss)
/// brings them within half a level (docs/benchmarks-history.md §14.2).
pub const MOTION_MIN_SAMPLES: u32 = 8;

/// Fewest samples of a pixel whose value hangs on its lens or light points (a penumbra, a
/// blur). Their points of the lens and of each light are stratified like the positions, so n
/// samples all miss only what covers less than about 1/n of the lens or the light: the sliver
/// of a light that an occluder hides at a penumbra's lit end, a small bright shape at the
/// edge of a circle of confusion. There all samples agree and the error estimate says the
/// pixel is done. At `MOTION_MIN_SAMPLES` such pixels of a penumbra were off by levels while
/// estimated at a fraction of one; at 16 the soft-shadow bench scene's penumbra is within
/// the bench's target (BENCHMARKS.md, "Soft shadows, spots and depth of field").
pub const SPREAD_MIN_SAMPLES: u32 = 16;

/// A pixel spread over lens or light points is refined to the frame's error target divided by
/// this. Its error estimate is the spread of its own samples' mean, and where a bright sliver of
/// the lens or a light is seen by few of them the estimate runs low: at the frame's target the
/// depth-of-field bench scene stayed well above it in RMSE while only its blurred pixels were
/// off. Only those pixels pay (BENCHMARKS.md, "Soft shadows, spots and depth of field").
pub const SPREAD_ERROR_DIVISOR: f32 = 4.0;

/// A pixel spread over lens or light points may take this many times `--max-spp`, which caps
/// every other pixel: a quarter of the error calls for about sixteen times the samples, and a
/// blur's pixels reached the old cap before the old target.
pub const SPREAD_SPP_FACTOR: u32 = 4;

/// Largest contrast (8-bit levels) between a pixel's centre sample and its 8 neighbours'
/// for the pixel to be flat and keep its centre sample, if all nine hit the same surface.
/// Smooth shading changes by about a level from pixel to pixel; a shadow or highlight edge,
/// or an edge in a reflection, by more; a looser bound gave a higher error for the same time
/// (docs/benchmarks-history.md §4).
pub const FLAT_CONTRAST: f32 = 2.0;

/// Share of the neighbourhood contrast taken as the error a few samples leave on an edge
/// pixel, for [`min_samples`]: a larger share buys little error for its samples, a smaller
/// one misses thin features (docs/benchmarks-history.md §4).
const EDGE_ERROR_SHARE: f32 = 0.2;

pub use crate::render::film::{tone, tone3};

/// The dimension pair of a thin lens ([`PixelPattern::pair`]).
pub const LENS_PAIR: u32 = 0;

/// The dimension pair of light `k` ([`PixelPattern::pair`]).
pub fn light_pair(k: usize) -> u32 {
    u32::try_from(k).map_or(u32::MAX, |k| k.saturating_add(1))
}

/// The scramble of one pixel: one key per dimension, derived from the pixel position alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelPattern {
    keys: [u64; 3],
}

impl PixelPattern {
    /// The pattern of pixel (`x`, `y`).
    pub fn new(x: u32, y: u32) -> Self {
        let base = mix64(((y as u64) << 32 | x as u64) ^ 0x5eed_a11a_5eed_a11a);
        PixelPattern {
            keys: [
                mix64(base),
                mix64(base ^ 0x9e37_79b9_7f4a_7c15),
                mix64(base ^ 0x3c6e_f372_fe94_f82a),
            ],
        }
    }

    /// The instant of the exposure of sample `i` (0 to 1), for frames in which something
    /// moves: the third Sobol dimension under this pixel's own scramble, so that time is
    /// stratified together with the position (any 2^m samples put one in each 2^-m of the
    /// exposure, and the first two dimensions keep their net).
    #[inline]
    pub fn time(&self, i: u32) -> f32 {
        let t = match SOBOL_TABLE.get(i as usize) {
            Some(&[_, t]) => t,
            None => sobol3(i).reverse_bits(),
        };
        to_unit(owen_scramble_reversed(t, self.keys[2]))
    }

    /// Point `i` of this pixel's dimension pair `pair` (one per thin lens or light: see
    /// [`LENS_PAIR`], [`light_pair`]), in [0,1)². The first two Sobol dimensions at index
    /// `j`, a nested scramble of `i` read from its highest bit down, keyed by the pixel and
    /// the pair: the first `2^m` indices go to the `2^m` of one aligned block, in some order,
    /// and every aligned block of a (0,2)-sequence is a (0,m,2)-net, so every power-of-two
    /// prefix is stratified as the pixel positions are; the shuffle pairs the strata of one
    /// pair with those of another (and of the position) differently in every pixel.
    pub fn pair(&self, i: u32, pair: u32) -> [f32; 2] {
        let key = |salt: u64| {
            mix64(self.keys[0] ^ mix64(u64::from(pair) << 8 | salt ^ 0x9a1d_5eed_0fa1_b2c3))
        };
        let j = owen_scramble_reversed(i.reverse_bits(), key(0));
        let b = match SOBOL_TABLE.get(j as usize) {
            Some(&[b, _]) => b,
            None => sobol2(j).1.reverse_bits(),
        };
        [
            to_unit(owen_scramble_reversed(j, key(1))),
            to_unit(owen_scramble_reversed(b, key(2))),
        ]
    }

    /// Sample `i` of this pixel, in [0,1)².
    #[inline]
    pub fn sample(&self, i: u32) -> (f32, f32) {
        // The first dimension is the bit reversal of `i`: reversed, it is `i` itself.
        let b = match SOBOL_TABLE.get(i as usize) {
            Some(&[b, _]) => b,
            None => sobol2(i).1.reverse_bits(),
        };
        (
            to_unit(owen_scramble_reversed(i, self.keys[0])),
            to_unit(owen_scramble_reversed(b, self.keys[1])),
        )
    }
}

/// The first two Sobol dimensions of point `i` as 32-bit fractions: the van der Corput
/// sequence and the dimension whose generator matrix is Pascal's triangle mod 2.
#[inline]
pub const fn sobol2(i: u32) -> (u32, u32) {
    let mut v = 1u32 << 31;
    let mut y = 0u32;
    let mut bits = i;
    while bits != 0 {
        if bits & 1 != 0 {
            y ^= v;
        }
        bits >>= 1;
        v ^= v >> 1;
    }
    (i.reverse_bits(), y)
}

/// Direction numbers of the third Sobol dimension (primitive polynomial x² + x + 1, initial
/// m = 1, 3: Joe and Kuo's table): v_k = v_{k−1} ⊕ v_{k−2} ⊕ (v_{k−2} >> 2).
const SOBOL3: [u32; 32] = {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    v[1] = 3 << 29;
    let mut k = 2;
    while k < 32 {
        v[k] = v[k - 1] ^ v[k - 2] ^ (v[k - 2] >> 2);
        k += 1;
    }
    v
};

/// The third Sobol dimension of point `i` as a 32-bit fraction.
#[inline]
pub const fn sobol3(i: u32) -> u32 {
    let mut y = 0u32;
    let mut bits = i;
    let mut k = 0;
    while bits != 0 {
        if bits & 1 != 0 {
            y ^= SOBOL3[k];
        }
        bits >>= 1;
        k += 1;
    }
    y
}

/// The second and third Sobol dimensions of the first points, bit-reversed as
/// [`owen_scramble_reversed`] takes them, read from a table instead of computed bit by bit:
/// every pixel's samples up to the default maximum (`limits::DEFAULT_MAX_SPP`) and beyond.
/// The first dimension reversed is the point's index, which needs no table.
const SOBOL_TABLE: [[u32; 2]; 64] = {
    let mut table = [[0u32; 2]; 64];
    let mut i = 0;
    while i < table.len() {
        table[i] = [
            sobol2(i as u32).1.reverse_bits(),
            sobol3(i as u32).reverse_bits(),
        ];
        i += 1;
    }
    table
};
const _: () = assert!(SOBOL_TABLE.len() >= crate::limits::DEFAULT_MAX_SPP as usize);

/// The instant of the exposure of sample `i` of `n` in pixel (`x`, `y`) under uniform
/// sampling: the strata `(σ(i) + ½)/n`, with σ a stride through them that is coprime to `n`
/// and near `n/φ` (so time does not follow the order of the sub-pixel grid), shifted by an
/// amount keyed by the pixel position alone (neighbours do not see the same instants at the
/// same sub-pixel offsets, which would print discrete copies of a moving edge).
pub fn uniform_time(x: u32, y: u32, i: u32, n: u32) -> f32 {
    let n = n.max(1) as u64;
    let mut stride = ((n as f64 * 0.618_033_988_749_895) as u64).max(1);
    while gcd(stride, n) != 1 {
        stride += 1;
    }
    let stratum = (i as u64 * stride) % n;
    let shift = mix64(((y as u64) << 32 | x as u64) ^ 0x7157_0f5e_ed00_71de) >> 11;
    let shift = shift as f64 / (1u64 << 53) as f64;
    let t = (stratum as f64 + 0.5) / n as f64 + shift;
    (t - t.floor()) as f32
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// A nested uniform scramble of a 32-bit fraction given by its bit reversal `x` (the
/// samplers keep their points reversed: the first dimension's reversal is its index, so a
/// sample pays for one reversal per dimension instead of two; x86 has no instruction for it).
/// Each digit is flipped or not depending only on the digits above it, which is what keeps
/// every elementary interval of a net mapped onto another of the same shape. On the reversed
/// value "digits above" are the lower bits, where adding a key and XOR-ing with a multiple by
/// an even number do exactly that (a carry or a product only moves upwards). The even
/// multipliers come from the key too, so every pixel gets a different permutation, not just a
/// shift.
#[inline]
fn owen_scramble_reversed(mut x: u32, key: u64) -> u32 {
    x = x.wrapping_add(key as u32);
    let k = key >> 32;
    x ^= x.wrapping_mul(((k as u32) << 1) | 2);
    x ^= x.wrapping_mul((((k >> 15) as u32) << 1) | 2);
    x ^= x.wrapping_mul(0x6f4f_2a36);
    x.reverse_bits()
}

/// The scramble of a fraction given as it is: the tests' reference for the tables.
#[cfg(test)]
fn owen_scramble(v: u32, key: u64) -> u32 {
    owen_scramble_reversed(v.reverse_bits(), key)
}

/// A 32-bit fraction as an f32 in [0,1): the top 24 bits fit the mantissa exactly.
#[inline]
fn to_unit(v: u32) -> f32 {
    (v >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// How much the error of a mean falls when a (0,2)-sequence doubles its samples: for a
/// pixel crossed by an edge (the error Whitted images have) a scrambled net's error goes as
/// n^(-3/4), not the n^(-1/2) of independent samples.
const NET_DECAY: f32 = 0.594_603_56; // 2^(-3/4)

/// Running sums of a pixel's samples, for its mean (linear colour) and for an estimate of the
/// error of that mean in tone-mapped 8-bit levels.
///
/// The estimate is built for stratified samples. The standard error formula for independent
/// samples, σ/√n, is far too pessimistic here: on an edge pixel σ is half the edge's contrast
/// whatever n, so it would send every edge pixel to the maximum. Instead, every power-of-two
/// prefix of the sequence is itself a net, so the change of the tone-mapped mean from n/2 to
/// n samples measures the error of the n/2-sample mean as the sampler actually has it (the
/// idea of Cycles's half-buffer estimate, made exact by the nesting of nets). The error of the
/// n-sample mean is that times the decay of one doubling; the last two doublings are both
/// consulted so that two halves agreeing by chance cannot stop a pixel alone.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// Samples added.
    pub n: u32,
    /// Their sum (linear radiance).
    pub sum: Vec3A,
    tone_sum: Vec3A,
    /// `tone_sum` when `n` was last a power of two.
    tone_at_half: Vec3A,
    /// |mean(n) − mean(n/2)| in 8-bit levels (worst channel) at the last two powers of two.
    changes: [f32; 2],
}

impl Moments {
    #[inline]
    /// Adds sample `c` (linear radiance).
    pub fn add(&mut self, c: Vec3A) {
        self.n += 1;
        self.sum += c;
        self.tone_sum += tone3(c);
        if self.n.is_power_of_two() {
            if self.n >= 2 {
                let n = self.n as f32;
                let change = (self.tone_sum / n - self.tone_at_half * (2.0 / n)).abs();
                self.changes = [self.changes[1], 255.0 * change.max_element()];
            }
            self.tone_at_half = self.tone_sum;
        }
    }

    /// The sums of `n` samples that agreed (a pixel that stopped at its first check) whose
    /// mean was `mean`, to take more of them: the next check compares the mean of `2n`
    /// with `mean`, as if every one of the `n` had been `mean`.
    pub fn resume(mean: Vec3A, n: u32) -> Moments {
        let n_f = n as f32;
        let tone_sum = tone3(mean) * n_f;
        Moments {
            n,
            sum: mean * n_f,
            tone_sum,
            tone_at_half: tone_sum,
            changes: [0.0; 2],
        }
    }

    /// The mean of the samples added (linear radiance).
    pub fn mean(&self) -> Vec3A {
        self.sum / self.n.max(1) as f32
    }

    /// Estimated error of the tone-mapped mean, in 8-bit levels; infinite before four
    /// samples (two doublings) are in.
    pub fn error(&self) -> f32 {
        if self.n < 4 {
            return f32::INFINITY;
        }
        NET_DECAY * self.changes[1].max(NET_DECAY * self.changes[0])
    }
}

/// Samples a refined pixel takes before its own error estimate may stop it. A handful of
/// samples can all miss a small feature that a neighbour's centre saw, and then agree with
/// each other perfectly; the neighbourhood contrast `contrast` (levels) says how much such a
/// miss would cost. A scrambled net's error on an edge falls as n^(-3/4), so reaching
/// `error` from an edge error of `EDGE_ERROR_SHARE·contrast` takes (share·contrast/error)^(4/3)
/// samples; rounded up to a power of two, where the estimate is checked.
pub fn min_samples(contrast: f32, error: f32, max_spp: u32) -> u32 {
    let n = (EDGE_ERROR_SHARE * contrast / error).powf(4.0 / 3.0);
    let n = if n.is_finite() {
        n.min(65536.0) as u32
    } else {
        65536
    };
    n.max(MIN_SAMPLES).next_power_of_two().min(max_spp)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(v: f32, cells: u32) -> u32 {
        (v * cells as f32) as u32
    }

    #[test]
    fn every_prefix_of_4_to_the_k_fills_each_grid_cell_once() {
        for (x, y) in [(0, 0), (1, 0), (17, 33), (639, 359), (65535, 65535)] {
            let p = PixelPattern::new(x, y);
            for k in 0..=5u32 {
                let side = 1u32 << k;
                let mut seen = vec![0u32; (side * side) as usize];
                for i in 0..side * side {
                    let (u, v) = p.sample(i);
                    assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                    seen[(cell(v, side) * side + cell(u, side)) as usize] += 1;
                }
                assert!(seen.iter().all(|&c| c == 1), "pixel ({x},{y}) k={k}");
            }
        }
    }

    #[test]
    fn every_power_of_two_prefix_is_a_net_for_all_interval_shapes() {
        // (0,m,2)-net: each 2^a × 2^b elementary interval with a + b = m holds one point.
        let p = PixelPattern::new(5, 9);
        for m in 0..=8u32 {
            for a in 0..=m {
                let (cx, cy) = (1u32 << a, 1u32 << (m - a));
                let mut seen = vec![0u32; (cx * cy) as usize];
                for i in 0..1u32 << m {
                    let (u, v) = p.sample(i);
                    seen[(cell(v, cy) * cx + cell(u, cx)) as usize] += 1;
                }
                assert!(seen.iter().all(|&c| c == 1), "m={m} a={a}");
            }
        }
    }

    #[test]
    fn every_prefix_of_a_dimension_pair_is_a_net_for_all_interval_shapes() {
        for (x, y) in [(0, 0), (5, 9), (639, 359)] {
            let p = PixelPattern::new(x, y);
            for pair in [LENS_PAIR, light_pair(0), light_pair(7)] {
                for m in 0..=8u32 {
                    for a in 0..=m {
                        let (cx, cy) = (1u32 << a, 1u32 << (m - a));
                        let mut seen = vec![0u32; (cx * cy) as usize];
                        for i in 0..1u32 << m {
                            let [u, v] = p.pair(i, pair);
                            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
                            seen[(cell(v, cy) * cx + cell(u, cx)) as usize] += 1;
                        }
                        assert!(
                            seen.iter().all(|&c| c == 1),
                            "({x},{y}) pair {pair} m={m} a={a}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn dimension_pairs_are_not_tied_to_the_position_or_to_each_other() {
        // Were a pair tied to the pixel position (or to another pair), the half of the pixel
        // a sample falls in would fix the half of the lens or the light it takes. Over many
        // pixels and samples, each half of one meets each half of the other about as often.
        let mut same = [0u32; 2];
        let mut total = 0u32;
        for y in 0..32 {
            for x in 0..32 {
                let p = PixelPattern::new(x, y);
                for i in 0..16 {
                    let (u, _) = p.sample(i);
                    let [lens, _] = p.pair(i, LENS_PAIR);
                    let [light, _] = p.pair(i, light_pair(0));
                    same[0] += u32::from((u < 0.5) == (lens < 0.5));
                    same[1] += u32::from((lens < 0.5) == (light < 0.5));
                    total += 1;
                }
            }
        }
        for s in same {
            let share = s as f32 / total as f32;
            assert!((share - 0.5).abs() < 0.03, "{share}");
        }
    }

    #[test]
    fn patterns_depend_on_position_only_and_differ_between_pixels() {
        assert_eq!(PixelPattern::new(3, 4), PixelPattern::new(3, 4));
        assert_eq!(
            PixelPattern::new(3, 4).sample(7),
            PixelPattern::new(3, 4).sample(7)
        );
        assert_ne!(
            PixelPattern::new(3, 4).sample(0),
            PixelPattern::new(4, 3).sample(0)
        );
    }

    #[test]
    fn unscrambled_sobol_starts_as_expected() {
        let half = 1u32 << 31;
        assert_eq!(sobol2(0), (0, 0));
        assert_eq!(sobol2(1), (half, half));
        assert_eq!(sobol2(2), (half >> 1, 3 << 30));
        assert_eq!(sobol2(3), (3 << 30, 1 << 30));
    }

    /// A pixel's samples and instants are the same from the table as computed bit by bit,
    /// on both sides of the table's end.
    #[test]
    fn tabled_points_are_the_computed_ones() {
        let pattern = PixelPattern::new(17, 5);
        for i in 0..200u32 {
            let (a, b) = sobol2(i);
            let keys = pattern.keys;
            let computed = (
                to_unit(owen_scramble(a, keys[0])),
                to_unit(owen_scramble(b, keys[1])),
            );
            assert_eq!(pattern.sample(i), computed, "sample {i}");
            let time = to_unit(owen_scramble(sobol3(i), keys[2]));
            assert_eq!(pattern.time(i), time, "instant {i}");
        }
    }

    #[test]
    fn error_estimate_of_known_samples() {
        let mut m = Moments::default();
        for _ in 0..3 {
            m.add(Vec3A::splat(1.0));
            assert_eq!(m.error(), f32::INFINITY);
        }
        // Tone-mapped samples 0.5, 0.5, 0.5, 0: the 2-sample mean is 0.5, the 4-sample mean
        // 0.375; that change (0.125) and the one before (0) make the estimate
        // 2^(-3/4)·0.125 of full scale.
        m.add(Vec3A::ZERO);
        assert!((m.error() - NET_DECAY * 0.125 * 255.0).abs() < 1e-3);
        assert_eq!(m.mean(), Vec3A::splat(0.75));
        // Identical samples have no error, whatever their value.
        let mut flat = Moments::default();
        for _ in 0..4 {
            flat.add(Vec3A::new(0.3, 2.0, 7.0));
        }
        assert!(flat.error() < 1e-4);
        // The worst channel decides, and an earlier change still counts after a calm
        // doubling: samples 1,0 then 1,0 (blue only) give changes 0.25 at n = 2, 0 at n = 4.
        let mut one = Moments::default();
        for b in [1.0, 0.0, 1.0, 0.0] {
            one.add(Vec3A::new(0.2, 0.2, b));
        }
        let expected = NET_DECAY * NET_DECAY * 0.25 * 255.0;
        assert!((one.error() - expected).abs() < 1e-3, "{}", one.error());
    }

    #[test]
    fn on_average_the_error_estimate_tracks_the_true_error_of_an_edge_pixel() {
        // A slanted edge, white (tone 1) below the line u + 0.37·v = 0.61, black above; its
        // true coverage is found with a fine grid. One pixel's two halves can agree by
        // chance, so the claim is about the average over many pixels' scrambles.
        let inside = |u: f32, v: f32| u + 0.37 * v < 0.61;
        let grid = 2048;
        let covered = (0..grid * grid)
            .filter(|i| {
                let (u, v) = ((i % grid) as f32 + 0.5, (i / grid) as f32 + 0.5);
                inside(u / grid as f32, v / grid as f32)
            })
            .count() as f32
            / (grid * grid) as f32;
        let mut estimated = [0.0f32; 2];
        let mut actual = [0.0f32; 2];
        for px in 0..400 {
            let p = PixelPattern::new(px % 20, px / 20);
            let mut m = Moments::default();
            for i in 0..64 {
                let (u, v) = p.sample(i);
                m.add(Vec3A::splat(if inside(u, v) { f32::INFINITY } else { 0.0 }));
                let slot = match m.n {
                    16 => 0,
                    64 => 1,
                    _ => continue,
                };
                estimated[slot] += m.error() / 400.0;
                actual[slot] += 255.0 * (m.tone_sum.x / m.n as f32 - covered).abs() / 400.0;
            }
        }
        for slot in 0..2 {
            let (e, a) = (estimated[slot], actual[slot]);
            assert!(
                e > a / 3.0 && e < a * 3.0,
                "n={}: {e} vs {a}",
                [16, 64][slot]
            );
        }
        assert!(estimated[1] < estimated[0] && actual[1] < actual[0]);
    }

    #[test]
    fn stronger_edges_start_with_more_samples() {
        assert_eq!(min_samples(0.0, 2.0, 32), MIN_SAMPLES);
        assert_eq!(min_samples(10.0, 2.0, 32), 4);
        // 0.2·100/2 = 10 → 10^(4/3) ≈ 21.5 → 32.
        assert_eq!(min_samples(100.0, 2.0, 64), 32);
        assert_eq!(min_samples(255.0, 0.01, 32), 32);
        assert_eq!(min_samples(255.0, 2.0, 2), 2);
    }
}
