//! Step 2 of the remapper (docs/design/mcc.md §5.2): for every background pixel P and camera c, e_c(P)
//! is the nearest edge pixel of c in P's region (Euclidean distance between pixel centres; ties to
//! the smallest row y, then the smallest column x). If c has no edge pixel in that region, c does
//! not participate at P and e_c(P) is the nearest edge pixel of c anywhere.
//!
//! The transform is Felzenszwalb & Huttenlocher's exact separable one, carrying the argmin along:
//! rows first (nearest feature column in each row, filled from the row's sorted edge pixels), then
//! columns (lower envelope of the parabolas f(y') + (y − y')²). Preferring the smaller index on every tie in both passes gives
//! exactly the raster tie rule: among features at the minimal distance the column pass keeps the
//! smallest row, and within a row every minimal feature is the row pass's (smaller column) choice.
//! Envelope breakpoints are compared as exact integer rationals, so ties are decided exactly.
//!
//! Regions restrict the features and the queries, not the geometry (distances stay straight
//! lines), so each (camera, region) pair runs the transform over the region's bounding box only:
//! the cost is the sum of the bounding-box areas per camera, the image area for compact regions
//! (pathologically interleaved regions, whose boxes overlap, cost more). The fallback for regions
//! where c has no edge pixel runs once per camera, over the union of those regions' boxes only.
//! Cameras run in parallel; each result depends only on its inputs, so any thread count gives the
//! same planes.

use super::grid::{Grid, Layout};
use rayon::prelude::*;

/// "No pixel" in an index plane.
pub(crate) const NONE: u32 = u32::MAX;

/// A rectangle of pixels: columns x0..x1, rows y0..y1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Rect {
    fn width(&self) -> usize {
        self.x1 - self.x0
    }
    fn height(&self) -> usize {
        self.y1 - self.y0
    }
    fn union(&self, other: &Rect) -> Rect {
        Rect {
            x0: self.x0.min(other.x0),
            y0: self.y0.min(other.y0),
            x1: self.x1.max(other.x1),
            y1: self.y1.max(other.y1),
        }
    }
}

/// Buffers one transform reuses (grown to the largest rectangle; nothing is allocated per pixel).
#[derive(Default)]
pub(crate) struct Scratch {
    /// Row pass, row-major: nearest feature column (absolute x) per pixel, or NONE.
    rows: Vec<u32>,
    /// The same, column-major, so the column pass reads memory in order.
    columns: Vec<u32>,
    /// Column pass: envelope sites as (row, f + row²), rows relative to the rectangle, and the
    /// breakpoints between consecutive sites as exact rationals (num, den > 0).
    sites: Vec<(i64, i64)>,
    breaks: Vec<(i64, i64)>,
}

/// Side of the square tiles in which planes are transposed: walking a column of a wide image
/// touches a new page per pixel, and tiles keep both sides of the copy in cache and TLB.
const TILE: usize = 32;

/// `dst[x·h + y] = src[y·w + x]`, tile by tile.
fn transpose(src: &[u32], w: usize, h: usize, dst: &mut [u32]) {
    for ty in (0..h).step_by(TILE) {
        for tx in (0..w).step_by(TILE) {
            for y in ty..(ty + TILE).min(h) {
                for x in tx..(tx + TILE).min(w) {
                    dst[x * h + y] = src[y * w + x];
                }
            }
        }
    }
}

/// The features of a transform: pixel indices inside `rect`, in raster order.
pub(crate) struct Features<'a> {
    pub rect: Rect,
    pub pixels: &'a [u32],
}

/// The pixels a transform must fill, and where: those with `pixel(p)`, all in the `columns`
/// marked true (indexed by x), get their nearest feature in `out` (a plane of the grid).
pub(crate) struct Query<'a, F> {
    pub pixel: F,
    pub columns: &'a [bool],
    pub out: &'a mut [u32],
}

