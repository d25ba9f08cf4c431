//! Image tiles: which primitives a ray from (or to) a point may meet, looked up by where it
//! crosses an image seen from that point. For the camera this is the vista buffer of classic
//! ray tracers: every primitive's bounds are projected onto the image once, each tile of
//! `TILE`×`TILE` pixels lists the primitives whose footprints cover it, nearest first, and a
//! camera ray tests its tile's list only until the next entry lies farther than its closest
//! hit so far, walking no hierarchy. Around a light, an image that takes in the whole scene
//! does the same for shadow rays (`ImageTiles::around`): a segment ending at the light is seen
//! from it as one point, and only the entries nearer to the light than the segment's far end
//! can lie on it.

use crate::math::Aabb;
use glam::{Vec3A, Vec4};

/// Pixels per side of a tile: the blocks camera rays are traced in.
const TILE: usize = 4;
/// Widening of every footprint, in pixels. Round-off in projecting a box's corners and in
/// placing a ray on the image is thousandths of a pixel (single precision, offsets of
/// thousands of pixels), and a hit test that counts a grazing ray as a hit is off by less.
const MARGIN: f32 = 1.0;
/// Share taken off a box's distance from the eye to bound the distance of any hit in it from
/// below: the box holds its primitive, and a computed hit's distance is off by far less.
const NEAR_SLACK: f32 = 1e-3;
/// Most primitives reaching the plane through the eye (whose footprints are unbounded, so
/// that every tile lists them); with more, tiles are not kept and camera rays walk the
/// hierarchy.
const AROUND_MAX: usize = 16;
/// Most entries the tiles hold: this many per primitive, and as many again per tile; with
/// more, tiles are not kept (a scene seen from inside a dense cloud).
const ENTRIES_PER_PRIMITIVE: usize = 8;
const ENTRIES_PER_TILE: usize = 16;
/// Lists are padded to a multiple of this many entries, so that they are tested four at once.
const GROUP: usize = 4;
/// Tiles of an image around a light, per primitive: finer tiles list fewer primitives each,
/// up to where more tiles stop shortening the lists (docs/benchmarks-history.md §9.8).
const TILES_PER_PRIMITIVE: usize = 8;
/// Most pixels along a side of an image around a light (1 MiB of tile starts).
const AROUND_SIDE_MAX: usize = 2048;
/// Widest half-angle an image around a light may take in (its tangent): wider, the pixels at
/// its edges stretch, and a scene that wraps round the light is left to the hierarchy.
const AROUND_TAN_MAX: f32 = 2.0;

/// A pinhole camera's image: where a point in front of the eye is seen, in pixels from the
/// image's top-left corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageView {
    /// Where the rays start.
    pub eye: Vec3A,
    /// Unit view direction times the image-plane distance, in pixels.
    pub forward: Vec3A,
    /// Unit vector along the image's rows (rightwards).
    pub right: Vec3A,
    /// Unit vector along the image's columns (upwards).
    pub up: Vec3A,
    /// Half the image's width, in pixels.
    pub half_w: f32,
    /// Half the image's height, in pixels.
    pub half_h: f32,
}

impl ImageView {
    /// Where the ray from the eye along `d` (of any length) crosses the image plane, if it
    /// runs forwards: the image position of every point `eye + s·d`, `s > 0`.
    #[inline]
    pub fn pixel_of(&self, d: Vec3A) -> Option<(f32, f32)> {
        let s = self.depth(d);
        if s.is_nan() || s <= 0.0 {
            return None;
        }
        Some((
            self.half_w + d.dot(self.right) / s,
            self.half_h - d.dot(self.up) / s,
        ))
    }

    /// A direction (not unit) of the ray from the eye through image position (`x`, `y`): the
    /// inverse of `pixel_of`.
    #[inline]
    pub fn through(&self, x: f32, y: f32) -> Vec3A {
        self.forward + self.right * (x - self.half_w) + self.up * (self.half_h - y)
    }

    /// Depth of the point `eye + d` in image-plane distances (positive in front of the eye).
    #[inline]
    fn depth(&self, d: Vec3A) -> f32 {
        d.dot(self.forward) / self.forward.length_squared()
    }

