//! What adaptive sampling asks of a thin lens: which pixels its blur reaches. The first pass
//! traces pinhole rays through the pixel centres, which the lens's rays through the same
//! pixel converge with in the plane in focus; a pixel may keep its centre only where that is
//! what the lens shows too. A point at depth `z` is spread over its circle of confusion
//! (`PinholeCamera::blur`) around where the pinhole sees it, so a pixel shows the
//! pinhole image of the points whose circles reach it. Points nearer than the plane in focus
//! spread over whatever lies behind them; a point at or behind it is hidden from the lens by
//! nothing the pinhole does not see in front of it. So a pixel keeps its centre when neither
//! its own hit nor a nearer point whose circle reaches it is blurred by more than
//! [`SHARP_RADIUS`], or when everything within the largest such circle is one surface within
//! the flat contrast (blurring it changes nothing). Decided per tile of the image, each as
//! blurred as its most blurred centre: more pixels take samples than need them, never fewer.

use super::pattern::FLAT_CONTRAST;
use glam::Vec3A;

/// Side of the square tiles the decision is made for, in pixels.
const TILE: usize = 8;

/// Circle-of-confusion radius (pixels) up to which a point is taken as sharp: half a pixel,
/// a circle one pixel across, which moves a pixel by a fraction of what anti-aliasing
/// already averages over.
pub const SHARP_RADIUS: f32 = 0.5;

/// One pixel centre of the first pass, as this module reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Centre {
    /// The radius of the circle of confusion of the point it hit (0 for the background,
    /// which is the same everywhere), negative for a point nearer than the plane in focus.
    pub blur: f32,
    /// The primitive it hit.
    pub prim: u32,
    /// Its tone-mapped radiance.
    pub tone: Vec3A,
}

/// What the centres of one tile hold.
#[derive(Clone, Copy, Debug)]
struct Tile {
    /// The largest circle of confusion of its centres.
    blur: f32,
    /// The largest of those nearer than the plane in focus (0 when none is).
    near: f32,
    /// The primitive all its centres hit, or `None` when they hit several.
    prim: Option<u32>,
    /// The least and greatest tones, per channel.
    lo: Vec3A,
    hi: Vec3A,
}

/// Per pixel of a `w × h` image whose centres `centre(i)` gives (row-major), whether a lens
/// blur reaches it (see the module doc).
pub(super) fn blurred((w, h): (usize, usize), centre: impl Fn(usize) -> Centre) -> Vec<bool> {
    let (tw, th) = (w.div_ceil(TILE), h.div_ceil(TILE));
    let mut tiles = vec![
        Tile {
            blur: 0.0,
            near: 0.0,
            prim: None,
            lo: Vec3A::INFINITY,
            hi: Vec3A::NEG_INFINITY,
        };
        tw * th
    ];
    for y in 0..h {
        for x in 0..w {
            let c = centre(y * w + x);
            let t = &mut tiles[(y / TILE) * tw + x / TILE];
            if t.lo.x == f32::INFINITY {
                t.prim = Some(c.prim);
            } else if t.prim != Some(c.prim) {
                t.prim = None;
            }
            t.blur = t.blur.max(c.blur.abs());
            t.near = t.near.max(-c.blur);
            (t.lo, t.hi) = (t.lo.min(c.tone), t.hi.max(c.tone));
        }
    }
    let farthest_near = tiles.iter().map(|t| t.near).fold(0.0f32, f32::max);
    let mut out = vec![false; w * h];
    for ty in 0..th {
        for tx in 0..tw {
            let at = |(qx, qy): (usize, usize)| &tiles[qy * tw + qx];
            let own = at((tx, ty));
            let reach = within((tx, ty), (tw, th), farthest_near)
                .map(|(q, gap)| (at(q).near, gap))
                .filter(|&(near, gap)| near > SHARP_RADIUS && gap <= near)
                .fold(own.blur, |r, (near, _)| r.max(near));
            if reach <= SHARP_RADIUS
                || flat(own, within((tx, ty), (tw, th), reach).map(|(q, _)| at(q)))
            {
                continue;
            }
            for y in ty * TILE..((ty + 1) * TILE).min(h) {
                out[y * w + tx * TILE..y * w + ((tx + 1) * TILE).min(w)].fill(true);
            }
        }
    }
    out
}

/// Whether the tiles `around` one (`own`) show one surface, within the flat contrast.
fn flat<'t>(own: &Tile, around: impl Iterator<Item = &'t Tile>) -> bool {
    let Some(prim) = own.prim else {
        return false;
    };
    let (mut lo, mut hi) = (own.lo, own.hi);
    for t in around {
        if t.prim != Some(prim) {
            return false;
        }
        (lo, hi) = (lo.min(t.lo), hi.max(t.hi));
    }
    255.0 * (hi - lo).max_element() <= FLAT_CONTRAST
}

/// The tiles of a `tw × th` grid whose pixels may lie within `radius` pixels of tile `(tx,
/// ty)`'s, with a lower bound of that distance (the gap between the two squares).
fn within(
    (tx, ty): (usize, usize),
    (tw, th): (usize, usize),
    radius: f32,
) -> impl Iterator<Item = ((usize, usize), f32)> {
    let k = (radius / TILE as f32).ceil().min((tw.max(th)) as f32) as usize + 1;
    let rows = ty.saturating_sub(k)..(ty + k + 1).min(th);
    rows.flat_map(move |qy| {
        (tx.saturating_sub(k)..(tx + k + 1).min(tw)).map(move |qx| {
            let apart = |a: usize, b: usize| (a.abs_diff(b).saturating_sub(1) * TILE) as f32;
            ((qx, qy), apart(qx, tx).hypot(apart(qy, ty)))
        })
    })
    .filter(move |&(_, gap)| gap <= radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64×32 image: a grey wall behind, and `near` (a blurred box, nearer than focus) over
    /// the columns 20..28 of rows 8..16.
    fn image(near_blur: f32, wall_blur: f32) -> impl Fn(usize) -> Centre {
        move |i| {
            let (x, y) = (i % 64, i / 64);
            if (20..28).contains(&x) && (8..16).contains(&y) {
                Centre {
                    blur: -near_blur,
                    prim: 1,
                    tone: Vec3A::splat(0.8),
                }
            } else {
                Centre {
                    blur: wall_blur,
                    prim: 0,
                    tone: Vec3A::splat(0.3),
                }
            }
        }
    }

    #[test]
    fn a_blurred_foreground_reaches_sharp_pixels_within_its_circle_only() {
        let out = blurred((64, 32), image(12.0, 0.0));
        // Its own pixels, and wall pixels within 12 of it, take samples.
        assert!(out[12 * 64 + 24]);
        assert!(out[12 * 64 + 35]);
        assert!(out[12 * 64 + 10]);
        // Wall pixels far beyond the circle keep their centres.
        assert!(!out[12 * 64 + 60]);
        assert!(!out[31 * 64 + 60]);
    }

    #[test]
    fn nothing_blurred_or_one_flat_surface_blurred_keeps_every_centre() {
        assert!(blurred((64, 32), image(0.4, 0.0)).iter().all(|&b| !b));
        // A blurred wall alone, far from the box: flat, nothing to blur.
        let out = blurred((64, 32), image(0.0, 5.0));
        assert!(!out[28 * 64 + 60]);
        // Near the box, the wall's blur meets another surface.
        assert!(out[12 * 64 + 30]);
    }
}