/// The exact nearest-feature transform over `features.rect` of `grid`: for every pixel p of
/// `within` (a part of that rectangle) with `query.pixel(p)`, `query.out[p]` becomes the index of
/// the nearest of the features, ties to the smallest y, then x. `out` is untouched elsewhere, and
/// everywhere when there is no feature. A column x with `!query.columns[x]` must hold no pixel
/// with `query.pixel(p)`: its column pass is skipped.
///
/// The row pass fills `within`'s columns of every row of `rect` from that row's features (the
/// feature lists are short: edges are a perimeter); the column pass builds each envelope from all
/// of `rect`'s rows and reads it out at `within`'s rows. Both passes read memory in order: the row
/// pass's result is transposed for the column pass, which writes `out` column by column (the rows
/// it touches stay in cache from one column to the next).
pub(crate) fn feature_transform(
    grid: Grid,
    features: Features,
    within: Rect,
    query: Query<impl Fn(usize) -> bool>,
    scratch: &mut Scratch,
) {
    let width = grid.width;
    let Features { rect, pixels: features } = features;
    let Query { pixel: query, columns: wanted, out } = query;
    let rh = rect.height();
    let (qw, qh) = (within.width(), within.height());
    if features.is_empty() || rect.width() == 0 || rh == 0 || qw == 0 || qh == 0 {
        return;
    }
    let Scratch { rows, columns, sites, breaks } = scratch;
    // Every pass writes all of its buffer: grow them, but spend no time clearing.
    for buffer in [&mut *rows, &mut *columns] {
        if buffer.len() < qw * rh {
            buffer.resize(qw * rh, NONE);
        }
    }
    let (rows, columns) = (&mut rows[..qw * rh], &mut columns[..qw * rh]);
    // Pass 1, rows: nearest feature column, the left one on a tie. Between consecutive features
    // a < b of a row, x goes to a up to (a + b) / 2 (integer division: the tie goes left), to b
    // after; before the first and after the last the end feature holds.
    let mut next = features.partition_point(|&p| (p as usize) < rect.y0 * width);
    for (ry, row) in rows.chunks_exact_mut(qw).enumerate() {
        let end_of_row = ((rect.y0 + ry + 1) * width) as u32;
        let start = next;
        while next < features.len() && features[next] < end_of_row {
            next += 1;
        }
        let in_row = &features[start..next];
        let Some((&first, rest)) = in_row.split_first() else {
            row.fill(NONE);
            continue;
        };
        // u32 division: several times cheaper than usize division on x86-64.
        let x_of = |p: u32| p % width as u32;
        let mut filled = within.x0;
        let mut current = x_of(first);
        for &p in rest {
            let b = x_of(p);
            let upto = ((current + b) as usize / 2 + 1).clamp(filled, within.x1);
            row[filled - within.x0..upto - within.x0].fill(current);
            filled = upto;
            current = b;
        }
        row[filled - within.x0..].fill(current);
    }
    transpose(rows, qw, rh, columns);
    // Pass 2, columns: lower envelope of the parabolas f(y') + (y − y')², f(y') = (x − column)².
    let skip = within.y0 - rect.y0;
    for (rx, column) in columns.chunks_exact(rh).enumerate() {
        if !wanted[within.x0 + rx] {
            // Nothing to write in this column.
            continue;
        }
        let x = (within.x0 + rx) as i64;
        sites.clear();
        breaks.clear();
        for (q, &c) in column.iter().enumerate() {
            if c == NONE {
                continue;
            }
            let (qi, hq) = (q as i64, (x - c as i64) * (x - c as i64) + (q as i64) * (q as i64));
            let mut s = (0, 1);
            while let Some(&(pi, hp)) = sites.last() {
                // Where q's parabola starts to lie at or below p's (q > p: the denominator is > 0).
                s = (hq - hp, 2 * (qi - pi));
                // Pop p if q is already there where p's stretch of the envelope begins (at an exact
                // tie the parabola before p wins, so p would win nowhere).
                match breaks.last() {
                    Some(&(n, d)) if s.0 * d <= n * s.1 => {
                        sites.pop();
                        breaks.pop();
                    }
                    _ => break,
                }
            }
            if !sites.is_empty() {
                breaks.push(s);
            }
            sites.push((qi, hq));
        }
        // Walk the envelope; a breakpoint exactly at y keeps the earlier (smaller-row) site.
        // Written straight into `out`, row-major: consecutive columns write the same few hundred
        // cache lines, which stay in L1, so no transpose back is needed.
        let mut k = 0;
        for qy in 0..qh {
            let ry = (skip + qy) as i64;
            while k < breaks.len() && breaks[k].0 < ry * breaks[k].1 {
                k += 1;
            }
            let p = (within.y0 + qy) * width + x as usize;
            if query(p) {
                let site = sites[k].0 as usize;
                out[p] = ((rect.y0 + site) * width) as u32 + column[site];
            }
        }
    }
}