    /// A square image `side` pixels wide, from `eye` towards the centre of `bounds`, that takes
    /// in all of it; `None` if no image narrower than `AROUND_TAN_MAX` does.
    fn around(eye: Vec3A, bounds: &Aabb, side: usize) -> Option<ImageView> {
        let ahead = (bounds.centroid() - eye).try_normalize()?;
        let right = ahead.any_orthonormal_vector();
        let up = right.cross(ahead);
        let mut widest = 0.0f32;
        for k in 0..8 {
            let d = corner(bounds, k) - eye;
            let s = d.dot(ahead);
            let off = d.dot(right).abs().max(d.dot(up).abs());
            // Also rejects a box whose corners are not numbers.
            if !(s > 0.0 && off <= AROUND_TAN_MAX * s) {
                return None;
            }
            widest = widest.max(off / s);
        }
        let half = side as f32 / 2.0;
        Some(ImageView {
            eye,
            forward: ahead * (half / widest.max(1e-3)),
            right,
            up,
            half_w: half,
            half_h: half,
        })
    }
}

/// A view's image-plane coordinates of points, in one product per axis (for the eight
/// corners of a box at a time).
struct Projector {
    eye: Vec3A,
    /// Per world axis, what a unit step along it adds to a point's offset along the image's
    /// rows, its offset along its columns (upwards), and its depth (as `ImageView::depth`).
    steps: [Vec3A; 3],
}

impl Projector {
    fn new(view: &ImageView) -> Projector {
        let depth = view.forward / view.forward.length_squared();
        let step = |a: usize| Vec3A::new(view.right[a], view.up[a], depth[a]);
        Projector {
            eye: view.eye,
            steps: [step(0), step(1), step(2)],
        }
    }

    /// The corners of `b` as their offsets along the image's rows and columns times their
    /// depth, and their depth (`x/z` and `y/z` place a corner on the image): per coordinate,
    /// the four corners at the low end of `z`, then the four at its high end.
    #[inline]
    fn corners(&self, b: &Aabb) -> [[Vec4; 2]; 3] {
        let d = b.min - self.eye;
        let e = b.max - b.min;
        let [sx, sy, sz] = self.steps;
        let base = sx * d.x + sy * d.y + sz * d.z;
        let (ex, ey, ez) = (sx * e.x, sy * e.y, sz * e.z);
        let coordinate = |c: usize| {
            let low = Vec4::splat(base[c]) + Vec4::new(0.0, ex[c], ey[c], ex[c] + ey[c]);
            [low, low + Vec4::splat(ez[c])]
        };
        [coordinate(0), coordinate(1), coordinate(2)]
    }
}

/// Corner `k` of `b`: bit `a` of `k` picks the high end along axis `a`.
#[inline]
fn corner(b: &Aabb, k: usize) -> Vec3A {
    let pick = |axis: usize| {
        if k >> axis & 1 == 0 {
            b.min[axis]
        } else {
            b.max[axis]
        }
    };
    Vec3A::new(pick(0), pick(1), pick(2))
}

/// Which primitives each tile of the image may show (see the module doc).
#[derive(Clone, Debug)]
pub struct ImageTiles {
    view: ImageView,
    width: f32,
    height: f32,
    cols: usize,
    rows: usize,
    /// Per tile, where its groups start in `near` (and, times `GROUP`, in `ids`); then the end.
    starts: Box<[u32]>,
    /// Per tile, its primitives nearest first, padded with the caller's `pad` to whole groups.
    ids: Box<[u32]>,
    /// Per group: no hit in its primitives lies closer to the eye than this.
    near: Box<[f32]>,
    /// Whether every primitive appears within the image, none around the eye (as around a
    /// light, `ImageTiles::around`): a ray from the eye that crosses the image plane outside
    /// it, by more than `MARGIN`, then meets none of them.
    holds_all: bool,
}

/// Tiles `c0..=c1` of rows `r0..=r1` (none when `c0 > c1`).
#[derive(Clone, Copy, Debug)]
struct Rect {
    c0: u16,
    c1: u16,
    r0: u16,
    r1: u16,
}

impl Rect {
    const NONE: Rect = Rect {
        c0: 1,
        c1: 0,
        r0: 1,
        r1: 0,
    };

    fn area(self) -> usize {
        (usize::from(self.c1) + 1).saturating_sub(self.c0.into())
            * (usize::from(self.r1) + 1).saturating_sub(self.r0.into())
    }

    /// Its tiles, one range of them a row, numbered as in `ImageTiles::starts`.
    fn rows(self, cols: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
        let (c0, c1) = (usize::from(self.c0), usize::from(self.c1) + 1);
        (usize::from(self.r0)..=usize::from(self.r1))
            .map(move |row| row * cols + c0..row * cols + c1)
    }
}

