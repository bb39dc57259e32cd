//! The pixel grid every blend step works on ([`Grid`]), what the steps share of the collage on
//! it ([`Layout`]), and per-camera planes (one value per pixel per camera, row-major) split into
//! rows. A leaf: the steps take their geometry from here, never from each other.

/// A picture's pixel grid: `width × height` pixels, row-major (pixel p is column p mod width of
/// row p div width).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Grid {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

impl Grid {
    /// A `width × height` grid.
    pub(crate) const fn new(width: usize, height: usize) -> Self {
        Self { width, height }
    }

    /// Its pixel count.
    pub(crate) const fn len(self) -> usize {
        self.width * self.height
    }

    /// The grid of 2 × 2 blocks over this one (a block at an odd edge is partial).
    pub(crate) const fn blocks(self) -> Self {
        Self::new(self.width.div_ceil(2), self.height.div_ceil(2))
    }

    /// Splits per-camera planes on this grid into rows: `rows[y][k]` is row y of plane k (for
    /// row-parallel passes that touch every camera at a pixel).
    pub(crate) fn rows_mut(self, planes: &mut [Vec<f32>]) -> Vec<Vec<&mut [f32]>> {
        let mut rows: Vec<Vec<&mut [f32]>> =
            (0..self.height).map(|_| Vec::with_capacity(planes.len())).collect();
        for plane in planes.iter_mut() {
            debug_assert_eq!(plane.len(), self.len());
            for (row, chunk) in rows.iter_mut().zip(plane.chunks_exact_mut(self.width)) {
                row.push(chunk);
            }
        }
        rows
    }
}

/// What every blend step reads of the collage: its grid, the dense camera plane `cam` (0 for
/// background, k + 1 for camera index k), the edge mask of `cam` (step 1) and the camera count.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout<'a> {
    /// The collage's grid.
    pub grid: Grid,
    /// Dense camera index + 1 per pixel, 0 for background.
    pub cam: &'a [u32],
    /// Edge pixels of `cam` ([`super::edges::edge_mask`]).
    pub edges: &'a [bool],
    /// How many cameras (the largest value in `cam`).
    pub cameras: usize,
}