/// Per camera, e_c(P) for every background pixel, and where each camera participates.
pub(crate) struct NearestEdges {
    /// One plane per camera index: the pixel index of e_c(P) at background pixels, NONE elsewhere.
    pub planes: Vec<Vec<u32>>,
    /// `participates[k][r]`: camera k has an edge pixel in region r.
    pub participates: Vec<Vec<bool>>,
}

/// Per region: bounding box and whether it holds background pixels.
pub(crate) struct RegionBoxes {
    pub rects: Vec<Rect>,
    pub background: Vec<usize>,
}

impl RegionBoxes {
    /// The boxes of the `count` regions of the `region` plane on `layout`'s grid.
    pub(crate) fn new(layout: &Layout, region: &[u32], count: usize) -> Self {
        let (cam, width) = (layout.cam, layout.grid.width);
        let mut rects = vec![Rect { x0: usize::MAX, y0: usize::MAX, x1: 0, y1: 0 }; count];
        let mut background = vec![0; count];
        for (y, (regions, cams)) in region.chunks_exact(width).zip(cam.chunks_exact(width)).enumerate() {
            for (x, (&r, &c)) in regions.iter().zip(cams).enumerate() {
                let b = &mut rects[r as usize];
                b.x0 = b.x0.min(x);
                b.y0 = b.y0.min(y);
                b.x1 = b.x1.max(x + 1);
                b.y1 = b.y1.max(y + 1);
                background[r as usize] += (c == 0) as usize;
            }
        }
        Self { rects, background }
    }
}