/// Sorts `keys` by their upper halves, keeping the order of keys whose upper halves are
/// equal: a least-significant-digit radix sort, 11 bits a pass. The tiles' keys are a
/// distance's bits above a primitive's number, pushed in order of number, so this is their
/// order as whole numbers, in linear time where a comparison sort takes n log n
/// (docs/benchmarks-history.md §9.11).
fn sort_by_upper_half(keys: &mut Vec<u64>) {
    const DIGIT_BITS: u32 = 11;
    const DIGITS: usize = 1 << DIGIT_BITS;
    let mut sorted = vec![0u64; keys.len()];
    for shift in (32..64).step_by(DIGIT_BITS as usize) {
        let digit = |k: u64| (k >> shift) as usize & (DIGITS - 1);
        let mut starts = vec![0usize; DIGITS];
        for &k in keys.iter() {
            starts[digit(k)] += 1;
        }
        // All keys share this digit: the pass would move nothing.
        if starts.contains(&keys.len()) {
            continue;
        }
        let mut at = 0;
        for s in starts.iter_mut() {
            (*s, at) = (at, at + *s);
        }
        for &k in keys.iter() {
            let d = digit(k);
            sorted[starts[d]] = k;
            starts[d] += 1;
        }
        std::mem::swap(keys, &mut sorted);
    }
}

/// Where a primitive's bounds appear on an image.
enum Footprint {
    /// Wholly behind the eye: no ray from it meets them.
    Behind,
    /// Reaching the plane through the eye: anywhere.
    Around,
    /// These tiles (none when off the image).
    Tiles(Rect),
}

impl ImageTiles {
    /// Tiles of the `width`×`height` image of `view` for the `n` primitives with (finite)
    /// bounds `bound(i)`, numbered by `i`; lists are padded with `pad`, a number the
    /// caller's tests never hit. `None` when too much lies around the eye or the lists would
    /// hold too many entries (`AROUND_MAX`, `ENTRIES_PER_PRIMITIVE`), or the image has more
    /// tiles along a side than a `u16` counts.
    pub fn new(
        view: ImageView,
        size: (u32, u32),
        n: usize,
        bound: impl Fn(usize) -> Aabb,
        pad: u32,
    ) -> Option<ImageTiles> {
        Some(ImageTiles::build(view, size, n, bound, pad)?.0)
    }

    /// `new`, and how many primitives reach the plane through the eye.
    fn build(
        view: ImageView,
        (width, height): (u32, u32),
        n: usize,
        bound: impl Fn(usize) -> Aabb,
        pad: u32,
    ) -> Option<(ImageTiles, usize)> {
        let cols = (width as usize).div_ceil(TILE);
        let rows = (height as usize).div_ceil(TILE);
        if cols == 0 || rows == 0 || cols.max(rows) > usize::from(u16::MAX) {
            return None;
        }
        let mut tiles = ImageTiles {
            view,
            width: width as f32,
            height: height as f32,
            cols,
            rows,
            starts: Box::default(),
            ids: Box::default(),
            near: Box::default(),
            holds_all: false,
        };
        let everywhere = Rect {
            c0: 0,
            c1: (cols - 1) as u16,
            r0: 0,
            r1: (rows - 1) as u16,
        };
        let cap = ENTRIES_PER_PRIMITIVE * n + ENTRIES_PER_TILE * cols * rows;
        let project = Projector::new(&view);
        let mut count = vec![0u32; cols * rows];
        let mut rects = Vec::with_capacity(n);
        // Each primitive with a footprint as its distance's bits (which order like the
        // distance, for one that is not negative) above its number: sorted, they come
        // nearest first, and each tile's list is filled in that order.
        let mut order = Vec::with_capacity(n);
        let (mut entries, mut around) = (0, 0);
        for i in 0..n {
            let b = bound(i);
            let rect = match tiles.footprint(&project, &b) {
                Footprint::Behind => Rect::NONE,
                Footprint::Around => {
                    around += 1;
                    everywhere
                }
                Footprint::Tiles(rect) => rect,
            };
            rects.push(rect);
            if rect.area() == 0 {
                continue;
            }
            entries += rect.area();
            if around > AROUND_MAX || entries > cap {
                return None;
            }
            for row in rect.rows(cols) {
                count[row].iter_mut().for_each(|c| *c += 1);
            }
            let distance = (view.eye - view.eye.clamp(b.min, b.max)).length();
            order.push(u64::from((distance * (1.0 - NEAR_SLACK)).to_bits()) << 32 | i as u64);
        }
        sort_by_upper_half(&mut order);
        let mut starts = Vec::with_capacity(cols * rows + 1);
        let mut groups = 0;
        for &k in &count {
            starts.push(groups);
            groups += (k as usize).div_ceil(GROUP) as u32;
        }
        starts.push(groups);
        let mut ids = vec![pad; groups as usize * GROUP];
        let mut near = vec![0.0f32; groups as usize];
        // `count` becomes each tile's entries placed so far.
        count.fill(0);
        for key in order {
            let i = key as u32;
            for row in rects[i as usize].rows(cols) {
                for (placed, &start) in count[row.clone()].iter_mut().zip(&starts[row]) {
                    let k = *placed as usize;
                    *placed += 1;
                    let group = start as usize + k / GROUP;
                    ids[group * GROUP + k % GROUP] = i;
                    if k.is_multiple_of(GROUP) {
                        near[group] = f32::from_bits((key >> 32) as u32);
                    }
                }
            }
        }
        tiles.starts = starts.into_boxed_slice();
        tiles.ids = ids.into_boxed_slice();
        tiles.near = near.into_boxed_slice();
        Some((tiles, around))
    }

    /// Tiles of an image from `eye` that takes in all `n` primitives (bounds `bound(i)`, all
    /// within `all`), for segments that end at `eye` (`towards`); `None` when no image
    /// takes them in (`AROUND_TAN_MAX`) or as `new`.
    pub fn around(
        eye: Vec3A,
        all: &Aabb,
        n: usize,
        bound: impl Fn(usize) -> Aabb,
        pad: u32,
    ) -> Option<ImageTiles> {
        let tiles_per_side = ((TILES_PER_PRIMITIVE * n) as f64).sqrt().ceil() as usize;
        let side = (TILE * tiles_per_side).clamp(4 * TILE, AROUND_SIDE_MAX);
        let view = ImageView::around(eye, all, side)?;
        let side = side as u32;
        let (mut tiles, around) = ImageTiles::build(view, (side, side), n, bound, pad)?;
        // The image takes in every corner of `all` (`ImageView::around`), so every primitive
        // in front of the eye.
        tiles.holds_all = around == 0;
        Some(tiles)
    }

    /// The tiles a box covers: the pixels between its corners' images, widened by `MARGIN`
    /// (a box in front of the eye appears within the hull of its corners' images).
    fn footprint(&self, project: &Projector, b: &Aabb) -> Footprint {
        let [xs, ys, zs] = project.corners(b);
        if zs[0].max(zs[1]).max_element() < 0.0 {
            return Footprint::Behind;
        }
        // Also a box whose depths are not numbers: nothing can be said of where it is.
        let nearest = zs[0].min(zs[1]).min_element();
        if nearest.is_nan() || nearest <= 0.0 {
            return Footprint::Around;
        }
        // Image offsets from the centre, `x` rightwards and `y` upwards.
        let (r0, r1) = (zs[0].recip(), zs[1].recip());
        let (x, y) = ([xs[0] * r0, xs[1] * r1], [ys[0] * r0, ys[1] * r1]);
        let (x0, x1) = (x[0].min(x[1]).min_element(), x[0].max(x[1]).max_element());
        let (y0, y1) = (y[0].min(y[1]).min_element(), y[0].max(y[1]).max_element());
        let view = &self.view;
        let span = |lo: f32, hi: f32, size: f32, tiles: usize| {
            let (lo, hi) = (lo - MARGIN, hi + MARGIN);
            // Also a span that is not a number.
            if !(hi >= 0.0 && lo < size) {
                return None;
            }
            // Through `i32`: one conversion instruction where `usize` takes several.
            let tile = |p: f32| ((p.clamp(0.0, size) as i32 as usize) / TILE).min(tiles - 1) as u16;
            Some((tile(lo), tile(hi)))
        };
        let cols = span(view.half_w + x0, view.half_w + x1, self.width, self.cols);
        let rows = span(view.half_h - y1, view.half_h - y0, self.height, self.rows);
        match (cols, rows) {
            (Some((c0, c1)), Some((r0, r1))) => Footprint::Tiles(Rect { c0, c1, r0, r1 }),
            _ => Footprint::Tiles(Rect::NONE),
        }
    }