/// Step 2 for every camera of `layout`, in the regions of the `region` plane (their `boxes`).
pub(crate) fn nearest_edges(layout: &Layout, region: &[u32], boxes: &RegionBoxes) -> NearestEdges {
    let Layout { grid, cam, edges, cameras } = *layout;
    let Grid { width, height } = grid;
    let regions = boxes.rects.len();
    let mut participates = vec![vec![false; regions]; cameras];
    // Every camera's edge pixels in raster order (one pass over the image).
    let mut edge_lists: Vec<Vec<u32>> = vec![Vec::new(); cameras];
    for (p, _) in edges.iter().enumerate().filter(|(_, e)| **e) {
        let k = cam[p] as usize - 1;
        participates[k][region[p] as usize] = true;
        edge_lists[k].push(p as u32);
    }
    let whole = Rect { x0: 0, y0: 0, x1: width, y1: height };
    // Columns with a background pixel: only they are ever queried (a column all camera pixels,
    // as between the strips of a collage, needs no envelope).
    let mut wanted = vec![false; width];
    for row in cam.chunks_exact(width) {
        wanted.iter_mut().zip(row).for_each(|(w, &c)| *w |= c == 0);
    }
    let wanted = &wanted;
    let plane_of = |k: usize, scratch: &mut Scratch| {
        let mut plane = vec![NONE; cam.len()];
        let (part, all) = (&participates[k], &edge_lists[k]);
        if regions == 1 {
            // No region image: no region logic.
            let query = Query { pixel: |p: usize| cam[p] == 0, columns: wanted, out: &mut plane };
            feature_transform(grid, Features { rect: whole, pixels: all }, whole, query, scratch);
            return plane;
        }
        // Regions without an edge of c still need e_c(P) there: the nearest edge anywhere.
        let mut elsewhere: Option<Rect> = None;
        let mut in_region = Vec::new();
        for (r, rect) in boxes.rects.iter().enumerate() {
            if boxes.background[r] == 0 {
                continue;
            }
            if !part[r] {
                elsewhere = Some(elsewhere.map_or(*rect, |e| e.union(rect)));
                continue;
            }
            let r = r as u32;
            in_region.clear();
            in_region.extend(all.iter().copied().filter(|&p| region[p as usize] == r));
            let query =
                Query { pixel: |p: usize| cam[p] == 0 && region[p] == r, columns: wanted, out: &mut plane };
            feature_transform(grid, Features { rect: *rect, pixels: &in_region }, *rect, query, scratch);
        }
        if let Some(within) = elsewhere {
            let pixel = |p: usize| cam[p] == 0 && !part[region[p] as usize];
            let query = Query { pixel, columns: wanted, out: &mut plane };
            feature_transform(grid, Features { rect: whole, pixels: all }, within, query, scratch);
        }
        plane
    };
    // Cameras in as many groups as threads, each group with one scratch: a scratch grown afresh
    // for every camera would pay the page faults of its first touch every time.
    let mut planes: Vec<Vec<u32>> = vec![Vec::new(); cameras];
    let per_group = cameras.div_ceil(rayon::current_num_threads().clamp(1, cameras.max(1))).max(1);
    planes.par_chunks_mut(per_group).enumerate().for_each(|(g, group)| {
        let mut scratch = Scratch::default();
        for (i, plane) in group.iter_mut().enumerate() {
            *plane = plane_of(g * per_group + i, &mut scratch);
        }
    });
    NearestEdges { planes, participates }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // brute-force references index on purpose
mod tests {
    use super::*;
    use crate::remap::edges::edge_mask;
    use crate::test_util::Rng;

    /// The definition: scan every edge pixel, raster order, strict improvement only.
    fn brute(cam: &[u32], edges: &[bool], region: &[u32], cameras: usize, w: usize) -> Vec<Vec<u32>> {
        let mut planes = vec![vec![NONE; cam.len()]; cameras];
        for k in 0..cameras {
            let c = k as u32 + 1;
            for p in 0..cam.len() {
                if cam[p] != 0 {
                    continue;
                }
                let nearest = |restrict: bool| {
                    let mut best = (i64::MAX, NONE);
                    for q in 0..cam.len() {
                        if edges[q] && cam[q] == c && (!restrict || region[q] == region[p]) {
                            let (dx, dy) = ((p % w) as i64 - (q % w) as i64, (p / w) as i64 - (q / w) as i64);
                            let d = dx * dx + dy * dy;
                            if d < best.0 {
                                best = (d, q as u32);
                            }
                        }
                    }
                    best.1
                };
                let e = nearest(true);
                planes[k][p] = if e != NONE { e } else { nearest(false) };
            }
        }
        planes
    }

    fn check(cam: &[u32], region: &[u32], regions: usize, cameras: usize, grid: Grid) {
        let (w, h) = (grid.width, grid.height);
        let edges = edge_mask(cam, grid);
        let layout = Layout { grid, cam, edges: &edges, cameras };
        let boxes = RegionBoxes::new(&layout, region, regions);
        let got = nearest_edges(&layout, region, &boxes);
        let want = brute(cam, &edges, region, cameras, w);
        for k in 0..cameras {
            for p in 0..cam.len() {
                assert_eq!(got.planes[k][p], want[k][p], "{w}x{h}, camera {k}, pixel ({}, {})", p % w, p / w);
            }
        }
    }

    /// Random blobs of cameras on background, random blocky regions.
    fn random_case(rng: &mut Rng) -> (Vec<u32>, Vec<u32>, usize, usize, Grid) {
        let (w, h) = (1 + rng.below(40) as usize, 1 + rng.below(30) as usize);
        let cameras = 1 + rng.below(5) as usize;
        let mut cam = vec![0u32; w * h];
        for k in 0..cameras {
            for _ in 0..1 + rng.below(3) {
                let (cx, cy) = (rng.below(w as u32) as i64, rng.below(h as u32) as i64);
                let rad = rng.below(6) as i64;
                for p in 0..w * h {
                    let (x, y) = ((p % w) as i64, (p / w) as i64);
                    if (x - cx).pow(2) + (y - cy).pow(2) <= rad * rad {
                        cam[p] = k as u32 + 1;
                    }
                }
            }
        }
        // Cameras that lost all their pixels to later blobs would be absent from a real collage.
        let mut present: Vec<u32> = cam.iter().copied().filter(|&c| c != 0).collect();
        present.sort();
        present.dedup();
        for c in cam.iter_mut().filter(|c| **c != 0) {
            *c = present.binary_search(c).unwrap() as u32 + 1;
        }
        let regions = 1 + rng.below(4) as usize;
        let (bw, bh) = (1 + rng.below(w as u32), 1 + rng.below(h as u32));
        let region: Vec<u32> = (0..w * h)
            .map(|p| ((p % w) as u32 / bw * 3 + (p / w) as u32 / bh * 5) % regions as u32)
            .collect();
        let mut used: Vec<u32> = region.clone();
        used.sort();
        used.dedup();
        let region = region.iter().map(|r| used.binary_search(r).unwrap() as u32).collect();
        (cam, region, used.len(), present.len(), Grid::new(w, h))
    }

    #[test]
    fn equals_brute_force_on_random_collages_with_regions() {
        let mut rng = Rng::new(2024);
        for _ in 0..400 {
            let (cam, region, regions, cameras, grid) = random_case(&mut rng);
            if cameras > 0 {
                check(&cam, &region, regions, cameras, grid);
            }
        }
    }

    #[test]
    fn degenerate_shapes() {
        // 1×1: a lone camera pixel (no background to fill).
        check(&[1], &[0], 1, 1, Grid::new(1, 1));
        // 1×N and N×1.
        let row: Vec<u32> = [0, 1, 0, 0, 2, 0, 0, 0, 1, 0].to_vec();
        check(&row, &[0; 10], 1, 2, Grid::new(10, 1));
        check(&row, &[0; 10], 1, 2, Grid::new(1, 10));
        let regions: Vec<u32> = [0, 0, 0, 1, 1, 1, 1, 0, 0, 0].to_vec();
        check(&row, &regions, 2, 2, Grid::new(10, 1));
        // Camera pixels only on the border: a frame of camera 1 and a top bar of camera 2.
        let (w, h) = (17, 11);
        let cam: Vec<u32> = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                if y == 0 && x < 8 {
                    2
                } else if x == 0 || y == 0 || x == w - 1 || y == h - 1 {
                    1
                } else {
                    0
                }
            })
            .collect();
        check(&cam, &vec![0; w * h], 1, 2, Grid::new(w, h));
        let diag: Vec<u32> = (0..w * h).map(|p| ((p % w) > (p / w)) as u32).collect();
        check(&cam, &diag, 2, 2, Grid::new(w, h));
    }

    #[test]
    fn ties_go_to_the_smallest_row_then_column() {
        // Background pixel (2, 2) is at distance 2 from (0, 2), (2, 0), (4, 2) and (2, 4).
        let w = 5;
        let mut cam = vec![0u32; 25];
        for p in [2, 10, 14, 22] {
            cam[p] = 1;
        }
        let grid = Grid::new(w, 5);
        let edges = edge_mask(&cam, grid);
        let region = vec![0; 25];
        let layout = Layout { grid, cam: &cam, edges: &edges, cameras: 1 };
        let boxes = RegionBoxes::new(&layout, &region, 1);
        let got = nearest_edges(&layout, &region, &boxes);
        assert_eq!(got.planes[0][12], 2, "(2, 0): smallest row");
        // (1, 1) is √2 from (2, 0) and √2 from (0, 2): smallest row again.
        assert_eq!(got.planes[0][6], 2);
        // (3, 3) ties (4, 2) and (2, 4): row 2 first.
        assert_eq!(got.planes[0][18], 14);
    }
}