    /// The primitives a ray from `origin` along `dir` may meet, as a list padded to whole
    /// groups of four, nearest first, with each group's least distance (see `near`), if the
    /// ray starts at the eye and crosses the image.
    #[inline]
    pub fn candidates(&self, origin: Vec3A, dir: Vec3A) -> Option<(&[u32], &[f32])> {
        if origin != self.view.eye {
            return None;
        }
        self.tile_of(dir)
    }

    /// The primitives the segment from `from` to the eye may meet, as `candidates` gives
    /// them (the segment's points are those of the eye's ray through `from` up to it).
    #[inline]
    pub fn towards(&self, from: Vec3A) -> Option<(&[u32], &[f32])> {
        let dir = from - self.view.eye;
        self.tile_of(dir).or_else(|| self.off_image(dir))
    }

    /// The list of the tile the eye's ray along `dir` crosses, if it crosses the image.
    #[inline]
    fn tile_of(&self, dir: Vec3A) -> Option<(&[u32], &[f32])> {
        let (x, y) = self.view.pixel_of(dir)?;
        if !(x >= 0.0 && x < self.width && y >= 0.0 && y < self.height) {
            return None;
        }
        let tile = (y as usize / TILE) * self.cols + x as usize / TILE;
        let (from, to) = (self.starts[tile] as usize, self.starts[tile + 1] as usize);
        Some((&self.ids[from * GROUP..to * GROUP], &self.near[from..to]))
    }

    /// For the eye's ray along `dir` that crosses no tile: an empty list when the image
    /// holds every primitive and the ray crosses the image plane beyond their widened
    /// footprints, else none.
    #[cold]
    #[inline(never)]
    fn off_image(&self, dir: Vec3A) -> Option<(&[u32], &[f32])> {
        let (x, y) = self.view.pixel_of(dir)?;
        let beyond = |p: f32, size: f32| p < -MARGIN || p > size + MARGIN;
        (self.holds_all && (beyond(x, self.width) || beyond(y, self.height))).then_some((&[], &[]))
    }

    /// Bytes the tiles and their lists hold.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + (self.starts.len() + self.ids.len() + self.near.len()) * 4
    }
}

#[cfg(test)]
mod tests {
    use super::super::segment_entry as entry;
    use super::*;
    use proptest::prelude::*;

    fn vec3(scale: f32) -> impl Strategy<Value = Vec3A> {
        (-scale..scale, -scale..scale, -scale..scale).prop_map(|(x, y, z)| Vec3A::new(x, y, z))
    }

    fn boxes() -> impl Strategy<Value = Vec<Aabb>> {
        prop::collection::vec((vec3(10.0), vec3(2.0)), 1..=40).prop_map(|v| {
            v.into_iter()
                .map(|(c, e)| Aabb::new(c - e.abs(), c + e.abs()))
                .collect()
        })
    }

    /// A view from `eye` along `ahead` (not vertical) with `half_w`/`half_h` pixels and a
    /// horizontal half-angle whose tangent is `spread`.
    fn view(eye: Vec3A, ahead: Vec3A, spread: f32, (w, h): (u32, u32)) -> ImageView {
        let ahead = ahead.normalize();
        let right = ahead.cross(Vec3A::Y).normalize();
        ImageView {
            eye,
            forward: ahead * (w as f32 / 2.0 / spread),
            right,
            up: right.cross(ahead),
            half_w: w as f32 / 2.0,
            half_h: h as f32 / 2.0,
        }
    }

    /// Whether `list` (with its groups' distances) offers box `i`, no nearer than `t`.
    fn offers((ids, near): (&[u32], &[f32]), i: usize, t: f64) -> bool {
        let at = ids.iter().position(|&id| id as usize == i);
        at.is_some_and(|k| near[k / GROUP] as f64 <= t)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// The radix sort puts keys in the order of a stable sort by their upper halves:
        /// upper halves from a few values (ties, and digits that all keys share) or from any,
        /// lower halves in any order.
        #[test]
        fn keys_sort_by_upper_half_keeping_the_order_of_ties(
            keys in prop::collection::vec(
                (prop_oneof![0u64..4, 0u64..=u64::from(u32::MAX)], any::<u32>()),
                0..3000,
            ),
        ) {
            let mut keys: Vec<u64> =
                keys.into_iter().map(|(hi, lo)| hi << 32 | u64::from(lo)).collect();
            let mut expected = keys.clone();
            expected.sort_by_key(|k| k >> 32);
            sort_by_upper_half(&mut keys);
            prop_assert_eq!(keys, expected);
        }

        /// Every box a ray from the eye through the image meets (boxes in front, behind and
        /// around the eye) is in the list of the ray's tile, in a group listed no farther
        /// than where the ray enters it; and groups come nearest first.
        #[test]
        fn a_camera_ray_finds_every_box_it_meets_in_its_tile(
            eye in vec3(12.0),
            ahead in vec3(1.0),
            spread in 0.2f32..2.0,
            bounds in boxes(),
            at in (0.0f32..1.0, 0.0f32..1.0),
        ) {
            prop_assume!(ahead.length() > 0.1 && ahead.normalize().y.abs() < 0.99);
            let size = (37, 23);
            let v = view(eye, ahead, spread, size);
            let Some(tiles) = ImageTiles::new(v, size, bounds.len(), |i| bounds[i], u32::MAX)
            else {
                // Only with more boxes around the eye than a tile list takes.
                let around = bounds.iter().filter(|b| {
                    (0..8).any(|k| v.depth(corner(b, k) - eye) <= 0.0)
                }).count();
                prop_assert!(around > AROUND_MAX);
                return Ok(());
            };
            let sorted = tiles.starts.windows(2).all(|t| {
                tiles.near[t[0] as usize..t[1] as usize].windows(2).all(|w| w[0] <= w[1])
            });
            prop_assert!(sorted);
            let (x, y) = (at.0 * size.0 as f32, at.1 * size.1 as f32);
            let dir = v.through(x, y).normalize();
            let list = tiles.candidates(eye, dir);
            prop_assert!(list.is_some(), "a ray through the image at ({x}, {y})");
            for (i, b) in bounds.iter().enumerate() {
                if let Some(t) = entry(b, eye, dir, f64::INFINITY) {
                    prop_assert!(offers(list.unwrap(), i, t), "box {i} {b:?} met at {t}");
                }
            }
            prop_assert!(tiles.candidates(eye + Vec3A::X * 1e-3, dir).is_none());
        }

        /// Around a point outside all the boxes (a light), every box a segment from a point
        /// in view to that point meets is listed where the point sees the segment's start, no
        /// farther than the box's nearest point on it.
        #[test]
        fn a_segment_to_the_light_finds_every_box_it_meets(
            light in vec3(40.0),
            bounds in boxes(),
            from in vec3(12.0),
        ) {
            let all = bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
            let Some(tiles) = ImageTiles::around(light, &all, bounds.len(), |i| bounds[i], u32::MAX)
            else {
                return Ok(());
            };
            check_segment(&tiles, light, &bounds, from)?;
        }

        /// The same for segments through the corner of the scene's box that sets the image's
        /// width, which the light sees on the image's edge (just off it, by round-off).
        #[test]
        fn a_segment_through_the_widest_corner_finds_the_boxes_there(
            light in vec3(40.0),
            bounds in boxes(),
            beyond in 1.0f32..3.0,
        ) {
            let all = bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
            let Some(tiles) = ImageTiles::around(light, &all, bounds.len(), |i| bounds[i], u32::MAX)
            else {
                return Ok(());
            };
            let v = tiles.view;
            let off = |k: usize| {
                let d = corner(&all, k) - light;
                d.dot(v.right).abs().max(d.dot(v.up).abs()) / d.dot(v.forward)
            };
            let widest = (0..8).max_by(|&a, &b| off(a).total_cmp(&off(b))).unwrap();
            let from = light + (corner(&all, widest) - light) * beyond;
            check_segment(&tiles, light, &bounds, from)?;
        }
    }

    /// Every box the segment from `from` to `light` meets is offered where the light sees
    /// `from` (if the tiles answer), no farther from the light than where the segment enters it.
    fn check_segment(
        tiles: &ImageTiles,
        light: Vec3A,
        bounds: &[Aabb],
        from: Vec3A,
    ) -> Result<(), TestCaseError> {
        // A start the image does not take in (outside the scene's box) may be left to the
        // hierarchy.
        let Some(list) = tiles.towards(from) else {
            return Ok(());
        };
        let to_light = light - from;
        let (dir, length) = (to_light.normalize(), to_light.length() as f64);
        for (i, b) in bounds.iter().enumerate() {
            if entry(b, from, dir, length).is_some() {
                // Where the segment enters the box, seen from the light.
                let t = entry(b, light, -dir, length).unwrap_or(length);
                prop_assert!(offers(list, i, t + 1e-3), "box {i} {b:?}");
            }
        }
        Ok(())
    }
}
